""""Record point" and the list of captured touches, each deletable (viser GUI), and "Export
CSV": the touches as POSES.csv (docs/cli.md; ``name,x,y,z,a,b,c,j1..jN``: the flange pose in
WORLD, mm and KUKA A, B, C in degrees, and the joint values in degrees / mm) sent to the browser
that clicked, ready for ``tcpcal solve xyz4``."""

from __future__ import annotations

from collections.abc import Callable, Coroutine, Sequence

import numpy as np
import viser
from scipy.spatial.transform import Rotation

from tcp_pendant.calibrate.text import empty_touches_markdown
from tcp_pendant.pendant.guidance import tip_offset_mm
from tcp_pendant.pendant.touch_feedback import touch_feedback
from tcp_pendant.session import Session, SessionChange, Touch
from tcp_pendant.translation import N_
from tcp_pendant.views.gui_util import ButtonEvent, client_of, set_content, target_of

__all__ = ["RECORD_POINT", "TOUCHES_FILENAME", "TouchListView", "touches_csv_text"]

RECORD_POINT = N_("Record point")
"""The button's English label; the page's script finds it in the session's language by the
pendant panel's hidden labels (``data-record-point``)."""

TOUCHES_FILENAME = "touches.csv"


def touches_csv_text(touches: Sequence[Touch]) -> str:
    """POSES.csv of the touches (layout ``kuka``): ``name,x,y,z,a,b,c`` and ``j1..jN`` when
    every touch has N joint values. Numbers written in full (``repr``), so a solve of the file
    reproduces the session's poses exactly; names are the touch labels' first word (P1, P2, ...).

    Raises:
        ValueError: no touch recorded.
    """
    if not touches:
        raise ValueError("No touch recorded yet: record points first (Record point), then export them.")
    n_joints = {len(t.joints_deg) for t in touches}
    joints = n_joints.pop() if len(n_joints) == 1 else 0
    header = ["name", "x", "y", "z", "a", "b", "c", *(f"j{i + 1}" for i in range(joints))]
    rows = [",".join(header)]
    for i, t in enumerate(touches):
        T = np.asarray(t.T_world_flange, dtype=float)
        abc = Rotation.from_matrix(T[:3, :3]).as_euler("ZYX", degrees=True)
        values = [*(T[:3, 3] * 1000.0), *abc, *(t.joints_deg if joints else ())]
        name = (t.label.split() or [f"P{i + 1}"])[0].replace(",", "_").replace('"', "")
        rows.append(",".join([name, *(repr(float(v)) for v in values)]))
    return "\n".join(rows) + "\n"


class TouchListView:
    """Builds the touch capture in the current GUI container; rows are rebuilt on change."""

    def __init__(self, session: Session) -> None:
        self.session = session
        gui = target_of(session).gui
        self.record = gui.add_button(RECORD_POINT, color="green", icon=None)
        self.folder = gui.add_folder("Touches")
        with self.folder:
            self.empty_md = gui.add_markdown(empty_touches_markdown(None, tr=session.translator))
            self.export_csv = gui.add_button("Export CSV")
        self._rows: list[viser.GuiMarkdownHandle | viser.GuiButtonHandle] = []
        self._delete_buttons: list[viser.GuiButtonHandle] = []
        self._relabel()
        self.record.on_click(session.loop.on_loop(self._on_record))
        self.export_csv.on_click(session.loop.on_loop(self._on_export_csv))
        session.subscribe(self.on_change)

    def _relabel(self) -> None:
        """Every label and hint in the session's language (the touches' own lines are names
        and numbers: P1, X, Y, Z, mm)."""
        _ = self.session.translator.gettext
        self.record.label = _(RECORD_POINT)
        self.record.hint = _("Store the current flange pose as a touch; key R.")
        self.folder.label = _("Touches")
        self.export_csv.label = _("Export CSV")
        self.export_csv.hint = _("The touches as POSES.csv with joint values (tcpcal solve xyz4), sent to this browser.")
        for i, b in enumerate(self._delete_buttons):
            b.label = _("Delete P{n}").format(n=i + 1)

    def on_change(self, change: SessionChange) -> None:
        """The change signal: redraw the rows when the touches changed; "Record point" is
        hidden while a wizard is open (one Record concept: the wizard dock's Record then);
        a ``language`` change relabels the view."""
        if change.language:
            self._relabel()
            self._render_empty()
        if change.touches:
            self.rebuild()
        if change.wizard:
            self.record.visible = not self.session.workflow.is_open
        if change.touches or change.wizard:
            self._render_empty()

    def _render_empty(self) -> None:
        """The line shown when no free touch is recorded: while a wizard has touches, where
        they are (its step list), not "No touch recorded"."""
        if self.session.touches:
            return
        set_content(self.empty_md, empty_touches_markdown(self.session.workflow.wizard, tr=self.session.translator))

    def _on_record(self, _event: ButtonEvent) -> None:
        s = self.session
        t = s.record_touch()
        said = t.label
        tr = s.translator
        if s.hide_distance and not s.rules.in_exercise:     # free practice by eye: how far it was
            frame = s.jogger.settings.frame
            offset = tip_offset_mm(s.pose_state(), s.controller.reference_tip_world_m, frame)
            said += f": {touch_feedback(offset, frame, tr=tr)}"
        s.notify(tr.gettext("Point recorded"), said, kind="success")

    def _on_export_csv(self, event: ButtonEvent) -> None:
        data = touches_csv_text(self.session.touches).encode("utf-8")
        # to the browser that clicked (in --shared mode the session is every browser's)
        target = event.client or client_of(self.session) or target_of(self.session)
        target.send_file_download(TOUCHES_FILENAME, data, save_immediately=True)

    def _delete_cb(self, index: int, label: str) -> Callable[..., Coroutine[object, object, None]]:
        def cb(_event: ButtonEvent) -> None:
            # the list may have changed since the button was drawn: delete by label
            labels = [t.label for t in self.session.touches]
            if label in labels:
                self.session.delete_touch(labels.index(label))
        return self.session.loop.on_loop(cb)

    def rebuild(self) -> None:
        """Redraw the rows: one markdown line and one "Delete Pn" button per touch."""
        gui = target_of(self.session).gui
        for h in self._rows:
            h.remove()
        self._rows = []
        self._delete_buttons = []
        _ = self.session.translator.gettext
        touches = list(self.session.touches)
        self.empty_md.visible = not touches
        with self.folder:
            for i, t in enumerate(touches):
                self._rows.append(gui.add_markdown(f"`{t.label}`"))
                b = gui.add_button(_("Delete P{n}").format(n=i + 1), color="red")
                b.on_click(self._delete_cb(i, t.label))
                self._rows.append(b)
                self._delete_buttons.append(b)
