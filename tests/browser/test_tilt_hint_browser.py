"""The dock's tilt hint in chromium at 1400x900 and 1024x768: the whole hint and the reachable
tilts are on the page in full (no ellipsis, nothing clipped: the element's box holds its text),
after two touches of an XYZ 4-point; screenshots in the test's tmp_path."""

from __future__ import annotations

import pytest

from support.pendant_page import TIMEOUT_MS, wait_until

from tcp_pendant.calibrate import AutoTouchRequest

pytestmark = pytest.mark.browser

_BOX = """() => {
  const el = [...document.querySelectorAll('div')].find(d => d.children.length <= 1 && d.innerText
      && d.innerText.startsWith('Tilt next:'));
  if (!el) return null;
  const s = getComputedStyle(el);
  return {text: el.innerText, scroll: el.scrollWidth, client: el.clientWidth, sh: el.scrollHeight,
          ch: el.clientHeight, overflow: s.textOverflow, wrap: s.whiteSpace};
}"""


@pytest.mark.parametrize("size", [(1400, 900), (1024, 768)])
def test_the_tilt_hint_is_shown_in_full(app_factory, new_page, shot, size) -> None:
    app = app_factory()
    page = new_page(app.url, width=size[0], height=size[1])
    wait_until(lambda: app.sessions, "the page's session")
    (s,) = app.sessions.values()
    with s.lock:
        s.wizard_commands.start("xyz4")
        for _ in range(2):
            assert s.wizard_commands.auto_touch(AutoTouchRequest()).ok
        s.changed(wizard=True, pose=True)
    page.wait_for_function(f"({_BOX})() !== null", timeout=TIMEOUT_MS)
    box = page.evaluate(_BOX)
    shot(page, f"tilt_hint_{size[0]}x{size[1]}")
    assert box["overflow"] != "ellipsis" and box["wrap"] != "nowrap", box
    assert box["scroll"] <= box["client"] + 1 and box["sh"] <= box["ch"] + 1, box   # nothing clipped
    assert "(key " in box["text"] and "Reachable 45° tilts, tip held (WORLD):" in box["text"], box
    assert "…" not in box["text"]
