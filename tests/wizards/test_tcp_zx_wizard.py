"""The TCP & Z, X wizard (ABB) on synthetic poses: its steps, result, record round trip and
auto-touch roles, against the known tool frames of conftest.py (independent geometry)."""

from __future__ import annotations


import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcp_pendant.calibrate.autotouch import auto_touch
from tcp_pendant.wizards import CalibrationFailedError, TcpZxWizard, Wizard, WizardError
from tcp_pendant.wizards.truth import compare_with_truth

from support.fake_controller import exact_tool, fake


def record_exact(wiz: TcpZxWizard, tool, synth, d_mm: float = 60.0) -> None:
    """Touches from the first n directions, then the reference on tool +Z and +X at d_mm."""
    for k in range(wiz.n_points):
        wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(*synth.directions[k])))
        wiz.next()
    R = synth.tool_orientation(*synth.directions[wiz.n_points - 1])
    wiz.record(synth.flange_pose_m(tool, R, offset_tool_mm=(0.0, 0.0, d_mm)))
    wiz.next()
    wiz.record(synth.flange_pose_m(tool, R, offset_tool_mm=(d_mm, 0.0, 0.0)))


def test_steps_are_touches_then_z_then_x() -> None:
    wiz = TcpZxWizard(n_points=5)
    assert [s.role for s in wiz.steps] == ["touch"] * 5 + ["z", "x"]
    assert "+Z axis ahead of the TCP" in wiz.steps[5].instruction
    assert "+X axis" in wiz.steps[6].instruction
    with pytest.raises(WizardError, match="between 4 and 20"):
        TcpZxWizard(n_points=3)


@pytest.mark.parametrize("n", [4, 6])
def test_exact_poses_give_the_true_tcp_and_frame(synth, synth_tool, n) -> None:
    wiz = TcpZxWizard(n_points=n)
    record_exact(wiz, synth_tool, synth)
    res = wiz.next()
    assert res.method == "tcp-zx" and wiz.is_complete
    np.testing.assert_allclose(res.tcp_mm, synth_tool.tcp_mm, atol=1e-9)
    np.testing.assert_allclose(res.rotation, synth_tool.R_flange_tool, atol=1e-9)
    R_abc = Rotation.from_euler("ZYX", res.abc_deg, degrees=True).as_matrix()
    np.testing.assert_allclose(R_abc, synth_tool.R_flange_tool, atol=1e-9)   # A, B, C of the frame
    assert len(res.per_touch_error_mm) == n and res.max_error_mm < 1e-9
    assert res.displacements_mm == pytest.approx((60.0, 60.0), abs=1e-9)
    assert res.orthogonality_defect_deg < 1e-6
    cmp = compare_with_truth(res, synth_tool.T_flange_tool_true_m)
    assert cmp.position_error_mm < 1e-9 and cmp.orientation_error_deg < 1e-6
    tool = wiz.to_tool("T")
    np.testing.assert_allclose(tool.rotation, synth_tool.R_flange_tool, atol=1e-9)
    assert tool.calibration.method == "tcp-zx" and tool.calibration.figures["n_touches"] == n


def test_record_round_trip_recomputes_the_same_result(synth) -> None:
    wiz = TcpZxWizard(n_points=4)
    record_exact(wiz, synth.tools["torch"], synth)
    res = wiz.next()
    back = Wizard.from_dict(wiz.to_dict())            # dispatch by kind through the registry
    assert isinstance(back, TcpZxWizard) and back.is_complete and back.n_points == 4
    np.testing.assert_allclose(back.result.tcp_mm, res.tcp_mm, atol=1e-12)
    np.testing.assert_allclose(back.result.rotation, res.rotation, atol=1e-12)


def test_the_tool_moved_the_wrong_way_is_said_and_nothing_is_lost(synth) -> None:
    tool = synth.tools["torch"]
    wiz = TcpZxWizard()
    for k in range(4):
        wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(*synth.directions[k])))
        wiz.next()
    R = synth.tool_orientation(*synth.directions[3])
    wiz.record(synth.flange_pose_m(tool, R, offset_tool_mm=(0.0, 0.0, 0.0)))    # did not back off
    wiz.next()
    wiz.record(synth.flange_pose_m(tool, R, offset_tool_mm=(60.0, 0.0, 0.0)))
    with pytest.raises(CalibrationFailedError, match=r"z row 5: the reference point is only .* back the tool off"):
        wiz.next()
    assert wiz.status == "in_progress" and wiz.on_last_step and len(wiz.recorded_poses) == 6


def test_the_meter_watches_the_touches_only(synth) -> None:
    tool = synth.tools["pointer"]
    wiz = TcpZxWizard()
    assert wiz.meter_active
    for k in range(4):
        T = synth.flange_pose_m(tool, synth.tool_orientation(*synth.directions[k]))
        if k == 3:
            gain = wiz.preview(T)
            assert gain.predicted_before == np.inf and np.isfinite(gain.predicted_after)
        wiz.record(T)
        wiz.next()
    assert wiz.step.role == "z" and not wiz.meter_active
    assert wiz.other_rotations().shape == (4, 3, 3)


