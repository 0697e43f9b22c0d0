"""The Calibrate menu's workflow without a browser: every wizard driven by training-mode
auto-touch on the real virtual controller, checked against the tools' hidden true TOOL frames
(``ToolModel.T_flange_tool_true``, read from the URDFs, converted with scipy in the test)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from tcp_pendant.calibrate import AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.wizards import (
    CalibrationFailedError,
    WizardError,
    WizardStateError,
    Xyz4Wizard,
)
from tcp_pendant.wizards.session_record import dumps

from tcpcal.errors import TcpcalError
from tcpcal.tool import Tool

from support.calib_helpers import library_tool_with_true_tcp, true_frame

EXACT_MM = 1e-6
EXACT_DEG = 1e-6


def run_auto(wf: CalibrationWorkflow, request: AutoTouchRequest | None = None) -> None:
    """Auto-touch until the wizard has its result (the last auto-touch computes it)."""
    for _ in range(wf.wizard.n_steps):
        out = wf.auto_touch(request or AutoTouchRequest())
        assert out.ok, out.message
    assert wf.result is not None


@pytest.mark.parametrize("robot,tool", [("kr6", "pointer"), ("kr6", "torch"), ("kr6", "gripper"),
                                        ("gp12", "pointer"), ("gp12", "torch")])
def test_xyz4_four_auto_touches_give_the_true_tcp_and_save_it(workflow, library, robot, tool) -> None:
    wf = workflow(robot, tool)
    wf.start("xyz4")
    run_auto(wf)                                    # four clicks, no Finish needed
    tcp_true, _, _ = true_frame(tool)
    np.testing.assert_allclose(wf.result.tcp_mm, tcp_true, atol=EXACT_MM)
    truth = wf.truth()
    assert truth is not None and truth.position_error_mm < EXACT_MM and truth.grade == "good"
    slot, saved = wf.save(f"{tool} 4P")
    assert slot == 1 and library.active_slot() is None   # the active tool is the session's, not the file's
    np.testing.assert_allclose(library.get(1).tcp_mm, tcp_true, atol=EXACT_MM)
    assert wf.controller.active_tool == saved        # "Save" also makes it the active tool data
    np.testing.assert_allclose(wf.controller.T_flange_tool[:3, 3] * 1000.0, tcp_true, atol=EXACT_MM)


def test_xyz4_with_operator_error_reports_an_error_inside_a_plausible_radius(workflow) -> None:
    """sigma 0.5 mm: the error against truth is non-zero and of the size of the 95 % radius."""
    wf = workflow(seed=7)
    wf.start("xyz4", n_points=8)
    run_auto(wf, AutoTouchRequest(sigma_mm=0.5))
    res, truth = wf.result, wf.truth()
    assert 0.0 < res.mean_error_mm < 2.0
    assert 0.0 < truth.position_error_mm < 3.0 * res.ci95_mm


def test_reference_needs_the_tool_change_then_gives_the_new_tools_tcp(workflow, library) -> None:
    library.save(1, library_tool_with_true_tcp("pointer", "Pointer"))
    wf = workflow(tool="pointer")
    wiz = wf.start("reference", slot=1, reference_tool_key="pointer", new_tool_key="torch")
    assert wf.controller.active_tool.name == "Pointer"     # "mounted and active"
    assert wf.required_tool() is None
    wf.auto_touch(AutoTouchRequest())
    assert wiz.step_index == 1 and wf.required_tool().key == "torch"
    assert not wiz.can_record
    with pytest.raises(WizardStateError, match=r"Mount the bent-neck welding torch first: the straight pointer is mounted now\."):
        wf.record()
    assert wf.mount_required_tool().key == "torch"
    assert wf.controller.mounted_tool.key == "torch" and wiz.can_record
    wf.auto_touch(AutoTouchRequest())
    tcp_true, _, _ = true_frame("torch")
    np.testing.assert_allclose(wf.result.tcp_mm, tcp_true, atol=EXACT_MM)
    assert any("sum of both touches' errors" in w for w in wf.result.warnings)
    assert wf.default_save_name() == "Bent-neck welding torch"
    slot, _ = wf.save("Torch")
    assert slot == 2 and library.get(1).name == "Pointer"


@pytest.mark.parametrize("robot", ["kr6", "gp12"])
@pytest.mark.parametrize("kind,variant", [("three-point", 1), ("three-point", 2), ("abc-world", "6d")])
def test_orientation_wizards_give_the_true_orientation(workflow, library, robot, kind, variant) -> None:
    library.save(1, library_tool_with_true_tcp("torch", "Torch"))
    wf = workflow(robot, "torch")
    if kind == "three-point":
        wf.start("three-point", slot=1, variant=variant)
    else:
        wf.start("abc-world", slot=1, variant=variant)
    assert wf.controller.active_tool.name == "Torch"
    run_auto(wf)
    tcp_true, R_true, abc_true = true_frame("torch")
    angle = np.degrees((Rotation.from_matrix(R_true).inv() * Rotation.from_matrix(wf.result.rotation)).magnitude())
    assert angle < EXACT_DEG
    assert wf.truth().orientation_error_deg < EXACT_DEG
    assert wf.default_save_name() == "Torch"
    slot, _ = wf.save(wf.default_save_name())       # same name: the same slot, now oriented
    assert slot == 1
    np.testing.assert_allclose(library.get(1).abc_deg, abc_true, atol=EXACT_DEG)
    np.testing.assert_allclose(library.get(1).tcp_mm, tcp_true, atol=1e-9)


def test_abc_world_5d_calibrates_tool_x(workflow, library) -> None:
    library.save(1, library_tool_with_true_tcp("torch", "Torch"))
    wf = workflow("kr6", "torch")
    wf.start("abc-world", slot=1, variant="5d")
    run_auto(wf)
    _, R_true, _ = true_frame("torch")
    x = wf.result.rotation[:, 0]
    assert np.degrees(np.arctan2(np.linalg.norm(np.cross(x, R_true[:, 0])), x @ R_true[:, 0])) < EXACT_DEG
    assert wf.truth().graded == ("x_axis",)


def test_starting_another_wizard_keeps_the_open_one_resumable(workflow) -> None:
    wf = workflow()
    first = wf.start("xyz4")
    wf.auto_touch(AutoTouchRequest())
    wf.auto_touch(AutoTouchRequest())
    poses = {i: p.T_world_flange_m.copy() for i, p in first.recorded_poses.items()}
    wf.start("xyz4", n_points=5)
    assert first.status == "cancelled" and [i for i, _ in wf.resumable()] == [0]
    assert "at step 3 of 4 (2 recorded), started " in wf.resumable()[0][1]
    wf.resume(0)
    assert wf.wizard is first and first.status == "in_progress" and first.step_index == 2
    for i, T in poses.items():
        np.testing.assert_array_equal(first.recorded_poses[i].T_world_flange_m, T)
    assert [i for i, _ in wf.resumable()] == [1]     # the 5-point one waits now
    with pytest.raises(WizardStateError, match="not waiting"):
        wf.resume(0)


def test_cancel_after_save_loses_nothing(workflow, library) -> None:
    wf = workflow()
    wf.start("xyz4")
    run_auto(wf)
    wf.save("Pen")
    before = library.path.read_bytes()
    wf.cancel()
    assert not wf.is_open and wf.result is None
    assert library.path.read_bytes() == before
    assert wf.resumable() == []                      # saved: nothing left half-way ...
    wf.resume(0)                                     # ... but the run is kept and can be reopened
    assert wf.result is not None and wf.result.tcp_mm == library.get(1).tcp_mm


def test_save_refusals_write_nothing(workflow, library) -> None:
    library.save(3, Tool(name="Taken", tcp_mm=(1.0, 2.0, 3.0)))
    before = library.path.read_bytes()
    wf = workflow()
    wf.start("xyz4")
    with pytest.raises(WizardStateError):
        wf.save("Early")                             # not finished
    run_auto(wf)
    with pytest.raises(WizardStateError, match="name"):
        wf.save("   ")
    with pytest.raises(TcpcalError):
        wf.save("Taken", slot=1)                     # the name belongs to slot 3
    assert library.path.read_bytes() == before
    assert wf.controller.active_tool is None


def test_auto_touch_is_a_training_tool_and_checks_its_request(workflow) -> None:
    wf = workflow()
    wf.start("xyz4")
    wf.training = False
    with pytest.raises(WizardStateError, match="training mode"):
        wf.auto_touch(AutoTouchRequest())
    assert wf.truth() is None
    with pytest.raises(WizardError, match="0 to 2 mm"):
        AutoTouchRequest(sigma_mm=2.5)
    with pytest.raises(WizardError, match="both tilt and azimuth"):
        AutoTouchRequest(tilt_deg=30.0)
    with pytest.raises(WizardError, match="finite"):
        AutoTouchRequest(tilt_deg=float("nan"), azimuth_deg=0.0)


def test_same_chosen_direction_four_times_is_degenerate_and_keeps_the_touches(workflow) -> None:
    """The lesson of pose diversity: four touches from one direction cannot give a TCP."""
    wf = workflow()
    wiz = wf.start("xyz4")
    same = AutoTouchRequest(tilt_deg=30.0, azimuth_deg=90.0)
    for _ in range(3):
        assert wf.auto_touch(same).ok
    with pytest.raises(CalibrationFailedError):
        wf.auto_touch(same)
    assert wiz.status == "in_progress" and wiz.on_last_step and all(s.recorded for s in wiz.steps)
    assert wf.result is None


def test_session_record_round_trip_replays_every_wizard(workflow, library) -> None:
    library.save(1, library_tool_with_true_tcp("pointer", "Pointer"))
    wf = workflow(seed=3)
    wf.start("xyz4", n_points=5)
    run_auto(wf, AutoTouchRequest(sigma_mm=0.5))
    tcp_first = wf.result.tcp_mm
    truth_first = wf.truth().position_error_mm
    wf.start("reference", slot=1, reference_tool_key="pointer", new_tool_key="gripper")
    wf.auto_touch(AutoTouchRequest())                # left half-way
    text = dumps(wf.export_record())
    record = json.loads(text)
    assert [w["state"]["kind"] for w in record["wizards"]] == ["xyz4", "reference"]
    assert record["wizards"][0]["truth"]["position_error_mm"] == pytest.approx(truth_first, abs=1e-12)

    other = workflow(seed=99)
    checks = other.load_record(text)
    assert [c.matches for c in checks] == [True, True]
    assert checks[0].truth.position_error_mm == pytest.approx(truth_first, abs=1e-9)
    assert isinstance(other.wizard, Xyz4Wizard) and other.result is not None      # finished one shown
    np.testing.assert_allclose(other.result.tcp_mm, tcp_first, atol=1e-9)
    assert [label.split(":")[0] for _, label in other.resumable()] == ["2"]        # the half-way one
    other.resume(1)
    assert other.wizard.kind == "reference" and other.wizard.step_index == 1


def test_a_bad_record_changes_nothing(workflow) -> None:
    wf = workflow()
    wf.start("xyz4")
    wf.auto_touch(AutoTouchRequest())
    with pytest.raises(WizardError, match="not valid JSON"):
        wf.load_record("{not json")
    with pytest.raises(WizardError, match="Not a TCP Pendant session record"):
        wf.load_record('{"format": "other"}')
    assert len(wf.runs) == 1 and wf.is_open and wf.wizard.step_index == 1


def test_unknown_choices_are_refused_with_the_options(workflow, library) -> None:
    wf = workflow()
    with pytest.raises(WizardError, match="Slot 4 of the tool library is empty"):
        wf.start("three-point", slot=4)
    library.save(1, library_tool_with_true_tcp("pointer", "Pointer"))
    with pytest.raises(WizardError, match="pointer, torch, gripper"):
        wf.start("reference", slot=1, reference_tool_key="pointer", new_tool_key="hammer")
    with pytest.raises(WizardError, match="same physical tool"):
        wf.start("reference", slot=1, reference_tool_key="pointer", new_tool_key="pointer")
    assert wf.runs == []
