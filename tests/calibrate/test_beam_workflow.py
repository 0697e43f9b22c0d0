"""The Automatic (beam) wizard through the Calibrate workflow on the real virtual controller of
both robots: Finish runs the controller's scan (``controller_job`` ->
``run`` -> ``give_controller_job``), the result is graded against the mounted tool's truth (also
a bent one), compared with the trainee's manual calibration of the same tool, saved to the
library, exported and replayed; Record and Auto-touch are refused in words. One in-process
pendant test (a websocket client, no browser) runs Finish through the steps view's worker.

Exact data: the beam sensor with ``sigma = 0``; the expected TCP and tool direction are the
tools' hidden truth (``ToolModel.T_flange_tool_true``), independent of the wizard.
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.calibrate.text import duration_words, result_markdown
from tcp_pendant.calibrate.jobs import BeamScanJob, TcpCheckJob
from tcp_pendant.controller import builtin_tools
from tcp_pendant.controller.beam import BeamSensor
from tcp_pendant.controller.scenarios import ToolBend, bent_tool
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.wizards import BeamWizard, BeamWizardResult, WizardError, WizardStateError

from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

from support.calib_helpers import true_frame
from support.calib_page import Page

pytestmark = pytest.mark.app_page(cls=Page, seed=5)


def exact_sensor(wf: CalibrationWorkflow) -> None:
    """The session's beam device where it stands, without repeatability noise."""
    s = wf.controller.beam_sensor
    wf.controller.set_beam_sensor(BeamSensor(s.point, s.direction, width=s.width, sigma=0.0))


def direction_error_deg(res: BeamWizardResult, T_true: np.ndarray) -> float:
    d, x = np.asarray(res.direction_flange), T_true[:3, 0]
    return math.degrees(math.atan2(float(np.linalg.norm(np.cross(d, x))), float(d @ x)))


def scan(wf: CalibrationWorkflow, **options) -> BeamWizardResult:
    wiz = wf.start("beam", **options)
    assert isinstance(wiz, BeamWizard) and wiz.scan_pending
    q_before = wf.controller.q_rad.copy()
    job = wf.controller_job()
    assert isinstance(job, BeamScanJob) and "Scanning" in job.busy_text
    outcome = job.run()                                   # pure: the controller is not moved
    np.testing.assert_array_equal(wf.controller.q_rad, q_before)
    res = wf.give_controller_job(job, outcome)
    assert isinstance(res, BeamWizardResult) and wf.result is res and res.scan is outcome
    return res


# ----------------------------------------------------------------------------- accuracy
@pytest.mark.parametrize("robot", ["kr6", "gp12"])
@pytest.mark.parametrize("tool", ["pointer", "torch"])
def test_exact_scan_gives_the_true_tcp_and_direction(workflow, robot, tool) -> None:
    wf = workflow(robot, tool, seed=1)
    exact_sensor(wf)
    res = scan(wf)
    T_true = builtin_tools()[tool].T_flange_tool_true
    np.testing.assert_allclose(res.tcp_mm, T_true[:3, 3] * 1000.0, atol=1e-6)
    assert direction_error_deg(res, T_true) < 1e-6
    truth = wf.truth()
    assert truth is not None and truth.position_error_mm < 1e-6 and truth.orientation_error_deg < 1e-6
    assert truth.grade == "good" and set(truth.graded) == {"position", "x_axis"}
    assert len(res.tip_event_indices) == 4 and len(res.axis_event_indices) == 8 and not res.scan.skipped
    # the real-robot time is the scan's, and it is the sum of its moves' length / speed
    assert res.duration_s == pytest.approx(sum(m.length_m * 1000.0 / m.speed_mm_s for m in res.scan.moves))


@pytest.mark.parametrize("robot", ["kr6", "gp12"])
def test_noisy_scan_lands_within_three_ci95(workflow, robot) -> None:
    for seed in range(4):
        wf = workflow(robot, "torch", seed=seed)            # the default sensor: 0.02 mm repeatability
        res = scan(wf, n_orientations=5)
        err = wf.truth().position_error_mm
        assert 0.0 < err <= 3.0 * res.ci95_mm and res.ci95_mm < 0.2
        assert wf.truth().x_axis_error_deg < 0.5


