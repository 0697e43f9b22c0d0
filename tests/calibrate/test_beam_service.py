"""The TCP service with the beam sensor (tcp_pendant.calibrate.beam_service):
"Check with beam" against the hidden truth, the bent-tool loop (crash, check, deviation,
Update, spin test says good) and Update's refusals. No browser."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tcp_pendant.calibrate.beam_service import (
    GOOD_BEAM_MM,
    BeamServiceError,
    beam_check_job,
    beam_check_markdown,
    update_tool_from_beam,
)
from tcp_pendant.controller import ControllerError, builtin_tools
from tcp_pendant.controller.scenarios import Scenario, realize
from tcp_pendant.controller.spin import spin_check_of
from tcp_pendant.text_escape import escape_markdown

from tcpcal.library import ToolLibrary
from tcpcal.tool import Calibration, Tool

from support.calib_helpers import make_controller


def truth_tool(tool_key: str, name: str) -> Tool:
    """Tool data equal to a built-in tool's (unbent) hidden truth."""
    T = builtin_tools()[tool_key].T_flange_tool_true
    return Tool.from_rotation(name, tuple(T[:3, 3] * 1000.0), T[:3, :3], mass_kg=1.5, cog_mm=(0, 0, 40), inertia_kgm2=(0.02, 0.02, 0.005), notes="shop 2",
                              calibration=Calibration("xyz4-lstsq", "2024-05-01T12:00:00+00:00", {"ci95_mm": 0.3}))


def bend(controller, seed: int):
    """The bent-tool scenario as ``Session.set_scenario`` plays it: the bent tool bolted on, the
    controller's tool data unchanged."""
    world = realize(Scenario("bent_tool", seed=seed), controller.kinematics, controller.mounted_tool)
    controller.mount_tool(world.tool_true)
    return world


def angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    return math.degrees(math.atan2(float(np.linalg.norm(np.cross(a, b))), float(a @ b)))


@pytest.mark.parametrize(("robot", "tool_key"), [("kr6", "torch"), ("gp12", "pointer"), ("kr6", "pointer"),
                                                 ("gp12", "torch")])
def test_stored_truth_checks_good(robot, tool_key):
    c = make_controller(robot, tool_key)
    tool = truth_tool(tool_key, "Tool A")
    c.set_active_tool(tool)
    q = c.q_rad
    check = beam_check_job(c, 2, tool, rng_seed=5).run()
    assert np.array_equal(c.q_rad, q)  # the controller did not move
    assert check.deviation_norm_mm < 0.05
    assert check.deviation_norm_mm == pytest.approx(float(np.linalg.norm(check.deviation_mm)))
    assert np.allclose(check.deviation_mm, check.measured_tcp_mm - check.stored_tcp_mm)
    assert np.allclose(check.stored_tcp_mm, tool.tcp_mm)
    assert check.good and check.verdict.startswith("TCP good")
    assert 0.005 < check.ci95_mm < 0.1  # 0.02 mm repeatability, 4 tip events
    assert check.direction_deviation_deg is not None and check.direction_deviation_deg < 0.2
    assert check.tool_name == "Tool A" and check.slot == 2 and check.seed == 5
    assert check.scan.skipped == () and len(check.scan.tip_indices) == 4
    assert check.consistent and check.residual_rms_mm < 3 * 0.027
    assert "absolute accuracy" not in check.verdict


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_bent_tool_deviation_is_the_bend(seed):
    c = make_controller("kr6", "torch")
    stored = truth_tool("torch", "Torch")
    c.set_active_tool(stored)
    world = bend(c, seed)
    T_bent = world.tool_true.T_flange_tool_true
    check = beam_check_job(c, 1, stored, rng_seed=seed).run()
    expected = T_bent[:3, 3] * 1000.0 - np.asarray(stored.tcp_mm)
    assert np.linalg.norm(expected) > 2.0  # the scenario bends by 2-5 mm
    assert np.linalg.norm(check.deviation_mm - expected) < 0.05
    assert not check.good and check.verdict.startswith(f"TCP off by {check.deviation_norm_mm:.3f} mm")
    # the axis turned by the bend's 1-3 deg; the verdict says that Update keeps the orientation
    assert check.direction_deviation_deg == pytest.approx(world.tool_bend.angle_deg, abs=0.1)
    assert "Update keeps the stored orientation" in check.verdict


