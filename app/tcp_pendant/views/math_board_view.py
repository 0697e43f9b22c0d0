"""Presenter mode's "Math board" (viser GUI): "The math" taking the whole screen.

A checkbox in the presenter folder; while it is ticked, an HTML element holds the open
wizard's sheet laid out for the board (``calibrate.math_board.board_html``) and the page script
(``serve/static/pendant.js``) shows a copy of it over the whole page, with a "Back to the pendant"
button that unticks the checkbox. In ``--shared`` mode every browser follows (the shared GUI).
It renders on the session's change signal when the ``wizard`` flag is set (a record, Back,
Finish, a variant change), never on a jog step, and only while ticked. Like "The math" panel it
reads the wizard's own poses only (never the hidden true tool). A language change re-labels the
checkbox and, while ticked, re-renders the board in the new language.
"""

from __future__ import annotations

from tcp_pendant.calibrate.math_board import BOARD_LABEL, board_html
from tcp_pendant.calibrate.math_view import math_sheet
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.translation import N_
from tcp_pendant.views.gui_util import CheckboxEvent, set_content, target_of

__all__ = ["BOARD_LABEL", "MathBoardView"]

_HINT = N_("The math of the open wizard over the whole screen, large, for the projector ('Back to the "
           "pendant' on the board ends it).")


class MathBoardView:
    """The "Math board" checkbox and the board's HTML, built in the current GUI container.

    Attributes:
        toggle, html: the widgets (for tests).
        renders: how many times the board was laid out.
    """

    def __init__(self, session: Session) -> None:
        self.session = session
        gui = target_of(session).gui
        _ = session.translator.gettext
        self.toggle = gui.add_checkbox(_(BOARD_LABEL), False, hint=_(_HINT))
        self.html = gui.add_html("", visible=False)
        self.renders = 0
        self.toggle.on_update(session.loop.on_loop(self._on_toggle))
        session.subscribe(self.on_change)

    @property
    def on(self) -> bool:
        return bool(self.toggle.value)

    def _on_toggle(self, _event: CheckboxEvent | None = None) -> None:
        self.render()

    def on_change(self, change: SessionChange) -> None:
        if change.language:
            _ = self.session.translator.gettext
            self.toggle.label, self.toggle.hint = _(BOARD_LABEL), _(_HINT)
        if self.on and (change.wizard or change.language):
            self.render()

    def render(self) -> None:
        """The board from the open wizard (hidden while the checkbox is off)."""
        if self.session.closed:
            return
        if not self.on:
            self.html.visible = False
            return
        wf = self.session.workflow
        wiz = None if wf is None or not wf.is_open else wf.wizard
        tr = self.session.translator
        sheet = None if wiz is None else math_sheet(wiz, tr=tr)
        self.renders += 1
        set_content(self.html, board_html(sheet, tr=tr))
        self.html.visible = True
