"""``VirtualController.T_world_tool_true`` answered from the flange pose the last jog ended on
(``jog.FlangeState``): bit for bit the fresh FK's, and never from a state of other joint angles
or of another robot than the physical one."""

from __future__ import annotations

import numpy as np
import pytest

from tcp_pendant.controller.scenarios import Scenario, realize

from .conftest import make_controller


def _fresh(ctrl) -> np.ndarray:
    """The definition: one FK pass of the physical robot at the current q."""
    return ctrl.true_kinematics.T_world_flange(ctrl.q_rad) @ ctrl.mounted_tool.T_flange_tool_true


@pytest.mark.parametrize("tool_key", ["pointer", "torch"])
def test_after_jogs_it_is_the_fresh_fk_bit_for_bit(robot, tool_key) -> None:
    ctrl = make_controller(robot, tool_key)
    rng = np.random.default_rng(7)
    used = 0
    for k in range(60):
        axis = "XYZABC"[k % 6]
        amount = float(rng.choice([0.1, 1.0, 10.0, -0.1, -1.0, -10.0]))
        ctrl.jog_cartesian(["WORLD", "TOOL", "BASE", "FLANGE"][k % 4], axis, amount)
        used += ctrl._flange_of_state() is not None
        T = ctrl.T_world_tool_true()
        assert np.array_equal(T, _fresh(ctrl))                     # the same bits, not just close
        T[0, 3] += 1.0                                             # a fresh array: the caller's to write
        assert np.array_equal(ctrl.T_world_tool_true(), _fresh(ctrl))
    assert used >= 50                                              # and the kept pose answered


def test_a_q_set_past_the_state_is_never_answered_from_it() -> None:
    ctrl = make_controller("kr6", "pointer")
    ctrl.jog_cartesian("WORLD", "X", 1.0)
    assert ctrl._flange_of_state() is not None
    q = ctrl.q_rad
    q[0] += 1e-9                                                   # one joint a hair away
    ctrl._q = q                                                    # behind the controller's back: no drop
    assert ctrl._flange_of_state() is None
    assert np.array_equal(ctrl.T_world_tool_true(), _fresh(ctrl))


@pytest.mark.parametrize("move", ["set_q", "jog_joint", "go_home", "move_true_tool_to"])
def test_every_other_move_gives_the_pose_of_the_new_joint_angles(move) -> None:
    ctrl = make_controller("kr6", "torch")
    ctrl.jog_cartesian("WORLD", "Z", -5.0)
    before = ctrl.T_world_tool_true()
    if move == "set_q":
        ctrl.set_q(ctrl.q_rad + np.radians(2.0))
    elif move == "jog_joint":
        ctrl.jog_joint(2, 3.0)
    elif move == "go_home":
        ctrl.go_home()
    else:
        T = before.copy()
        T[:3, 3] += (0.01, 0.0, 0.0)
        assert ctrl.move_true_tool_to(T).ok
    after = ctrl.T_world_tool_true()
    assert not np.allclose(after, before)
    assert np.array_equal(after, _fresh(ctrl))


def test_a_physical_robot_other_than_the_model_is_asked_itself() -> None:
    ctrl = make_controller("kr6", "pointer")
    ctrl.jog_cartesian("WORLD", "X", 1.0)
    world = realize(Scenario("robot_accuracy", seed=3), ctrl.kinematics, ctrl.mounted_tool)
    ctrl.set_true_kinematics(world.true_kinematics)
    ctrl.jog_cartesian("WORLD", "X", 1.0)                          # a state of the model, not of the robot
    assert ctrl._state is not None and ctrl._flange_of_state() is None
    T = ctrl.T_world_tool_true()
    assert np.array_equal(T, _fresh(ctrl))
    model = ctrl.kinematics.T_world_flange(ctrl.q_rad) @ ctrl.mounted_tool.T_flange_tool_true
    assert not np.allclose(T[:3, 3], model[:3, 3], atol=1e-6)      # the model's would be wrong


def test_another_tool_mounted_after_the_jog_is_the_one_used() -> None:
    from tcp_pendant.controller import builtin_tools

    ctrl = make_controller("kr6", "pointer")
    ctrl.jog_cartesian("WORLD", "X", 1.0)
    ctrl.mount_tool(builtin_tools()["torch"])
    assert np.array_equal(ctrl.T_world_tool_true(), _fresh(ctrl))
