"""Helpers of the Calibrate-menu tests and the others that calibrate: a controller and a session
as the app builds them, the tools' hidden truth."""

from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial.transform import Rotation
from tcp_pendant.controller import (
    RobotKinematics,
    VirtualController,
    builtin_robots,
    builtin_tools,
)
from tcp_pendant.serve.server import default_reference_tip_mm, ready_configuration

from tcpcal.tool import Tool

_KINEMATICS: dict[str, RobotKinematics] = {}
def make_controller(robot: str = "kr6", tool_key: str = "pointer") -> VirtualController:
    """A controller like a pendant session's: default reference tip, ready pose."""
    if robot not in _KINEMATICS:
        _KINEMATICS[robot] = RobotKinematics.from_urdf(builtin_robots()[robot])
    k = _KINEMATICS[robot]
    kin = RobotKinematics(k.model, k.urdf_path, k.flange_link, k.base_link)
    tip_m = np.asarray(default_reference_tip_mm(kin)) / 1000.0
    c = VirtualController(kin, tool=builtin_tools()[tool_key], reference_tip_world_m=tip_m)
    c.set_q(ready_configuration(kin))
    return c


def true_frame(tool_key: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(TCP mm, R_flange_tool, KUKA A, B, C deg) of a built-in tool's hidden truth, via scipy."""
    T = builtin_tools()[tool_key].T_flange_tool_true
    R = T[:3, :3]
    with warnings.catch_warnings():          # the pointer has B = -90 deg: gimbal lock is expected
        warnings.simplefilter("ignore", UserWarning)
        abc = Rotation.from_matrix(R).as_euler("ZYX", degrees=True)
    return T[:3, 3] * 1000.0, R, abc


def library_tool_with_true_tcp(tool_key: str, name: str) -> Tool:
    """Library data of a tool whose TCP was calibrated exactly (orientation not yet: A=B=C=0)."""
    tcp, _, _ = true_frame(tool_key)
    return Tool(name=name, tcp_mm=tuple(float(v) for v in tcp))


def make_session(library_path, *, robot: str = "kr6", tool_key: str = "pointer", seed: int = 0):
    """A pendant session without a browser (no views; ``target`` None): a controller as
    :func:`make_controller`, its workflow seeded with ``seed``; every command is the session's."""
    from tcp_pendant.calibrate import CalibrationWorkflow
    from tcp_pendant.session import Session

    from tcpcal.library import ToolLibrary

    c = make_controller(robot, tool_key)
    library = ToolLibrary(library_path)
    rng = np.random.default_rng(seed)
    return Session(c, library, CalibrationWorkflow(c, library, robot=robot, rng=rng), rng=rng)
