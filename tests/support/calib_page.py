"""One connected browser on an in-process pendant, for the Calibrate-tab tests: the app tests'
``AppPage`` with its Calibrate view. The ``page`` fixture (``support.fixtures``) makes them in a
module marked ``pytest.mark.app_page(cls=Page)``."""

from __future__ import annotations


from support.app_page import AppPage
from tcp_pendant.serve.server import PendantApp
from tcp_pendant.views.wizard_menu import CalibrateView


class Page(AppPage):
    """One connected browser: its session, Calibrate view and client."""

    def __init__(self, app: PendantApp) -> None:
        super().__init__(app)
        self.view: CalibrateView = self.session.views["calibrate"]
