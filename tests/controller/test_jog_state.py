"""The jog's kinematics cache (``jog.FlangeState``, kept by the controller between paths) and the
fast Newton step: the same joint angles and stops as the algorithm before them
(``tests/bench/jog_yardstick.py``), and a cache that is never used stale."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tcp_pendant.controller import VirtualController
from tcp_pendant.controller.jog import (
    FlangeState,
    JogSettings,
    follow_path,
    smallest_singular_value,
)
from tcp_pendant.controller.scenarios import Scenario, realize

from .conftest import TIP_M, kinematics, make_controller, truth_tool_data

from bench.jog_yardstick import LegacyController

# A5 = +-10 deg: the same arm on both sides of the wrist singularity, det J_flange of opposite sign
Q_WRIST_PLUS_DEG = (0.0, -80.0, 100.0, 0.0, 10.0, 0.0)
Q_WRIST_MINUS_DEG = (0.0, -80.0, 100.0, 0.0, -10.0, 0.0)


def _pair(robot: str, tool_key: str, active: bool, q_deg: tuple[float, ...] | None = None
          ) -> tuple[VirtualController, VirtualController]:
    new = make_controller(robot, tool_key, active=active, q_deg=q_deg)
    model = new.mounted_tool
    old = LegacyController(kinematics(robot), tool=model, reference_tip_world_m=TIP_M[robot],
                           active_tool=truth_tool_data(model) if active else None)
    old.set_q(new.q_rad)
    return new, old


def _moves(seed: int, n: int) -> list[tuple[str, str, float]]:
    rng = np.random.default_rng(seed)
    amounts = (0.1, 1.0, 10.0, 0.1, 1.0, 5.0)
    return [(str(rng.choice(["WORLD", "BASE", "FLANGE", "TOOL"])), str(rng.choice(list("XYZABC"))),
             float(rng.choice([-1.0, 1.0]) * amounts[int(rng.integers(len(amounts)))])) for _ in range(n)]


@pytest.mark.parametrize("robot,tool_key,active,q_deg", [
    ("kr6", "pointer", False, None),                    # the class: TCP = flange
    ("kr6", "torch", True, None),                       # an offset and rotated TCP
    ("gp12", "gripper", True, None),
    ("kr6", "pointer", False, (0.0, -80.0, 100.0, 0.0, 3.0, 0.0)),   # in the damped zone, A5 near 0
    ("kr6", "torch", True, (0.0, -90.0, 90.0, 0.0, 0.0, 0.0)),       # HOME: on the singularity
])
def test_jogs_land_where_the_previous_algorithm_landed_and_stop_for_the_same_reasons(robot, tool_key, active,
                                                                                     q_deg):
    new, old = _pair(robot, tool_key, active, q_deg)
    stops = 0
    for frame, axis, amount in _moves(seed=len(robot) + len(tool_key) + int(active), n=120):
        a = new.jog_cartesian(frame, axis, amount)
        b = old.jog_cartesian(frame, axis, amount)
        assert (a.ok, a.stopped_by, a.message) == (b.ok, b.stopped_by, b.message), (frame, axis, amount)
        assert a.moved == pytest.approx(b.moved, abs=1e-12)
        # both converged to 1e-10 m / 1e-10 rad on the same targets
        np.testing.assert_allclose(new.q_rad, old.q_rad, rtol=0.0, atol=1e-8)
        stops += not a.ok
    if q_deg is not None:
        assert stops > 0          # the singular starts exercise the stop rules, not only free motion


def test_many_small_increments_match_the_previous_algorithm_to_the_last_shown_digit():
    new, old = _pair("kr6", "pointer", False)
    for k in range(400):
        sign = 1.0 if (k // 50) % 2 == 0 else -1.0
        assert new.jog_cartesian("WORLD", "XYZ"[k % 3], 0.1 * sign).ok
        assert old.jog_cartesian("WORLD", "XYZ"[k % 3], 0.1 * sign).ok
    np.testing.assert_allclose(new.q_rad, old.q_rad, rtol=0.0, atol=1e-9)
    a, b = new.readout("WORLD"), old.readout("WORLD")
    assert [f"{v:.2f}" for v in (a.x_mm, a.y_mm, a.z_mm)] == [f"{v:.2f}" for v in (b.x_mm, b.y_mm, b.z_mm)]
    assert [f"{v:.2f}" for v in (a.a_deg, a.b_deg, a.c_deg)] == [f"{v:.2f}" for v in (b.a_deg, b.b_deg, b.c_deg)]


def _state(ctrl: VirtualController) -> FlangeState | None:
    return ctrl._state


def test_the_kept_state_is_the_kinematics_at_the_joint_angles_reached():
    ctrl = make_controller("kr6", "torch")
    eps = ctrl.settings.singular_eps
    exact_sigmas = 0
    for frame, axis, amount in [("WORLD", "X", 0.1), ("TOOL", "A", 1.0), ("BASE", "Z", 10.0)] + _moves(7, 60):
        res = ctrl.jog_cartesian(frame, axis, amount)
        st = _state(ctrl)
        assert st is not None and st.valid_for(ctrl.kinematics, ctrl.q_rad, ctrl.settings), res
        q = ctrl.q_rad
        kin = ctrl.kinematics
        np.testing.assert_array_equal(st.J, kin.jacobian_flange(q))
        T = kin.T_world_flange(q)
        np.testing.assert_allclose(st.R_wf, T[:3, :3], rtol=0.0, atol=1e-15)
        np.testing.assert_allclose(st.p_wf, T[:3, 3], rtol=0.0, atol=1e-15)
        # sigma_min itself, or a lower bound of it that clears 2 eps (all the rules need then)
        exact = smallest_singular_value(kin, q)
        assert st.sigma <= exact * (1.0 + 1e-12)
        if st.sigma != pytest.approx(exact, rel=1e-12):
            assert st.sigma >= 2.0 * eps
        else:
            exact_sigmas += 1
        assert st.det_sign == float(np.sign(np.linalg.det(kin.jacobian_flange(q)))) != 0.0
        if st.lu is not None:
            lu, piv = st.lu
            det = np.prod(np.diag(lu)) * (-1.0) ** sum(int(p) != i for i, p in enumerate(piv))
            assert det == pytest.approx(np.linalg.det(st.J), rel=1e-9)
    assert exact_sigmas > 0              # the bound runs out and sigma is computed again


def test_follow_path_ignores_a_state_of_other_joint_angles_or_another_robot():
    ctrl = make_controller("kr6", "pointer", active=False, q_deg=Q_WRIST_PLUS_DEG)
    assert ctrl.jog_cartesian("WORLD", "X", 0.1).ok
    stale = _state(ctrl)
    assert stale is not None
    other = make_controller("kr6", "pointer", active=False, q_deg=Q_WRIST_MINUS_DEG)
    q = other.q_rad
    assert not stale.valid_for(other.kinematics, q)
    assert not stale.valid_for(kinematics("gp12"), stale.q_rad)
    q_moved = stale.q_rad.copy()
    q_moved[0] += 1e-15                                  # an exact compare: the last bit counts
    assert not stale.valid_for(stale.kin, q_moved)
    assert stale.valid_for(stale.kin, stale.q_rad)
    assert not stale.valid_for(stale.kin, stale.q_rad, JogSettings(length_scale_m=0.5))   # sigma of another W
    from tcp_pendant.controller.jog import CartesianPath
    T0 = other.T_world_tcp()
    path = CartesianPath(T0[:3, 3], T0[:3, :3], np.array([1e-4, 0.0, 0.0]), np.zeros(3))
    with_stale = follow_path(other.kinematics, q, np.eye(4), path, start=stale)
    fresh = follow_path(other.kinematics, q, np.eye(4), path)
    assert with_stale.stopped_by is None and fresh.stopped_by is None    # stale det sign +: a false stop
    np.testing.assert_array_equal(with_stale.q_rad, fresh.q_rad)


def _twin(ctrl: VirtualController) -> VirtualController:
    """A controller in the same state as ``ctrl`` but with nothing kept from earlier jogs."""
    twin = VirtualController(ctrl.kinematics, tool=ctrl.mounted_tool, active_tool=ctrl.active_tool,
                             reference_tip_world_m=ctrl.reference_tip_world_m, T_world_base=ctrl.T_world_base,
                             settings=ctrl.settings)
    twin.set_true_kinematics(None if ctrl.true_kinematics is ctrl.kinematics else ctrl.true_kinematics)
    twin.set_q(ctrl.q_rad)
    twin.set_rest_configuration(ctrl.rest_q_rad)
    return twin


def _next_jogs_as_fresh(ctrl: VirtualController) -> None:
    twin = _twin(ctrl)
    for frame, axis, amount in (("WORLD", "X", 0.1), ("WORLD", "Y", 1.0), ("TOOL", "B", 1.0)):
        a, b = ctrl.jog_cartesian(frame, axis, amount), twin.jog_cartesian(frame, axis, amount)
        assert (a.ok, a.stopped_by, a.message, a.moved) == (b.ok, b.stopped_by, b.message, b.moved)
        np.testing.assert_allclose(ctrl.q_rad, twin.q_rad, rtol=0.0, atol=1e-12)


def _jogged_at_wrist_plus() -> VirtualController:
    ctrl = make_controller("kr6", "pointer", active=False, q_deg=Q_WRIST_PLUS_DEG)
    assert ctrl.jog_cartesian("WORLD", "X", 0.1).ok
    assert _state(ctrl) is not None and _state(ctrl).det_sign == 1.0
    return ctrl


def test_a_wizard_move_to_the_other_side_of_the_wrist_singularity_drops_the_state():
    ctrl = _jogged_at_wrist_plus()
    ctrl.set_q(np.radians(Q_WRIST_MINUS_DEG))          # MotionCommands.set_joints: a wizard's or a scan's move
    assert _state(ctrl) is None
    res = ctrl.jog_cartesian("WORLD", "X", 0.1)        # a stale det sign (+) would stop it here
    assert res.ok, res.message
    _next_jogs_as_fresh(ctrl)


def test_a_joint_jog_through_a5_zero_drops_the_state():
    ctrl = _jogged_at_wrist_plus()
    assert ctrl.jog_joint(4, -20.0).ok
    assert math.degrees(ctrl.q_rad[4]) == pytest.approx(-10.0, abs=0.01)
    assert _state(ctrl) is None
    assert ctrl.jog_cartesian("WORLD", "X", 0.1).ok
    _next_jogs_as_fresh(ctrl)


def test_going_home_drops_the_state_and_home_is_the_singularity_again():
    ctrl = _jogged_at_wrist_plus()
    ctrl.go_home()
    assert _state(ctrl) is None
    # a stale, well-conditioned sigma would call this "unreachable" instead of naming the singularity
    res = ctrl.jog_cartesian("WORLD", "Y", 1.0)
    assert res.stopped_by == "singularity" and res.message == "A5 near 0.0 deg: wrist singularity (A4 and A6 aligned)"


def test_ik_moves_drop_the_state():
    ctrl = make_controller("kr6", "pointer")
    assert ctrl.jog_cartesian("WORLD", "X", 1.0).ok
    assert ctrl.auto_approach(tilt_deg=20.0, azimuth_deg=30.0).ok
    assert _state(ctrl) is None
    _next_jogs_as_fresh(ctrl)
    T = ctrl.T_world_tool_true()
    T[:3, 3] += (0.01, -0.02, 0.015)
    assert ctrl.move_true_tool_to(T).ok
    assert _state(ctrl) is None
    _next_jogs_as_fresh(ctrl)


def test_a_tool_change_and_a_scenario_change_drop_the_state():
    ctrl = make_controller("kr6", "pointer", active=False)
    assert ctrl.jog_cartesian("WORLD", "X", 1.0).ok
    ctrl.set_active_tool(truth_tool_data(make_controller("kr6", "torch").mounted_tool, "torch"))
    assert _state(ctrl) is None
    _next_jogs_as_fresh(ctrl)
    assert _state(ctrl) is not None
    world = realize(Scenario("robot_accuracy", seed=3), ctrl.kinematics, ctrl.mounted_tool)
    ctrl.set_true_kinematics(world.true_kinematics)
    assert _state(ctrl) is None
    _next_jogs_as_fresh(ctrl)


def test_other_jog_settings_do_not_reuse_a_sigma_of_the_old_ones():
    ctrl = make_controller("kr6", "pointer", active=False, q_deg=Q_WRIST_PLUS_DEG)
    assert ctrl.jog_cartesian("WORLD", "X", 0.1).ok
    kept = _state(ctrl)
    assert kept is not None
    other = JogSettings(length_scale_m=3.0)          # another W: another sigma_min at the same q
    assert smallest_singular_value(ctrl.kinematics, ctrl.q_rad, other) < 0.5 * kept.sigma
    assert not kept.valid_for(ctrl.kinematics, ctrl.q_rad, other)
    ctrl.settings = other
    assert ctrl.jog_cartesian("WORLD", "X", 0.1).ok
    st = _state(ctrl)
    assert st is not None and st.settings is other
    assert st.sigma <= smallest_singular_value(ctrl.kinematics, ctrl.q_rad, other) * (1.0 + 1e-12)
    _next_jogs_as_fresh(ctrl)


def test_the_kept_arrays_are_its_own_later_pinocchio_passes_leave_them():
    ctrl = make_controller("kr6", "torch")
    assert ctrl.jog_cartesian("WORLD", "X", 0.1).ok
    st = _state(ctrl)
    assert st is not None
    saved = [a.copy() for a in (st.J, st.R_wf, st.p_wf, st.q_rad)]
    kin = ctrl.kinematics
    for q in (np.zeros(6), np.ones(6), np.full(6, -0.5)):
        kin.jacobian_and_pose(q)
        kin.T_world_flange(q)
        kin.link_poses(q)
    for a, b in zip((st.J, st.R_wf, st.p_wf, st.q_rad), saved):
        np.testing.assert_array_equal(a, b)


def test_a_repeated_small_press_costs_one_pinocchio_pass_and_lands_as_plain_newton():
    new, old = _pair("kr6", "pointer", False)
    kin = new.kinematics
    calls = []
    real = kin.jacobian_and_pose
    kin.jacobian_and_pose = lambda q: (calls.append(1), real(q))[1]   # type: ignore[method-assign]
    try:
        for k in range(30):
            assert new.jog_cartesian("WORLD", "X", 0.1).ok and old.jog_cartesian("WORLD", "X", 0.1).ok
            if k == 1:
                calls.clear()       # from the third press on, the midpoint step converges at once
    finally:
        del kin.jacobian_and_pose
    assert len(calls) == 28
    # each press converged to 1e-10 m (the midpoint step lands within ~2e-12 m, plain Newton's
    # second step closer still): 30 presses apart by less than 30 tolerances
    T, T_old = new.T_world_tcp(), old.T_world_tcp()
    assert np.linalg.norm(T[:3, 3] - T_old[:3, 3]) < 30 * 1e-10
    np.testing.assert_allclose(new.q_rad, old.q_rad, rtol=0.0, atol=1e-8)
