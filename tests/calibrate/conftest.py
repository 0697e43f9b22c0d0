"""Fixtures of the Calibrate-menu tests: a tool library in tmp_path, the workflow on a real
controller (see ``calib_helpers``) and ``page``: a browser on an in-process pendant
(``calib_page.Page``)."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.calibrate import CalibrationWorkflow

from tcpcal.library import ToolLibrary

sys.path.insert(0, str(Path(__file__).parent))
from calib_helpers import make_controller
from calib_page import Page
from app_page import app_pages


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


@pytest.fixture
def page(tmp_path: Path) -> Iterator[Callable[..., Page]]:
    """Factory: ``page(tool="pointer")`` starts a pendant (port 0, library in tmp_path) and
    connects a browser to it; its workflow's auto-touch generator is seeded
    (``app_page.app_pages``)."""
    with app_pages(tmp_path, Page, seed=5) as make:
        yield make
