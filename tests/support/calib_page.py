"""One connected browser on an in-process pendant, for the Calibrate-tab tests: the app tests'
``AppPage`` with its Calibrate view. The ``page`` fixture in ``conftest.py`` makes them."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1] / "app"))
from app_page import AppPage  # noqa: E402
from tcp_pendant.server import PendantApp  # noqa: E402
from tcp_pendant.views.wizard_menu import CalibrateView  # noqa: E402


class Page(AppPage):
    """One connected browser: its session, Calibrate view and client."""

    def __init__(self, app: PendantApp) -> None:
        super().__init__(app)
        self.view: CalibrateView = self.session.views["calibrate"]