def test_the_whole_loop_crash_check_update_spin_test(library: ToolLibrary):
    c = make_controller("gp12", "torch")
    stored = truth_tool("torch", "Torch 1")
    library.save(4, stored)
    library.save(1, truth_tool("pointer", "Pointer"))
    c.set_active_tool(stored)
    bend(c, 7)
    before = spin_check_of(c)
    assert before.implied_tcp_error_mm > 2.0  # the spin test sees the crash too

    check = beam_check_job(c, 4, c.active_tool, rng_seed=11).run()
    assert check.deviation_norm_mm > 2.0
    updated = update_tool_from_beam(library, 4, check)
    reread = ToolLibrary(library.path).get(4)  # what is on disk now
    assert reread == updated
    assert np.allclose(reread.tcp_mm, check.measured_tcp_mm, atol=1e-9)
    assert reread.abc_deg == stored.abc_deg  # orientation kept
    assert (reread.name, reread.mass_kg, reread.cog_mm, reread.notes) == ("Torch 1", 1.5, (0, 0, 40), "shop 2")
    assert reread.inertia_kgm2 == (0.02, 0.02, 0.005)
    cal = reread.calibration
    assert cal.method == "beam"
    assert cal.figures["deviation_mm"] == pytest.approx(check.deviation_norm_mm)
    assert cal.figures["ci95_mm"] == pytest.approx(check.ci95_mm)
    assert cal.figures["n_events"] == 4.0 and cal.figures["n_axis_events"] == 8.0
    assert cal.figures["direction_deviation_deg"] == pytest.approx(check.direction_deviation_deg)
    assert cal.calibrated_at[:4] >= "2025" and cal.calibrated_at.endswith("+00:00")
    assert ToolLibrary(library.path).get(1).name == "Pointer"  # the other slot untouched
    assert library.active_slot() is None  # which tool is active is the session's

    c.set_active_tool(updated)
    after = spin_check_of(c)
    assert after.implied_tcp_error_mm < GOOD_BEAM_MM
    assert after.implied_tcp_error_mm < 0.1  # the TCP is right now; the 2 deg axis tilt is not seen
    again = beam_check_job(c, 4, updated, rng_seed=12).run()
    assert again.good


def test_update_refuses_when_the_slot_changed(library: ToolLibrary):
    c = make_controller("kr6", "pointer")
    stored = truth_tool("pointer", "Pointer")
    library.save(3, stored)
    bend(c, 2)
    check = beam_check_job(c, 3, stored, rng_seed=1).run()
    # someone recalibrated the slot meanwhile
    other = Tool(name="Pointer", tcp_mm=(1.0, 2.0, 180.0))
    library.save(3, other)
    with pytest.raises(BeamServiceError, match="Slot 3 changed since the check.*nothing was written"):
        update_tool_from_beam(library, 3, check)
    assert ToolLibrary(library.path).get(3) == other
    library.remove(3)
    with pytest.raises(BeamServiceError, match="Slot 3 is empty now"):
        update_tool_from_beam(library, 3, check)
    assert ToolLibrary(library.path).get(3) is None
    library.save(3, stored)
    with pytest.raises(BeamServiceError, match="The check was of slot 3, not slot 5"):
        update_tool_from_beam(library, 5, check)
    unsaved = beam_check_job(c, None, stored, rng_seed=1).run()
    with pytest.raises(BeamServiceError, match="not in the library: save it to a slot first"):
        update_tool_from_beam(library, 3, unsaved)
    assert ToolLibrary(library.path).get(3) == stored
    # unchanged slot: written
    assert update_tool_from_beam(library, 3, check).calibration.method == "beam"


def test_job_is_a_snapshot_and_reproducible():
    c = make_controller("kr6", "torch")
    stored = truth_tool("torch", "Torch")
    c.set_active_tool(stored)
    job = beam_check_job(c, 1, stored, rng_seed=3)
    c.set_q(c.q_rad + 0.05)  # the loop goes on jogging: the job keeps its snapshot
    c.set_reference_tip(c.reference_tip_world_m + [0.03, 0.0, 0.0])
    a, b = job.run(), job.run()
    assert np.array_equal(a.measured_tcp_mm, b.measured_tcp_mm)
    assert job.kinematics is not c.kinematics  # its own pinocchio data for the worker thread
    other_seed = beam_check_job(c, 1, stored, rng_seed=4).run()
    assert not np.array_equal(a.measured_tcp_mm, other_seed.measured_tcp_mm)
    fresh = beam_check_job(c, 1, stored)
    assert isinstance(fresh.seed, int) and fresh.seed >= 0


