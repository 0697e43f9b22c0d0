""""Export touches (CSV)" in the wizard panel: the wizard's recorded steps as the POSES.csv that
``tcpcal solve`` reads (``calibrate.touches_export``: flange poses and joints only, so it gives
no answer in an exercise), sent to the browser that clicked. Shown when the wizard on show has
a step recorded and ``tcpcal solve`` has a command for its method. Its words are the session's
language (relabelled on a ``language`` change); the file is the same in every language."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from tcp_pendant.calibrate.touches_export import EXPORTABLE, touches_csv_filename, wizard_touches_csv
from tcp_pendant.session import SessionChange
from tcp_pendant.translation import N_
from tcp_pendant.views.gui_util import ButtonEvent, client_of, target_of
from tcp_pendant.wizards import Wizard

if TYPE_CHECKING:
    from tcp_pendant.views.wizard_menu import CalibrateView

__all__ = ["TouchesExport"]

_LABEL = N_("Export touches (CSV)")
_HINT = N_("The recorded steps as POSES.csv (flange poses, joints) for tcpcal solve; its first line is the command.")


class TouchesExport:
    """The button, built in the current GUI container (the wizard panel's folder)."""

    def __init__(self, parent: CalibrateView) -> None:
        self.parent = parent
        self.button = target_of(parent.session).gui.add_button(_LABEL, visible=False, hint=_HINT)
        self.button.on_click(parent.action(self._on_click))
        self.relabel()
        parent.session.subscribe(self.on_change)

    def on_change(self, change: SessionChange) -> None:
        """The change signal: the button's words on ``language``."""
        if change.language:
            self.relabel()

    def relabel(self) -> None:
        """The button's label and hint in the session's language."""
        tr = self.parent.session.translator
        self.button.label = tr.gettext(_LABEL)
        self.button.hint = tr.gettext(_HINT)

    def render(self, wizard: Wizard | None) -> None:
        """Shown for a wizard whose method ``tcpcal solve`` has, once a step is recorded."""
        self.button.visible = wizard is not None and wizard.kind in EXPORTABLE and bool(wizard.recorded_poses)

    def _on_click(self, event: ButtonEvent) -> None:
        tr = self.parent.session.translator
        run = self.parent.workflow.run
        if run is None:
            raise ValueError(tr.gettext("No calibration is open: start one and record its steps first."))
        data = wizard_touches_csv(run.wizard, run.joints_deg, tr=tr).encode("utf-8")
        session: Any = self.parent.session
        target = getattr(event, "client", None) or client_of(session) or target_of(session)
        target.send_file_download(touches_csv_filename(run.wizard), data, save_immediately=True)
