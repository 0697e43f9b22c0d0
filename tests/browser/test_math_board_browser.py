"""Presenter mode's "Math board" on a 1024x768 projector (``tcp-pendant --shared --presenter``,
Debian's chromium): ticked, "The math" of the open wizard covers the whole page, every block of
the method's sheet in view without scrolling, its equations monospace at 20 px or more; "Back
to the pendant" gives the pendant back. XYZ 4-point after four touches (the stacked A, its
singular values and rank) and three-point variant 1 (the straightened c2). Screenshots go to
tmp_path; the numbers themselves are checked against numpy in tests/calibrate/test_math_view.py.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool
from tcp_pendant.translation import PSEUDO_LANGUAGE, translator

from support.calib_helpers import true_frame
from support.pendant_page import TIMEOUT_MS, choose
from support.wizard_page import auto_touch_to_result, open_calibrate, press, wait_text

pytestmark = [pytest.mark.browser, pytest.mark.timeout(1200)]

MIN_FONT_PX = 20.0

_MEASURE = """() => {
    const board = document.getElementById('tcp-pendant-board');
    const blocks = [...board.querySelectorAll('.board-block')].map(e => {
        const box = e.getBoundingClientRect(), lines = e.querySelector('.board-lines');
        const st = getComputedStyle(lines);
        return {key: e.dataset.key, left: box.left, top: box.top, right: box.right, bottom: box.bottom,
                px: parseFloat(st.fontSize), family: st.fontFamily,
                fits: lines.scrollWidth <= lines.clientWidth + 1};
    });
    const cols = board.querySelector('.board-columns');
    return {blocks, width: innerWidth, height: innerHeight,
            scrolls: cols.scrollWidth > cols.clientWidth + 1 || board.scrollHeight > board.clientHeight + 1,
            board: board.getBoundingClientRect().toJSON(), text: board.innerText};
}"""


def board_in_view(page: Any, keys: tuple[str, ...]) -> str:
    """The board covers the window, shows exactly ``keys``' blocks, each inside the window,
    nothing scrolled away; returns the board's text."""
    last = page.locator(f'#tcp-pendant-board .board-block[data-key="{keys[-1]}"]')
    last.wait_for(state="visible", timeout=TIMEOUT_MS)
    m = page.evaluate(_MEASURE)
    assert m["board"]["width"] == m["width"] and m["board"]["height"] == m["height"], m["board"]
    assert tuple(b["key"] for b in m["blocks"]) == keys, [b["key"] for b in m["blocks"]]
    assert not m["scrolls"], "the board scrolls"
    for b in m["blocks"]:
        assert b["px"] >= MIN_FONT_PX and "monospace" in b["family"], b
        assert b["fits"], f"a line of {b['key']} is cut off"
        assert 0 <= b["left"] and b["right"] <= m["width"] and 0 <= b["top"] and b["bottom"] <= m["height"], b
    return str(m["text"]).replace("\xa0", " ")


def tick_board(page: Any) -> None:
    page.get_by_label("Math board").first.check()
    page.locator("#tcp-pendant-board").wait_for(state="visible", timeout=TIMEOUT_MS)


def test_xyz4_board_at_1024x768(pendant_server, new_page, shot) -> None:
    server = pendant_server("--shared", "--presenter")
    page = new_page(server.url, width=1024, height=768)
    open_calibrate(page)
    press(page, "Start")
    wait_text(page, "Step 1 of 4")
    press(page, "Auto-touch")
    tick_board(page)
    text = board_in_view(page, ("A",))
    assert "rank 3 of 6" in text and "1 touch recorded." in text
    for k in (2, 3, 4):                         # the board follows the touches
        page.locator("#tcp-pendant-board").get_by_role("button", name="Back to the pendant").click()
        page.locator("#tcp-pendant-board").wait_for(state="detached", timeout=TIMEOUT_MS)
        wait_text(page, f"Step {k} of 4")
        press(page, "Auto-touch")
        tick_board(page)
    wait_text(page, "Against the true TOOL frame: good")
    text = board_in_view(page, ("A", "pair", "stack", "lstsq", "sphere"))
    assert "rank 6 of 6" in text and "σ(A)" in text
    shot(page, "board_xyz4_1024x768")


def test_three_point_board_at_1024x768(pendant_server, new_page, shot, tmp_path: Path) -> None:
    tcp_true, _R, _abc = true_frame("torch")
    ToolLibrary(tmp_path / "tools.json").save(1, Tool(name="Torch", tcp_mm=tuple(tcp_true)))
    server = pendant_server("--shared", "--presenter", "--tool", "torch")
    page = new_page(server.url, width=1024, height=768)
    open_calibrate(page)
    choose(page, "Method", "Three-point orientation", "Calibrates the orientation of 1: Torch")
    press(page, "Start")
    auto_touch_to_result(page, 3)
    tick_board(page)
    text = board_in_view(page, ("eq7", "eq8-17", "eq18-24", "eq30"))
    assert "c2' =" in text and "3 poses recorded." in text
    shot(page, "board_three_point_1024x768")


def test_in_another_language_the_board_and_its_button_speak_it_and_the_button_still_unticks(
        pendant_server, new_page, shot) -> None:
    """The page script finds the "Math board" checkbox by its label in the pendant's language
    and words its button in it (the board's data-toggle and data-back; serve/static/pendant.js,
    9.): the pseudo-locale, whose words are nothing like English."""
    qps = translator(PSEUDO_LANGUAGE)
    server = pendant_server("--shared", "--presenter", "--language", PSEUDO_LANGUAGE)
    page = new_page(server.url, width=1024, height=768, wait_for=qps.gettext("Record point"))
    page.get_by_label(qps.gettext("Math board")).first.check()
    board = page.locator("#tcp-pendant-board")
    board.wait_for(state="visible", timeout=TIMEOUT_MS)
    back = board.get_by_role("button", name=qps.gettext("Back to the pendant"))
    assert back.count() == 1
    assert qps.gettext("No method with worked equations is open: start one in the Calibrate tab.") in board.inner_text()
    shot(page, "board_pseudo_locale_1024x768")
    back.click()
    board.wait_for(state="detached", timeout=TIMEOUT_MS)
    assert not page.get_by_label(qps.gettext("Math board")).first.is_checked()
