"""Shared fixtures for the virtual controller tests: robots, tools, controllers, helpers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcpcal.tool import Tool
from tcp_pendant.controller import (
    RobotKinematics,
    ToolModel,
    VirtualController,
    builtin_robots,
    builtin_tools,
    example_robot_urdf,
)

ROBOTS = ("kr6", "gp12")
TOOL_KEYS = ("pointer", "torch", "gripper")
# well-conditioned working configurations (degrees), away from limits and singularities
WORK_Q_DEG = {"kr6": (10.0, -80.0, 100.0, 20.0, 40.0, 30.0),
              "gp12": (10.0, 10.0, 10.0, 20.0, -50.0, 30.0)}
TIP_M = {"kr6": (0.55, 0.05, 0.25), "gp12": (0.95, 0.05, 0.35)}

_KIN: dict[str, RobotKinematics] = {}


def kinematics(robot: str) -> RobotKinematics:
    """Cached kinematics of a built-in robot ("kr6", "gp12") or "ur5" (example-robot-data)."""
    if robot not in _KIN:
        path = example_robot_urdf() if robot == "ur5" else builtin_robots()[robot]
        _KIN[robot] = RobotKinematics.from_urdf(path)
    return _KIN[robot]


def truth_tool_data(model: ToolModel, name: str | None = None) -> Tool:
    """tcpcal tool data equal to the hidden truth of a tool model."""
    T = model.T_flange_tool_true
    return Tool.from_rotation(name or model.key, tuple(T[:3, 3] * 1000.0), T[:3, :3])


def make_controller(robot: str, tool_key: str = "torch", *, active: bool = True,
                    q_deg: tuple[float, ...] | None = None, T_world_base: np.ndarray | None = None
                    ) -> VirtualController:
    model = builtin_tools()[tool_key]
    ctrl = VirtualController(kinematics(robot), tool=model, reference_tip_world_m=TIP_M.get(robot),
                             active_tool=truth_tool_data(model) if active else None,
                             T_world_base=T_world_base)
    ctrl.set_q(np.radians(WORK_Q_DEG[robot] if q_deg is None else q_deg))
    return ctrl


def angle_deg(R_a: np.ndarray, R_b: np.ndarray) -> float:
    """Rotation angle between two rotation matrices, degrees."""
    return float(np.degrees(np.linalg.norm(Rotation.from_matrix(R_a @ R_b.T).as_rotvec())))


def distance_to_line_mm(p: np.ndarray, origin: np.ndarray, direction: np.ndarray) -> float:
    """Distance (mm) of point p (m) from the line origin + s direction (m, unit direction)."""
    d = p - origin
    return float(np.linalg.norm(d - (d @ direction) * direction) * 1000.0)


@pytest.fixture(params=ROBOTS)
def robot(request) -> str:
    return request.param
