"""The Automatic (beam) wizard as a state machine, fed a scan built here from the beam sensor's
geometry (``controller.beam``: ``tip_on_beam`` / ``crossing_events`` on known flange poses), so
the expected TCP and tool direction are the true tool's, known independently of the wizard.

Covers: the description (registry, options, one controller step, no Record), the solve (exact
events give the true TCP and tool direction to 1e-6 mm / deg; noisy ones land within 3x the
95 % radius), the saved frame (the planning orientation turned minimally onto the measured
direction), the record round trip (replay without a robot, same numbers) and the checks of an
untrusted record.
"""

from __future__ import annotations

import copy
import json
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcp_pendant.controller.beam import BeamSensor, ToolShape, crossing_events, tip_on_beam
from tcp_pendant.wizards import (
    BeamWizard,
    BeamWizardResult,
    ManualComparison,
    Wizard,
    WizardError,
    WizardStateError,
    wizard_class,
)
from tcp_pendant.wizards.beam import RecordedScan, ScanEvent, wall_time_s
from tcp_pendant.wizards.session_record import SessionRecordError, load_and_replay, session_to_dict
from tcp_pendant.wizards.truth import compare_with_truth
from tcpcal.tool import Tool

R_DOWN = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])   # tool X straight down
SENSOR = BeamSensor(point=np.array([0.55, -0.20, 0.30]), direction=np.array([0.0, 1.0, 0.0]), sigma=0.0)


def true_frame(tcp_mm, zyx_deg) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("ZYX", zyx_deg, degrees=True).as_matrix()
    T[:3, 3] = np.asarray(tcp_mm, float) / 1000.0
    return T


POINTER = true_frame([0.0, 0.0, 180.0], [0.0, -90.0, 0.0])            # tool X = flange Z
TORCH = true_frame([35.0, -12.0, 310.0], [20.0, -65.0, 15.0])          # off-axis, turned


@dataclass(frozen=True)
class FakeScan:
    """Shaped like ``controller.beam_scan.BeamScan`` (what the wizard reads of it)."""

    events: tuple[Any, ...]
    orientation_index: tuple[int, ...]
    duration_s: float = 12.5
    path_length_m: float = 1.1
    skipped: tuple[str, ...] = ()
    moves: tuple[Any, ...] = field(default=())


