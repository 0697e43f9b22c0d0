""""The math" folder of the Calibrate tab (viser GUI): the open wizard's equations filled in
with this run's numbers (``calibrate.math_view``), next to its result and live while the
touches are recorded.

It renders on the session's change signal when the ``wizard`` flag is set (a record, an
auto-touch, Back, Finish, an estimator or variant change, a start or resume); never on a jog
step (``pose`` alone), so jogging costs nothing here. The sheet is the wizard's own poses and
data only: the hidden true tool is never read, so an exercise (``workflow.hide_truth``) shows the
trainee's numbers and nothing else. For the methods whose sheet shows a pair of touches
(``math_view.PAIR_VIEWS``) a "Pair (4P-2)" dropdown picks it (a view setting, default the last
two touches); it re-renders this folder only. Lines are monospace text in markdown (why not
rendered images: ``calibrate.math_view``'s module docstring), ``MATH_FONT_PX`` high, legible in
the 320 px presenter panel on a 1024x768 projector.
"""

from __future__ import annotations

from tcp_pendant.calibrate.math_view import PAIR_VIEWS, MathSheet, math_markdown, math_sheet
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.views.gui_util import DropdownEvent, set_content, set_options, target_of

__all__ = ["LATEST_PAIR", "MathView"]

LATEST_PAIR = "last two touches"


def _pair_label(a: int, b: int) -> str:
    return f"{a + 1} and {b + 1}"


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
        self.folder = gui.add_folder("The math", visible=False)
        with self.folder:
            self.pair = gui.add_dropdown("Pair (4P-2)", (LATEST_PAIR,), initial_value=LATEST_PAIR, visible=False,
                                         hint="The two touches whose difference equation (lecture Eq. 7) is shown.")
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
        """Re-render on a wizard change only (not on a jog step)."""
        if change.wizard:
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
        name = type(wiz).math_view
        pair = None
        if name in PAIR_VIEWS:
            steps = [i for i in sorted(wiz.recorded_poses) if wiz.steps[i].role == "touch"]
            self._pairs = {_pair_label(a, b): (a, b) for k, a in enumerate(steps) for b in steps[k + 1:]}
            set_options(self.pair, (LATEST_PAIR, *self._pairs))
            pair = self._pairs.get(str(self.pair.value))
        self.pair.visible = name in PAIR_VIEWS and len(self._pairs) > 1
        self.sheet = math_sheet(wiz, pair=pair)
        set_content(self.md, math_markdown(self.sheet))
        self.folder.visible = True
