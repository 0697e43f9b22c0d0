"""Fixtures of the app tests: controllers on the KR 6, a tool library in tmp_path, a pendant
server in-process on a free port (real viser server, headless websocket clients)."""

from __future__ import annotations

import os
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
from app_page import running_pendants  # noqa: E402

# a fast path into viser's private API that falls back raises (views.viser_adapter)
os.environ.setdefault("TCP_PENDANT_STRICT_VISER", "1")


@pytest.fixture(scope="session")
def kr6() -> RobotKinematics:
    return RobotKinematics.from_urdf(builtin_robots()["kr6"])


@pytest.fixture
def controller(kr6: RobotKinematics) -> VirtualController:
    return VirtualController(kr6.own_copy(), tool=builtin_tools()["pointer"])


@pytest.fixture
def library(tmp_path: Path) -> ToolLibrary:
    return ToolLibrary(tmp_path / "tools.json")


@pytest.fixture
def app_factory(tmp_path: Path) -> Iterator[Callable[..., object]]:
    """``app_factory(**AppConfig options)``: a started pendant in this process (``app_page.running_pendants``)."""
    with running_pendants(tmp_path) as start:
        yield start
