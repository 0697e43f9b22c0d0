"""TCP check (spin test): rotations about the active TCP in the active TOOL axes, the true tip's
deviation against (SC-1) computed independently with scipy, the implied TCP error of (SC-2),
unreachable rotations reported, bad input refused (methods.md, "TCP check")."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcpcal.tool import Tool
from tcp_pendant.controller import ControllerError, builtin_tools
from tcp_pendant.controller.jog import JogSettings
from tcp_pendant.controller.spin import spin_check, spin_check_of

from .conftest import ROBOTS, TOOL_KEYS, kinematics, make_controller, truth_tool_data

TOOL_AXIS = {"A": "z", "B": "y", "C": "x"}


def offset_tool(model, offset_flange_mm) -> Tool:
    """The tool's true data with ``offset_flange_mm`` added to its TCP (FLANGE, mm)."""
    T = model.T_flange_tool_true
    return Tool.from_rotation("offset", tuple(T[:3, 3] * 1000.0 + np.asarray(offset_flange_mm)), T[:3, :3])


def expected_deviation_tool_mm(axis: str, angle_deg: float, e_tool_mm: np.ndarray) -> np.ndarray:
    """(Rot - I) e, the rotation built by scipy about the named TOOL axis."""
    R = Rotation.from_euler(TOOL_AXIS[axis], angle_deg, degrees=True).as_matrix()
    return (R - np.eye(3)) @ e_tool_mm


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("tool_key", TOOL_KEYS)
def test_exact_tcp_keeps_the_true_tip_still(robot, tool_key):
    ctrl = make_controller(robot, tool_key)
    q_before = ctrl.q_rad
    res = spin_check_of(ctrl)
    assert [r.label for r in res.rotations] == ["+A 30°", "-A 30°", "+B 30°", "-B 30°", "+C 30°", "-C 30°"]
    reached = [r for r in res.rotations if r.reached]
    assert len(reached) >= 4
    for r in res.rotations:  # also where a rotation stopped early: the tip stays put
        assert r.deviation_mm < 1e-6, r
    assert res.max_deviation_mm < 1e-6
    assert res.implied_tcp_error_mm is not None and res.implied_tcp_error_mm < 1e-6
    assert res.fit_rms_mm < 1e-6
    np.testing.assert_array_equal(ctrl.q_rad, q_before)  # the controller itself is not moved


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("tool_key", TOOL_KEYS)
@pytest.mark.parametrize("angle", [30.0, 15.0])
def test_one_mm_offset_in_the_active_data(robot, tool_key, angle):
    model = builtin_tools()[tool_key]
    ctrl = make_controller(robot, tool_key)
    ctrl.set_active_tool(offset_tool(model, (1.0, 0.0, 0.0)))
    res = spin_check_of(ctrl, angle_deg=angle)
    # independent expectation: the true tip in active TOOL axes, mm
    R_ft = ctrl.T_flange_tool[:3, :3]
    e = R_ft.T @ (model.T_flange_tool_true[:3, 3] - ctrl.T_flange_tool[:3, 3]) * 1000.0
    np.testing.assert_allclose(np.linalg.norm(e), 1.0, atol=1e-12)
    R0 = (ctrl.T_world_flange() @ ctrl.T_flange_tool)[:3, :3]
    assert sum(r.reached for r in res.rotations) >= 4
    if tool_key != "torch":  # the torch's +B meets a wrist singularity at this pose on both arms
        assert res.all_reached
    for r in res.rotations:
        if not r.reached:
            continue
        k = "xyz".index(TOOL_AXIS[r.axis])
        e_perp = e - e[k] * np.eye(3)[k]
        assert r.deviation_mm == pytest.approx(2 * abs(math.sin(math.radians(r.angle_deg) / 2))
                                               * np.linalg.norm(e_perp), abs=1e-6)
        d_tool = expected_deviation_tool_mm(r.axis, r.angle_deg, e)
        np.testing.assert_allclose(r.deviation_tool_mm, d_tool, atol=1e-6)
        np.testing.assert_allclose(r.deviation_world_mm, R0 @ d_tool, atol=1e-6)
    assert res.max_deviation_mm == pytest.approx(max(r.deviation_mm for r in res.rotations if r.reached))
    assert res.implied_tcp_error_mm == pytest.approx(1.0, abs=1e-6)
    np.testing.assert_allclose(res.implied_offset_tool_mm, e, atol=1e-6)
    # the correction to add to the tool data's tcp_mm: back onto the true tip
    np.testing.assert_allclose(res.implied_offset_flange_mm, [-1.0, 0.0, 0.0], atol=1e-6)
    assert res.fit_rms_mm < 1e-6


@pytest.mark.parametrize("robot", ROBOTS)
def test_rotations_turn_about_the_active_tool_axes_through_the_active_tcp(robot):
    """+A turns about TOOL Z, B about Y, C about X (KUKA's A, B, C in the TOOL frame)."""
    ctrl = make_controller(robot, "pointer")
    ctrl.set_active_tool(offset_tool(builtin_tools()["pointer"], (3.0, -2.0, 5.0)))
    res = spin_check_of(ctrl, angle_deg=20.0)
    kin = ctrl.kinematics
    T0 = ctrl.T_world_flange() @ ctrl.T_flange_tool
    assert res.all_reached
    for r in res.rotations:
        T = kin.T_world_flange(r.q_rad) @ ctrl.T_flange_tool
        assert np.linalg.norm(T[:3, 3] - T0[:3, 3]) * 1000.0 < 1e-6  # the active TCP stays put
        R_expected = T0[:3, :3] @ Rotation.from_euler(TOOL_AXIS[r.axis], r.angle_deg, degrees=True).as_matrix()
        angle = np.linalg.norm(Rotation.from_matrix(T[:3, :3] @ R_expected.T).as_rotvec())
        assert angle < 1e-9, r.label


