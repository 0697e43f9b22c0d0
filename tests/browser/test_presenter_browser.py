"""Presenter mode in a real browser at a projector's 1024x768: the readout's
numbers are >= 28 px by computed style, the panel leaves the scene about 70 % of the width, the
step list marks the running wizard's step; switched off in the GUI, the panel is wide again."""

from __future__ import annotations


import pytest

from support.pendant_page import TIMEOUT_MS, assert_not_blank, press
from support.wizard_page import wait_text as wait_visible_text

from tcp_pendant.calibrate import AutoTouchRequest

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


# Every text uPlot writes on a canvas (its tick labels are drawn, not DOM), per canvas, since
# the canvas was last cleared whole (a redraw starts with clearRect of the whole canvas).
_RECORD_CANVAS_TEXT = """
(() => {
  const P = CanvasRenderingContext2D.prototype, fill = P.fillText, clear = P.clearRect;
  window.__canvasTexts = new Map();
  P.clearRect = function (x, y, w, h) {
    if (x <= 0 && y <= 0 && w >= this.canvas.width && h >= this.canvas.height) window.__canvasTexts.set(this.canvas, []);
    return clear.apply(this, arguments);
  };
  P.fillText = function (text) {
    const list = window.__canvasTexts.get(this.canvas) || [];
    list.push(String(text));
    window.__canvasTexts.set(this.canvas, list);
    return fill.apply(this, arguments);
  };
})();
"""


def _presenter_folder(page):
    return page.locator(".presenter-readout").first.locator(
        "xpath=ancestor::div[contains(@class,'mantine-Paper-root')][1]")


def test_presenter_block_stays_pinned_with_its_chart_above_the_fold(app_factory, new_page, shot) -> None:
    """1024x768, ``--shared --presenter``, a 4-point result of exact Auto-touches (all errors
    ~0; driven on the in-process server, as the Calibrate tab's buttons do): the panel scrolled
    to the wizard's buttons, the presenter block is still at the top, its chart inside the
    viewport with distinct tick labels and a legend without '--' placeholders; the Close button
    shows below the block, nothing sticks out at the side."""
    app = app_factory(shared=True, presenter=True)
    page = new_page(app.url, width=1024, height=768, wait_for="")
    page.add_init_script(_RECORD_CANVAS_TEXT)
    page.reload()
    _check_pinned_block(app, page, shot)


def _check_pinned_block(app, page, shot) -> None:
    page.locator(".presenter-readout").first.wait_for(state="visible", timeout=TIMEOUT_MS)
    folder = _presenter_folder(page)
    page.get_by_role("tab", name="Calibrate").click()
    s = app.shared_session
    s.wizard_commands.start("xyz4")
    for _ in range(4):
        assert s.wizard_commands.auto_touch(AutoTouchRequest()).ok
    wait_visible_text(page, "Against the true TOOL frame: good")
    chart = folder.locator(".uplot-container").first
    chart.locator("canvas").first.wait_for(state="visible", timeout=TIMEOUT_MS)
    top_before = folder.bounding_box()["y"]
    close = page.get_by_role("button", name="Close (not saved)", exact=True).filter(visible=True).first
    close.evaluate("e => e.scrollIntoView({block: 'end'})")
    page.wait_for_timeout(500)
    scrolled = float(page.locator(".mantine-ScrollArea-viewport").first.evaluate("e => e.scrollTop"))
    assert scrolled > 100.0, "the panel did not scroll"
    box, c_box, b_box = folder.bounding_box(), chart.locator("canvas").first.bounding_box(), close.bounding_box()
    assert 40.0 <= box["y"] <= top_before + 2.0, (box, top_before)          # pinned at the top
    assert c_box["y"] >= 0 and c_box["y"] + c_box["height"] <= 768, c_box   # the chart above the fold
    assert b_box["y"] >= box["y"] + box["height"] - 1 and b_box["y"] + b_box["height"] <= 769   # Close shows
    assert b_box["x"] + b_box["width"] <= 1024 and box["x"] + box["width"] <= 1024        # nothing off the side
    legend = chart.locator(".u-legend").first.inner_text()
    assert "error (mm)" in legend and "--" not in legend, legend
    ticks = chart.evaluate("""e => {
        const c = e.querySelector('canvas');
        return (window.__canvasTexts.get(c) || []).slice();
    }""")
    numbers = [t for t in ticks if t.strip().replace(".", "", 1).isdigit()]
    y_ticks = [t for t in numbers if float(t) < 1.0 or t == "0"]
    print("presenter chart labels:", ticks)
    assert len(y_ticks) >= 2 and len(set(numbers)) == len(numbers), ticks   # no "0.001, 0.001, 0.001, 0"
    assert_not_blank(shot(page, "presenter_pinned_1024x768"))