def flange_for(T_flange_tool: np.ndarray, R_world_tool: np.ndarray, tip_world: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R_world_tool @ T_flange_tool[:3, :3].T
    T[:3, 3] = tip_world - T[:3, :3] @ T_flange_tool[:3, 3]
    return T


def make_scan(T_flange_tool: np.ndarray, *, n: int = 4, tilt_deg: float = 10.0, sensor: BeamSensor = SENSOR,
              rng: np.random.Generator | None = None, skipped: tuple[str, ...] = ()) -> FakeScan:
    """Per orientation k (tool X down, tilted about the beam, turned k x 90 deg about the tool
    axis): two sideways passes crossing the shaft 15 and 35 mm behind the tip, then a vertical
    approach whose tip meets the beam line."""
    shape = ToolShape(T_flange_tool, radius=1e-3, length=0.1)
    b, u = sensor.point, sensor.direction
    across = np.cross(u, [0.0, 0.0, 1.0])
    events, index = [], []
    for k in range(n):
        R = (Rotation.from_rotvec(u * math.radians(tilt_deg if k % 2 == 0 else -tilt_deg))
             * Rotation.from_matrix(R_DOWN) * Rotation.from_euler("x", 360.0 * k / n, degrees=True)).as_matrix()
        x = R[:, 0]
        s = 0.01 * (k - n / 2)                                   # along the beam: spread the events
        for h in (0.015, 0.035):
            start = b + s * u + h * x - 0.03 * across            # the shaft h behind the tip meets the beam
            evs = crossing_events(flange_for(T_flange_tool, R, start), across, sensor, shape,
                                  max_travel=0.06, rng=rng)
            events += list(evs)
            index += [k] * len(evs)
        start = b + s * u + np.array([0.0, 0.0, 0.02])
        ev = tip_on_beam(flange_for(T_flange_tool, R, start), [0.0, 0.0, -1.0], sensor, shape, rng=rng)
        assert ev is not None
        events.append(ev)
        index.append(k)
    return FakeScan(tuple(events), tuple(index), skipped=skipped)


def finished(T_true: np.ndarray, *, R_base: np.ndarray | None = None, **kw: Any) -> BeamWizard:
    wiz = BeamWizard()
    wiz.give_scan(make_scan(T_true, **kw), R_flange_tool_base=T_true[:3, :3] if R_base is None else R_base)
    wiz.finish()
    return wiz


# ----------------------------------------------------------------------------- description
def test_registered_and_described() -> None:
    cls = wizard_class("beam")
    assert cls is BeamWizard and cls.needs_tool == "mounted"
    assert cls.calibrates == "the TCP and the tool direction"
    assert [r.name for r in cls.step_roles] == ["scan"] and cls.step_role("scan").auto.by_controller
    assert cls.parse_options({}) == {"n_orientations": 4, "scan_speed_mm_s": 50}
    with pytest.raises(WizardError, match="out of range 3..5"):
        cls.parse_options({"n_orientations": 6})
    with pytest.raises(WizardError, match="out of range 5..250"):
        cls.parse_options({"scan_speed_mm_s": 1000})


def test_no_record_no_finish_without_a_scan() -> None:
    wiz = BeamWizard(n_orientations=3)
    assert wiz.n_steps == 1 and wiz.scan_pending and wiz.can_next and not wiz.can_record
    assert wiz.progress == 0.0 and not wiz.step.recorded
    assert "3 tool orientations" in wiz.step.instruction
    with pytest.raises(WizardStateError, match="controller runs this step itself"):
        wiz.record(np.eye(4))
    with pytest.raises(WizardStateError, match="Run the scan first"):
        wiz.next()
    with pytest.raises(WizardStateError, match="Run the scan first"):
        wiz.finish()
    with pytest.raises(WizardStateError, match="Finish the wizard"):
        wiz.to_tool("x")


def test_the_scan_is_no_recorded_touch() -> None:
    """The classroom counts recorded poses as touches: a scan records none, the step is done."""
    wiz = BeamWizard()
    wiz.give_scan(make_scan(POINTER), R_flange_tool_base=POINTER[:3, :3])
    assert wiz.recorded_poses == {} and wiz.step.recorded and wiz.progress == 0.5
    assert isinstance(wiz.next(), BeamWizardResult)
    assert wiz.recorded_poses == {} and wiz.progress == 1.0 and wiz.is_complete
    assert wiz.to_dict()["poses"] == {}


@pytest.mark.parametrize("bad", [{"n_orientations": 2}, {"n_orientations": 3.5}, {"scan_speed_mm_s": 0},
                                 {"scan_speed_mm_s": float("nan")}, {"n_orientations": True}])
def test_bad_constructor_options(bad: dict[str, Any]) -> None:
    with pytest.raises(WizardError):
        BeamWizard(**bad)


# ----------------------------------------------------------------------------- the solve
@pytest.mark.parametrize("T_true", [POINTER, TORCH], ids=["pointer", "torch"])
def test_exact_events_give_the_true_tcp_and_direction(T_true: np.ndarray) -> None:
    wiz = finished(T_true)
    res = wiz.result
    assert isinstance(res, BeamWizardResult) and wiz.is_complete
    assert np.allclose(res.tcp_mm, T_true[:3, 3] * 1000.0, atol=1e-6)
    d = np.asarray(res.direction_flange)
    x = T_true[:3, 0]
    assert math.degrees(math.atan2(np.linalg.norm(np.cross(d, x)), float(d @ x))) < 1e-6
    cmp = compare_with_truth(res, T_true)
    assert cmp.position_error_mm < 1e-6 and cmp.orientation_error_deg < 1e-6 and cmp.grade == "good"
    assert len(res.tip_event_indices) == 4 and len(res.axis_event_indices) == 8
    assert max(res.per_touch_error_mm) < 1e-6 and res.duration_s == 12.5
    assert res.method == "beam" and res.direction_turn_deg < 1e-6
    # markers: the tip events' computed tips lie on the beam line
    for i in res.tip_event_indices:
        p = res.event_points_world_m()[i] - SENSOR.point
        assert np.linalg.norm(p - (p @ SENSOR.direction) * SENSOR.direction) < 1e-9


def test_noisy_events_land_within_three_ci95() -> None:
    rng = np.random.default_rng(7)
    sensor = BeamSensor(point=SENSOR.point, direction=SENSOR.direction, sigma=2e-5)
    for _ in range(5):
        wiz = BeamWizard(n_orientations=5)
        wiz.give_scan(make_scan(TORCH, n=5, sensor=sensor, rng=rng), R_flange_tool_base=TORCH[:3, :3])
        res = wiz.finish()
        err = float(np.linalg.norm(np.asarray(res.tcp_mm) - TORCH[:3, 3] * 1000.0))
        assert 0.0 < err <= 3.0 * res.ci95_mm
        assert 0.001 < res.ci95_mm < 0.5


def test_saved_frame_is_the_planning_orientation_turned_onto_the_measured_direction() -> None:
    """A bent tool (true X 3 deg off the believed one, plus a twist about X the beam cannot see):
    the saved X is the true X, the rest is the believed frame turned by the smallest rotation."""
    believed = TORCH[:3, :3]
    bend = Rotation.from_rotvec(np.radians(3.0) * np.cross(believed[:, 0], believed[:, 1]))
    bent = TORCH.copy()
    bent[:3, :3] = bend.as_matrix() @ believed
    bent[:3, 3] += [1.0e-3, -2.0e-3, 0.5e-3]
    wiz = finished(bent, R_base=believed)
    res = wiz.result
    assert np.allclose(res.tcp_mm, bent[:3, 3] * 1000.0, atol=1e-6)
    assert abs(res.direction_turn_deg - 3.0) < 1e-6
    assert np.allclose(res.rotation, bent[:3, :3], atol=1e-9)        # a pure tilt is recovered whole
    cmp = compare_with_truth(res, bent)
    assert cmp.position_error_mm < 1e-6 and cmp.orientation_error_deg < 1e-6
    tool = wiz.to_tool("Torch")
    assert isinstance(tool, Tool) and tool.calibration.method == "beam"
    assert np.allclose(tool.tcp_mm, bent[:3, 3] * 1000.0, atol=1e-6)
    assert tool.calibration.figures["n_tip_events"] == 4.0 and "scan_duration_s" in tool.calibration.figures
    assert any("not the turn about it" in n for n in res.notes)


def test_too_few_tip_events_fail_in_words() -> None:
    scan = make_scan(POINTER, n=3, skipped=("orientation 3: out of reach",))
    keep = [e for e in scan.events if e.kind == "axis"][:4] + [e for e in scan.events if e.kind == "tip"][:1]
    wiz = BeamWizard()
    wiz.give_scan(FakeScan(tuple(keep), (0,) * len(keep), skipped=scan.skipped), R_flange_tool_base=np.eye(3))
    with pytest.raises(WizardError, match=r"1 tip event;.*out of reach"):
        wiz.finish()
    assert wiz.status == "in_progress"


def test_no_direction_keeps_the_planning_orientation_and_warns() -> None:
    scan = make_scan(POINTER)
    tips = tuple(e for e in scan.events if e.kind == "tip")
    wiz = BeamWizard()
    wiz.give_scan(FakeScan(tips, tuple(range(4))), R_flange_tool_base=POINTER[:3, :3])
    res = wiz.finish()
    assert res.direction_flange is None and res.axis_result is None
    assert np.allclose(res.rotation, POINTER[:3, :3])
    assert any("tool direction needs 2" in w for w in res.warnings)


def test_manual_comparison_and_wall_time() -> None:
    assert wall_time_s("2026-11-28T02:00:00Z", "2026-11-28T02:03:12Z") == 192.0
    assert wall_time_s("yesterday", "2026-11-28T02:03:12Z") is None
    manual = ManualComparison("XYZ 4-point", "xyz4", 1, 192.0, 0.8, None, "fair")
    wiz = BeamWizard()
    wiz.give_scan(make_scan(POINTER), R_flange_tool_base=POINTER[:3, :3], manual=manual)
    assert wiz.finish().manual == manual


# ----------------------------------------------------------------------------- record
def record_of(wiz: Wizard, T_true: np.ndarray) -> dict[str, Any]:
    from tcp_pendant.wizards.session_record import WizardRun
    return json.loads(json.dumps(session_to_dict([WizardRun(wiz, "torch", T_true)], robot="kr6")))


def test_record_round_trip_rebuilds_the_same_result_without_a_robot() -> None:
    manual = ManualComparison("XYZ 4-point", "xyz4", 1, 192.0, 0.8, 0.0, "fair")
    wiz = BeamWizard(n_orientations=4)
    wiz.give_scan(make_scan(TORCH, rng=np.random.default_rng(3),
                            sensor=BeamSensor(SENSOR.point, SENSOR.direction, sigma=2e-5)),
                  R_flange_tool_base=TORCH[:3, :3], manual=manual)
    res = wiz.finish()
    check = load_and_replay(record_of(wiz, TORCH)).checks[0]
    assert check.matches and check.tcp_diff_mm == 0.0 and check.rotation_diff_deg < 1e-9
    again = check.wizard.finished_result
    assert isinstance(again, BeamWizardResult) and isinstance(again.scan, RecordedScan)
    assert again.tcp_mm == res.tcp_mm and again.direction_flange == res.direction_flange
    assert again.manual == manual and again.duration_s == res.duration_s
    assert again.per_touch_error_mm == res.per_touch_error_mm and again.scan.moves == ()
    assert check.truth is not None and check.truth.position_error_mm < 0.1


def test_honest_record_drops_the_manual_errors() -> None:
    wiz = BeamWizard()
    wiz.give_scan(make_scan(POINTER), R_flange_tool_base=POINTER[:3, :3],
                  manual=ManualComparison("XYZ 4-point", "xyz4", 1, 60.0, 0.4, None, "good"))
    wiz.finish()
    from tcp_pendant.wizards.session_record import WizardRun
    rec = session_to_dict([WizardRun(wiz, "pointer", POINTER)], robot="kr6", honest=True)
    manual = rec["wizards"][0]["state"]["params"]["manual"]
    assert manual["truth"] is None and manual["wall_time_s"] == 60.0
    assert "0.4" not in json.dumps(rec["wizards"][0]["state"]["params"]["manual"])
    again = load_and_replay(json.loads(json.dumps(rec))).checks[0].wizard.finished_result
    assert again.manual.position_error_mm is None


def test_unfinished_and_cancelled_round_trip() -> None:
    wiz = BeamWizard(n_orientations=5, scan_speed_mm_s=20)
    wiz.cancel()
    back = load_and_replay(record_of(wiz, TORCH)).checks[0].wizard
    assert isinstance(back, BeamWizard) and back.status == "cancelled" and back.n_orientations == 5
    assert back.scan_speed_mm_s == 20.0 and back.finished_result is None


def _tamper(rec: dict[str, Any], fn) -> dict[str, Any]:
    rec = copy.deepcopy(rec)
    fn(rec["wizards"][0]["state"]["params"])
    return rec


@pytest.mark.parametrize("edit, words", [
    (lambda p: p["scan"].update(events=[p["scan"]["events"][0]] * 101), "at most 100"),
    (lambda p: p["scan"]["events"][0].update(kind="laser"), "kind must be"),
    (lambda p: p["scan"]["events"][0].update(T_world_flange_m=[[1, 0], [0, 1]]), "4x4"),
    (lambda p: p["scan"]["events"][0].update(beam_point_m=[1e9, 0, 0]), "beam point"),
    (lambda p: p["scan"]["events"][0].update(beam_dir=[0, 0, 0]), "zero vector"),
    (lambda p: p["scan"]["events"][0].update(beam=7), "beam must be 0 or 1"),
    (lambda p: p["scan"].update(duration_s=float("inf")), "duration"),
    (lambda p: p["scan"].update(skipped=["x"] * 11), "at most 10"),
    (lambda p: p.update(R_flange_tool_base=[[2, 0, 0], [0, 1, 0], [0, 0, 1]]), "rotation"),
    (lambda p: p["manual"].update(run_number=-1), "number must be"),
    (lambda p: p["manual"]["truth"].update(grade="excellent"), "grade"),
    (lambda p: p.update(n_orientations=99), "3 to 5"),
])
def test_untrusted_record_is_checked(edit, words) -> None:
    wiz = BeamWizard()
    wiz.give_scan(make_scan(POINTER), R_flange_tool_base=POINTER[:3, :3],
                  manual=ManualComparison("XYZ 4-point", "xyz4", 1, 60.0, 0.4, None, "good"))
    wiz.finish()
    rec = _tamper(record_of(wiz, POINTER), edit)
    with pytest.raises(SessionRecordError, match=words):
        load_and_replay(json.loads(json.dumps(rec, allow_nan=True)))


def test_stored_texts_are_cut() -> None:
    scan = RecordedScan.from_dict({"events": [], "duration_s": 1.0, "path_length_m": 0.1, "skipped": ["y" * 5000]})
    assert len(scan.skipped[0]) == 200
    ev = ScanEvent.from_dict({"kind": "tip", "T_world_flange_m": np.eye(4).tolist(), "beam_point_m": [0, 0, 0],
                              "beam_dir": [0, 2, 0]})
    assert np.allclose(ev.beam_dir, [0, 1, 0]) and ev.orientation == 0


def test_back_from_the_result_scans_again() -> None:
    wiz = finished(POINTER)
    with pytest.raises(WizardStateError, match="press Back to scan again"):
        wiz.give_scan(make_scan(POINTER), R_flange_tool_base=np.eye(3))
    wiz.back()
    assert wiz.scan_pending and wiz.status == "in_progress" and not wiz.step.recorded
    wiz.give_scan(make_scan(TORCH), R_flange_tool_base=TORCH[:3, :3])
    assert np.allclose(wiz.finish().tcp_mm, TORCH[:3, 3] * 1000.0, atol=1e-6)
