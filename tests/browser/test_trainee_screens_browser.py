"""A trainee's first lesson on any screen, in chromium (issue 44's browser side).

* **Keys reach the pendant** after a click on a checkbox ("Hide distance"), a button
  ("Overview"), a dropdown ("Jog frame") and a slider ("Override %"): key 1 then jogs X + by the
  increment; in a text field it types and does not jog (the barrier: key 2 jogs Y + after the
  field lost the focus, and X has not moved). N and B step the open wizard.
* **In sight while a wizard runs**, at 1400x900 and 1024x768, no scrolling: the step's text, its
  Record, the touch feedback (the note after a Record), the twelve jog keys and the tip views'
  image all lie inside the viewport.
* **Touch screens** (``has_touch``, ``is_mobile``; a coarse pointer) at 820x1180 and 390x844:
  jog keys, Record and Next at least 44 CSS px tall, the "Keys:" line hidden; on the phone the
  reference tip, projected with the browser's own camera, lies in the viewport and outside the
  panel's bottom sheet.
* **A hold is a lease:** a touch held on a hold-to-jog key, then the page's main thread blocked
  2.5 s (a loaded browser: no renewal, the release queued) with the finger lifted during the
  block: no tick ran later than ``LEASE_S`` after the last renewal's arrival (server stamps), the
  late release and the renewal that came with it moved nothing.
* **The tip views find the tip** from 25 mm: the page shows them zoomed out (the orange frame)
  with the arrow or the tool in the tool colour.

Screenshots with a wizard open at the four sizes go to ``$UI_SHOTS_DIR`` when set
(``UI_SHOTS_DIR=docs/img pytest tests/browser/test_trainee_screens_browser.py -k screenshots``
writes the README's), else to the test's tmp_path.
"""

from __future__ import annotations

import io
import os
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.pendant.hold import LEASE_S
from tcp_pendant.pendant.tip_insets import TOOL_COLOR
from tcp_pendant.views import arrival

from support import chromium_session
from support.app_page import true_tip_at
from support.pendant_page import TIMEOUT_MS, assert_not_blank, choose, field, wait_until

pytestmark = pytest.mark.browser

DESKTOP = ((1400, 900), (1024, 768))
TOUCH = ((820, 1180), (390, 844))
JOG_KEYS = tuple(f"{ax} {s}" for ax in "XYZABC" for s in ("−", "+"))


def open_page(browser: Any, app: Any, size: tuple[int, int], *, touch: bool = False) -> tuple[Any, Any, Any]:
    """A fresh context and page on ``app`` at ``size`` (a touch device when ``touch``), its session."""
    before = set(app.sessions)
    options: dict[str, Any] = {"viewport": {"width": size[0], "height": size[1]}}
    if touch:
        options.update(has_touch=True, is_mobile=True)
    ctx = browser.new_context(**options)
    page = ctx.new_page()
    page.set_default_timeout(TIMEOUT_MS)
    page.goto(chromium_session.with_render_scale(app.url))
    page.get_by_role("button", name="Record point").first.wait_for(state="attached", timeout=TIMEOUT_MS)
    new = wait_until(lambda: set(app.sessions) - before, "the page's session")
    (sid,) = new
    page.locator("[data-tcp-pendant-script]").wait_for(state="attached", timeout=TIMEOUT_MS)
    return ctx, page, app.sessions[sid]


def tcp_mm(s: Any) -> np.ndarray:
    with s.lock:
        return s.controller.T_world_tcp()[:3, 3] * 1000.0


def open_wizard(s: Any, page: Any) -> None:
    """XYZ 4-point at step 2 (one auto touch), the tool tip 3.5 mm off the reference tip."""
    with ThreadPoolExecutor(max_workers=1) as pool:
        pool.submit(lambda: (s.wizard_commands.start("xyz4"), s.wizard_commands.auto_touch(AutoTouchRequest()))).result()
    true_tip_at(s, (1.5, -1.0, 3.0))
    page.get_by_text("Step 2 of 4").first.wait_for(state="visible", timeout=TIMEOUT_MS)


def close_toasts(page: Any) -> None:
    """viser's "Software WebGL rendering detected" notice (a software renderer only)."""
    for b in page.locator(".mantine-Notification-root button").all():
        try:
            b.click(timeout=2000)
        except Exception:
            pass


