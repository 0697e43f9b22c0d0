"""Fixtures of the app tests: controllers on the KR 6, a tool library in tmp_path (the pendants
in this process are ``support.fixtures``' ``app_factory`` and ``page``)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from tcp_pendant.controller import (
    RobotKinematics,
    VirtualController,
    builtin_robots,
    builtin_tools,
)

from tcpcal.library import ToolLibrary

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
