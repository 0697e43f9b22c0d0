""""The math" of an XYZ 4-point run in Debian's chromium: at 1400x900, then in presenter mode
at a projector's 1024x768. The equations are monospace, at least 17 px, and every block fits
the panel (no line cut off or scrolled away); the rank message shows after two touches and the
pseudo-inverse beside the joint least squares after four. Screenshots go to tmp_path."""

from __future__ import annotations

import re

import pytest

from support.pendant_page import TIMEOUT_MS, assert_not_blank
from support.wizard_page import open_calibrate, press, wait_text

pytestmark = [pytest.mark.browser, pytest.mark.timeout(1200)]     # software WebGL on a loaded machine
KEYS = ("touch-1", "touch-4", "A", "pair", "stack", "lstsq", "sphere")


def block(page, key: str):
    loc = page.locator(f'.math-block[data-key="{key}"]').filter(visible=True).first
    loc.wait_for(state="visible", timeout=TIMEOUT_MS)
    return loc


_MEASURE = """els => els.filter(e => e.offsetParent !== null).map(e => {
    const st = getComputedStyle(e), box = e.getBoundingClientRect();
    return {key: e.dataset.key, px: parseFloat(st.fontSize), family: st.fontFamily,
            fits: e.scrollWidth <= e.clientWidth + 1, right: box.right};
})"""


def check_legible(page, keys: tuple[str, ...], min_px: float) -> None:
    """Every shown block (one measurement in the page): monospace, at least ``min_px``, no line
    wider than the panel, nothing past the right edge of the window."""
    block(page, keys[-1])
    shown = {m["key"]: m for m in page.locator(".math-block").evaluate_all(_MEASURE)}
    assert set(keys) <= set(shown), (keys, list(shown))
    width = page.viewport_size["width"]
    for key, m in shown.items():
        assert m["px"] >= min_px and "monospace" in m["family"], m
        assert m["fits"], f"the {key} block is wider than the panel"
        assert m["right"] <= width, m


def test_xyz4_math_view_at_1400x900_and_in_presenter_mode(pendant_server, new_page, shot) -> None:
    server = pendant_server()
    page = new_page(server.url, width=1400, height=900)
    open_calibrate(page)
    press(page, "Start")
    for k in (1, 2):
        wait_text(page, f"Step {k} of 4")
        press(page, "Auto-touch")
    pair = block(page, "pair")
    assert "rank 2 of 3" in pair.inner_text().replace("\xa0", " ")
    wait_text(page, "normally a singular matrix and results in no solution")
    pair.scroll_into_view_if_needed()
    assert_not_blank(shot(page, "math_two_touches_1400x900"))
    for k in (3, 4):
        wait_text(page, f"Step {k} of 4")
        press(page, "Auto-touch")
    wait_text(page, "Against the true TOOL frame: good")
    lstsq = block(page, "lstsq")
    assert re.search(r"\|t − t_pinv\| = \d+\.\d\d mm", lstsq.inner_text().replace("\xa0", " "))
    check_legible(page, KEYS, 17.0)
    block(page, "stack").scroll_into_view_if_needed()
    assert_not_blank(shot(page, "math_xyz4_1400x900"))

    page.get_by_label("Presenter mode").first.check()
    page.locator(".presenter-readout").first.wait_for(state="visible", timeout=TIMEOUT_MS)
    page.set_viewport_size({"width": 1024, "height": 768})
    page.wait_for_timeout(500)
    check_legible(page, KEYS, 17.0)
    block(page, "pair").scroll_into_view_if_needed()
    assert_not_blank(shot(page, "math_xyz4_presenter_1024x768"))
    block(page, "lstsq").scroll_into_view_if_needed()
    shot(page, "math_xyz4_presenter_1024x768_lstsq")
