"""Systematic-error scenarios: the trainer's choice is validated, the drawn errors are in their
ranges and reproducible, the perturbed robot and the bent tool are what the docstrings say, and
each scenario shows in a calibration and in the TCP check as methods.md "Systematic errors"
states (perfect touches on the perturbed robot leave 0.05-0.5 mm residuals for every seed)."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from tcpcal.origin import solve_xyz4
from tcpcal.tool import Tool
from tcp_pendant.controller import ControllerError, approach_pose, builtin_tools, solve_ik
from tcp_pendant.controller.scenarios import (
    DEFAULT_SEED_RANGE,
    SCENARIO_KINDS,
    KinematicErrors,
    Scenario,
    ScenarioWorld,
    bent_tool,
    draw_kinematic_errors,
    draw_reference_move,
    draw_tool_bend,
    explain,
    perturbed_kinematics,
    perturbed_model,
    realize,
)
from tcp_pendant.controller.spin import spin_check_of

from .conftest import ROBOTS, TIP_M, TOOL_KEYS, kinematics, make_controller

# touch directions (tilt, azimuth in degrees); the first six reachable ones are used, as
# auto-touch retries another direction when one is out of reach
DIRECTIONS = [(0, 0), (30, 0), (30, 90), (30, 270), (45, 45), (40, 135), (35, 225), (25, 180), (20, 315)]


def exact_touches(kin_nominal, kin_true, T_flange_tool_true, tip_world_m, move=None):
    """Auto-touch-like touches, exact on the TRUE robot; the flange poses the controller
    records come from the NOMINAL model (mm). ``move``: a ReferenceMove."""
    rotations, positions = [], []
    q = kin_nominal.home_rad
    for tilt, az in DIRECTIONS:
        n = len(rotations)  # touches recorded so far
        if n == 6:
            break
        tip = np.asarray(tip_world_m) if move is None else move.tip_world_m(tip_world_m, n)
        sol = solve_ik(kin_true, approach_pose(tip, tilt_deg=tilt, azimuth_deg=az), q,
                       T_flange_tcp=T_flange_tool_true)
        if not sol.ok:
            continue
        F = kin_nominal.T_world_flange(sol.q_rad)
        rotations.append(F[:3, :3])
        positions.append(F[:3, 3] * 1000.0)
    assert len(rotations) == 6, "fewer than six reachable touch directions"
    return solve_xyz4(np.array(rotations), np.array(positions), detect_outliers=False)


# ----------------------------------------------------------------------------- the choice
def test_off_by_default():
    assert Scenario().kind == "off"
    assert SCENARIO_KINDS == ("off", "bent_tool", "robot_accuracy", "moved_reference")
    world = realize(Scenario(), kinematics("kr6"), builtin_tools()["torch"])
    assert world.true_kinematics is kinematics("kr6")
    assert world.tool_true is builtin_tools()["torch"]
    assert world.tool_bend is world.kinematic_errors is world.reference_move is None


@pytest.mark.parametrize("kwargs, match", [
    ({"kind": "crash"}, "Unknown scenario 'crash'; choose one of off, bent_tool, robot_accuracy, moved_reference"),
    ({"seed": -1}, "seed must be a whole number >= 0"),
    ({"seed": 1.5}, "seed must be a whole number >= 0"),
    ({"seed": True}, "seed must be a whole number >= 0"),
    ({"bend_shift_mm": (5.0, 2.0)}, r"bend_shift_mm must satisfy 0 <= low <= high <= 50 mm"),
    ({"bend_angle_deg": (-1.0, 2.0)}, r"bend_angle_deg must satisfy"),
    ({"link_length_mm": (0.1, float("nan"))}, r"link_length_mm must satisfy"),
    ({"joint_zero_deg": (0.01, 0.05, 0.1)}, r"joint_zero_deg must be two numbers"),
    ({"reference_shift_mm": "far"}, r"reference_shift_mm must be two numbers"),
    ({"reference_moves_after_touch": 0}, "reference_moves_after_touch must be a touch number >= 1"),
])
def test_bad_choices_are_refused_by_name(kwargs, match):
    with pytest.raises(ControllerError, match=match):
        Scenario(**kwargs)


def test_draws_are_reproducible_and_differ_between_seeds():
    kin = kinematics("kr6")
    a, b, c = Scenario("bent_tool", 3), Scenario("bent_tool", 3), Scenario("bent_tool", 4)
    assert draw_tool_bend(a) == draw_tool_bend(b) != draw_tool_bend(c)
    assert draw_kinematic_errors(a, kin) == draw_kinematic_errors(b, kin) != draw_kinematic_errors(c, kin)
    assert draw_reference_move(a) == draw_reference_move(b) != draw_reference_move(c)


@pytest.mark.parametrize("seed", DEFAULT_SEED_RANGE)
def test_drawn_errors_lie_in_the_ranges(seed):
    s = Scenario("bent_tool", seed)
    bend = draw_tool_bend(s)
    assert 2.0 <= bend.shift_mm <= 5.0 and 1.0 <= bend.angle_deg <= 3.0
    for robot in ROBOTS:
        kin = kinematics(robot)
        err = draw_kinematic_errors(s, kin)
        lengths = [np.linalg.norm(kin.model.jointPlacements[j].translation) for j in range(1, kin.model.njoints)]
        for L, dL in zip(lengths, err.length_offsets_mm):
            assert (0.1 <= abs(dL) <= 0.5) if L > 1e-9 else dL == 0.0
        assert all(0.01 <= abs(d) <= 0.05 for d in err.joint_zero_offsets_deg)
    move = draw_reference_move(s)
    assert move.shift_mm[2] == 0.0 and 2.0 <= np.linalg.norm(move.shift_mm) <= 5.0
    assert move.after_touch == 2


# ----------------------------------------------------------------------------- bent tool
@pytest.mark.parametrize("tool_key", TOOL_KEYS)
@pytest.mark.parametrize("seed", range(5))
def test_bent_tool_moves_the_tip_sideways_and_tilts_its_axis(tool_key, seed):
    tool = builtin_tools()[tool_key]
    T_before = tool.T_flange_tool_true.copy()
    world = realize(Scenario("bent_tool", seed), kinematics("kr6"), tool)
    bend, bent = world.tool_bend, world.tool_true
    assert (bent.key, bent.label, bent.urdf_path) == (tool.key, tool.label, tool.urdf_path)
    np.testing.assert_array_equal(bent_tool(tool, bend).T_flange_tool_true, bent.T_flange_tool_true)
    np.testing.assert_array_equal(tool.T_flange_tool_true, T_before)  # the library's tool unchanged
    T0, T1 = tool.T_flange_tool_true, bent.T_flange_tool_true
    x_old, shift = T0[:3, 0], (T1[:3, 3] - T0[:3, 3]) * 1000.0
    assert np.linalg.norm(shift) == pytest.approx(bend.shift_mm, abs=1e-9)
    assert abs(shift @ x_old) < 1e-9  # sideways: perpendicular to the working direction
    turn = np.degrees(np.linalg.norm(Rotation.from_matrix(T1[:3, :3] @ T0[:3, :3].T).as_rotvec()))
    assert turn == pytest.approx(bend.angle_deg, abs=1e-9)
    assert (T1[:3, 0] - x_old) @ shift > 0.0  # the tool axis leans towards the side the tip went


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("seed", range(3))
def test_bent_tool_small_residual_new_tcp_and_the_check_finds_the_bend(robot, seed):
    tool = builtin_tools()["torch"]
    kin = kinematics(robot)
    world = realize(Scenario("bent_tool", seed), kin, tool)
    bent = world.tool_true
    # recalibrating after the crash: the touches agree, the new TCP is the bent one
    res = exact_touches(kin, kin, bent.T_flange_tool_true, TIP_M[robot])
    assert res.rms_error < 1e-6
    np.testing.assert_allclose(res.tcp, bent.T_flange_tool_true[:3, 3] * 1000.0, atol=1e-6)
    # the TCP check with the stale library data: implied error = the bend's tip shift
    ctrl = make_controller(robot, "torch")  # active data = the unbent truth (the library's)
    ctrl.mount_tool(bent)
    check = spin_check_of(ctrl)
    assert check.implied_tcp_error_mm == pytest.approx(world.tool_bend.shift_mm, abs=1e-6)
    np.testing.assert_allclose(check.implied_offset_flange_mm,
                               (bent.T_flange_tool_true[:3, 3] - tool.T_flange_tool_true[:3, 3]) * 1000.0,
                               atol=1e-6)


# ----------------------------------------------------------------------------- robot accuracy
@pytest.mark.parametrize("robot", ROBOTS)
def test_joint_zero_offsets_equal_the_nominal_model_at_shifted_angles(robot):
    kin = kinematics(robot)
    offsets = tuple(float(v) for v in np.linspace(-0.05, 0.05, kin.n_joints))
    true = perturbed_kinematics(kin, KinematicErrors((0.0,) * kin.n_joints, offsets))
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = rng.uniform(kin.lower_rad, kin.upper_rad) * 0.8
        np.testing.assert_allclose(true.T_world_flange(q), kin.T_world_flange(q + np.radians(offsets)),
                                   atol=1e-12)


@pytest.mark.parametrize("robot", ROBOTS)
def test_length_offsets_lengthen_each_joint_placement_along_itself(robot):
    kin = kinematics(robot)
    before = [pin.SE3(P) for P in kin.model.jointPlacements]
    lengths = tuple(0.1 * (j + 1) for j in range(kin.n_joints))
    model = perturbed_model(kin.model, KinematicErrors(lengths, (0.0,) * kin.n_joints))
    for j in range(1, kin.model.njoints):
        t0, t1 = before[j].translation, model.jointPlacements[j].translation
        np.testing.assert_allclose(model.jointPlacements[j].rotation, before[j].rotation, atol=1e-15)
        if np.linalg.norm(t0) > 1e-9:
            assert (np.linalg.norm(t1) - np.linalg.norm(t0)) * 1000.0 == pytest.approx(lengths[j - 1], abs=1e-9)
            np.testing.assert_allclose(t1 / np.linalg.norm(t1), t0 / np.linalg.norm(t0), atol=1e-12)
        else:
            np.testing.assert_array_equal(t1, t0)
        # the nominal model is a different object and unchanged
        np.testing.assert_array_equal(kin.model.jointPlacements[j].translation, before[j].translation)


def test_perturbed_model_refuses_errors_for_another_robot():
    kin = kinematics("kr6")
    with pytest.raises(ControllerError, match="the robot has 6 joints"):
        perturbed_model(kin.model, KinematicErrors((0.1,) * 5, (0.01,) * 6))


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("tool_key", TOOL_KEYS)
def test_perfect_touches_on_the_real_robot_leave_tenths_of_a_millimetre(robot, tool_key):
    """Auto-touch-like exact touches of the TRUE tip, solved with the NOMINAL flange poses:
    residual RMS 0.05-0.5 mm for every default seed (0.1-0.3 mm typically), as on a real arm."""
    kin, tool = kinematics(robot), builtin_tools()[tool_key]
    control = exact_touches(kin, kin, tool.T_flange_tool_true, TIP_M[robot])
    assert control.rms_error < 1e-6  # without the scenario the same touches are exact
    rms, tcp_err = [], []
    for seed in DEFAULT_SEED_RANGE:
        world = realize(Scenario("robot_accuracy", seed), kin, tool)
        assert world.true_kinematics.joint_names == kin.joint_names
        res = exact_touches(kin, world.true_kinematics, tool.T_flange_tool_true, TIP_M[robot])
        rms.append(res.rms_error)
        tcp_err.append(np.linalg.norm(res.tcp - tool.T_flange_tool_true[:3, 3] * 1000.0))
    assert 0.05 <= min(rms) and max(rms) <= 0.5, np.round(rms, 3)
    assert 0.01 < min(tcp_err) and max(tcp_err) < 2.0  # the TCP is off by tenths, not millimetres


@pytest.mark.parametrize("robot", ROBOTS)
def test_tcp_check_on_the_real_robot_shows_tenths_no_tcp_explains(robot):
    ctrl = make_controller(robot, "pointer")  # exact tool data
    for seed in range(5):
        world = realize(Scenario("robot_accuracy", seed), ctrl.kinematics, ctrl.mounted_tool)
        check = spin_check_of(ctrl, true_kinematics=world.true_kinematics)
        assert 0.05 < check.max_deviation_mm < 1.0
        assert check.fit_rms_mm > 0.02  # a pure TCP error would leave ~0 (test_spin)


# ----------------------------------------------------------------------------- moved reference
def test_reference_tip_moves_after_touch_k():
    move = draw_reference_move(Scenario("moved_reference", 1, reference_moves_after_touch=3))
    tip = np.array([0.5, 0.0, 0.2])
    for n in range(3):
        np.testing.assert_array_equal(move.tip_world_m(tip, n), tip)
    for n in (3, 4, 10):
        np.testing.assert_allclose(move.tip_world_m(tip, n), tip + np.array(move.shift_mm) / 1000.0)


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("seed", range(5))
def test_moved_reference_large_residual_and_the_check_shows_the_wrong_tcp(robot, seed):
    kin, tool = kinematics(robot), builtin_tools()["pointer"]
    world = realize(Scenario("moved_reference", seed), kin, tool)
    res = exact_touches(kin, kin, tool.T_flange_tool_true, TIP_M[robot], move=world.reference_move)
    assert res.rms_error > 0.5  # above anything the accuracy scenario gives
    tcp_error = np.linalg.norm(res.tcp - tool.T_flange_tool_true[:3, 3] * 1000.0)
    assert tcp_error > 0.5
    # working with that TCP, the TCP check (no reference tip needed) finds exactly that error
    ctrl = make_controller(robot, "pointer")
    ctrl.set_active_tool(Tool.from_rotation("calibrated", tuple(res.tcp), tool.T_flange_tool_true[:3, :3]))
    check = spin_check_of(ctrl)
    assert check.implied_tcp_error_mm == pytest.approx(tcp_error, abs=1e-6)


# ----------------------------------------------------------------------------- words
def test_explain_says_how_each_scenario_shows_and_how_the_check_reveals_it():
    kin, tool = kinematics("kr6"), builtin_tools()["torch"]
    assert "No systematic error" in explain(Scenario())
    for kind, shows in (("bent_tool", "small residual"), ("robot_accuracy", "residual of a few tenths"),
                        ("moved_reference", "residual is large")):
        text = explain(Scenario(kind))
        assert shows in text and "TCP check" in text, kind
    bent = realize(Scenario("bent_tool", 2), kin, tool)
    assert f"tip moved {bent.tool_bend.shift_mm:.1f} mm sideways" in explain(bent)
    moved = realize(Scenario("moved_reference", 2), kin, tool)
    s = math.hypot(*moved.reference_move.shift_mm)
    assert f"knocked {s:.1f} mm after touch 2" in explain(moved)
    assert isinstance(moved, ScenarioWorld)
