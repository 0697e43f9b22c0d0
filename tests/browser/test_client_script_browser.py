"""The page's own script in chromium (``serve/static/pendant.js``, ``tcp_pendant.serve.client_script``):
keyboard shortcuts that click the pendant's buttons, the trainee's name remembered across a
reload, the trainer view opened from ``/?trainer=TOKEN``, and "Shadows" off in a browser that
draws WebGL in software.

The pendant runs in this process (``PendantApp`` on a free port) so each key's effect is read
off the session's controller, workflow and classroom, not only off the page.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from tcp_pendant.pendant.hold import DEADMAN_S
from tcp_pendant.serve.server import PendantApp

from support.chromium_session import with_render_scale
from support.pendant_page import TIMEOUT_MS, assert_not_blank, field, type_text, wait_text, wait_until
from support.wsclient import loop_ran_for

pytestmark = pytest.mark.browser

TOKEN = "trainer-secret-4242"
AXES = ("X", "Y", "Z", "A", "B", "C")


def open_page(app: PendantApp, new_page: Callable[..., Any], url: str | None = None, **kw: Any) -> tuple[Any, Any]:
    """A chromium page on ``app`` (its script loaded) and the session it made."""
    n = len(app.sessions)
    page = new_page(url or app.url, **kw)
    page.wait_for_function("document.documentElement.dataset.tcpPendantScript === '1'", timeout=TIMEOUT_MS)
    wait_until(lambda: len(app.sessions) > n, "the page's session")
    return page, list(app.sessions.values())[-1]


def pose(session: Any) -> np.ndarray:
    with session.lock:
        return session.controller.T_world_tcp().copy()


def settled(session: Any, before: np.ndarray) -> np.ndarray:
    """The TCP pose once it moved away from ``before`` and stopped changing."""
    wait_until(lambda: not np.allclose(pose(session), before, atol=1e-9), "the robot to move")
    last = pose(session)
    while True:
        time.sleep(0.3)
        now = pose(session)
        if np.allclose(now, last, atol=1e-9):
            return now
        last = now


def expected_move(axis: str, sign: int, amount: float) -> tuple[np.ndarray, np.ndarray]:
    """(translation mm, rotation vector deg) of one press in the WORLD jog frame."""
    t, r = np.zeros(3), np.zeros(3)
    if axis in "XYZ":
        t["XYZ".index(axis)] = sign * amount
    else:
        r["CBA".index(axis)] = sign * amount         # A about Z, B about Y, C about X
    return t, r


def assert_moved(T0: np.ndarray, T1: np.ndarray, axis: str, sign: int, amount: float) -> None:
    t, r = expected_move(axis, sign, amount)
    np.testing.assert_allclose((T1[:3, 3] - T0[:3, 3]) * 1000.0, t, atol=0.02, err_msg=f"{axis} {sign:+d}")
    rot = Rotation.from_matrix(T1[:3, :3] @ T0[:3, :3].T).as_rotvec(degrees=True)
    np.testing.assert_allclose(rot, r, atol=0.01, err_msg=f"{axis} {sign:+d}")


def increment(session: Any) -> str:
    return str(session.jogger.settings.increment)


# ---------------------------------------------------------------------------------------------
def test_each_key_jogs_its_axis_by_the_increment_and_brackets_change_it(app_factory, new_page, shot) -> None:
    app = app_factory()
    page, s = open_page(app, new_page)
    assert s.jogger.settings.frame == "WORLD" and increment(s) == "10"
    wait_text(page, "Keys:")
    for row, axis in enumerate(AXES):
        for sign in (1, -1):
            T0 = pose(s)
            page.keyboard.press(f"Shift+Digit{row + 1}" if sign < 0 else f"Digit{row + 1}")
            assert_moved(T0, settled(s, T0), axis, sign, 10.0)
    # [ : the next smaller increment, ] : the next larger; the keys then jog by it
    page.keyboard.press("BracketLeft")
    wait_until(lambda: increment(s) == "1", "increment 1")
    T0 = pose(s)
    page.keyboard.press("Digit3")
    assert_moved(T0, settled(s, T0), "Z", 1, 1.0)
    page.keyboard.press("BracketLeft")
    wait_until(lambda: increment(s) == "0.1", "increment 0.1")
    page.keyboard.press("BracketLeft")                    # the smallest stays
    T0 = pose(s)
    page.keyboard.press("Shift+Digit1")
    assert_moved(T0, settled(s, T0), "X", -1, 0.1)
    assert increment(s) == "0.1"
    for want in ("1", "10", "100"):
        page.keyboard.press("BracketRight")
        wait_until(lambda want=want: increment(s) == want, f"increment {want}")
    # the Increment row shows the selection the keys made
    wait_text(page, "✓ 100")
    for size in ((1400, 900), (1024, 768)):
        page.set_viewport_size({"width": size[0], "height": size[1]})
        page.wait_for_timeout(500)
        assert_not_blank(shot(page, f"pendant_keys_{size[0]}x{size[1]}"), min_colors=200)


def test_cont_mode_holds_the_key_like_the_mouse_button(app_factory, new_page) -> None:
    app = app_factory()
    page, s = open_page(app, new_page)
    page.keyboard.press("BracketRight")                   # 10 -> 100
    wait_until(lambda: increment(s) == "100", "increment 100")
    page.keyboard.press("BracketRight")                   # 100 -> Cont.
    wait_until(lambda: increment(s) == "Cont.", "continuous mode")
    page.get_by_role("button", name="X +", exact=True).first.wait_for(state="visible", timeout=TIMEOUT_MS)
    # viser shows no tooltip for single buttons: the script names their keys in the native one
    page.wait_for_function("""() => {
        const b = [...document.querySelectorAll('button')];
        const t = n => (b.find(x => x.textContent.trim() === n) || {}).title;
        return t('X +') === 'Key 1' && t('X \u2212') === 'Key Shift+1' && t('C +') === 'Key 6'
            && t('Record point') === 'Key R';
    }""", timeout=TIMEOUT_MS)
    T0 = pose(s)
    page.keyboard.down("Digit1")
    wait_until(lambda: (pose(s)[0, 3] - T0[0, 3]) * 1000.0 > 20.0, "X to move 20 mm while the key is held")
    page.keyboard.up("Digit1")
    T1 = settled(s, T0)
    loop_ran_for(app.server.get_event_loop(), 1.5 * DEADMAN_S)   # every tick due meanwhile has run
    np.testing.assert_allclose(pose(s), T1, atol=1e-9)    # stopped at the release
    dx = (T1[:3, 3] - T0[:3, 3]) * 1000.0
    assert dx[0] > 20.0 and abs(dx[1]) < 0.05 and abs(dx[2]) < 0.05, dx


def test_the_record_key_records_a_free_touch_and_a_wizard_step(app_factory, new_page) -> None:
    app = app_factory()
    page, s = open_page(app, new_page)
    assert len(s.touches) == 0
    page.keyboard.press("r")
    wait_until(lambda: len(s.touches) == 1, "a free touch")
    page.keyboard.press("Enter")                           # nothing has the focus: Enter records too
    wait_until(lambda: len(s.touches) == 2, "a second free touch")
    # a wizard: the dock's Record (the step's) is what the key presses; far from the tip it asks first
    page.get_by_role("tab", name="Calibrate").click()
    page.get_by_role("button", name="Start", exact=True).first.click()
    wf = wait_until(lambda: s.workflow if s.workflow is not None and s.workflow.wizard is not None else None,
                    "a running wizard")
    page.get_by_role("tab", name="Jog").click()
    page.get_by_text("Step 1 of 4").filter(visible=True).first.wait_for(timeout=TIMEOUT_MS)
    assert len(wf.wizard.recorded_poses) == 0
    T0 = pose(s)
    page.keyboard.press("Digit3")                          # the jog keys work while the wizard runs
    assert_moved(T0, settled(s, T0), "Z", 1, 10.0)
    page.keyboard.press("r")
    wait_text(page, "mm from the reference tip")        # the check's question, nothing recorded
    assert len(wf.wizard.recorded_poses) == 0 and len(s.touches) == 2
    page.keyboard.press("r")                               # the second Record confirms
    wait_until(lambda: len(wf.wizard.recorded_poses) == 1, "the wizard's step recorded")
    np.testing.assert_allclose(wf.wizard.recorded_poses[0].T_world_flange_m, s.controller.T_world_flange(),
                               atol=1e-9)
    assert len(s.touches) == 2                             # the free list is untouched: one Record concept


def test_typing_in_a_field_does_not_jog(app_factory, new_page) -> None:
    app = app_factory()
    page, s = open_page(app, new_page)
    page.get_by_role("tab", name="Tool").click()
    T0 = pose(s)
    type_text(page, "New name", "r1[2]3")
    page.keyboard.press("Enter")
    page.keyboard.press("Shift+Digit2")
    typed = field(page, "New name").input_value()          # the field's last value: sent behind the keys
    wait_until(lambda: s.views["tools"].new_name.value == typed, "the field's value on the server")
    np.testing.assert_allclose(pose(s), T0, atol=1e-12)
    assert len(s.touches) == 0 and increment(s) == "10"
    # the same keys with the focus out of the field do act
    page.get_by_role("tab", name="Jog").click()
    page.keyboard.press("Digit2")
    assert_moved(T0, settled(s, T0), "Y", 1, 10.0)


def test_the_name_is_remembered_across_a_reload(app_factory, new_page, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN)
    page, s = open_page(app, new_page)
    welcome = page.get_by_text("Welcome to the TCP Pendant")
    welcome.wait_for(state="visible", timeout=TIMEOUT_MS)
    T0 = pose(s)
    page.evaluate("document.activeElement && document.activeElement.blur()")
    assert page.evaluate("!document.activeElement || document.activeElement === document.body")
    page.keyboard.press("Digit1")                         # the welcome window is open: keys do nothing
    page.keyboard.press("r")
    type_text(page, "Your name", "Anna 12")               # digits typed in the name do not jog either
    wait_until(lambda: s.views["identity"].name_field.value == "Anna 12",
               "the typed name on the server (sent behind the keys)")
    np.testing.assert_allclose(pose(s), T0, atol=1e-12)
    assert len(s.touches) == 0
    page.get_by_role("button", name="Join the class", exact=True).click()
    welcome.wait_for(state="hidden", timeout=TIMEOUT_MS)
    wait_text(page, "Trainee: Anna 12")
    np.testing.assert_allclose(pose(s), T0, atol=1e-12)
    page.wait_for_function("localStorage.getItem('tcpPendant.traineeName') === 'Anna 12'", timeout=TIMEOUT_MS)
    # a reload (a new connection, a new session): the page names itself, the server sees it
    n = len(app.sessions)
    page.reload()
    wait_until(lambda: len(app.sessions) >= n and s not in app.sessions.values(), "the old session closed")
    wait_text(page, "Trainee: Anna 12")
    page.get_by_text("Welcome to the TCP Pendant").wait_for(state="hidden", timeout=TIMEOUT_MS)
    wait_until(lambda: [t.name for t in app.classroom.trainee_statuses() if t.connected] == ["Anna 12"],
               "the reloaded page named in the class list")
    assert len({id(x) for x in app.sessions.values()}) == 1


def test_the_trainer_url_opens_the_trainer_view_and_leaves_the_address_bar(app_factory, new_page, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN)
    assert app.trainer_url == f"{app.url}/?trainer={TOKEN}"
    # a wrong token: no trainer view, the token gone from the address bar all the same
    page, s = open_page(app, new_page, f"{app.url}/?trainer=wrong-token-1")
    wait_text(page, "That trainer token is not right")
    assert "trainer" not in s.views
    assert "trainer" not in page.url and "wrong-token" not in page.url
    assert page.get_by_text("Download grades (CSV)").count() == 0
    # the printed address: the trainer view, and the address bar no longer holds the token
    page, s = open_page(app, new_page, app.trainer_url)
    wait_text(page, "Download grades (CSV)")
    page.get_by_text("Welcome to the TCP Pendant").wait_for(state="hidden", timeout=TIMEOUT_MS)
    assert "trainer" in s.views
    assert TOKEN not in page.url and "trainer=" not in page.url
    assert page.evaluate("location.href") == with_render_scale(app.url + "/")   # only the tests' own parameter left
    assert TOKEN not in page.evaluate("JSON.stringify(localStorage) + JSON.stringify(sessionStorage)")


def test_the_typed_token_still_works(app_factory, new_page, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="token with & and + and #")
    assert app.trainer_url.endswith("/?trainer=token%20with%20%26%20and%20%2B%20and%20%23")
    page, s = open_page(app, new_page, app.trainer_url)      # percent-encoded: the page reads it whole
    wait_text(page, "Download grades (CSV)")
    assert "trainer" in s.views
    page, s = open_page(app, new_page)                         # a trainee's welcome window: no trainer rows
    page.get_by_text("Join the class").first.wait_for(timeout=TIMEOUT_MS)
    page.wait_for_function("""() => [...document.querySelectorAll('button')].some(
        b => b.textContent.trim() === 'Open trainer view' && b.style.display === 'none')""", timeout=TIMEOUT_MS)
    assert page.get_by_text("Trainer token").is_hidden()
    assert page.get_by_role("button", name="Open trainer view", exact=True).is_hidden()
    assert page.get_by_text("Trainer: open").is_hidden()
    page, s = open_page(app, new_page, app.url + "/?trainer")   # the trainer's: the rows, the token typed
    type_text(page, "Trainer token", "token with & and + and #")
    page.wait_for_timeout(400)
    page.get_by_role("button", name="Open trainer view", exact=True).click()
    wait_text(page, "Download grades (CSV)")
    assert "trainer" in s.views


_HARDWARE_RENDERER = """
(() => {   // this page's WebGL says it runs on a graphics card (chromium here draws with SwiftShader)
  const UNMASKED_RENDERER_WEBGL = 0x9246;
  for (const C of [WebGLRenderingContext, WebGL2RenderingContext]) {
    const get = C.prototype.getParameter;
    C.prototype.getParameter = function (p) {
      return p === UNMASKED_RENDERER_WEBGL ? "ANGLE (NVIDIA, NVIDIA GeForce RTX 3060 Direct3D11 vs_5_0 ps_5_0)" : get.call(this, p);
    };
  }
})();
"""


def _shadows_decision(page: Any) -> str:
    """What the page's script decided for the Shadows checkbox ("off" or "kept"), once it did."""
    box = "[data-tcp-pendant-shadows]"
    page.wait_for_selector(box, state="attached", timeout=TIMEOUT_MS)
    return str(page.get_attribute(box, "data-tcp-pendant-shadows"))


