"""The TCP check (spin test) wizard through the Calibrate workflow on the real virtual controller
of both robots: auto-touch puts the tip on the reference tip, Finish runs the
six rotations about the active TCP from the recorded pose; exact tool data -> the tip stays put,
data 1 mm off -> an implied error of 1 mm and the correction back onto the true TCP. A check is
not graded against truth, not saveable, and the session record replays it."""

from __future__ import annotations

from tcp_pendant.text_escape import escape_markdown

import json

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.calibrate.text import result_markdown
from tcp_pendant.wizards import TcpCheckResult, TcpCheckWizard, WizardError, WizardStateError
from tcp_pendant.wizards.registry import wizard_class
from tcp_pendant.wizards.session_record import dumps

from tcpcal.tool import Tool

from support.calib_helpers import true_frame

OFFSET_FLANGE_MM = np.array([0.6, -0.48, 0.64])     # |.| = 1.000 mm


def saved_tool(library, tool_key: str, offset_mm=(0.0, 0.0, 0.0), name: str = "Checked") -> int:
    """Library data of ``tool_key``: its true frame, the TCP moved by ``offset_mm`` (FLANGE)."""
    tcp, _, abc = true_frame(tool_key)
    slot = library.first_free_slot()
    library.save(slot, Tool(name=name, tcp_mm=tuple(float(v) for v in tcp + np.asarray(offset_mm)),
                            abc_deg=tuple(float(v) for v in abc)))
    return slot


def check(wf: CalibrationWorkflow, slot: int, **options) -> TcpCheckResult:
    wiz = wf.start("tcp-check", slot=slot, **options)
    assert isinstance(wiz, TcpCheckWizard) and [s.role for s in wiz.steps] == ["touch"]
    out = wf.auto_touch(AutoTouchRequest(tilt_deg=25.0, azimuth_deg=30.0))
    assert out.ok, out.message
    assert wf.result is None and wiz.check_pending          # auto-touch records; Finish checks
    res = wf.next()
    assert isinstance(res, TcpCheckResult) and wf.result is res
    return res


@pytest.mark.parametrize("robot", ["kr6", "gp12"])
def test_exact_tool_data_the_tip_stays_on_the_reference(workflow, library, robot) -> None:
    wf = workflow(robot, "torch", seed=3)
    slot = saved_tool(library, "torch")
    res = check(wf, slot)
    c = res.check
    assert [r.label for r in c.rows] == ["+A 30°", "-A 30°", "+B 30°", "-B 30°", "+C 30°", "-C 30°"]
    assert all(r.reached for r in c.rows)
    assert max(r.deviation_mm for r in c.rows) < 1e-3
    assert c.implied_tcp_error_mm < 1e-3
    assert "TCP good" in c.verdict


@pytest.mark.parametrize("robot", ["kr6", "gp12"])
def test_tool_data_1mm_off_implies_1mm_and_the_correction(workflow, library, robot) -> None:
    wf = workflow(robot, "pointer", seed=5)
    slot = saved_tool(library, "pointer", OFFSET_FLANGE_MM, name="Pointer off")
    res = check(wf, slot, angle_deg=30)
    c = res.check
    assert c.implied_tcp_error_mm == pytest.approx(1.0, abs=0.01)
    np.testing.assert_allclose(c.correction_flange_mm, -OFFSET_FLANGE_MM, atol=0.01)   # back onto the truth
    assert all(r.reached for r in c.rows) and max(r.deviation_mm for r in c.rows) > 0.1
    assert "off by 1.0" in c.verdict
    text = result_markdown(res)
    assert text.count("\n| ") == 7 and "Implied TCP error: 1.00" in text and "slot 1: Pointer off" in text


