"""Synthetic flange poses for driving the wizards without the controller.

A known tool ``T_flange_tool`` (mm) and a reference tip ``r`` (WORLD, mm) give, for any chosen
tool orientation ``R_world_tool`` and tip offset ``o`` (TOOL coordinates, mm), the flange pose
that puts the reference tip at ``o`` in the tool frame:

    p_world_tool = r - R_world_tool o,   R_world_flange = R_world_tool R_flange_tool^T,
    p_world_flange = p_world_tool - R_world_flange t

returned in metres like the controller's ``T_world_flange()``. This is the independent
computation the tests compare the wizards against.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

R_DOWN = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # tool X down (PA-1)


@dataclass(frozen=True)
class SynthTool:
    name: str
    tcp_mm: np.ndarray
    R_flange_tool: np.ndarray

    @property
    def T_flange_tool_true_m(self) -> np.ndarray:
        T = np.eye(4)
        T[:3, :3] = self.R_flange_tool
        T[:3, 3] = self.tcp_mm / 1000.0
        return T


SYNTH_TOOLS = {
    # straight pointer on the flange axis: tool X = flange Z
    "pointer": SynthTool("pointer", np.array([0.0, 0.0, 180.0]),
                         Rotation.from_euler("y", -90, degrees=True).as_matrix()),
    # bent torch: off-axis TCP, tool X rotated about two axes
    "torch": SynthTool("torch", np.array([35.0, -12.0, 310.0]),
                       Rotation.from_euler("ZYX", [20.0, -65.0, 15.0], degrees=True).as_matrix()),
    # gripper: TCP between the fingers
    "gripper": SynthTool("gripper", np.array([0.0, 0.0, 145.0]),
                         Rotation.from_euler("ZYX", [90.0, -90.0, 0.0], degrees=True).as_matrix()),
}

REFERENCE_MM = np.array([620.0, 80.0, 240.0])


def tool_orientation(tilt_deg: float, azimuth_deg: float, spin_deg: float = 0.0) -> np.ndarray:
    """R_world_tool with tool X tilted ``tilt`` from WORLD -Z, turned ``azimuth`` about Z."""
    return (Rotation.from_euler("z", azimuth_deg, degrees=True)
            * Rotation.from_euler("y", -tilt_deg, degrees=True)
            * Rotation.from_matrix(R_DOWN)
            * Rotation.from_euler("x", spin_deg, degrees=True)).as_matrix()


def flange_pose_m(tool: SynthTool, R_world_tool: np.ndarray, *, offset_tool_mm=(0.0, 0.0, 0.0),
                  reference_mm: np.ndarray = REFERENCE_MM, noise_mm: np.ndarray | None = None) -> np.ndarray:
    p_tool = reference_mm - R_world_tool @ np.asarray(offset_tool_mm, dtype=float)
    if noise_mm is not None:
        p_tool = p_tool + noise_mm
    R_wf = R_world_tool @ tool.R_flange_tool.T
    T = np.eye(4)
    T[:3, :3] = R_wf
    T[:3, 3] = (p_tool - R_wf @ tool.tcp_mm) / 1000.0
    return T


# Four well spread touch directions (tilt, azimuth, spin), 35-45 deg apart about two axes.
DIRECTIONS = [(0.0, 0.0, 0.0), (40.0, 0.0, 30.0), (40.0, 120.0, -20.0), (45.0, 240.0, 60.0),
              (30.0, 60.0, -60.0), (35.0, 300.0, 10.0), (25.0, 180.0, 80.0), (45.0, 30.0, -45.0)]


@pytest.fixture(params=sorted(SYNTH_TOOLS))
def synth_tool(request) -> SynthTool:
    return SYNTH_TOOLS[request.param]


@pytest.fixture
def synth():
    """The helpers above, for test modules (importlib import mode cannot import conftest)."""
    import types

    return types.SimpleNamespace(tools=SYNTH_TOOLS, tool_orientation=tool_orientation,
                                 flange_pose_m=flange_pose_m, directions=DIRECTIONS,
                                 reference_mm=REFERENCE_MM, SynthTool=SynthTool)
