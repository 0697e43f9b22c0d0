""""The math" folder of the Calibrate tab (viser GUI): the open wizard's equations filled in
with this run's numbers (``calibrate.math_view``), next to its result and live while the
touches are recorded.

It renders on the session's change signal when the ``wizard`` flag is set (a record, an
auto-touch, Back, Finish, an estimator or variant change, a start or resume); never on a jog
step (``pose`` alone), so jogging costs nothing here. The sheet is the wizard's own poses and
data only: the hidden true tool is never read, so an exercise (``workflow.hide_truth``) shows the
trainee's numbers and nothing else. For the methods whose sheet shows a pair of touches
(``math_view.PAIR_VIEWS``) a "Pair (4P-2)" dropdown picks it (a view setting, default the last
two touches); it re-renders this folder only, and keeps its pair when the language changes. Lines are monospace text in markdown (why not
rendered images: ``calibrate.math_view``'s module docstring), ``MATH_FONT_PX`` high, legible in
the 320 px presenter panel on a 1024x768 projector. Its words are the session's language: a
language change (``SessionChange.language``) re-labels the folder and the dropdown and re-renders
the sheet.
"""

from __future__ import annotations

from tcp_pendant.calibrate.math_view import PAIR_VIEWS, MathSheet, math_markdown, math_sheet
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.views.gui_util import DropdownEvent, set_content, set_options, target_of

__all__ = ["LATEST_PAIR", "MathView"]

LATEST_PAIR = N_("last two touches")
"""The pair dropdown's first option (English msgid; shown translated)."""
_FOLDER = N_("The math")
_PAIR = N_("Pair (4P-2)")
_PAIR_HINT = N_("The two touches whose difference equation (lecture Eq. 7) is shown.")


def _pair_label(a: int, b: int, tr: Translator = ENGLISH) -> str:
    """A pair of 0-based steps as the dropdown shows it: ``"1 and 3"``."""
    return tr.gettext("{a} and {b}").format(a=a + 1, b=b + 1)


class MathView:
    """The "The math" folder (see the module docstring), built in the current GUI container.

    Attributes:
        folder, pair, md: the widgets (for tests).
        sheet: the sheet on show (None: no wizard open, or one without equations).
        renders: how many times the sheet was computed (tests: not on jog steps).
    """

    def __init__(self, session: Session) -> None:
        self.session = session
        gui = target_of(session).gui
        _ = session.translator.gettext
        self.folder = gui.add_folder(_(_FOLDER), visible=False)
        with self.folder:
            latest = _(LATEST_PAIR)
            self.pair = gui.add_dropdown(_(_PAIR), (latest,), initial_value=latest, visible=False, hint=_(_PAIR_HINT))
            self.md = gui.add_markdown("")
        self.sheet: MathSheet | None = None
        self.renders = 0
        self._pairs: dict[str, tuple[int, int]] = {}
        self.pair.on_update(session.loop.on_loop(self._on_pair))
        session.subscribe(self.on_change)
        self.render()

    def _on_pair(self, event: DropdownEvent) -> None:
        if getattr(event, "client", None) is not None:      # not our own assignment's echo
            self.render()

    def on_change(self, change: SessionChange) -> None:
        """Re-render on a wizard or language change only (not on a jog step)."""
        if change.language:
            _ = self.session.translator.gettext
            self.folder.label = _(_FOLDER)
            self.pair.label, self.pair.hint = _(_PAIR), _(_PAIR_HINT)
        if change.wizard or change.language:
            self.render()

    def render(self) -> None:
        """Show the open wizard's sheet (hide the folder when no wizard is open)."""
        if self.session.closed:
            return
        wf = self.session.workflow
        wiz = wf.wizard
        if wiz is None or not wf.is_open or getattr(type(wiz), "math_view", None) is None:
            self.folder.visible = False
            self.sheet = None
            return
        self.renders += 1
        tr = self.session.translator
        name = type(wiz).math_view
        pair = None
        if name in PAIR_VIEWS:
            chosen = self._pairs.get(str(self.pair.value))        # by the labels on show (any language)
            steps = [i for i in sorted(wiz.recorded_poses) if wiz.steps[i].role == "touch"]
            self._pairs = {_pair_label(a, b, tr): (a, b) for k, a in enumerate(steps) for b in steps[k + 1:]}
            keep = next((label for label, p in self._pairs.items() if p == chosen), tr.gettext(LATEST_PAIR))
            set_options(self.pair, (tr.gettext(LATEST_PAIR), *self._pairs), keep=keep)
            pair = self._pairs.get(str(self.pair.value))
        self.pair.visible = name in PAIR_VIEWS and len(self._pairs) > 1
        self.sheet = math_sheet(wiz, pair=pair, tr=tr)
        set_content(self.md, math_markdown(self.sheet, tr=tr))
        self.folder.visible = True