def test_the_check_starts_from_the_recorded_pose_not_where_the_robot_is_now(workflow, library) -> None:
    wf = workflow("kr6", "pointer", seed=2)
    slot = saved_tool(library, "pointer", OFFSET_FLANGE_MM)
    wf.start("tcp-check", slot=slot)
    assert wf.controller.active_tool.name == "Checked"          # the checked data is made active
    wf.auto_touch(AutoTouchRequest(tilt_deg=25.0, azimuth_deg=30.0))
    q_touch = wf.controller.q_rad.copy()
    assert wf.controller.jog_cartesian("WORLD", "Z", 50.0).stopped_by is None     # backed off 50 mm
    assert not np.allclose(wf.controller.q_rad, q_touch)
    job = wf.controller_job()
    np.testing.assert_allclose(job.q_rad, q_touch)
    res = wf.give_controller_job(job, job.run())
    assert res.check.implied_tcp_error_mm == pytest.approx(1.0, abs=0.01)


def test_a_check_is_not_graded_and_saves_nothing(workflow, library) -> None:
    wf = workflow("kr6", "torch", seed=4)
    slot = saved_tool(library, "torch", (1.0, 0.0, 0.0))
    check(wf, slot)
    before = library.tools()
    assert wf.truth() is None and wf.T_flange_tool_true_m() is None      # a check, not a calibration
    assert wf.preview_tool() is None and wf.T_flange_tool_computed_m() is None
    with pytest.raises(WizardStateError, match="saves nothing"):
        wf.save("Should not exist")
    assert library.tools() == before


def test_finish_before_the_check_and_bad_options_say_what_to_do(workflow, library) -> None:
    wf = workflow("kr6", "pointer", seed=1)
    slot = saved_tool(library, "pointer")
    with pytest.raises(WizardError, match="Check angle"):
        wf.start("tcp-check", slot=slot, angle_deg=120)
    with pytest.raises(WizardError, match="Tool data"):
        wf.start("tcp-check")
    wiz = wf.start("tcp-check", slot=slot)
    with pytest.raises(WizardStateError, match="Record"):
        wiz.next()
    wf.auto_touch(AutoTouchRequest())
    with pytest.raises(WizardStateError, match="Run the check first"):
        wiz.finish()                                    # the state machine alone cannot check
    job = wf.controller_job()
    wf.record()                                         # recorded again while the check "ran"
    with pytest.raises(WizardStateError, match="recorded again"):
        wf.give_controller_job(job, job.run())
    assert wiz.check_pending and wf.run_controller_job() is wf.result


def test_the_session_record_replays_the_check_without_a_robot(workflow, library) -> None:
    wf = workflow("gp12", "torch", seed=8)
    slot = saved_tool(library, "torch", OFFSET_FLANGE_MM)
    res = check(wf, slot)
    text = dumps(wf.export_record())
    entry = json.loads(text)["wizards"][0]
    assert entry["state"]["kind"] == "tcp-check" and entry["true_tool"] is None and entry["truth"] is None
    other = workflow("kr6", seed=99)
    (replayed,) = other.load_record(text)
    assert replayed.matches, replayed.message
    again = replayed.wizard.finished_result
    assert isinstance(again, TcpCheckResult)
    assert again.check == res.check and other.truth() is None
    bad = json.loads(text)
    bad["wizards"][0]["state"]["params"]["check"]["rows"][0]["deviation_mm"] = "NaN"
    with pytest.raises(WizardError, match="deviation"):
        other.load_record(json.dumps(bad))
    assert wizard_class("tcp-check") is TcpCheckWizard


def test_a_finished_check_is_done_not_left_half_way(workflow, library) -> None:
    wf = workflow("kr6", "pointer", seed=6)
    slot = saved_tool(library, "pointer")
    check(wf, slot)
    assert wf.result_saved                                # "Close", nothing to resume later
    wf.cancel()
    assert wf.resumable() == []
    wf.start("tcp-check", slot=slot)
    wf.auto_touch(AutoTouchRequest())
    wf.cancel()                                           # an unfinished one waits to be resumed
    assert [label.split(", started")[0] for _, label in wf.resumable()] == [
        "2: TCP check (spin test), at step 1 of 1 (1 recorded)"]


