"""Fixtures of the Calibrate-menu tests: a tool library in tmp_path and the workflow on a real
controller (see ``support.calib_helpers``). Their ``page`` (a browser on an in-process pendant)
is ``support.fixtures``' with ``support.calib_page.Page``: ``pytest.mark.app_page(cls=Page, seed=5)``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.calibrate import CalibrationWorkflow

from support.calib_helpers import make_controller
from tcpcal.library import ToolLibrary


@pytest.fixture
def library(tmp_path: Path) -> ToolLibrary:
    return ToolLibrary(tmp_path / "tools.json")


@pytest.fixture
def workflow(library: ToolLibrary) -> Callable[..., CalibrationWorkflow]:
    """Factory: ``workflow(robot="kr6", tool="pointer", seed=0)``."""

    def make(robot: str = "kr6", tool: str = "pointer", seed: int = 0) -> CalibrationWorkflow:
        return CalibrationWorkflow(make_controller(robot, tool), library, robot=robot,
                                   rng=np.random.default_rng(seed))

    return make
