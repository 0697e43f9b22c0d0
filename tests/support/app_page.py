"""One connected browser on an in-process pendant, shared by the app and Calibrate tests: its
session, client and notifications (``AppPage``), and ``app_pages``, the factory behind each
test file's ``page`` fixture (a server on port 0 with its library in ``tmp_path``). A test file
subclasses ``AppPage`` for the views and helpers it needs."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

sys.path.insert(0, str(Path(__file__).parents[1] / "calibrate"))
from guiclick import choose, click  # noqa: E402
from tcp_pendant.server import AppConfig, PendantApp  # noqa: E402
from tcpcal.tool import Tool  # noqa: E402
from wsclient import DrainingClient, wait_until  # noqa: E402

P = TypeVar("P", bound="AppPage")


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


@contextmanager
def running_pendants(tmp_path: Path) -> Iterator[Callable[..., PendantApp]]:
    """``start(tools=None, **config)``: a pendant in this process on a free port (``AppConfig``
    options, the library ``tmp_path/tools.json`` holding ``tools`` {slot: Tool}, polled every
    0.1 s); every one stopped at exit."""
    apps: list[PendantApp] = []

    def start(tools: dict[int, Tool] | None = None, **config: Any) -> PendantApp:
        app = PendantApp(AppConfig(port=0, tool_library=tmp_path / "tools.json", library_poll_s=0.1, **config))
        for slot, tool in (tools or {}).items():
            app.library.save(slot, tool)
        app.start()
        apps.append(app)
        return app

    try:
        yield start
    finally:
        for a in apps:
            a.stop()


@contextmanager
def app_pages(tmp_path: Path, page_cls: type[P], *, seed: int | None = None) -> Iterator[Callable[..., P]]:
    """``make(tools=None, **config)``: start a pendant (:func:`running_pendants`) and connect a
    ``page_cls`` browser to it; the server started with ``seed`` (``AppConfig.seed``, the
    ``--seed`` option: every session's randomness), if given. Everything stops at exit."""
    pages: list[P] = []
    with running_pendants(tmp_path) as start:

        def make(tools: dict[int, Tool] | None = None, **config: Any) -> P:
            if seed is not None:
                config.setdefault("seed", seed)
            p = page_cls(start(tools, **config))
            pages.append(p)
            return p

        try:
            yield make
        finally:
            for p in pages:
                p.ws.close()