def _figures(reached: tuple[bool, ...], err_mm: float):
    from tcp_pendant.wizards.tcp_check import CheckFigures, CheckRow

    labels = ("+A 30°", "−A 30°", "+B 30°", "−B 30°", "+C 30°", "−C 30°")
    rows = tuple(CheckRow(lab, ok, "" if ok else "A5 at its limit 120.0 deg", 0.0 if not ok else 0.1)
                 for lab, ok in zip(labels, reached))
    return CheckFigures(30.0, rows, err_mm, (0.0, 0.0, err_mm), 0.0)


def test_a_rotation_that_could_not_be_made_keeps_the_verdict_open() -> None:
    """Two rotations stopped at A5's limit showed '0.000 mm' moved and 'TCP good'."""
    from tcp_pendant.wizards.tcp_check import TcpCheckResult, tcp_check_markdown

    open_ = _figures((False, True, True, False, True, True), 0.05)
    assert open_.verdict.startswith("Not determined: +A 30°, −B 30° could not be made from this pose")
    assert "TCP good" not in open_.verdict
    assert _figures((True,) * 6, 0.05).verdict.startswith("TCP good")
    # an error found by the rotations that were made stands
    assert _figures((False, True, True, True, True, True), 1.5).verdict.startswith("TCP off by 1.500 mm")
    res = TcpCheckResult(wizard="tcp-check", method="tcp-check", tcp_mm=(0.0, 0.0, 180.0), check=open_,
                         tool_name="Pen", slot=1)
    md = tcp_check_markdown(res)
    plus_a = escape_markdown("+A 30°")
    assert f"| {plus_a} | not made | stopped: {escape_markdown('A5 at its limit 120.0 deg')} |" in md and f"| {plus_a} | 0.000" not in md


def test_auto_touch_for_a_check_picks_a_pose_from_which_all_six_rotations_can_be_made(workflow, library) -> None:
    slot = saved_tool(library, "torch", (0.0, 0.0, 0.0))
    for seed in range(4):
        wf = workflow("kr6", "torch", seed=seed)
        wf.start("tcp-check", slot=slot)
        assert wf.auto_touch(AutoTouchRequest()).ok
        res = wf.run_controller_job()
        assert all(r.reached for r in res.check.rows), (seed, [r.message for r in res.check.rows])
        assert res.check.verdict.startswith("TCP good"), seed


def test_in_an_exercise_the_check_reads_the_tip_by_eye_and_gives_no_correction(workflow, library) -> None:
    wf = workflow("kr6", "pointer", seed=5)
    wf.hide_truth = True                                     # the classroom's exercise
    slot = saved_tool(library, "pointer", OFFSET_FLANGE_MM, name="Pointer off")
    res = check(wf, slot, angle_deg=30)
    c = res.check
    assert c.implied_tcp_error_mm is None and c.correction_flange_mm is None and c.fit_rms_mm is None
    assert all(r.deviation_mm % 0.5 == 0.0 for r in c.rows) and max(r.deviation_mm for r in c.rows) >= 0.5
    text = result_markdown(res)
    assert "Implied TCP error" not in text and "suggested correction" not in text
    assert "0.600" not in text and "-0.60" not in text and "by eye" in text
    record = json.dumps(wf.export_record())
    assert "correction_flange_mm\": null" in record and "-0.6" not in record


def test_in_an_exercise_a_check_recorded_away_from_the_reference_tip_is_refused(workflow, library) -> None:
    """A Record from anywhere with a made-up TCP would measure the tool without a touch."""
    wf = workflow("kr6", "pointer", seed=5)
    wf.hide_truth = True
    slot = saved_tool(library, "pointer", OFFSET_FLANGE_MM)
    wf.start("tcp-check", slot=slot)
    assert wf.controller.touch_geometry().distance_mm > 50.0         # the ready pose hovers
    wf.record()
    with pytest.raises(WizardStateError, match="bring the tool tip to the reference tip"):
        wf.next()
    assert wf.result is None