def test_bent_tool_is_graded_against_the_bent_truth(workflow) -> None:
    """The physical tool bent in a crash (2 mm, 1.5 deg): the controller plans with the stale
    catalogue data, the beam sees the bent tool; the result is the bent tool, graded against it."""
    wf = workflow("kr6", "torch", seed=2)
    exact_sensor(wf)
    bent = bent_tool(builtin_tools()["torch"], ToolBend(shift_mm=2.0, angle_deg=1.5, direction_deg=40.0))
    wf.controller.mount_tool(bent)
    res = scan(wf)
    np.testing.assert_allclose(res.tcp_mm, bent.T_flange_tool_true[:3, 3] * 1000.0, atol=1e-6)
    assert direction_error_deg(res, bent.T_flange_tool_true) < 1e-6
    assert res.direction_turn_deg == pytest.approx(1.5, abs=1e-6)          # turned off the stale data
    truth = wf.truth()
    np.testing.assert_allclose(wf.run.T_flange_tool_true_m, bent.T_flange_tool_true)
    assert truth.position_error_mm < 1e-6 and truth.orientation_error_deg < 1e-6
    stale = np.linalg.norm(np.asarray(res.tcp_mm) - builtin_tools()["torch"].T_flange_tool_true[:3, 3] * 1000.0)
    assert stale > 1.9


# ----------------------------------------------------------------------------- the lesson
def test_compared_with_the_last_manual_calibration_of_the_same_tool(workflow) -> None:
    wf = workflow("kr6", "pointer", seed=4)
    exact_sensor(wf)
    res = scan(wf)
    assert res.manual is None and "no manual calibration of this tool" in result_markdown(res)
    wf.start("xyz4")
    for _ in range(4):
        assert wf.auto_touch(AutoTouchRequest(sigma_mm=0.5)).ok
    manual_truth = wf.truth()
    res = scan(wf)
    m = res.manual
    assert m is not None and m.kind == "xyz4" and m.title == "XYZ 4-point" and m.run_number == 2
    assert m.position_error_mm == pytest.approx(manual_truth.position_error_mm, abs=1e-12)
    assert m.direction_error_deg is None and m.grade == manual_truth.grade and m.wall_time_s >= 0.0
    text = result_markdown(res, wf.truth())
    # Auto-touch did the four touches: the lesson says so (it called them "by hand", "your time")
    assert m.touches == 4 and m.auto_touches == 4
    assert f"| 2: {escape_markdown('XYZ 4-point')} (by Auto-touch) |" in text and f"{manual_truth.position_error_mm:.3f} mm" in text
    assert "(Auto-touch's clicks)" in text and "by hand)" not in text and "your time" not in text
    assert f"| Automatic (beam) | {duration_words(res.duration_s)} on a real robot | 0.000 mm |" in text
    no_truth = result_markdown(res)                       # where the truth may not be shown
    assert "TCP error" not in no_truth and "(Auto-touch's clicks)" in no_truth
    wf.resume(1)                                          # touch 4 again, by hand: a mixed run
    wf.back()
    wf.record()
    wf.next()
    mixed = scan(wf).manual
    assert (mixed.touches, mixed.auto_touches) == (4, 3)
    assert "(3 of 4 touches by Auto-touch)" in result_markdown(scan(wf)) and "(your time)" in result_markdown(scan(wf))
    # another tool's manual calibration does not count; an exercise computes no errors
    wf.controller.mount_tool(builtin_tools()["torch"])
    assert scan(wf).manual is None
    wf.controller.mount_tool(builtin_tools()["pointer"])
    # an exercise: the beam is off (it would measure the exercise's tool), also for a beam wizard
    # opened before the trainer started it; the comparison computes no errors
    wf.start("beam")
    wf.hide_truth = True
    with pytest.raises(WizardStateError, match="scan is off during the trainer's exercise"):
        wf.controller_job()
    with pytest.raises(WizardError, match="wizard is off during the trainer's exercise"):
        wf.start("beam")
    m = wf.manual_comparison()
    assert m is not None and m.run_number == 2 and m.position_error_mm is None and m.grade is None


def test_duration_words() -> None:
    assert [duration_words(s) for s in (17.04, 192.0, 3725.0)] == ["17.0 s", "3 min 12 s", "1 h 02 min"]