def test_a_software_webgl_browser_turns_the_shadows_off_and_a_graphics_card_keeps_them(app_factory, new_page) -> None:
    from tcp_pendant.views.pendant_panel import SHADOWS_LABEL

    app = app_factory()
    page, s = open_page(app, new_page)
    renderer = page.evaluate("""() => { const gl = document.createElement('canvas').getContext('webgl');
        const i = gl.getExtension('WEBGL_debug_renderer_info'); return gl.getParameter(i.UNMASKED_RENDERER_WEBGL); }""")
    assert "swiftshader" in renderer.lower()                 # this machine's chromium: no GPU
    assert _shadows_decision(page) == "off"
    wait_until(lambda: s.views["pendant"].shadows.value is False, "the server told: shadows off")
    assert page.get_by_role("checkbox", name=SHADOWS_LABEL).is_checked() is False
    page.get_by_role("checkbox", name=SHADOWS_LABEL).click()          # the trainee may tick it again
    wait_until(lambda: s.views["pendant"].shadows.value is True, "shadows on again")
    # a page whose WebGL names a graphics card keeps them
    page2, s2 = open_page(app, new_page, init_script=_HARDWARE_RENDERER)
    assert _shadows_decision(page2) == "kept"
    assert page2.get_by_role("checkbox", name=SHADOWS_LABEL).is_checked() is True
    assert s2.views["pendant"].shadows.value is True
