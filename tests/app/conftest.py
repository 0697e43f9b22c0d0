"""Fixtures of the app tests: controllers on the KR 6, a tool library in tmp_path, a pendant
server in-process on a free port (real viser server, headless websocket clients)."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from tcp_pendant.controller import (
    RobotKinematics,
    VirtualController,
    builtin_robots,
    builtin_tools,
)

from tcpcal.library import ToolLibrary

sys.path.insert(0, str(Path(__file__).parent))
from wsclient import free_port, wait_until  # noqa: F401  (re-exported: the tests import them from here)


@pytest.fixture(scope="session")
def kr6() -> RobotKinematics:
    return RobotKinematics.from_urdf(builtin_robots()["kr6"])


@pytest.fixture
def controller(kr6: RobotKinematics) -> VirtualController:
    k = RobotKinematics(kr6.model, kr6.urdf_path, kr6.flange_link, kr6.base_link)
    return VirtualController(k, tool=builtin_tools()["pointer"])


@pytest.fixture
def library(tmp_path: Path) -> ToolLibrary:
    return ToolLibrary(tmp_path / "tools.json")


@pytest.fixture
def app_factory(tmp_path: Path) -> Iterator[Callable[..., object]]:
    from tcp_pendant.server import AppConfig, PendantApp

    apps: list[PendantApp] = []

    def make(**kw: object) -> PendantApp:
        cfg = AppConfig(port=0, tool_library=tmp_path / "tools.json", library_poll_s=0.1, **kw)  # type: ignore[arg-type]
        app = PendantApp(cfg)
        app.start()
        apps.append(app)
        return app

    yield make
    for a in apps:
        a.stop()
