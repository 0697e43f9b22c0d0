"""XYZ 4-point wizard driven with synthetic flange poses (no controller, no browser)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcpcal.tool import Tool
from tcp_pendant.wizards import (
    CalibrationFailedError,
    InvalidPoseError,
    Wizard,
    WizardError,
    WizardStateError,
    Xyz4Result,
    Xyz4Wizard,
)


def run_xyz4(wiz, synth, tool, directions, noise=None):
    for k, d in enumerate(directions):
        if k >= wiz.n_points:
            wiz.add_point()
        assert wiz.can_record
        n = None if noise is None else noise[k]
        wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(*d), noise_mm=n))
        out = wiz.next()
    return out


def test_exact_recovery_all_estimators(synth, synth_tool):
    wiz = Xyz4Wizard()
    res = run_xyz4(wiz, synth, synth_tool, synth.directions[:4])
    assert isinstance(res, Xyz4Result) and wiz.is_complete and wiz.result is res
    assert np.linalg.norm(np.array(res.tcp_mm) - synth_tool.tcp_mm) < 1e-6
    assert res.method == "xyz4-lstsq" and res.estimator == "lstsq"
    assert res.max_error_mm < 1e-6 and len(res.per_touch_error_mm) == 4
    # the sphere: centre = reference tip, radius = |t|, every flange origin on it
    assert np.linalg.norm(np.array(res.sphere_centre_mm) - synth.reference_mm) < 1e-6
    assert res.sphere_radius_mm == pytest.approx(np.linalg.norm(synth_tool.tcp_mm), abs=1e-6)
    d = np.linalg.norm(res.flange_positions_mm - synth.reference_mm, axis=1)
    np.testing.assert_allclose(d, np.linalg.norm(synth_tool.tcp_mm), atol=1e-6)
    # approach direction: unit vector from flange origin to the tip, in WORLD
    expected = (synth.reference_mm - res.flange_positions_mm) / d[:, None]
    np.testing.assert_allclose(res.approach_directions_world, expected, atol=1e-9)
    # the three estimators side by side, all exact on noise-free data
    rows = res.comparison_rows()
    assert [r["estimator"] for r in rows] == ["lstsq", "sphere", "pairwise"]
    for r in rows:
        if r["ok"]:
            assert np.linalg.norm(np.array(r["tcp_mm"]) - synth_tool.tcp_mm) < 1e-6
    assert sum(r["ok"] for r in rows) >= 2 and rows[0]["chosen"]
    assert any("residual does not prove" in n for n in res.notes)


def test_estimator_switch_recomputes(synth):
    tool = synth.tools["torch"]
    wiz = Xyz4Wizard(estimator="pairwise")
    res = run_xyz4(wiz, synth, tool, synth.directions[:6])
    assert res.method == "xyz4-pairwise"
    res2 = wiz.set_estimator("lstsq")
    assert res2.method == "xyz4-lstsq" and wiz.result is res2
    assert np.linalg.norm(np.array(res2.tcp_mm) - tool.tcp_mm) < 1e-6
    with pytest.raises(WizardError, match="estimator"):
        wiz.set_estimator("magic")


def test_record_enabled_only_when_it_should_be(synth):
    tool = synth.tools["pointer"]
    wiz = Xyz4Wizard()
    assert wiz.can_record and not wiz.can_next and not wiz.can_back
    assert wiz.step.heading == "Step 1 of 4" and wiz.step.instruction
    with pytest.raises(WizardStateError, match="Record step 1"):
        wiz.next()
    wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(*synth.directions[0])))
    assert wiz.can_next and wiz.step.recorded
    wiz.cancel()
    assert not wiz.can_record and wiz.blocked_reason and "resume" in wiz.blocked_reason
    with pytest.raises(WizardStateError):
        wiz.record(np.eye(4))
    wiz.resume()
    run = [synth.directions[i] for i in range(1, 4)]
    wiz.next()
    for d in run:
        wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(*d)))
        wiz.next()
    assert wiz.is_complete and not wiz.can_record and wiz.progress == 1.0


def test_back_next_keeps_poses_and_rerecord_overwrites(synth):
    tool = synth.tools["gripper"]
    wiz = Xyz4Wizard()
    poses = [synth.flange_pose_m(tool, synth.tool_orientation(*d)) for d in synth.directions[:4]]
    for T in poses[:3]:
        wiz.record(T)
        wiz.next()
    assert wiz.step_index == 3 and wiz.progress == pytest.approx(3 / 5)
    wiz.back()
    wiz.back()
    assert wiz.step_index == 1 and wiz.step.recorded
    np.testing.assert_array_equal(wiz.recorded_poses[1].T_world_flange_m, poses[1])
    wiz.record(poses[3])  # overwrite step 2 ...
    np.testing.assert_array_equal(wiz.recorded_poses[1].T_world_flange_m, poses[3])
    wiz.record(poses[1])  # ... and back
    wiz.go_to(3)
    wiz.record(poses[3])
    res = wiz.next()
    assert np.linalg.norm(np.array(res.tcp_mm) - tool.tcp_mm) < 1e-6
    # back from the result: reopens at the last step, result gone, poses kept
    wiz.back()
    assert wiz.status == "in_progress" and wiz.result is None and wiz.step_index == 3
    assert len(wiz.recorded_poses) == 4
    with pytest.raises(WizardStateError):
        wiz.go_to(7)


def test_cancel_and_resume_complete_wizard(synth):
    tool = synth.tools["pointer"]
    wiz = Xyz4Wizard()
    res = run_xyz4(wiz, synth, tool, synth.directions[:4])
    wiz.cancel()
    assert wiz.status == "cancelled" and wiz.result is None
    back = wiz.resume()
    assert wiz.is_complete and back is res


def test_add_point_up_to_20_and_remove(synth):
    tool = synth.tools["torch"]
    wiz = Xyz4Wizard()
    rng = np.random.default_rng(3)
    dirs = [(rng.uniform(15, 50), rng.uniform(0, 360), rng.uniform(-90, 90)) for _ in range(20)]
    res = run_xyz4(wiz, synth, tool, dirs)
    assert wiz.n_points == 20 and res.tcp_result.n_touches == 20
    assert not wiz.can_add_point
    with pytest.raises(WizardStateError, match="20"):
        wiz.add_point()
    assert np.linalg.norm(np.array(res.tcp_mm) - tool.tcp_mm) < 1e-6
    wiz.remove_point(0)
    assert wiz.n_points == 19 and wiz.status == "in_progress" and len(wiz.recorded_poses) == 19
    with pytest.raises(WizardError):
        Xyz4Wizard(n_points=3)
    small = Xyz4Wizard()
    with pytest.raises(WizardStateError, match="At least 4"):
        small.remove_point(0)


def test_outlier_flagged_and_dropped(synth):
    tool = synth.tools["pointer"]
    wiz = Xyz4Wizard()
    noise = [np.zeros(3)] * 8
    noise = [n.copy() for n in noise]
    noise[5] = np.array([5.0, 0.0, 0.0])  # one careless touch, 5 mm off
    rng = np.random.default_rng(0)
    noise = [n + rng.normal(0, 0.05, 3) for n in noise]
    res = run_xyz4(wiz, synth, tool, synth.directions[:8], noise)
    assert 5 in res.outliers
    assert any("outlier" in w for w in res.warnings)
    before = np.linalg.norm(np.array(res.tcp_mm) - tool.tcp_mm)
    res2 = wiz.drop_outliers()
    assert wiz.excluded == res.outliers and 5 not in res2.used_indices
    after = np.linalg.norm(np.array(res2.tcp_mm) - tool.tcp_mm)
    assert after < before and after < 0.2
    assert res2.flange_positions_mm.shape == (8, 3)  # all touches still shown
    res3 = wiz.restore_all()
    assert res3.used_indices == tuple(range(8))


def test_preview_meter(synth):
    tool = synth.tools["pointer"]
    wiz = Xyz4Wizard(assumed_sigma_mm=0.5)
    first = wiz.preview(np.eye(4))  # nothing to compare with yet: not observable, says so
    assert not first.too_close and first.predicted_after == np.inf and first.message
    assert wiz.quality().n_touches == 0 and not wiz.quality().observable
    Ts = [synth.flange_pose_m(tool, synth.tool_orientation(*d)) for d in synth.directions[:4]]
    for T in Ts[:3]:
        wiz.record(T)
        wiz.next()
    near = wiz.preview(synth.flange_pose_m(tool, synth.tool_orientation(41.0, 121.0, -20.0)))
    assert near.too_close and near.angle_to_nearest_deg < 15.0
    far = wiz.preview(Ts[3])
    assert not far.too_close and np.isfinite(far.predicted_after)
    assert far.predicted_after < near.predicted_after
    q = wiz.quality()
    assert q is not None and q.n_touches == 3
    with pytest.raises(InvalidPoseError):
        wiz.preview(np.full((4, 4), np.nan))


def test_degenerate_touches_fail_clearly_and_keep_state(synth):
    tool = synth.tools["torch"]
    wiz = Xyz4Wizard()
    # all rotations about WORLD Z (same tilt, different azimuth): one axis unobservable
    for az in (0.0, 90.0, 180.0, 270.0):
        wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(0.0, az, 0.0)))
        if not wiz.on_last_step:
            wiz.next()
    with pytest.raises(CalibrationFailedError) as exc:
        wiz.next()
    assert str(exc.value) and wiz.status == "in_progress" and len(wiz.recorded_poses) == 4


def test_invalid_poses_rejected():
    wiz = Xyz4Wizard()
    bad_rot = np.eye(4)
    bad_rot[0, 1] = 0.1
    for bad, msg in ((np.eye(3), "4x4"), (np.full((4, 4), np.nan), "NaN"), (bad_rot, "orthonormal"),
                     ("abc", "4x4")):
        with pytest.raises(InvalidPoseError, match=msg):
            wiz.record(bad)
    assert not wiz.recorded_poses


def test_to_tool_and_serialisation(synth):
    tool = synth.tools["gripper"]
    base = Tool(name="old gripper", tcp_mm=(0.0, 0.0, 100.0), abc_deg=(10.0, 20.0, 30.0), mass_kg=1.2,
                cog_mm=(0.0, 5.0, 60.0), load_abc_deg=(0.0, 90.0, 0.0), inertia_kgm2=(0.01, 0.02, 0.03))
    wiz = Xyz4Wizard(base_tool=base)
    res = run_xyz4(wiz, synth, tool, synth.directions[:5])
    t = wiz.to_tool("gripper 1")
    assert isinstance(t, Tool) and t.name == "gripper 1" and t.mass_kg == 1.2
    assert t.cog_mm == (0.0, 5.0, 60.0)  # the load is the tool's, not the calibration's
    assert (t.load_abc_deg, t.inertia_kgm2) == ((0.0, 90.0, 0.0), (0.01, 0.02, 0.03))
    np.testing.assert_allclose(t.tcp_mm, tool.tcp_mm, atol=1e-6)
    assert t.abc_deg == pytest.approx((10.0, 20.0, 30.0))
    assert t.calibration.method == "xyz4-lstsq"
    assert t.calibration.figures["max_error_mm"] == pytest.approx(res.max_error_mm)
    assert t.calibration.figures["n_touches"] == 5

    # half-way wizard: serialise, rebuild, resume where it was
    half = Xyz4Wizard(n_points=6)
    for d in synth.directions[:3]:
        half.record(synth.flange_pose_m(tool, synth.tool_orientation(*d)))
        half.next()
    d = json.loads(json.dumps(half.to_dict()))
    again = Wizard.from_dict(d)
    assert isinstance(again, Xyz4Wizard) and again.step_index == 3 and again.n_points == 6
    assert sorted(again.recorded_poses) == [0, 1, 2]
    # complete wizard: rebuilt and recomputed
    full = Wizard.from_dict(json.loads(json.dumps(wiz.to_dict())))
    assert full.is_complete
    np.testing.assert_allclose(full.result.tcp_mm, res.tcp_mm, atol=1e-12)
    with pytest.raises(WizardStateError):
        Xyz4Wizard().to_tool("x")
    with pytest.raises(WizardError, match="Unknown wizard kind"):
        Wizard.from_dict({"kind": "nope"})


def test_save_result_writes_the_library_but_not_its_active_slot(synth, tmp_path):
    """Saving lives in calibrate/ (the wizard only computes); it never sets the library's
    active slot (the session's business)."""
    from tcpcal.errors import TcpcalError
    from tcpcal.library import ToolLibrary
    from tcp_pendant.calibrate.library_save import save_result

    assert not hasattr(Xyz4Wizard(), "save_to_library")          # no file I/O in the state machine
    tool = synth.tools["pointer"]
    lib = ToolLibrary(tmp_path / "tools.json")
    wiz = Xyz4Wizard()
    with pytest.raises(WizardStateError, match="Finish"):
        save_result(wiz, lib, "pointer")
    run_xyz4(wiz, synth, tool, synth.directions[:4])
    slot, saved = save_result(wiz, lib, "pointer")
    assert slot == 1 and lib.active_slot() is None
    assert lib.get(1).tcp_mm == pytest.approx(tuple(tool.tcp_mm), abs=1e-6)
    assert lib.get(1).calibration.method == "xyz4-lstsq"
    # same name again: same slot, overwritten; explicit slot elsewhere with that name: refused
    assert save_result(wiz, lib, "pointer")[0] == 1
    with pytest.raises(TcpcalError):
        save_result(wiz, lib, "pointer", slot=5)
    assert save_result(wiz, lib, "pointer 2", slot=5)[0] == 5
    assert lib.active_slot() is None
