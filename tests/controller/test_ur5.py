"""Any URDF drives the controller: the UR5 of example-robot-data jogs and auto-approaches like
the built-in robots ("any other URDF given on the command line must also load")."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcp_pendant.controller import VirtualController, builtin_tools

from .conftest import angle_deg, distance_to_line_mm, kinematics, truth_tool_data

UR5_WORK_Q_DEG = (10.0, -80.0, 90.0, -100.0, -80.0, 20.0)  # elbow bent, wrist bent: well conditioned
TIP_M = (0.45, 0.1, 0.1)


def ur5_controller(tool_key: str = "torch") -> VirtualController:
    model = builtin_tools()[tool_key]
    ctrl = VirtualController(kinematics("ur5"), tool=model, reference_tip_world_m=TIP_M,
                             active_tool=truth_tool_data(model))
    ctrl.set_q(np.radians(UR5_WORK_Q_DEG))
    return ctrl


@pytest.mark.parametrize("frame, axis", [("WORLD", "Z"), ("TOOL", "X"), ("FLANGE", "Y")])
def test_ur5_jogs_along_straight_lines(frame, axis):
    ctrl = ur5_controller()
    T0 = ctrl.T_world_tcp()
    i = "XYZ".index(axis)
    direction = {"WORLD": np.eye(3)[:, i], "TOOL": T0[:3, i], "FLANGE": ctrl.T_world_flange()[:3, i]}[frame]
    for _ in range(50):
        assert ctrl.jog_cartesian(frame, axis, -1.0).ok
        T = ctrl.T_world_tcp()
        assert distance_to_line_mm(T[:3, 3], T0[:3, 3], direction) < 0.01
        assert angle_deg(T[:3, :3], T0[:3, :3]) < 0.001
    assert (T[:3, 3] - T0[:3, 3]) @ direction * 1000.0 == pytest.approx(-50.0, abs=0.01)


def test_ur5_rotation_jog_keeps_the_tcp_fixed():
    ctrl = ur5_controller()
    T0 = ctrl.T_world_tcp()
    for k in range(1, 6):
        assert ctrl.jog_cartesian("TOOL", "B", 2.0).ok
        T = ctrl.T_world_tcp()
        assert np.linalg.norm(T[:3, 3] - T0[:3, 3]) * 1000.0 < 0.01
        expected = T0[:3, :3] @ Rotation.from_euler("y", 2.0 * k, degrees=True).as_matrix()
        assert angle_deg(T[:3, :3], expected) < 0.001


def test_ur5_stretched_zero_pose_stops_at_the_elbow_singularity():
    ctrl = ur5_controller("pointer")
    ctrl.set_q(np.zeros(6))  # example-robot-data's UR5 at zero: arm stretched horizontally
    res = ctrl.jog_cartesian("WORLD", "Y", 1.0)
    assert not res.ok and res.stopped_by == "singularity"
    assert res.message == "elbow_joint near 0.0 deg: arm stretched (elbow singularity)"


def test_ur5_auto_approach_touches_exactly():
    ctrl = ur5_controller()
    rng = np.random.default_rng(5)
    tip = np.array(TIP_M)
    for _ in range(5):
        tilt, az = rng.uniform(0.0, 40.0), rng.uniform(0.0, 360.0)
        res = ctrl.auto_approach(tilt_deg=tilt, azimuth_deg=az)
        assert res.ok, res.message
        T = ctrl.T_world_tool_true()
        assert np.linalg.norm(T[:3, 3] - tip) * 1000.0 < 1e-6
        t, a = math.radians(tilt), math.radians(az)
        np.testing.assert_allclose(T[:3, 0], [math.sin(t) * math.cos(a), math.sin(t) * math.sin(a), -math.cos(t)],
                                   atol=1e-9)
