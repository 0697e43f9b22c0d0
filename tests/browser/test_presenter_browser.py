"""Presenter mode in a real browser at a projector's 1024x768: the readout's
numbers are >= 28 px by computed style, the panel leaves the scene about 70 % of the width, the
step list marks the running wizard's step; switched off in the GUI, the panel is wide again."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from pendant_page import TIMEOUT_MS, assert_not_blank, press, wait_text  # noqa: E402

pytestmark = pytest.mark.browser


def _canvas_width(page) -> float:
    return max(b["width"] for b in (c.bounding_box() for c in page.locator("canvas").all()) if b)


def _wait_canvas(page, cond, what: str) -> float:
    for _ in range(60):
        w = _canvas_width(page)
        if cond(w):
            return w
        page.wait_for_timeout(100)
    raise AssertionError(f"{what}: the scene is {w} px wide")


def test_presenter_mode_at_1024x768(pendant_server, new_page, shot) -> None:
    server = pendant_server("--shared", "--presenter")
    page = new_page(server.url, width=1024, height=768)
    readout = page.locator(".presenter-readout").first
    readout.wait_for(state="visible", timeout=TIMEOUT_MS)
    px = float(readout.evaluate("e => parseFloat(getComputedStyle(e).fontSize)"))
    family = str(readout.evaluate("e => getComputedStyle(e).fontFamily"))
    assert px >= 28.0 and "monospace" in family
    assert "X" in readout.inner_text() and "mm" in readout.inner_text()
    box = readout.bounding_box()
    assert box is not None and box["x"] + box["width"] <= 1024      # the numbers are not cut off
    wide_scene = _wait_canvas(page, lambda w: w >= 0.66 * 1024, "presenter panel narrow")
    # the running wizard's steps, the current one marked
    page.get_by_role("tab", name="Calibrate").click()
    press(page, "Start")
    current = page.locator(".presenter-steps .current-step").first
    current.wait_for(state="visible", timeout=TIMEOUT_MS)
    assert current.inner_text().startswith("▶ 1.")
    steps_px = float(page.locator(".presenter-steps").first.evaluate("e => parseFloat(getComputedStyle(e).fontSize)"))
    assert steps_px >= 18.0
    png = shot(page, "presenter_1024x768")
    assert_not_blank(png)
    # switched off in the GUI: no big readout, the usual wide panel
    page.get_by_label("Presenter mode").first.uncheck()
    page.locator(".presenter-readout").first.wait_for(state="hidden", timeout=TIMEOUT_MS)
    _wait_canvas(page, lambda w: w < wide_scene - 30, "normal panel wide again")
    shot(page, "presenter_off_1024x768")
    page.get_by_label("Presenter mode").first.check()
    readout.wait_for(state="visible", timeout=TIMEOUT_MS)
    page.set_viewport_size({"width": 1400, "height": 900})
    page.wait_for_timeout(500)
    shot(page, "presenter_1400x900")
