"""The controller with a physical robot next to its model: the true tip, the
touch geometry, auto-approach and ``move_true_tool_to`` use ``true_kinematics``; readouts,
recorded flange poses, ``T_world_tcp`` and jogs use the nominal ``kinematics``; the pose state
agrees with the controller; the bent tool and the moved reference tip play on a controller."""

from __future__ import annotations

import numpy as np
import pytest

from tcp_pendant.controller import ControllerError, RobotKinematics, VirtualController, builtin_tools
from tcp_pendant.controller.pose_state import pose_state
from tcp_pendant.controller.scenarios import Scenario, realize
from tcp_pendant.controller.spin import spin_check_of

from .conftest import TIP_M, kinematics, make_controller, truth_tool_data


def accuracy_controller(robot: str = "kr6", seed: int = 3) -> tuple[VirtualController, RobotKinematics]:
    ctrl = make_controller(robot, "pointer")
    world = realize(Scenario("robot_accuracy", seed=seed), ctrl.kinematics, ctrl.mounted_tool)
    ctrl.set_true_kinematics(world.true_kinematics)
    return ctrl, world.true_kinematics


def test_default_true_kinematics_is_the_model_itself():
    ctrl = make_controller("kr6")
    assert ctrl.true_kinematics is ctrl.kinematics
    np.testing.assert_allclose(ctrl.T_world_tool_true(),
                               ctrl.T_world_flange() @ ctrl.mounted_tool.T_flange_tool_true, atol=1e-15)


def test_true_tip_comes_from_the_physical_robot_readouts_from_the_model():
    ctrl, true_kin = accuracy_controller()
    q = ctrl.q_rad
    nominal = ctrl.kinematics.T_world_flange(q)
    physical = true_kin.T_world_flange(q)
    gap_mm = np.linalg.norm(physical[:3, 3] - nominal[:3, 3]) * 1000.0
    assert 0.05 < gap_mm < 5.0                        # a real arm's absolute accuracy
    np.testing.assert_allclose(ctrl.T_world_flange(), nominal, atol=1e-15)
    np.testing.assert_allclose(ctrl.T_world_tcp(), nominal @ ctrl.T_flange_tool, atol=1e-15)
    np.testing.assert_allclose(ctrl.T_world_tool_true(), physical @ ctrl.mounted_tool.T_flange_tool_true,
                               atol=1e-15)
    r = ctrl.readout()
    p_nominal = (nominal @ ctrl.T_flange_tool)[:3, 3] * 1000.0
    np.testing.assert_allclose([r.x_mm, r.y_mm, r.z_mm], p_nominal, atol=1e-9)


def test_touch_geometry_and_pose_state_use_the_physical_robot():
    ctrl, true_kin = accuracy_controller()
    # put the NOMINAL true tip exactly on the reference tip: physically it is a few tenths off
    ctrl.set_reference_tip((ctrl.kinematics.T_world_flange(ctrl.q_rad) @ ctrl.mounted_tool.T_flange_tool_true)[:3, 3])
    g = ctrl.touch_geometry()
    assert 0.05 < g.distance_mm < 5.0
    state = pose_state(ctrl)
    np.testing.assert_allclose(state.T_world_tool_true, ctrl.T_world_tool_true(), atol=1e-15)
    np.testing.assert_allclose(state.T_world_flange, ctrl.T_world_flange(), atol=1e-15)
    assert state.touch.distance_mm == pytest.approx(g.distance_mm, abs=1e-12)


def test_pose_state_key_changes_with_the_physical_robot():
    from tcp_pendant.controller.pose_state import pose_state_key

    ctrl, true_kin = accuracy_controller()
    key = pose_state_key(ctrl)
    ctrl.set_true_kinematics(None)
    assert ctrl.true_kinematics is ctrl.kinematics
    assert pose_state_key(ctrl) != key


def test_auto_approach_touches_with_the_physical_robot_records_the_model_pose():
    ctrl, true_kin = accuracy_controller()
    res = ctrl.auto_approach(tilt_deg=20.0, azimuth_deg=30.0)
    assert res.ok, res.message
    assert ctrl.touch_geometry().distance_mm < 1e-6   # physically touching
    # the flange pose the controller records is the model's at those joints
    np.testing.assert_allclose(ctrl.T_world_flange(), ctrl.kinematics.T_world_flange(ctrl.q_rad), atol=1e-15)
    nominal_tip = (ctrl.T_world_flange() @ ctrl.mounted_tool.T_flange_tool_true)[:3, 3]
    assert np.linalg.norm(nominal_tip - ctrl.reference_tip_world_m) * 1000.0 > 0.05


