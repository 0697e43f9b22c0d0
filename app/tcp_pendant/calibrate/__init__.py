"""The Calibrate menu without viser: the workflow of the wizards in one pendant session
(``workflow``), the jobs the controller runs for a wizard (``jobs``), the words and tables it
shows (``text``), the per-touch error chart's data (``chart``) and what one pendant may do
(``pendant_rules``: the exercise's rules and the library rights it obeys). The viser views
(``tcp_pendant.views.wizard_*``) render these; the math is tcpcal's, reached through the wizards
(``tcp_pendant.wizards``).
"""

from tcp_pendant.calibrate.chart import ErrorBars, error_bars
from tcp_pendant.calibrate.jobs import JOBS, BeamScanJob, ControllerJob, TcpCheckJob
from tcp_pendant.calibrate.workflow import (
    AUTO_SIGMA_MAX_MM,
    AutoTouchRequest,
    CalibrationWorkflow,
)

__all__ = [
    "AUTO_SIGMA_MAX_MM",
    "JOBS",
    "AutoTouchRequest",
    "BeamScanJob",
    "CalibrationWorkflow",
    "ControllerJob",
    "ErrorBars",
    "TcpCheckJob",
    "error_bars",
]
