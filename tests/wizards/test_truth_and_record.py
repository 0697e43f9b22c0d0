"""Training mode: truth comparison and the session record (export, load, replay)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcpcal.tool import Tool
from tcp_pendant.wizards import AbcWorldWizard, ThreePointWizard, WizardError, WizardResult, Xyz4Wizard
from tcp_pendant.wizards.session_record import (
    SessionRecordError,
    WizardRun,
    check_session_record,
    dumps,
    parse_session_record,
    read_session_file,
    replay,
    save_session,
    session_to_dict,
)
from tcp_pendant.wizards.truth import compare_with_truth


def T_true(tcp_mm, abc_deg=(0.0, 0.0, 0.0)):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("ZYX", abc_deg, degrees=True).as_matrix()
    T[:3, 3] = np.asarray(tcp_mm) / 1000.0
    return T


@pytest.mark.parametrize("offset_mm, grade", [(0.3, "good"), (1.2, "fair"), (3.0, "poor")])
def test_position_verdict_thresholds(offset_mm, grade):
    res = WizardResult(wizard="xyz4", method="xyz4-lstsq", tcp_mm=(10.0, 20.0 + offset_mm, 200.0), ci95_mm=1.0)
    cmp = compare_with_truth(res, T_true((10.0, 20.0, 200.0)))
    assert cmp.position_error_mm == pytest.approx(offset_mm)
    assert cmp.grade == grade and cmp.verdict.startswith(grade + ":")
    assert cmp.orientation_error_deg is None and cmp.graded == ("position",)
    assert cmp.inside_ci95 is (offset_mm <= 1.0)
    assert cmp.position_error_vector_mm == pytest.approx((0.0, offset_mm, 0.0))


@pytest.mark.parametrize("err_deg, grade", [(0.2, "good"), (1.0, "fair"), (5.0, "poor")])
def test_orientation_verdict_is_graded_on_orientation(err_deg, grade):
    R_true = Rotation.from_euler("ZYX", [30.0, -60.0, 10.0], degrees=True)
    R_res = R_true * Rotation.from_rotvec(np.radians(err_deg) * np.array([0.0, 0.6, 0.8]))
    res = WizardResult(wizard="three-point", method="three-point-1", tcp_mm=(0.0, 0.0, 105.0),
                       abc_deg=tuple(R_res.as_euler("ZYX", degrees=True)), rotation=R_res.as_matrix())
    cmp = compare_with_truth(res, T_true((0.0, 0.0, 100.0), R_true.as_euler("ZYX", degrees=True)))
    assert cmp.orientation_error_deg == pytest.approx(err_deg, abs=1e-9)
    assert cmp.grade == grade and cmp.graded == ("orientation",)
    assert cmp.position_error_mm == pytest.approx(5.0)  # reported, not graded
    assert "5.00 mm" in cmp.verdict


def test_5d_is_graded_on_tool_x():
    R_true = Rotation.from_euler("ZYX", [10.0, -80.0, 5.0], degrees=True)
    R_res = R_true * Rotation.from_euler("x", 30.0, degrees=True)  # spin about tool X only
    res = WizardResult(wizard="abc-world", method="abc-world-5d", tcp_mm=(0.0, 0.0, 100.0),
                       abc_deg=tuple(R_res.as_euler("ZYX", degrees=True)), rotation=R_res.as_matrix())
    cmp = compare_with_truth(res, T_true((0.0, 0.0, 100.0), R_true.as_euler("ZYX", degrees=True)))
    assert cmp.x_axis_error_deg == pytest.approx(0.0, abs=1e-6) and cmp.grade == "good"
    assert cmp.orientation_error_deg == pytest.approx(30.0)


def test_beam_is_graded_on_tcp_and_tool_x():
    """The beam scan measures the TCP and the direction of tool X, not the turn about it: a
    result turned 30 deg about tool X is good; one whose X is 3 deg off is poor."""
    R_true = Rotation.from_euler("ZYX", [10.0, -80.0, 5.0], degrees=True)
    truth = T_true((1.0, 2.0, 150.0), R_true.as_euler("ZYX", degrees=True))
    for turn, tilt, grade in ((30.0, 0.0, "good"), (0.0, 3.0, "poor")):
        R_res = R_true * Rotation.from_euler("xy", [turn, tilt], degrees=True)
        res = WizardResult(wizard="beam", method="beam", tcp_mm=(1.0, 2.0, 150.0),
                           abc_deg=tuple(R_res.as_euler("ZYX", degrees=True)), rotation=R_res.as_matrix(),
                           tcp_result=object())  # type: ignore[arg-type]
        cmp = compare_with_truth(res, truth)
        assert cmp.graded == ("position", "x_axis") and cmp.grade == grade
        assert cmp.x_axis_error_deg == pytest.approx(tilt, abs=1e-6)
        assert "tool X error" in cmp.verdict


def test_truth_rejects_bad_input():
    with pytest.raises(WizardError):
        compare_with_truth("result", np.eye(4))  # type: ignore[arg-type]
    res = WizardResult(wizard="xyz4", method="xyz4-lstsq", tcp_mm=(0.0, 0.0, 1.0))
    with pytest.raises(WizardError, match="true tool frame"):
        compare_with_truth(res, np.zeros((4, 4)))


def _session(synth, rng):
    tool = synth.tools["torch"]
    xyz = Xyz4Wizard()
    for k, d in enumerate(synth.directions[:5]):
        if k >= xyz.n_points:
            xyz.add_point()
        xyz.record(synth.flange_pose_m(tool, synth.tool_orientation(*d), noise_mm=rng.normal(0, 0.3, 3)))
        xyz.next()
    lib_tool = xyz.to_tool("torch")
    tp = ThreePointWizard(lib_tool, variant=2)
    R_wt = synth.tool_orientation(15.0, 30.0, 20.0)
    for off in ((0, 0, 0), (-60.0, 0, 0), (-20.0, 60.0, 0)):
        tp.record(synth.flange_pose_m(tool, R_wt, offset_tool_mm=off, noise_mm=rng.normal(0, 0.3, 3)))
        tp.next()
    half = AbcWorldWizard(lib_tool)  # left unfinished
    return tool, [WizardRun(xyz, "torch", tool.T_flange_tool_true_m),
                  WizardRun(tp, "torch", tool.T_flange_tool_true_m), WizardRun(half)]


def test_session_record_round_trip_and_replay(synth, tmp_path):
    tool, runs = _session(synth, np.random.default_rng(7))
    touches = [(np.eye(4), "home"), {"T_world_flange_m": np.eye(4).tolist(), "label": "p2"}]
    rec = session_to_dict(runs, robot="kr6", reference_tip_world_m=synth.reference_mm / 1000, touches=touches)
    path = save_session(tmp_path / "session.json", rec)
    loaded = read_session_file(path)
    assert loaded == json.loads(dumps(rec))
    assert loaded["format"] == "tcp-pendant-session" and loaded["version"] == 2
    assert [t["label"] for t in loaded["touches"]] == ["home", "p2"]
    w0 = loaded["wizards"][0]
    assert w0["state"]["kind"] == "xyz4" and len(w0["state"]["poses"]) == 5
    # the stored truth is the independent comparison with the true frame
    err = np.linalg.norm(np.array(w0["result"]["tcp_mm"]) - tool.tcp_mm)
    assert w0["truth"]["position_error_mm"] == pytest.approx(err)
    assert loaded["wizards"][2]["result"] is None

    checks = replay(loaded)
    assert [c.kind for c in checks] == ["xyz4", "three-point", "abc-world"]
    assert all(c.matches for c in checks), [c.message for c in checks]
    assert checks[0].tcp_diff_mm <= 1e-9 and checks[1].rotation_diff_deg <= 1e-9
    assert checks[0].truth.position_error_mm == pytest.approx(err)
    assert checks[2].wizard.status == "in_progress" and checks[2].truth is None

    # tampering with a recorded touch is caught by the replay
    k = loaded["wizards"][0]["state"]["poses"]["2"]["T_world_flange_m"]
    k[0][3] += 0.002
    checks = replay(loaded)
    assert not checks[0].matches and checks[0].tcp_diff_mm > 1e-3 and "differs" in checks[0].message
    assert checks[1].matches


def test_load_session_errors(tmp_path):
    with pytest.raises(SessionRecordError, match="not valid JSON"):
        parse_session_record(b"{not json")
    with pytest.raises(SessionRecordError, match="Not a TCP Pendant"):
        check_session_record({"format": "other"})
    with pytest.raises(SessionRecordError, match="version"):
        check_session_record({"format": "tcp-pendant-session", "version": 99})
    with pytest.raises(SessionRecordError, match="Cannot read"):
        read_session_file(tmp_path / "missing.json")
    with pytest.raises(SessionRecordError, match="Wizard 1"):
        replay({"format": "tcp-pendant-session", "version": 1, "wizards": [{"state": {"kind": "xyz4",
                "poses": {"9": {"T_world_flange_m": np.eye(4).tolist(), "recorded_at": "x"}}}}]})


def test_a_finished_wizard_closed_to_resume_later_keeps_its_result_in_the_record(synth):
    """Closing a result (cancel) must not drop it from the session record a trainer grades."""
    tool = synth.tools["pointer"]
    wiz = Xyz4Wizard()
    for d in synth.directions[:4]:
        wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(*d)))
        out = wiz.next()
    tcp = out.tcp_mm
    wiz.cancel()
    assert wiz.result is None and wiz.finished_result is out      # hidden, not lost
    rec = session_to_dict([WizardRun(wiz, "pointer", tool.T_flange_tool_true_m)], robot="kr6")
    (entry,) = rec["wizards"]
    assert entry["result"]["tcp_mm"] == pytest.approx(list(tcp), abs=1e-12)
    assert entry["truth"]["position_error_mm"] < 1e-6
    (check,) = replay(json.loads(dumps(rec)))
    assert check.matches and check.wizard.status == "cancelled"
    assert check.wizard.finished_result.tcp_mm == pytest.approx(tcp, abs=1e-9)
    # never finished: no result while cancelled either
    half = Xyz4Wizard()
    half.record(synth.flange_pose_m(tool, synth.tool_orientation(*synth.directions[0])))
    half.cancel()
    assert half.finished_result is None
