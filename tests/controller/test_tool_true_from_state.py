"""``VirtualController.tool_tip_true_m``: the true tool tip from the flange pose the last jog
ended on (``jog.FlangeState``) - the tip of ``T_world_tool_true()`` to rounding - and never from
a state of other joint angles or of another robot than the physical one."""

from __future__ import annotations

import numpy as np
import pytest

from tcp_pendant.controller import builtin_tools
from tcp_pendant.controller.scenarios import Scenario, realize

from .conftest import make_controller

ROUNDING_M = 1e-15


def _fresh_tip(ctrl) -> np.ndarray:
    """The definition: one FK pass of the physical robot at the current q."""
    return (ctrl.true_kinematics.T_world_flange(ctrl.q_rad) @ ctrl.mounted_tool.T_flange_tool_true)[:3, 3]


def _no_fk(ctrl) -> None:
    """Make the controller's own FK pass fail: whatever answers then came from the kept state."""
    def fail() -> np.ndarray:
        raise AssertionError("FK pass")
    ctrl.T_world_flange_true = fail


@pytest.mark.parametrize("tool_key", ["pointer", "torch"])
def test_after_jogs_it_is_the_fk_tip_to_rounding_and_comes_from_the_kept_state(robot, tool_key) -> None:
    ctrl = make_controller(robot, tool_key)
    probe = make_controller(robot, tool_key)
    _no_fk(probe)
    rng = np.random.default_rng(7)
    for k in range(60):
        axis = "XYZABC"[k % 6]
        amount = float(rng.choice([0.1, 1.0, 10.0, -0.1, -1.0, -10.0]))
        frame = ["WORLD", "TOOL", "BASE", "FLANGE"][k % 4]
        assert ctrl.jog_cartesian(frame, axis, amount).ok
        tip = ctrl.tool_tip_true_m()
        assert all(type(v) is float for v in tip)
        np.testing.assert_allclose(tip, _fresh_tip(ctrl), rtol=0, atol=ROUNDING_M)
        np.testing.assert_allclose(tip, ctrl.T_world_tool_true()[:3, 3], rtol=0, atol=ROUNDING_M)
        probe.set_q(ctrl.q_rad)                     # the same pose, no kept state: the FK is asked
        with pytest.raises(AssertionError, match="FK pass"):
            probe.tool_tip_true_m()
    _no_fk(ctrl)
    ctrl.tool_tip_true_m()                          # after a jog: no FK pass


def test_a_q_set_past_the_state_is_never_answered_from_it() -> None:
    ctrl = make_controller("kr6", "pointer")
    ctrl.jog_cartesian("WORLD", "X", 1.0)
    kept = ctrl.tool_tip_true_m()
    q = ctrl.q_rad
    q[0] += 1e-6                                    # one joint a hair away
    ctrl._q = q                                     # behind the controller's back: the state is not dropped
    tip = ctrl.tool_tip_true_m()
    np.testing.assert_allclose(tip, _fresh_tip(ctrl), rtol=0, atol=ROUNDING_M)
    assert np.linalg.norm(np.subtract(tip, kept)) > 1e-7


@pytest.mark.parametrize("move", ["set_q", "jog_joint", "go_home", "move_true_tool_to"])
def test_every_other_move_gives_the_tip_of_the_new_joint_angles(move) -> None:
    ctrl = make_controller("kr6", "torch")
    ctrl.jog_cartesian("WORLD", "Z", -5.0)
    before = ctrl.tool_tip_true_m()
    if move == "set_q":
        ctrl.set_q(ctrl.q_rad + np.radians(2.0))
    elif move == "jog_joint":
        ctrl.jog_joint(2, 3.0)
    elif move == "go_home":
        ctrl.go_home()
    else:
        T = ctrl.T_world_tool_true()
        T[:3, 3] += (0.01, 0.0, 0.0)
        assert ctrl.move_true_tool_to(T).ok
    after = ctrl.tool_tip_true_m()
    assert np.linalg.norm(np.subtract(after, before)) > 1e-3
    np.testing.assert_allclose(after, _fresh_tip(ctrl), rtol=0, atol=ROUNDING_M)


def test_a_physical_robot_other_than_the_model_is_asked_itself() -> None:
    ctrl = make_controller("kr6", "pointer")
    world = realize(Scenario("robot_accuracy", seed=3), ctrl.kinematics, ctrl.mounted_tool)
    ctrl.set_true_kinematics(world.true_kinematics)
    assert ctrl.jog_cartesian("WORLD", "X", 1.0).ok     # a state of the model, not of the robot
    assert ctrl._state is not None
    tip = ctrl.tool_tip_true_m()
    np.testing.assert_allclose(tip, _fresh_tip(ctrl), rtol=0, atol=ROUNDING_M)
    model = (ctrl.kinematics.T_world_flange(ctrl.q_rad) @ ctrl.mounted_tool.T_flange_tool_true)[:3, 3]
    assert np.linalg.norm(np.subtract(tip, model)) > 1e-6   # the model's would be wrong


def test_another_tool_mounted_after_the_jog_is_the_one_used() -> None:
    ctrl = make_controller("kr6", "pointer")
    ctrl.jog_cartesian("WORLD", "X", 1.0)
    ctrl.mount_tool(builtin_tools()["torch"])
    np.testing.assert_allclose(ctrl.tool_tip_true_m(), _fresh_tip(ctrl), rtol=0, atol=ROUNDING_M)
