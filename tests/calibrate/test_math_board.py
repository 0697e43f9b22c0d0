"""The math board's layout (``calibrate.math_board``): the sheet's blocks with their lines as
they are, the per-touch blocks folded into A once it is there, no notes, everything escaped."""

from __future__ import annotations

import html
import re

import numpy as np

from tcp_pendant.calibrate.math_board import BOARD_FONT_PX, board_blocks, board_html
from tcp_pendant.calibrate.math_view import MathBlock, MathSheet, Shown

_BLOCK = re.compile(r'<div class="board-block" data-key="([^"]+)"')
_LINES = re.compile(r'<div class="board-lines"[^>]*>(.*?)</div>', re.S)


def _block(key: str, lines: tuple[str, ...], note: str = "") -> MathBlock:
    return MathBlock(key, f"({key})", f"the {key} block", lines, {"x": Shown(np.array(1.0), 2)}, note)


def test_touch_blocks_fold_into_a_and_notes_stay_off_the_board() -> None:
    sheet = MathSheet("xyz4", "XYZ 4-point", (
        _block("touch-1", ("R₁ = 1.00",)), _block("A", ("A =", "0.50 <b>", "rank 3 of 6"), note="a note"),
        _block("pair", ("σ = 1.00",))), "1 touch recorded. More words.")
    assert [b.key for b in board_blocks(sheet)] == ["A", "pair"]
    out = board_html(sheet)
    assert _BLOCK.findall(out) == ["A", "pair"]
    first = html.unescape(_LINES.findall(out)[0].replace("&nbsp;", " ")).split("<br>")
    assert first == ["A =", "0.50 <b>", "rank 3 of 6"]             # the lines as they are, escaped
    assert "<b>" not in out and "a note" not in out
    assert "1 touch recorded." in out and "More words" not in out
    assert f"font-size:{BOARD_FONT_PX}px" in out and BOARD_FONT_PX >= 20


def test_without_a_the_touch_blocks_stay_and_no_sheet_is_said_in_words() -> None:
    sheet = MathSheet("three_point", "Three-point <orientation>", (_block("eq7", ("t = 1.00",)),), "1 pose recorded.")
    assert _BLOCK.findall(board_html(sheet)) == ["eq7"]
    assert "Three-point &lt;orientation&gt;" in board_html(sheet)
    assert "No method with worked equations is open" in board_html(None)
