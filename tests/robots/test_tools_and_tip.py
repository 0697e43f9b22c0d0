"""Tools (true TOOL frames) and the reference tip: frames as documented in robots/README.md,
and the visible geometry agrees with them (the tip is where the frame says).

Expected frames are computed here from the documented design figures (mm, deg).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import trimesh
import yourdfpy

ROBOTS = Path(__file__).resolve().parents[2] / "robots"
TOOLS = ROBOTS / "tools"
TIP = ROBOTS / "reference_tip" / "reference_tip.urdf"
DEG = np.pi / 180.0


def _expected_torch() -> tuple[np.ndarray, np.ndarray]:
    """Torch: 220 mm straight body on the flange axis, then the neck bent 22 deg away from
    flange Z, the bend plane turned 30 deg about flange Z (from flange X towards flange Y);
    TCP 110 mm (neck) + 15 mm (wire stick-out) along the neck from the bend."""
    b, c = 22.0 * DEG, 30.0 * DEG
    u = np.array([np.sin(b) * np.cos(c), np.sin(b) * np.sin(c), np.cos(b)])
    p_mm = np.array([0.0, 0.0, 220.0]) + 125.0 * u
    y = np.array([-np.sin(c), np.cos(c), 0.0])  # tool Y: horizontal in the flange plane
    R = np.column_stack([u, y, np.cross(u, y)])
    return p_mm / 1000.0, R


STRAIGHT = np.column_stack([[0, 0, 1], [0, 1, 0], [-1, 0, 0]]).astype(float)
EXPECTED = {
    "pointer": (np.array([0.0, 0.0, 0.180]), STRAIGHT),
    "torch": _expected_torch(),
    "gripper": (np.array([0.0, 0.0, 0.165]), STRAIGHT),
}


def _vertices(urdf: yourdfpy.URDF, name_contains: str = "") -> np.ndarray:
    """Visual vertices (metres) in the root link frame."""
    out = []
    for node in urdf.scene.graph.nodes_geometry:
        T, geom_name = urdf.scene.graph.get(node)
        if name_contains in geom_name:
            out.append(trimesh.transform_points(urdf.scene.geometry[geom_name].vertices, T))
    return np.vstack(out)


@pytest.mark.parametrize("tool", sorted(EXPECTED))
def test_tool_frame_as_documented(tool: str) -> None:
    path = TOOLS / f"{tool}.urdf"
    urdf = yourdfpy.URDF.load(str(path))
    assert urdf.base_link == "tool_mount"
    assert urdf.actuated_joint_names == []
    T = urdf.get_transform("tcp", "tool_mount")
    p, R = EXPECTED[tool]
    np.testing.assert_allclose(T[:3, 3], p, atol=1e-12)
    np.testing.assert_allclose(T[:3, :3], R, atol=1e-12)
    assert np.linalg.det(T[:3, :3]) == pytest.approx(1.0, abs=1e-12)
    # pinocchio reads the same frame.
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.zeros(model.nq))
    T_pin = data.oMf[model.getFrameId("tcp")].homogeneous @ np.linalg.inv(
        data.oMf[model.getFrameId("tool_mount")].homogeneous)
    np.testing.assert_allclose(T_pin, T, atol=1e-12)


@pytest.mark.parametrize("tool", ["pointer", "torch"])
def test_tip_is_the_foremost_point_along_tool_x(tool: str) -> None:
    """Nothing of the tool sticks out beyond the TCP along the working direction, and the
    geometry ends at the TCP (a vertex within 1.5 mm: the pointer's apex, the wire's end)."""
    urdf = yourdfpy.URDF.load(str(TOOLS / f"{tool}.urdf"))
    T = urdf.get_transform("tcp", "tool_mount")
    v = _vertices(urdf)
    along = (v - T[:3, 3]) @ T[:3, 0]
    assert along.max() == pytest.approx(0.0, abs=2e-6)
    assert np.linalg.norm(v - T[:3, 3], axis=1).min() < 1.5e-3


def test_torch_tcp_is_off_axis_and_tilted() -> None:
    p, R = EXPECTED["torch"]
    assert np.hypot(p[0], p[1]) > 0.04  # well off the flange axis
    tilt = np.degrees(np.arccos(R[2, 0]))
    assert tilt == pytest.approx(22.0)


def test_gripper_tcp_between_the_fingertip_pads() -> None:
    urdf = yourdfpy.URDF.load(str(TOOLS / "gripper.urdf"))
    T = urdf.get_transform("tcp", "tool_mount")
    pads = _vertices(urdf, "red")
    lo, hi = pads.min(axis=0), pads.max(axis=0)
    # Centred between the pads in the closing (flange Y) and the width (flange X) directions,
    # and within the pads' height along the approach axis.
    np.testing.assert_allclose(T[:2, 3], (lo[:2] + hi[:2]) / 2.0, atol=1e-6)
    assert lo[2] < T[2, 3] < hi[2]
    # The pads lie on both sides of the TCP along tool Y (the closing direction).
    side = (pads - T[:3, 3]) @ T[:3, 1]
    assert side.min() < -0.015 and side.max() > 0.015


def test_reference_tip_at_the_spike_point() -> None:
    urdf = yourdfpy.URDF.load(str(TIP))
    assert urdf.base_link == "stand_base"
    T = urdf.get_transform("tip", "stand_base")
    expected = np.eye(4)
    expected[2, 3] = 0.250  # the point 250 mm above the floor, axes as the stand's
    np.testing.assert_allclose(T, expected, atol=1e-12)
    v = _vertices(urdf)
    top = v[np.argmax(v[:, 2])]
    np.testing.assert_allclose(top, T[:3, 3], atol=1e-6)
    # Sharp: 5 mm below the point the spike is under 2 mm in radius.
    near = v[v[:, 2] > T[2, 3] - 0.005]
    assert np.hypot(near[:, 0], near[:, 1]).max() < 0.002
    # Standing on the floor.
    assert v[:, 2].min() == pytest.approx(0.0, abs=1e-9)
