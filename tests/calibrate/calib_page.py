"""One connected browser on an in-process pendant, for the Calibrate-tab tests: its session,
Calibrate view and headless websocket client (``guiclick`` sends clicks as a browser does).
The ``page`` fixture in ``conftest.py`` makes them."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).parents[1] / "app"))
from guiclick import choose, click  # noqa: E402
from tcp_pendant.server import PendantApp  # noqa: E402
from tcp_pendant.views.wizard_menu import CalibrateView  # noqa: E402
from wsclient import DrainingClient, wait_until  # noqa: E402


class Page:
    """One connected browser: its session, Calibrate view and client."""

    def __init__(self, app: PendantApp) -> None:
        n = len(app.sessions)
        self.ws = DrainingClient(app.port)
        wait_until(lambda: len(app.sessions) > n, what="session built")
        self.session = list(app.sessions.values())[-1]
        self.view: CalibrateView = self.session.views["calibrate"]
        self.client = self.session.client
        self.notes: list[tuple[str, str]] = []
        self.session.notify = lambda title, body, kind="info": self.notes.append((title, body))  # type: ignore[method-assign]

    def click(self, handle: Any) -> None:
        click(handle, self.client)

    def choose(self, handle: Any, value: Any) -> None:
        choose(handle, value, self.client)