# ----------------------------------------------------------------------------- save, record
def test_save_to_the_library(workflow, library) -> None:
    wf = workflow("gp12", "torch", seed=6)
    res = scan(wf)
    preview = wf.preview_tool()
    assert preview is not None and preview.tcp_mm == res.tcp_mm
    slot, tool = wf.save("Torch beam")
    stored = ToolLibrary(library.path).get(slot)
    assert stored is not None and stored.calibration.method == "beam"
    assert stored.tcp_mm == pytest.approx(res.tcp_mm) and stored.abc_deg == pytest.approx(res.abc_deg)
    assert stored.calibration.figures["n_tip_events"] == 4.0
    assert wf.controller.active_tool.name == "Torch beam" and wf.result_saved


def test_session_record_round_trip(workflow, tmp_path) -> None:
    wf = workflow("kr6", "torch", seed=8)
    wf.start("xyz4")
    for _ in range(4):
        wf.auto_touch(AutoTouchRequest(sigma_mm=0.3))
    res = scan(wf, n_orientations=3, scan_speed_mm_s=20)
    record = json.loads(json.dumps(wf.export_record()))
    entry = record["wizards"][1]
    assert entry["state"]["kind"] == "beam" and entry["truth"]["grade"] == "good"
    assert len(entry["state"]["params"]["scan"]["events"]) == len(res.events) == 9
    other = CalibrationWorkflow(wf.controller, ToolLibrary(tmp_path / "other.json"), robot="kr6")
    checks = other.load_record(json.dumps(record))
    assert [c.matches for c in checks] == [True, True]
    again = other.result
    assert isinstance(again, BeamWizardResult) and again.tcp_mm == res.tcp_mm
    assert again.direction_flange == res.direction_flange and again.duration_s == res.duration_s
    assert again.manual == res.manual and again.scan.moves == ()
    assert checks[1].truth.position_error_mm == pytest.approx(wf.truth().position_error_mm, abs=1e-12)
    assert "Automatic vs by hand" in result_markdown(again, other.truth())


# ----------------------------------------------------------------------------- refusals
def test_record_and_auto_touch_are_refused_in_words(workflow) -> None:
    wf = workflow("kr6", "pointer")
    wf.start("beam")
    with pytest.raises(WizardStateError, match="controller runs this step itself"):
        wf.record()
    with pytest.raises(WizardStateError, match="nothing to touch.*press Finish"):
        wf.auto_touch(AutoTouchRequest())
    assert wf.wizard.scan_pending and wf.wizard.status == "in_progress"
    assert isinstance(wf.next(), BeamWizardResult)        # Next on the only step runs the scan here


def test_a_tool_the_beam_cannot_measure_is_refused(workflow) -> None:
    wf = workflow("kr6", "gripper")
    wf.start("beam")
    with pytest.raises(WizardStateError, match="cannot measure this tool.*pointer or the torch"):
        wf.next()
    assert wf.wizard.scan_pending


def test_an_unreachable_beam_is_refused_and_nothing_is_lost(workflow) -> None:
    wf = workflow("kr6", "pointer")
    wf.controller.set_beam_sensor(BeamSensor(np.array([5.0, 5.0, 3.0]), np.array([1.0, 0.0, 0.0])))
    wiz = wf.start("beam")
    with pytest.raises(WizardStateError):
        wf.next()
    assert wiz.scan_pending and wiz.status == "in_progress" and wf.result is None
    wf.controller.set_beam_sensor(None)                   # back where it stands: now it scans
    assert isinstance(wf.next(), BeamWizardResult)


def test_a_tool_without_catalogue_data_needs_active_tool_data(workflow) -> None:
    wf = workflow("kr6", "pointer", seed=3)
    exact_sensor(wf)
    pointer = builtin_tools()["pointer"]
    mystery = type(pointer)("mystery-1", "Mystery tool", pointer.urdf_path, pointer.T_flange_tool_true)
    wf.controller.mount_tool(mystery)
    wf.start("beam")
    with pytest.raises(WizardStateError, match="approximate tool data"):
        wf.controller_job()
    tcp, _, abc = true_frame("pointer")
    wf.controller.set_active_tool(Tool("Rough", tcp_mm=tuple(tcp + [3.0, -2.0, 5.0]), abc_deg=tuple(abc)))
    res = wf.run_controller_job()
    np.testing.assert_allclose(res.tcp_mm, tcp, atol=1e-6)   # planned with rough data, measured exactly