def auto_touch_steps(wiz: Wizard, ctrl, rng: np.random.Generator, n: int) -> tuple[float, float, float] | None:
    """Auto-touch the next ``n`` steps as the workflow does (each step given the previous
    step's direction); the last direction used."""
    previous = None
    for _ in range(n):
        out = auto_touch(wiz, ctrl, rng=rng, previous_direction_deg=previous)
        assert out.ok, out.message
        previous = out.direction_deg
    return previous


def test_auto_touch_performs_every_step_and_z_x_keep_the_last_touch_orientation(synth) -> None:
    ctrl = fake(synth, "torch")
    wiz = TcpZxWizard()
    auto_touch_steps(wiz, ctrl, np.random.default_rng(4), wiz.n_steps)
    offsets = [c[4] for c in ctrl.calls]
    assert offsets == [(0.0, 0.0, 0.0)] * 4 + [(0.0, 0.0, 60.0), (60.0, 0.0, 0.0)]
    assert ctrl.calls[3][1:4] == ctrl.calls[4][1:4] == ctrl.calls[5][1:4]
    assert all(20.0 <= c[1] <= 50.0 for c in ctrl.calls[:4])       # touches from spread directions
    res = wiz.next()
    cmp = compare_with_truth(res, synth.tools["torch"].T_flange_tool_true_m)
    assert cmp.position_error_mm < 1e-9 and cmp.orientation_error_deg < 1e-6


def test_truth_grades_both_the_tcp_and_the_frame(synth) -> None:
    """TCP & Z, X calibrates both: a TCP 3 mm off the truth is poor even with an exact frame
    (an orientation-only verdict would have called it good)."""
    tool = synth.tools["torch"]
    wiz = TcpZxWizard()
    record_exact(wiz, tool, synth)
    res = wiz.next()
    T_true = tool.T_flange_tool_true_m.copy()
    T_true[:3, 3] += np.array([0.0, 0.003, 0.0])                    # the truth 3 mm aside
    cmp = compare_with_truth(res, T_true)
    assert cmp.graded == ("position", "orientation") and cmp.grade == "poor"
    assert cmp.position_error_mm == pytest.approx(3.0, abs=1e-9) and cmp.orientation_error_deg < 1e-6
    assert "position error" in cmp.verdict and "TCP used" not in cmp.verdict


def test_auto_touch_z_step_out_of_reach_retries_shorter_then_a_new_orientation(synth) -> None:
    """The kept orientation may be out of reach for the back-off along tool +Z (about 2 % of
    random runs on the KR 6 with the torch): auto-touch tries half the distance and 20 mm in the
    same orientation, then, since TCP & Z, X solves with each row's own rotation, a new
    direction; the result is still the true frame."""
    ctrl = fake(synth, "torch")
    wiz = TcpZxWizard()
    rng = np.random.default_rng(4)
    previous = auto_touch_steps(wiz, ctrl, rng, wiz.n_points)
    n_calls = len(ctrl.calls)
    ctrl.fail_first = 3                                   # 60, 30 and 20 mm in the kept orientation
    out = auto_touch(wiz, ctrl, rng=rng, previous_direction_deg=previous)
    assert out.ok and out.attempts == 4 and "new one was drawn" in out.message
    tried = ctrl.calls[n_calls:]
    assert [c[4] for c in tried] == [(0.0, 0.0, 60.0), (0.0, 0.0, 30.0), (0.0, 0.0, 20.0), (0.0, 0.0, 60.0)]
    assert all(c[1:4] == tuple(previous) for c in tried[:3]) and tried[3][1:4] != tuple(previous)
    assert 5.0 <= tried[3][1] <= 30.0
    ctrl.fail_first = 1                                   # the x step: half distance, same orientation
    out = auto_touch(wiz, ctrl, rng=rng, previous_direction_deg=out.direction_deg)
    assert out.ok and out.attempts == 2 and "30 mm off the tip" in out.message
    res = wiz.next()
    cmp = compare_with_truth(res, synth.tools["torch"].T_flange_tool_true_m)
    assert cmp.position_error_mm < 1e-9 and cmp.orientation_error_deg < 1e-6


def test_three_point_keeps_its_orientation_and_never_draws_a_new_one(synth) -> None:
    from tcp_pendant.calibrate.autotouch import MIN_RETRY_DISTANCE_MM
    from tcp_pendant.wizards import MIN_DISPLACEMENT_MM, ThreePointWizard
    assert MIN_RETRY_DISTANCE_MM >= MIN_DISPLACEMENT_MM          # a retry is still a valid step
    ctrl = fake(synth, "gripper")
    wiz = ThreePointWizard(exact_tool(synth, "gripper"), variant=1)
    out = auto_touch(wiz, ctrl, rng=np.random.default_rng(2))
    assert out.ok
    ctrl.fail_first = 10
    failed = auto_touch(wiz, ctrl, rng=np.random.default_rng(2), previous_direction_deg=out.direction_deg)
    assert not failed.ok and failed.attempts == 3                  # 60, 30, 20 mm; no new direction