def box_inside(page: Any, locator: Any, size: tuple[int, int], what: str) -> dict[str, float]:
    locator.wait_for(state="visible", timeout=TIMEOUT_MS)
    b = locator.bounding_box()
    assert b is not None, f"{what}: no box"
    w, h = size
    assert b["x"] >= 0 and b["y"] >= 0 and b["x"] + b["width"] <= w + 0.5 and b["y"] + b["height"] <= h + 0.5, \
        f"{what} at {w}x{h}: {b} not inside the viewport"
    return b


# ------------------------------------------------------------------ keys
def test_keys_reach_the_pendant_after_a_click_on_any_control(app_factory, browser) -> None:
    app = app_factory()
    ctx, page, s = open_page(browser, app, (1400, 900))
    try:
        def jogged_by_key(what: str) -> None:
            x0 = tcp_mm(s)
            page.keyboard.press("1")
            wait_until(lambda: tcp_mm(s)[0] > x0[0] + 9.0, f"key 1 jogged X + after a click on {what}")

        box = field(page, "Hide distance")
        box.click()
        assert page.evaluate("document.activeElement && document.activeElement.type") == "checkbox"
        jogged_by_key("the checkbox")
        page.get_by_role("button", name="Overview", exact=True).first.click()
        jogged_by_key("a button")
        choose(page, "Jog frame", "WORLD")
        jogged_by_key("a dropdown")
        slider = page.locator(".mantine-Slider-root").filter(visible=True).first
        slider.click()
        jogged_by_key("a slider")
        # a text field keeps the keys: "1" is typed, no jog; then (focus gone) "2" jogs Y +
        text_field = page.locator("input[type=text], input:not([type]), input[type=number]").filter(visible=True).first
        text_field.click()
        p0 = tcp_mm(s)
        page.keyboard.press("1")
        page.evaluate("document.activeElement.blur()")
        page.keyboard.press("2")
        wait_until(lambda: tcp_mm(s)[1] > p0[1] + 9.0, "key 2 jogged Y + once the field lost the focus")
        assert abs(tcp_mm(s)[0] - p0[0]) < 1e-6, "key 1 jogged while a text field had the focus"
        # N and B step the wizard
        open_wizard(s, page)
        page.keyboard.press("b")
        page.get_by_text("Step 1 of 4").first.wait_for(state="visible", timeout=TIMEOUT_MS)
        page.keyboard.press("n")
        page.get_by_text("Step 2 of 4").first.wait_for(state="visible", timeout=TIMEOUT_MS)
    finally:
        ctx.close()


# ------------------------------------------------------------------ layout
@pytest.mark.parametrize("size", DESKTOP, ids=lambda s: f"{s[0]}x{s[1]}")
def test_step_record_feedback_keys_and_tip_views_in_sight_with_a_wizard_open(app_factory, browser,
                                                                             size) -> None:
    app = app_factory()
    ctx, page, s = open_page(browser, app, size)
    try:
        open_wizard(s, page)
        with s.lock:
            s.set_hide_distance(True)
        page.get_by_role("button", name="Record", exact=True).first.click()       # the touch feedback
        page.get_by_text("recorded").first.wait_for(state="visible", timeout=TIMEOUT_MS)
        page.get_by_text("Step 2 of 4").first.wait_for(state="visible", timeout=TIMEOUT_MS)
        scroll = page.evaluate("[...document.querySelectorAll('.mantine-ScrollArea-viewport')]"
                               ".map(e => e.scrollTop).reduce((a, b) => a + b, 0)")
        assert scroll == 0
        box_inside(page, page.get_by_text("Step 2 of 4").first, size, "the step")
        box_inside(page, page.get_by_role("button", name="Record", exact=True).first, size, "Record")
        box_inside(page, page.get_by_text("recorded").first, size, "the touch feedback")
        box_inside(page, page.get_by_role("button", name="Next ▶", exact=True).first, size, "Next")
        for name in JOG_KEYS:
            box_inside(page, page.get_by_role("button", name=name, exact=True).first, size, f"key {name}")
        img = box_inside(page, page.locator("[data-tcp-pendant-tipviews] img").first, size, "the tip views")
        assert img["width"] >= 300, img                     # both views, near their own size
    finally:
        ctx.close()