def test_wizard_left_while_scanning_keeps_the_scan(workflow) -> None:
    wf = workflow("kr6", "pointer", seed=9)
    wiz = wf.start("beam")
    job = wf.controller_job()
    outcome = job.run()
    wf.cancel()                                           # the trainee closed it meanwhile
    assert wf.give_controller_job(job, outcome) is None and wiz.scan is not None
    wf.resume()
    assert wf.controller_job() is None                    # nothing to scan again
    res = wf.next()
    assert isinstance(res, BeamWizardResult) and res.scan is outcome


def test_the_tcp_check_runs_through_the_same_job_pair(workflow, library) -> None:
    tcp, _, abc = true_frame("pointer")
    slot = library.first_free_slot()
    library.save(slot, Tool("Pointer", tcp_mm=tuple(tcp), abc_deg=tuple(abc)))
    wf = workflow("kr6", "pointer", seed=3)
    wf.start("tcp-check", slot=slot)
    assert wf.controller_job() is None                    # nothing recorded yet
    assert wf.auto_touch(AutoTouchRequest(tilt_deg=25.0, azimuth_deg=30.0)).ok
    job = wf.controller_job()
    assert isinstance(job, TcpCheckJob) and "Checking" in job.busy_text
    res = wf.give_controller_job(job, job.run())
    assert res is wf.result and "TCP good" in res.check.verdict


def test_bad_start_options_are_refused(workflow) -> None:
    wf = workflow()
    with pytest.raises(WizardError, match="out of range 3..5"):
        wf.start("beam", n_orientations=7)
    with pytest.raises(WizardError, match="takes no option slot"):
        wf.start("beam", slot=1)


# ----------------------------------------------------------------------------- the views (no browser)
def test_steps_view_runs_the_scan_in_its_worker(page) -> None:
    """In-process pendant, websocket client: the beam step shows no Record and no Auto-touch,
    Finish runs the scan off the loop and the result panel shows the events and the lesson."""
    from tcp_pendant.views.wizard_dock import BACK, CANCEL, FINISH
    from support.wsclient import wait_until

    p = page()
    v = p.view
    p.choose(v.method, "Automatic (beam)")
    p.click(v.start)
    steps = v.steps
    assert steps.folder.visible and "Beam scan" in steps.head_md.content
    assert not steps.record.visible and not steps.auto_folder.visible and not steps.blocked_md.visible
    assert steps.next.label == "Finish" and not steps.next.disabled
    dock = p.session.views["dock"]                        # the Jog tab's dock: no Record either
    assert dock.folder.visible and not dock.record.visible and tuple(dock.nav.options) == (BACK, FINISH, CANCEL)
    p.click(steps.next)
    wait_until(lambda: v.result.folder.visible, what="the beam result")
    text = v.result.result_md.content
    assert "**Events** (12)" in text and "on a real robot" in text and "Automatic vs by hand" in text
    first = v.workflow.result
    assert isinstance(first, BeamWizardResult)
    assert "Against the true TOOL frame: good" in v.result.truth_md.content
    # the dock: Back forgets the scan, Finish scans again (on the loop, through the workflow)
    p.choose(dock.nav, BACK)
    assert v.workflow.wizard.scan_pending and not dock.record.visible
    p.choose(dock.nav, FINISH)
    wait_until(lambda: isinstance(v.workflow.result, BeamWizardResult), what="the second scan's result")
    assert v.workflow.result is not first and not p.notes


def test_crossed_beams(workflow) -> None:
    """Two beams crossing at right angles: events of both beams, each solved on its own beam."""
    wf = workflow("kr6", "torch", seed=5)
    s = wf.controller.beam_sensor
    second = np.cross([0.0, 0.0, 1.0], s.direction)
    wf.controller.set_beam_sensor(BeamSensor(s.point, s.direction, sigma=0.0, second_direction=second))
    res = scan(wf)
    assert {e.beam for e in res.events} == {0, 1}
    T_true = builtin_tools()["torch"].T_flange_tool_true
    np.testing.assert_allclose(res.tcp_mm, T_true[:3, 3] * 1000.0, atol=1e-6)
    assert direction_error_deg(res, T_true) < 1e-6
    events_table = result_markdown(res).split("**Events**")[1]
    beams = re.findall(r"^\| \d+ \| \d \| [^|]+ \| (\d) \|", events_table, flags=re.M)
    assert len(beams) == len(res.events) and set(beams) == {"1", "2"}     # the beam column: 1-based