def test_labels_show_the_angle_as_given():
    ctrl = make_controller("kr6", "pointer")
    res = spin_check_of(ctrl, angle_deg=12.5)
    assert [r.label for r in res.rotations] == ["+A 12.5°", "-A 12.5°", "+B 12.5°", "-B 12.5°",
                                                "+C 12.5°", "-C 12.5°"]
    assert [r.angle_deg for r in res.rotations] == [12.5, -12.5] * 3
    assert res.angle_deg == 12.5


@pytest.mark.parametrize("robot", ROBOTS)
def test_a_rotation_stopped_at_a_joint_limit_is_reported_not_raised(robot):
    model = builtin_tools()["pointer"]
    ctrl = make_controller(robot, "pointer")
    q = ctrl.q_rad
    q[4] = ctrl.kinematics.upper_rad[4] - math.radians(1.0)  # the wrist 1 deg from its limit
    ctrl.set_q(q)
    ctrl.set_active_tool(offset_tool(model, (0.0, 2.0, 0.0)))
    res = spin_check_of(ctrl)
    stopped = [r for r in res.rotations if not r.reached]
    assert stopped and not res.all_reached
    name = ctrl.kinematics.joint_names[4]
    e = ctrl.T_flange_tool[:3, :3].T @ np.array([0.0, -2.0, 0.0])
    for r in stopped:
        assert r.stopped_by == "joint_limit"
        assert r.message.startswith(f"{name} at its limit")
        assert 0.0 < r.moved < 1.0
        # the deviation is where the robot stopped: (SC-1) with the angle actually turned
        d_tool = expected_deviation_tool_mm(r.axis, r.angle_deg * r.moved, e)
        np.testing.assert_allclose(r.deviation_tool_mm, d_tool, atol=1e-6)
        assert f"{r.label}: not reached ({r.message})" in res.summary()
    # the reached rotations still determine the offset (two or more axes reached)
    assert res.implied_tcp_error_mm == pytest.approx(2.0, abs=1e-6)
    assert res.max_deviation_mm == pytest.approx(max(r.deviation_mm for r in res.rotations if r.reached))


def test_nothing_reached_gives_no_estimate_and_says_why():
    ctrl = make_controller("gp12", "gripper")
    res = spin_check(ctrl.kinematics, ctrl.q_rad, ctrl.T_flange_tool, ctrl.mounted_tool.T_flange_tool_true,
                     settings=JogSettings(max_iterations=0))
    assert not any(r.reached for r in res.rotations)
    assert all(r.stopped_by == "unreachable" for r in res.rotations)
    assert math.isnan(res.max_deviation_mm)
    assert res.implied_tcp_error_mm is None and res.implied_offset_tool_mm is None
    assert res.implied_offset_flange_mm is None and res.fit_rms_mm is None
    assert "at least two of A, B, C must be reached" in res.summary()


def test_summary_states_each_deviation_and_the_implied_error():
    ctrl = make_controller("kr6", "gripper")
    ctrl.set_active_tool(offset_tool(builtin_tools()["gripper"], (0.0, 0.0, 1.0)))
    res = spin_check_of(ctrl)
    text = res.summary()
    for r in res.rotations:
        assert f"{r.label}: the tip moved {r.deviation_mm:.3f} mm" in text
    assert "implied TCP error 1.000 mm" in text


@pytest.mark.parametrize("angle", [0.0, -30.0, 90.5, float("nan"), float("inf"), "thirty", None])
def test_bad_angle_is_refused_with_the_allowed_range(angle):
    ctrl = make_controller("kr6", "pointer")
    with pytest.raises(ControllerError, match="spin angle"):
        spin_check_of(ctrl, angle_deg=angle)


def test_bad_frames_joints_and_robots_are_refused():
    ctrl = make_controller("kr6", "pointer")
    kin, q, T = ctrl.kinematics, ctrl.q_rad, ctrl.T_flange_tool
    T_true = ctrl.mounted_tool.T_flange_tool_true
    with pytest.raises(ControllerError, match="T_flange_tool_active must be a finite 4x4"):
        spin_check(kin, q, np.eye(3), T_true)
    bad = T.copy()
    bad[:3, :3] *= 2.0
    with pytest.raises(ControllerError, match="T_flange_tool_true has no proper rotation"):
        spin_check(kin, q, T, bad)
    with pytest.raises(ControllerError, match="Expected 6 joint values"):
        spin_check(kin, q[:5], T, T_true)
    far = q.copy()
    far[4] = kin.upper_rad[4] + 0.1
    with pytest.raises(ControllerError, match=r"A5 = .* beyond its upper limit"):
        spin_check(kin, far, T, T_true)
    with pytest.raises(ControllerError, match="same robot"):
        spin_check(kin, q, T, T_true, true_kinematics=kinematics("gp12"))


def test_result_arrays_are_read_only():
    res = spin_check_of(make_controller("kr6", "pointer"))
    with pytest.raises(ValueError):
        res.rotations[0].deviation_world_mm[0] = 1.0
    with pytest.raises(ValueError):
        res.q_start_rad[0] = 1.0


def test_truth_tool_data_helper_matches_the_tool():
    """Guards the fixture the exact-TCP test relies on."""
    model = builtin_tools()["torch"]
    T = truth_tool_data(model).T_flange_tool_mm
    np.testing.assert_allclose(T[:3, 3] / 1000.0, model.T_flange_tool_true[:3, 3], atol=1e-12)
    np.testing.assert_allclose(T[:3, :3], model.T_flange_tool_true[:3, :3], atol=1e-12)
