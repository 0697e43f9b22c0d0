"""Jogging: straight lines and fixed orientation, rotations about a fixed TCP, joint limits,
singularities (with the specific message) and no configuration jumps."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcp_pendant.controller import ControllerError, JogFrame

from .conftest import WORK_Q_DEG, angle_deg, distance_to_line_mm, make_controller


def _base_frame() -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("ZYX", [35.0, -20.0, 10.0], degrees=True).as_matrix()
    T[:3, 3] = [0.3, -0.2, 0.1]
    return T


@pytest.mark.parametrize("frame", ["TOOL", "WORLD", "BASE", "FLANGE"])
@pytest.mark.parametrize("axis", ["X", "Y", "Z"])
def test_hundred_1mm_steps_stay_on_the_line_with_fixed_orientation(robot, frame, axis):
    base = _base_frame()
    ctrl = make_controller(robot, "torch", T_world_base=base)
    T0 = ctrl.T_world_tcp()
    i = "XYZ".index(axis)
    # the commanded direction, computed independently of the controller's frame handling
    direction = {"TOOL": T0[:3, i], "WORLD": np.eye(3)[:, i], "BASE": base[:3, i],
                 "FLANGE": ctrl.T_world_flange()[:3, i]}[frame]
    for k in range(1, 101):
        res = ctrl.jog_cartesian(JogFrame(frame), axis, 1.0)
        assert res.ok and res.moved == 1.0 and res.stopped_by is None, res
        T = ctrl.T_world_tcp()
        assert distance_to_line_mm(T[:3, 3], T0[:3, 3], direction) < 0.01
        assert angle_deg(T[:3, :3], T0[:3, :3]) < 0.001
    travelled_mm = (T[:3, 3] - T0[:3, 3]) @ direction * 1000.0
    assert travelled_mm == pytest.approx(100.0, abs=0.01)


@pytest.mark.parametrize("frame", ["TOOL", "WORLD", "BASE", "FLANGE"])
@pytest.mark.parametrize("axis", ["A", "B", "C"])
def test_rotation_jog_keeps_the_tcp_fixed_and_turns_about_the_frame_axis(robot, frame, axis):
    base = _base_frame()
    ctrl = make_controller(robot, "torch", T_world_base=base)
    T0 = ctrl.T_world_tcp()
    frame_R = {"TOOL": T0[:3, :3], "WORLD": np.eye(3), "BASE": base[:3, :3],
               "FLANGE": ctrl.T_world_flange()[:3, :3]}[frame]
    u = frame_R[:, {"A": 2, "B": 1, "C": 0}[axis]]  # KUKA: A about Z, B about Y, C about X
    for k in range(1, 6):
        res = ctrl.jog_cartesian(frame, axis, 2.0)
        assert res.ok, res
        T = ctrl.T_world_tcp()
        assert np.linalg.norm(T[:3, 3] - T0[:3, 3]) * 1000.0 < 0.01
        expected = Rotation.from_rotvec(u * math.radians(2.0 * k)).as_matrix() @ T0[:3, :3]
        assert angle_deg(T[:3, :3], expected) < 0.001


def test_flange_tcp_without_active_tool_and_per_step_joint_change_is_small(robot):
    ctrl = make_controller(robot, "pointer", active=False)
    T0 = ctrl.T_world_flange()
    q_prev = ctrl.q_rad
    for _ in range(50):
        assert ctrl.jog_cartesian("WORLD", "Z", -1.0).ok
        q = ctrl.q_rad
        assert np.degrees(np.abs(q - q_prev)).max() < 1.0  # 1 mm never needs a big joint move
        q_prev = q
    np.testing.assert_allclose((ctrl.T_world_flange()[:3, 3] - T0[:3, 3]) * 1000.0, [0, 0, -50.0], atol=0.01)


def test_joint_jog_clamps_at_the_limit_and_names_the_axis():
    ctrl = make_controller("kr6")
    q_a5 = math.degrees(ctrl.q_rad[4])
    res = ctrl.jog_joint(4, 200.0)
    assert not res.ok and res.stopped_by == "joint_limit"
    assert res.message == "A5 at its limit +120.0 deg"
    assert math.degrees(ctrl.q_rad[4]) == pytest.approx(120.0, abs=1e-12)
    assert res.moved == pytest.approx((120.0 - q_a5) / 200.0)
    again = ctrl.jog_joint(4, 1.0)
    assert not again.ok and again.moved == 0.0
    res = ctrl.jog_joint(0, -400.0)
    assert res.message == "A1 at its limit -170.0 deg"
    ok = ctrl.jog_joint(0, 10.0)
    assert ok.ok and ok.moved == 1.0 and math.degrees(ctrl.q_rad[0]) == pytest.approx(-160.0)
    gp = make_controller("gp12")
    assert gp.jog_joint(5, 1000.0).message == "T at its limit +455.0 deg"


def test_cartesian_jog_stops_at_a_joint_limit_on_the_path():
    # pointer: tool X = flange Z, so C (about tool X) mostly turns A6; start 2 deg from a limit
    ctrl = make_controller("kr6", "pointer", q_deg=(10.0, -80.0, 100.0, 20.0, 40.0, 0.0))
    q0 = ctrl.q_rad
    assert ctrl.jog_cartesian("TOOL", "C", 0.5).ok
    sign = 1.0 if ctrl.q_rad[5] > q0[5] else -1.0  # which way +C turns A6
    ctrl.set_q(np.radians([10.0, -80.0, 100.0, 20.0, 40.0, sign * 348.0]))
    T0 = ctrl.T_world_tcp()
    res = ctrl.jog_cartesian("TOOL", "C", 10.0)
    assert not res.ok and res.stopped_by == "joint_limit"
    assert res.message == f"A6 at its limit {'+' if sign > 0 else '-'}350.0 deg"
    assert 0.1 < res.moved < 0.3  # about 2 of the 10 deg
    assert abs(math.degrees(ctrl.q_rad[5])) == pytest.approx(350.0, abs=0.05)
    assert abs(math.degrees(ctrl.q_rad[5])) <= 350.0 + 1e-9
    # the part that was carried out stayed on the commanded rotation about the TCP
    T = ctrl.T_world_tcp()
    assert np.linalg.norm(T[:3, 3] - T0[:3, 3]) * 1000.0 < 0.01
    turned = angle_deg(T[:3, :3], T0[:3, :3])
    assert turned == pytest.approx(10.0 * res.moved, abs=1e-6)


def test_wrist_singularity_stops_jogging_before_a5_crosses_zero():
    # A5 at 10 deg; rotating about flange Y (B) in the direction that lowers A5 runs into A5 = 0
    ctrl = make_controller("kr6", "pointer", active=False, q_deg=(0.0, -80.0, 100.0, 0.0, 10.0, 0.0))
    q0 = ctrl.q_rad
    ctrl.jog_cartesian("FLANGE", "B", 0.5)
    step = 1.0 if ctrl.q_rad[4] < q0[4] else -1.0
    res = None
    for _ in range(40):
        q_before = ctrl.q_rad
        res = ctrl.jog_cartesian("FLANGE", "B", step)
        assert np.degrees(np.abs(ctrl.q_rad - q_before)).max() < 6.0  # never a jump
        if not res.ok:
            break
    assert res is not None and not res.ok and res.stopped_by == "singularity"
    assert res.message.startswith("A5 near ") and "wrist singularity" in res.message
    a5 = math.degrees(ctrl.q_rad[4])
    assert 0.0 < a5 < 4.0  # stopped near, never through, the singularity
    assert f"A5 near {a5:.1f} deg" in res.message


def test_home_sits_in_the_wrist_singularity_and_refuses_only_what_it_cannot_follow():
    ctrl = make_controller("kr6", "pointer", active=False, q_deg=(0, -90, 90, 0, 0, 0))
    # sideways with fixed orientation needs infinite A4/A6 speed at A5 = 0
    res = ctrl.jog_cartesian("WORLD", "Y", 1.0)
    assert not res.ok and res.stopped_by == "singularity" and res.moved == 0.0
    assert res.message == "A5 near 0.0 deg: wrist singularity (A4 and A6 aligned)"
    np.testing.assert_allclose(np.degrees(ctrl.q_rad), (0, -90, 90, 0, 0, 0), atol=1e-12)
    # forwards and up can be followed
    for axis in ("X", "Z"):
        assert ctrl.jog_cartesian("WORLD", axis, 1.0).ok


def test_stretching_the_arm_stops_at_the_elbow_singularity():
    ctrl = make_controller("kr6", "pointer", active=False)
    res = None
    for _ in range(200):
        q_before = ctrl.q_rad
        res = ctrl.jog_cartesian("TOOL", "Z", 10.0)  # flange Z: forward and down, away from the base
        assert np.degrees(np.abs(ctrl.q_rad - q_before)).max() < 30.0
        if not res.ok:
            break
    assert res is not None and res.stopped_by == "singularity"
    assert res.message.startswith("A3 near ") and "arm stretched (elbow singularity)" in res.message
    # A3 stopped near the stretched arm: forearm in line with the upper arm at -atan(35/420)... + 90
    # deg of KUKA zero offset is not involved: the stretched arm is A3 = atan2(35, 420) = 4.76 deg
    assert math.degrees(ctrl.q_rad[2]) == pytest.approx(math.degrees(math.atan2(35, 420)), abs=5.0)
    q_stop = ctrl.q_rad
    for amount in (-0.1, -1.0, -10.0):  # every increment backs out of the stretched arm
        ctrl.set_q(q_stop)
        assert ctrl.jog_cartesian("TOOL", "Z", amount).ok


def test_gp12_wrist_singularity_names_b():
    ctrl = make_controller("gp12", "pointer", active=False, q_deg=(0, 0, 0, 0, 0, 0))
    res = ctrl.jog_cartesian("WORLD", "Y", 1.0)
    assert res.stopped_by == "singularity"
    assert res.message == "B near 0.0 deg: wrist singularity (R and T aligned)"


def test_move_tcp_to_follows_a_straight_line_to_the_target(robot):
    ctrl = make_controller(robot, "torch")
    T0 = ctrl.T_world_tcp()
    target = T0.copy()
    target[:3, 3] += [0.04, -0.03, 0.05]
    target[:3, :3] = Rotation.from_euler("xyz", [5.0, -8.0, 12.0], degrees=True).as_matrix() @ T0[:3, :3]
    res = ctrl.move_tcp_to(target)
    assert res.ok, res
    np.testing.assert_allclose(ctrl.T_world_tcp(), target, atol=1e-9)


def test_move_tcp_to_stops_on_a_singularity_without_jumping():
    ctrl = make_controller("kr6", "pointer", active=False)
    T0 = ctrl.T_world_tcp()
    far = T0.copy()
    far[:3, 3] = [2.0, 0.0, 0.5]  # beyond the 0.9 m reach
    res = ctrl.move_tcp_to(far)
    assert not res.ok and res.stopped_by in ("singularity", "unreachable") and 0.0 < res.moved < 1.0
    # where it stopped is on the commanded line
    d = far[:3, 3] - T0[:3, 3]
    assert distance_to_line_mm(ctrl.T_world_tcp()[:3, 3], T0[:3, 3], d / np.linalg.norm(d)) < 0.01


def test_bad_jog_input_is_rejected_with_the_controllers_error():
    ctrl = make_controller("kr6")
    with pytest.raises(ControllerError, match="jog frame"):
        ctrl.jog_cartesian("TOOLS", "X", 1.0)
    with pytest.raises(ControllerError, match="jog axis"):
        ctrl.jog_cartesian("TOOL", "W", 1.0)
    with pytest.raises(ControllerError, match="finite"):
        ctrl.jog_cartesian("TOOL", "X", float("nan"))
    with pytest.raises(ControllerError, match="Joint index"):
        ctrl.jog_joint(6, 1.0)
    with pytest.raises(ControllerError, match="A2 = -200.0 deg is beyond its lower limit -190.0 deg"):
        ctrl.set_q(np.radians([0, -200, 90, 0, 0, 0]))
    with pytest.raises(ControllerError, match="6 joint values"):
        ctrl.set_q([0.0, 0.0])


@pytest.mark.parametrize("frame", ["WORLD", "TOOL", "FLANGE"])
def test_turning_the_long_torch_about_its_tip_stops_only_at_a_named_limit_or_singularity(robot, frame):
    """The torch's TCP is 339 mm from the flange: turning it about the TCP swings the flange on
    a 339 mm circle, so the axes move several degrees per degree. That is a legitimate motion:
    a 100 deg rotation jog (the pendant's largest increment) either completes or stops at a
    joint limit or a singularity that the message names, never with an unexplained stop, and
    the TCP stays put throughout."""
    for axis in ("A", "B", "C"):
        for sign in (1.0, -1.0):
            ctrl = make_controller(robot, "torch")
            p0 = ctrl.T_world_tcp()[:3, 3]
            res = ctrl.jog_cartesian(frame, axis, sign * 100.0)
            assert res.stopped_by in (None, "joint_limit", "singularity"), (axis, sign, res)
            if res.stopped_by == "joint_limit":
                assert " at its limit " in res.message
            elif res.stopped_by == "singularity":
                assert "singularity" in res.message
            assert np.linalg.norm(ctrl.T_world_tcp()[:3, 3] - p0) * 1000.0 < 0.01


@pytest.mark.parametrize("increment", [100.0, 10.0, 1.0, 0.1])
@pytest.mark.parametrize("frame", ["WORLD", "TOOL"])
def test_every_pendant_increment_is_one_exact_move(robot, frame, increment):
    """One press of each increment (100, 10, 1, 0.1 mm or deg) moves exactly that far: the TCP
    on its line (< 0.01 mm) with the orientation held, or turned about the TCP, then back."""
    ctrl = make_controller(robot, "pointer")
    T0 = ctrl.T_world_tcp()
    direction = {"WORLD": np.array([0.0, 0.0, -1.0]), "TOOL": T0[:3, 0]}[frame]
    res = ctrl.jog_cartesian(frame, "Z" if frame == "WORLD" else "X", increment * (-1.0 if frame == "WORLD" else 1.0))
    assert res.ok, res
    T = ctrl.T_world_tcp()
    assert distance_to_line_mm(T[:3, 3], T0[:3, 3], direction) < 0.01
    assert (T[:3, 3] - T0[:3, 3]) @ direction * 1000.0 == pytest.approx(increment, abs=1e-6)
    assert angle_deg(T[:3, :3], T0[:3, :3]) < 0.001
    turn = increment
    ctrl.set_q(np.radians(WORK_Q_DEG[robot]))  # back to the start, then turn about the tip
    res = ctrl.jog_cartesian(frame, "A", turn)
    assert res.ok, res
    T = ctrl.T_world_tcp()
    assert np.linalg.norm(T[:3, 3] - T0[:3, 3]) * 1000.0 < 0.01
    assert angle_deg(T[:3, :3], T0[:3, :3]) == pytest.approx(turn, abs=0.001)