@pytest.mark.parametrize("hidden", [True, False], ids=["distance hidden", "distance shown"])
@pytest.mark.parametrize("size", DESKTOP, ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_estimate_button_leaves_record_keys_and_tip_views_in_sight(app_factory, browser, size, hidden) -> None:
    """At step 3 (two touches) the dock adds "Tilt about the wizard's estimate": it, Record,
    Next, the jog keys and the tip views are all in sight without scrolling, with the distance
    hidden or shown."""
    app = app_factory()
    ctx, page, s = open_page(browser, app, size)
    try:
        with s.lock:
            s.set_hide_distance(hidden)
        with ThreadPoolExecutor(max_workers=1) as pool:
            pool.submit(lambda: (s.wizard_commands.start("xyz4"), s.wizard_commands.auto_touch(AutoTouchRequest()),
                                 s.wizard_commands.auto_touch(AutoTouchRequest(tilt_deg=45.0, azimuth_deg=0.0)))).result()
        true_tip_at(s, (1.5, -1.0, 3.0))
        page.get_by_text("Step 3 of 4").first.wait_for(state="visible", timeout=TIMEOUT_MS)
        button = page.get_by_role("button", name="Tilt about the wizard's estimate", exact=True).first
        button.wait_for(state="visible", timeout=TIMEOUT_MS)
        box_inside(page, button, size, "the estimate button")
        box_inside(page, page.get_by_role("button", name="Record", exact=True).first, size, "Record")
        box_inside(page, page.get_by_role("button", name="Next ▶", exact=True).first, size, "Next")
        for name in JOG_KEYS:
            box_inside(page, page.get_by_role("button", name=name, exact=True).first, size, f"key {name}")
        box_inside(page, page.locator("[data-tcp-pendant-tipviews] img").first, size, "the tip views")
        button.click()
        wait_until(lambda: s.controller.active_tool is not None, "the estimate active")
        assert s.controller.active_tool.name == "Estimate, 2 touches"
    finally:
        ctx.close()


# ------------------------------------------------------------------ touch
def reference_tip_on_screen(s: Any, page: Any) -> tuple[float, float]:
    """The reference tip in CSS px, projected with the browser's camera (viser's report)."""
    from scipy.spatial.transform import Rotation

    cam = s.client.camera
    p = np.asarray(s.controller.reference_tip_world_m, dtype=float)
    w, x, y, z = cam.wxyz
    R = Rotation.from_quat([x, y, z, w]).as_matrix()            # camera to world, OpenCV axes
    pc = R.T @ (p - np.asarray(cam.position))
    vw, vh = page.viewport_size["width"], page.viewport_size["height"]
    f = 0.5 * vh / np.tan(0.5 * cam.fov)
    return vw / 2 + f * pc[0] / pc[2], vh / 2 + f * pc[1] / pc[2]


@pytest.mark.parametrize("size", TOUCH, ids=lambda s: f"{s[0]}x{s[1]}")
def test_touch_screens_big_keys_no_keys_line_and_the_tip_in_view(app_factory, browser, size) -> None:
    app = app_factory()
    ctx, page, s = open_page(browser, app, size, touch=True)
    try:
        assert page.evaluate("matchMedia('(pointer: coarse)').matches")
        open_wizard(s, page)
        for name in (*JOG_KEYS, "Record", "Next ▶"):
            b = page.get_by_role("button", name=name, exact=True).first.bounding_box()
            assert b is not None and b["height"] >= 44.0 - 0.01, f"{name} at {size}: {b}"
        line = page.locator("[data-tcp-pendant-keys-line]").first
        line.wait_for(state="attached", timeout=TIMEOUT_MS)
        assert not line.is_visible(), "the keys line is shown on a touch screen"
        if size[0] < 600:                                   # the phone: the sheet leaves the tip in view
            sheet = page.locator(".mantine-Paper-root[style*='position: fixed']").first.bounding_box()
            wait_until(lambda: s.client.camera.fov > 0, "the browser's camera")
            u, v = reference_tip_on_screen(s, page)
            assert 0 <= u <= size[0] and 0 <= v <= size[1], (u, v)
            assert v < sheet["y"] or u < sheet["x"], f"reference tip at ({u:.0f}, {v:.0f}) under the sheet {sheet}"
    finally:
        ctx.close()


def test_a_held_key_released_late_moves_no_further_than_its_lease(app_factory, browser) -> None:
    app = app_factory()
    ctx, page, s = open_page(browser, app, TOUCH[0], touch=True)
    try:
        panel = s.views["pendant"]
        renewals: list[float] = []
        ticks: list[tuple[float, float]] = []
        on_hold, hold_step = panel._on_hold, panel._hold_step

        def watched_hold(axis: Any, sign: int) -> None:
            renewals.append(arrival.arrived_s() or time.monotonic())
            on_hold(axis, sign)

        def watched_step(axis: Any, sign: int) -> Any:
            res = hold_step(axis, sign)
            ticks.append((time.monotonic(), float(tcp_mm(s)[0])))
            return res

        panel._on_hold, panel._hold_step = watched_hold, watched_step
        page.get_by_role("button", name="Cont.", exact=True).first.click()
        key = page.locator("button[id]").filter(has_text="X +").filter(visible=True).first
        key.wait_for(state="visible", timeout=TIMEOUT_MS)
        with s.lock:
            s.jogger.settings = s.jogger.settings.with_(override_pct=10)
        key.scroll_into_view_if_needed()
        b = key.bounding_box()
        cdp = ctx.new_cdp_session(page)
        point = [{"x": b["x"] + b["width"] / 2, "y": b["y"] + b["height"] / 2}]
        x0 = float(tcp_mm(s)[0])
        cdp.send("Input.dispatchTouchEvent", {"type": "touchStart", "touchPoints": point})
        wait_until(lambda: len(ticks) >= 3, "the held key moving")
        # the loaded browser: its main thread blocked 2.5 s, the finger lifted meanwhile
        page.evaluate("() => { setTimeout(() => { const t = performance.now(); while (performance.now() - t < 2500) {} }, 0); }")
        cdp.send("Input.dispatchTouchEvent", {"type": "touchEnd", "touchPoints": []})
        wait_until(lambda: panel._hold is not None and panel._hold.key is None and panel._hold.lapsed is None,
                   "the late release", timeout=60)
        hold = panel._hold
        last_tick = max(t for t, _ in ticks)
        in_time = [r for r in renewals if r <= last_tick]
        print(f"{len(renewals)} renewals, {len(ticks)} ticks; moved {ticks[-1][1] - x0:.2f} mm; the last tick "
              f"{last_tick - in_time[-1]:+.3f} s after the renewal before it")
        assert last_tick - in_time[-1] <= LEASE_S + 1e-6        # by the stamps (the server's clock)
        assert hold.last_tick_s is not None and hold.last_tick_s <= in_time[-1] + LEASE_S + 1e-6
        assert abs(float(tcp_mm(s)[0]) - ticks[-1][1]) < 1e-9      # nothing after the last tick
        late = [r for r in renewals if r > last_tick + LEASE_S]
        print(f"{len(late)} renewals arrived after the lease ran out; they moved nothing")
    finally:
        ctx.close()


# ------------------------------------------------------------------ tip views from afar
def test_the_tip_views_zoom_out_and_point_the_way_from_25_mm(app_factory, browser) -> None:
    from PIL import Image

    app = app_factory()
    ctx, page, s = open_page(browser, app, (1400, 900))
    try:
        true_tip_at(s, (25.0, 0.0, 5.0))
        page.get_by_text("zoomed out").first.wait_for(state="visible", timeout=TIMEOUT_MS)
        img = page.locator("[data-tcp-pendant-tipviews] img").first

        def shot() -> Any:
            a = np.asarray(Image.open(io.BytesIO(img.screenshot())).convert("RGB")).astype(int)
            tool = np.all(np.abs(a - np.array(TOOL_COLOR)) <= 40, axis=2)
            frame = np.all(np.abs(a - np.array((240, 140, 0))) <= 40, axis=2)
            return a if tool.sum() > 50 and frame.sum() > 200 else None

        a = wait_until(shot, "the zoomed-out views with the arrow")
        tool = np.all(np.abs(a - np.array(TOOL_COLOR)) <= 40, axis=2)
        half = a.shape[1] // 2
        cols = np.nonzero(tool[:, :half])[1]
        assert cols.size > 20, "no arrow in the front view"
        assert cols.mean() > half / 2 + 20, "the front view's arrow does not point to +X (right of the reference tip)"
    finally:
        ctx.close()


# ------------------------------------------------------------------ screenshots
@pytest.mark.parametrize("size", DESKTOP + TOUCH, ids=lambda s: f"{s[0]}x{s[1]}")
def test_screenshots_with_a_wizard_open(app_factory, browser, tmp_path, size) -> None:
    out = Path(os.environ.get("UI_SHOTS_DIR") or tmp_path)
    out.mkdir(parents=True, exist_ok=True)
    app = app_factory()
    ctx, page, s = open_page(browser, app, size, touch=size in TOUCH)
    try:
        open_wizard(s, page)
        page.locator("[data-tcp-pendant-tipviews] img").first.wait_for(state="visible", timeout=TIMEOUT_MS)
        close_toasts(page)
        if size not in TOUCH:
            page.mouse.move(5, 5)                            # no hint over the panel in the shot
        page.wait_for_timeout(1500)                          # the 3D view drawn (software WebGL)
        png = out / f"wizard_{size[0]}x{size[1]}.png"
        page.screenshot(path=str(png))
        assert_not_blank(png)
    finally:
        ctx.close()
