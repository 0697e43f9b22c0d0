"""One connected browser on an in-process pendant, shared by the app and Calibrate tests: its
session, client and notifications (``AppPage``, what the ``page`` fixture of
``support.fixtures`` makes), and helpers that act on a session as a browser would. A test file
subclasses ``AppPage`` for the views and helpers it needs."""

from __future__ import annotations

from typing import Any

import numpy as np
from tcp_pendant.serve.server import PendantApp

from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until
from tcpcal.tool import Tool


def true_tip_at(session: Any, offset_mm: Any) -> None:
    """Teleport the mounted tool's true tip to the reference tip + ``offset_mm`` (WORLD, mm),
    the tool's orientation kept, and signal the move (as the gizmo would)."""
    with session.lock:
        c = session.controller
        T = c.T_world_tool_true().copy()
        T[:3, 3] = c.reference_tip_world_m + np.asarray(offset_mm, dtype=float) / 1000.0
        res = c.move_true_tool_to(T)
        assert res.ok, res.message
        session.moved()


def truth_tool(key: str, name: str, offset_mm: Any = (0.0, 0.0, 0.0)) -> Tool:
    """Tool data equal to a built-in tool's (unbent) hidden true frame, its TCP moved by
    ``offset_mm`` (FLANGE, mm)."""
    from tcp_pendant.controller import builtin_tools

    T = builtin_tools()[key].T_flange_tool_true
    return Tool.from_rotation(name, tuple(T[:3, 3] * 1000.0 + np.asarray(offset_mm)), T[:3, :3])


class AppPage:
    """One connected browser: its session, client and the notifications it was shown."""

    def __init__(self, app: PendantApp) -> None:
        self.app = app
        n = len(app.sessions)
        self.ws = DrainingClient(app.port)
        wait_until(lambda: len(app.sessions) > n, what="session built")
        self.session = list(app.sessions.values())[-1]
        self.client = self.session.client
        self.notes: list[tuple[str, str]] = []
        self.session.notify = lambda title, body, kind="info": self.notes.append((title, body))  # type: ignore[method-assign]

    def click(self, handle: Any) -> None:
        click(handle, self.client)

    def choose(self, handle: Any, value: Any) -> None:
        choose(handle, value, self.client)


def join_as_the_only_trainee(app: PendantApp, name: str) -> Any:
    """The one browser of a class server, once its name prompt is up, joined as ``name``
    (typed and Start clicked as that browser's messages); returns its session."""
    wait_until(lambda: len(app.sessions) == 1 and all("identity" in s.views for s in app.sessions.values()),
               what="the name prompt")
    session = next(iter(app.sessions.values()))
    prompt = session.views["identity"]
    choose(prompt.name_field, name, session.client)
    click(prompt.start, session.client)
    assert prompt.name == name
    return session