def test_move_true_tool_to_uses_the_physical_robot():
    ctrl, _ = accuracy_controller()
    target = ctrl.T_world_tool_true()
    target[:3, 3] += [0.01, -0.02, 0.005]
    assert ctrl.move_true_tool_to(target).ok
    np.testing.assert_allclose(ctrl.T_world_tool_true(), target, atol=1e-9)


def test_jogs_follow_the_model():
    ctrl, _ = accuracy_controller()
    before = ctrl.T_world_tcp()
    assert ctrl.jog_cartesian("WORLD", "X", 5.0).ok
    after = ctrl.T_world_tcp()
    np.testing.assert_allclose(after[:3, 3] - before[:3, 3], [0.005, 0.0, 0.0], atol=1e-7)


def test_a_robot_with_other_joints_is_refused():
    ctrl = make_controller("kr6")
    with pytest.raises(ControllerError, match="same robot"):
        ctrl.set_true_kinematics(kinematics("gp12"))
    with pytest.raises(ControllerError, match="RobotKinematics"):
        ctrl.set_true_kinematics("kr6")  # type: ignore[arg-type]


def test_tcp_check_with_the_physical_robot_shows_what_no_tcp_explains():
    ctrl, true_kin = accuracy_controller()
    exact = spin_check_of(ctrl, true_kinematics=ctrl.true_kinematics)
    assert exact.max_deviation_mm > 0.02               # the arm's inaccuracy shows
    model_only = spin_check_of(ctrl)
    assert model_only.max_deviation_mm < 0.01         # on the model alone the exact TCP stays put


def test_bent_tool_mounted_keeps_the_library_data_stale():
    ctrl = make_controller("kr6", "torch")             # active data = the unbent truth
    world = realize(Scenario("bent_tool", seed=1), ctrl.kinematics, ctrl.mounted_tool)
    ctrl.mount_tool(world.tool_true)
    bend = np.linalg.norm(world.tool_true.T_flange_tool_true[:3, 3] - builtin_tools()["torch"].T_flange_tool_true[:3, 3])
    assert 2.0 <= bend * 1000.0 <= 5.5
    check = spin_check_of(ctrl, true_kinematics=ctrl.true_kinematics)
    assert check.implied_tcp_error_mm == pytest.approx(world.tool_bend.shift_mm, rel=0.05, abs=0.1)


def test_moved_reference_tip_after_touch_k():
    ctrl = make_controller("kr6")
    world = realize(Scenario("moved_reference", seed=2, reference_moves_after_touch=2), ctrl.kinematics,
                    ctrl.mounted_tool)
    tip0 = np.asarray(TIP_M["kr6"])
    move = world.reference_move
    for n in (0, 1):
        ctrl.set_reference_tip(move.tip_world_m(tip0, n))
        np.testing.assert_allclose(ctrl.reference_tip_world_m, tip0)
    ctrl.set_reference_tip(move.tip_world_m(tip0, 2))
    shift = np.linalg.norm(ctrl.reference_tip_world_m - tip0) * 1000.0
    assert 2.0 <= shift <= 5.0


def test_truth_helper_used_above_is_the_tool():
    model = builtin_tools()["pointer"]
    np.testing.assert_allclose(truth_tool_data(model).T_flange_tool_mm[:3, 3] / 1000.0,
                               model.T_flange_tool_true[:3, 3], atol=1e-12)


def test_kinematics_for_worker_are_own_copies_of_both_robots():
    """A job in a worker thread gets the nominal and the physical robot with their own pinocchio
    data (the models shared), the physical one being the nominal copy without accuracy error."""
    plain = make_controller("kr6")
    nominal, physical = plain.kinematics_for_worker()
    assert physical is nominal and nominal is not plain.kinematics
    assert nominal.model is plain.kinematics.model and nominal.data is not plain.kinematics.data
    c, true_kin = accuracy_controller()
    nominal, physical = c.kinematics_for_worker()
    assert nominal.model is c.kinematics.model and physical.model is true_kin.model
    assert physical.data is not true_kin.data and nominal.data is not c.kinematics.data
    q = c.q_rad
    np.testing.assert_array_equal(physical.T_world_flange(q), true_kin.T_world_flange(q))
    np.testing.assert_array_equal(nominal.T_world_flange(q), c.kinematics.T_world_flange(q))