def test_bad_requests_are_clear_errors():
    c = make_controller("kr6", "gripper")
    tool = Tool(name="Gripper", tcp_mm=(0.0, 0.0, 165.0))
    with pytest.raises(ControllerError, match="gripper has no tip"):
        beam_check_job(c, 1, tool)
    c = make_controller("kr6", "pointer")
    with pytest.raises(ControllerError, match="slot must be 1..16"):
        beam_check_job(c, 17, tool)
    with pytest.raises(ControllerError, match="rng_seed"):
        beam_check_job(c, 1, tool, rng_seed=-1)
    with pytest.raises(ControllerError, match="tcpcal tool data"):
        beam_check_job(c, 1, None)  # type: ignore[arg-type]


def test_markdown_escapes_the_tool_name():
    c = make_controller("kr6", "pointer")
    name = "*x*[a](http://e.vil)"
    stored = truth_tool("pointer", name)
    check = beam_check_job(c, 2, stored, rng_seed=0).run()
    md = beam_check_markdown(check)
    assert escape_markdown(name) in md and name not in md
    assert "slot 2" in md and f"{check.deviation_norm_mm:.3f} mm" in md
    assert "✔" in md and check.verdict in md.replace("\\", "")


@pytest.mark.parametrize(("robot", "seed"), [("gp12", 1), ("kr6", 3)])
def test_robot_accuracy_shows_as_disagreeing_events(robot, seed):
    """The absolute-accuracy scenario: the recorded poses are the model's, the beam sees the real
    arm; the tip events disagree by tenths of a mm (far beyond 0.02 mm) and the verdict says
    that the robot, not the tool, limits the measurement."""
    c = make_controller(robot, "torch")
    stored = truth_tool("torch", "Torch")
    c.set_active_tool(stored)
    world = realize(Scenario("robot_accuracy", seed=seed), c.kinematics, c.mounted_tool)
    c.set_true_kinematics(world.true_kinematics)
    check = beam_check_job(c, 1, stored, rng_seed=seed).run()
    assert check.residual_rms_mm > 0.3
    assert not check.consistent
    assert "the robot's absolute accuracy" in check.verdict
    assert f"{check.residual_rms_mm:.3f} mm RMS" in check.verdict
    # the physical tool is exactly the stored one: what the check reports is the robot's error
    assert 0.1 < check.deviation_norm_mm < 2.0


def test_one_orientation_is_too_few_for_a_check():
    """A wrist narrowed so that only the first orientation is in reach: one tip event cannot
    give a TCP; the check says so in words with the skip reasons (no crash, no number)."""
    from tcp_pendant.calibrate.beam_service import evaluate_check
    from tcp_pendant.controller import RobotKinematics, run_beam_scan, tool_shape

    c = make_controller("kr6", "pointer")
    stored = truth_tool("pointer", "Pointer")
    full = run_beam_scan(c.kinematics, c.q_rad, c.beam_sensor, _plan_m(stored), tool_shape(c.mounted_tool))
    q = np.degrees([mv.q_end_rad for mv in full.moves if mv.kind == "approach"][0])
    kin = RobotKinematics(c.kinematics.model, c.kinematics.urdf_path, c.kinematics.flange_link, c.kinematics.base_link)
    kin.lower_rad, kin.upper_rad = kin.lower_rad.copy(), kin.upper_rad.copy()
    for j in (3, 5):
        kin.lower_rad[j], kin.upper_rad[j] = np.radians(q[j] - 20.0), np.radians(q[j] + 20.0)
    scan = run_beam_scan(kin, c.q_rad, c.beam_sensor, _plan_m(stored), tool_shape(c.mounted_tool))
    assert len(scan.tip_indices) == 1 and len(scan.skipped) == 3
    with pytest.raises(ControllerError, match=r"too few tip events for a TCP: 1 of 4 orientations.*"
                                              r"Orientation 2 \(turned 90 deg about the tool axis\) was skipped.*"
                                              r"Place the beam sensor where the robot reaches it"):
        evaluate_check(stored, 1, scan)


def _plan_m(tool: Tool) -> np.ndarray:
    T = np.array(tool.T_flange_tool_mm)
    T[:3, 3] /= 1000.0
    return T
