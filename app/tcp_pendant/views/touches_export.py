""""Export touches (CSV)" in the wizard panel: the wizard's recorded steps as the POSES.csv that
``tcpcal solve`` reads (``calibrate.touches_export``: flange poses and joints only, so it gives
no answer in an exercise), sent to the browser that clicked. Shown when the wizard on show has
a step recorded and ``tcpcal solve`` has a command for its method."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from tcp_pendant.calibrate.touches_export import EXPORTABLE, touches_csv_filename, wizard_touches_csv
from tcp_pendant.views.gui_util import ButtonEvent, client_of, target_of
from tcp_pendant.wizards import Wizard

if TYPE_CHECKING:
    from tcp_pendant.views.wizard_menu import CalibrateView

__all__ = ["TouchesExport"]


class TouchesExport:
    """The button, built in the current GUI container (the wizard panel's folder)."""

    def __init__(self, parent: CalibrateView) -> None:
        self.parent = parent
        self.button = target_of(parent.session).gui.add_button(
            "Export touches (CSV)", visible=False,
            hint="The recorded steps as POSES.csv (flange poses, joints) for tcpcal solve; its first line "
                 "is the command.")
        self.button.on_click(parent.action(self._on_click))

    def render(self, wizard: Wizard | None) -> None:
        """Shown for a wizard whose method ``tcpcal solve`` has, once a step is recorded."""
        self.button.visible = wizard is not None and wizard.kind in EXPORTABLE and bool(wizard.recorded_poses)

    def _on_click(self, event: ButtonEvent) -> None:
        run = self.parent.workflow.run
        if run is None:
            raise ValueError("No calibration is open: start one and record its steps first.")
        data = wizard_touches_csv(run.wizard, run.joints_deg).encode("utf-8")
        session: Any = self.parent.session
        target = getattr(event, "client", None) or client_of(session) or target_of(session)
        target.send_file_download(touches_csv_filename(run.wizard), data, save_immediately=True)
