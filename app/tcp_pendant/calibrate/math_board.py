""""The math" as a board for the projector: the whole sheet on the screen, large (no viser).

:func:`board_html` lays a :class:`~tcp_pendant.calibrate.math_view.MathSheet` out for the page
script's full-screen board (``serve/static/pendant.js``, presenter mode's "Math board"): the
method's title and what is recorded on top, then the blocks in newspaper columns
(``column-width`` of :data:`BOARD_COLUMN_CH` characters, so three at 1024 px), each block whole
in one column, its label over its monospace lines at :data:`BOARD_FONT_PX`, with
:data:`BOARD_LINE_HEIGHT`. The columns fill
one screen's height, left to right (``column-fill: auto``): at 1024x768 the current method's
sheet is in view without scrolling. To fit it, the board leaves out what the panel's view
says in addition: the notes (the lecturer says them) and, once the stacked matrix A is on the
sheet, the per-touch blocks (A holds every R_i). The numbers are the sheet's lines as they are
(``MathBlock.lines``); every text is escaped (``text_escape.escape_html``).

The board's words come in the session's language: the sheet's own (``math_view.math_sheet``'s
``tr``), the "no method" line and, as ``data-toggle`` and ``data-back`` attributes of the outer
``<div>``, the "Math board" checkbox's label and the "Back to the pendant" button's text: the
page script finds the checkbox and words its button by them.
"""

from __future__ import annotations

from tcp_pendant.calibrate.math_view import MathBlock, MathSheet
from tcp_pendant.text_escape import escape_html
from tcp_pendant.translation import ENGLISH, N_, Translator

__all__ = ["BACK_LABEL", "BOARD_CLASS", "BOARD_COLUMN_CH", "BOARD_FONT_PX", "BOARD_LABEL", "board_blocks",
           "board_html"]

BOARD_LABEL = N_("Math board")
"""The presenter's checkbox that shows the board (English msgid; shown translated)."""
BACK_LABEL = N_("Back to the pendant")
"""The board's button that unticks :data:`BOARD_LABEL` (English msgid; shown translated)."""

BOARD_CLASS = "math-board"
"""The class of the board's outer ``<div>`` (the page script shows it full screen)."""
BOARD_FONT_PX = 20
"""Font size of the board's equations and labels, pixels (at least 20 px on a projector)."""
BOARD_COLUMN_CH = 26
"""A column's width in characters of the monospace font: the longest line of a sheet
(``math_view.MAX_WIDE_LINE``); three columns fit 1024 px at :data:`BOARD_FONT_PX`."""
BOARD_LINE_HEIGHT = 1.08
"""Line height of the equations, in font sizes (the matrices' bracket pieces nearly join)."""
BOARD_LABEL_PX = 18
"""Font size of a block's label (its equation number, in sans-serif above the lines)."""


def board_blocks(sheet: MathSheet) -> tuple[MathBlock, ...]:
    """The blocks the board shows: the sheet's, without the per-touch ones once A is there."""
    folded = sheet.has("A")
    return tuple(b for b in sheet.blocks if not (folded and b.key.startswith("touch-")))


def _block(b: MathBlock) -> str:
    body = "<br>".join(escape_html(line).replace(" ", "&nbsp;") for line in b.lines)
    return (f'<div class="board-block" data-key="{escape_html(b.key)}" style="break-inside:avoid; '
            f'margin:0 0 6px 0">'
            f'<div class="board-label" style="font-family:sans-serif; font-weight:700; '
            f'font-size:{BOARD_LABEL_PX}px; line-height:1.2; color:#1c4e9c">{escape_html(b.label)}</div>'
            f'<div class="board-lines" style="font-family:monospace; font-size:{BOARD_FONT_PX}px; '
            f'line-height:{BOARD_LINE_HEIGHT}; white-space:nowrap">{body}</div></div>')


def _outer(tr: Translator, view: str = "") -> str:
    """The board's opening ``<div>``: its class, the view, the page script's two labels."""
    data_view = f' data-view="{escape_html(view)}"' if view else ""
    return (f'<div class="{BOARD_CLASS}"{data_view} data-toggle="{escape_html(tr.gettext(BOARD_LABEL))}" '
            f'data-back="{escape_html(tr.gettext(BACK_LABEL))}">')


def board_html(sheet: MathSheet | None, *, tr: Translator = ENGLISH) -> str:
    """The board's HTML (one ``<div class="math-board">``) for ``sheet`` (None: no method with
    equations is open, said in words), its own words in ``tr``'s language (the sheet's come in
    the sheet's)."""
    if sheet is None:
        words = escape_html(tr.gettext("No method with worked equations is open: start one in the Calibrate tab."))
        inner = f'<div class="board-title" style="font:{BOARD_FONT_PX}px sans-serif">{words}</div>'
        return f"{_outer(tr)}{inner}</div>"
    if sheet.headline:
        intro = sheet.headline
    else:
        intro = sheet.intro.split(". ")[0].rstrip(".") + "." if sheet.intro else ""
    title = (f'<div class="board-title" style="font:700 {BOARD_FONT_PX + 2}px/1.3 sans-serif; margin:0 0 8px 0; '
             f'white-space:nowrap; overflow:hidden; text-overflow:ellipsis">{escape_html(sheet.title)}'
             f'<span style="font-weight:400"> · {escape_html(intro)}</span></div>')
    blocks = "".join(_block(b) for b in board_blocks(sheet))
    columns = (f'<div class="board-columns" style="column-width:{BOARD_COLUMN_CH}ch; column-gap:18px; '
               f'column-fill:auto; height:calc(100vh - 60px); font-family:monospace; '
               f'font-size:{BOARD_FONT_PX}px">{blocks}</div>')
    return f"{_outer(tr, sheet.view)}{title}{columns}</div>"
