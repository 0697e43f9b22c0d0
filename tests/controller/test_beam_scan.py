"""The automatic beam scan (tcp_pendant.controller.beam_scan) and the controller's beam
sensor: the scan's events against the hidden truth through tcpcal's beam solves (methods.md
section 9), its durations, skips and purity. Metres inside, mm for tcpcal."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from support.pseudo_text import english_words

from tcpcal import solve_beam, solve_beam_axis
from tcp_pendant.controller import (
    BeamScanConfig,
    BeamSensor,
    ControllerError,
    RobotKinematics,
    VirtualController,
    builtin_tools,
    default_beam_sensor,
    run_beam_scan,
    tool_shape,
)
from tcp_pendant.controller.approach import solve_ik
from tcp_pendant.controller.words import in_language
from tcp_pendant.translation import PSEUDO_LANGUAGE, translator
from tcp_pendant.controller.beam_scan import scan_arrays_mm
from tcp_pendant.controller.scenarios import Scenario, draw_kinematic_errors, perturbed_kinematics

from .conftest import ROBOTS, kinematics

BEAM_TOOLS = ("pointer", "torch")


def ready(robot: str) -> tuple[np.ndarray, np.ndarray]:
    """(q, reference tip) of the app's start: the controller's default reference tip (below the
    home flange at half its height, as the server's default) and the flange pointing down."""
    kin = kinematics(robot)
    ctrl = VirtualController(kin, tool=builtin_tools()["pointer"])
    q = np.array(kin.home_rad, dtype=float)
    q[4] = math.pi / 2
    if -kin.T_world_flange(q)[2, 2] < 0.9:
        q[4] = -math.pi / 2
    return q, ctrl.reference_tip_world_m


def angle_between_deg(a: np.ndarray, b: np.ndarray) -> float:
    """Angle between two vectors (deg), accurate for tiny angles."""
    return math.degrees(math.atan2(float(np.linalg.norm(np.cross(a, b))), float(a @ b)))


def solve(scan) -> tuple[np.ndarray, np.ndarray]:
    """TCP (mm) and tool direction (FLANGE) from a scan's events, by tcpcal."""
    rot, pos, b, u = scan_arrays_mm(scan.events)
    ti, ai = list(scan.tip_indices), list(scan.axis_indices)
    tcp = solve_beam(rot[ti], pos[ti], b[ti], u[ti]).tcp
    d = solve_beam_axis(rot[ai], pos[ai], b[ai], u[ai], tcp).direction
    return np.asarray(tcp), np.asarray(d)


def believed_off(T: np.ndarray, shift_mm=(3.0, -4.0, 2.5), angle_deg: float = 2.0) -> np.ndarray:
    """Tool data several mm and 2 deg off the truth (a bent tool's stale data)."""
    out = np.array(T, dtype=float)
    out[:3, 3] += np.asarray(shift_mm) / 1000.0
    out[:3, :3] = Rotation.from_rotvec(math.radians(angle_deg) * np.array([0.6, 0.8, 0.0])).as_matrix() @ out[:3, :3]
    return out


# ---------------------------------------------------------------------------------- exact data
@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("tool_key", BEAM_TOOLS)
@pytest.mark.parametrize("stale", [False, True], ids=["data-true", "data-off"])
def test_exact_scan_gives_the_true_tcp_and_direction(robot, tool_key, stale):
    q0, tip = ready(robot)
    model = builtin_tools()[tool_key]
    T_true = model.T_flange_tool_true
    plan = believed_off(T_true) if stale else T_true
    scan = run_beam_scan(kinematics(robot), q0, default_beam_sensor(tip), plan, tool_shape(model))
    assert scan.skipped == ()
    assert len(scan.tip_indices) == 4 and len(scan.axis_indices) == 8
    assert scan.orientation_index == tuple(k for k in range(4) for _ in range(3))
    tcp, d = solve(scan)
    assert np.linalg.norm(tcp - T_true[:3, 3] * 1000.0) < 1e-6  # mm
    assert angle_between_deg(d, T_true[:3, 0]) < 1e-6  # deg
    for i in scan.tip_indices:  # the approach along the measured axis hits the beam dead centre
        assert scan.events[i].miss_distance < 1e-9
        # the marker: the physical tip on the beam line
        ev = scan.events[i]
        p = scan.tip_world_m(i) - ev.beam_point
        assert np.linalg.norm(p - (p @ ev.beam_dir) * ev.beam_dir) < 1e-9
    for i in scan.axis_indices:
        assert scan.events[i].on_shaft


def test_the_stale_data_check_fails_without_the_approach_line():
    """Control for the test above: aiming the approach with the believed (stale) tool data
    instead of the measured axis misses the beam centre by millimetres."""
    q0, tip = ready("kr6")
    model = builtin_tools()["pointer"]
    plan = believed_off(model.T_flange_tool_true)
    scan = run_beam_scan(kinematics("kr6"), q0, default_beam_sensor(tip), plan, tool_shape(model))
    ev = scan.events[scan.tip_indices[0]]
    T = ev.T_world_flange
    tip_believed = T[:3, :3] @ plan[:3, 3] + T[:3, 3]
    p = tip_believed - ev.beam_point
    assert np.linalg.norm(p - (p @ ev.beam_dir) * ev.beam_dir) > 2e-3


def test_recorded_poses_are_the_model_poses_of_the_moves():
    q0, tip = ready("gp12")
    kin = kinematics("gp12")
    model = builtin_tools()["torch"]
    scan = run_beam_scan(kin, q0, default_beam_sensor(tip), model.T_flange_tool_true, tool_shape(model))
    for mv in scan.moves:
        assert np.allclose(kin.T_world_flange(mv.q_start_rad), mv.T_world_flange_start, atol=1e-9)
        assert np.allclose(kin.T_world_flange(mv.q_end_rad), mv.T_world_flange_end, atol=1e-9)
    for prev, nxt in zip(scan.moves, scan.moves[1:]):  # a continuous motion
        assert np.array_equal(prev.q_end_rad, nxt.q_start_rad)
    assert np.array_equal(scan.moves[0].q_start_rad, q0)
    assert np.array_equal(scan.q_end_rad, scan.moves[-1].q_end_rad)
    # each event belongs to exactly one pass or approach, in order
    listed = [i for mv in scan.moves for i in mv.event_indices]
    assert listed == list(range(len(scan.events)))
    for mv in scan.moves:
        for i in mv.event_indices:
            ev = scan.events[i]
            assert mv.kind == ("approach" if ev.kind == "tip" else "pass")
            # the event lies on the straight motion: start + travel * direction
            step = mv.T_world_flange_end[:3, 3] - mv.T_world_flange_start[:3, 3]
            m = step / np.linalg.norm(step)
            assert np.allclose(ev.T_world_flange_exact[:3, 3],
                               mv.T_world_flange_start[:3, 3] + ev.travel * m, atol=1e-12)
            assert np.allclose(ev.T_world_flange_exact[:3, :3], mv.T_world_flange_start[:3, :3])
        if mv.kind == "approach":  # the robot stops at the tip event
            assert len(mv.event_indices) == 1
            assert np.allclose(scan.events[mv.event_indices[0]].T_world_flange_exact,
                               mv.T_world_flange_end, atol=1e-12)


# ---------------------------------------------------------------------------------- noise
def test_noise_gives_errors_of_the_sensor_repeatability():
    q0, tip = ready("kr6")
    model = builtin_tools()["torch"]
    T_true = model.T_flange_tool_true
    sensor = default_beam_sensor(tip)
    assert sensor.sigma == pytest.approx(2e-5)  # 0.02 mm
    errors, angles, misses = [], [], []
    for seed in range(12):
        scan = run_beam_scan(kinematics("kr6"), q0, sensor, T_true, tool_shape(model),
                             rng=np.random.default_rng(seed))
        tcp, d = solve(scan)
        errors.append(np.linalg.norm(tcp - T_true[:3, 3] * 1000.0))
        angles.append(angle_between_deg(d, T_true[:3, 0]))
        misses += [scan.events[i].miss_distance for i in scan.tip_indices]
    rms = math.sqrt(np.mean(np.square(errors)))
    # 4 tip events of 0.02 mm per axis (plus the aiming error from the noisy axis events):
    # a few hundredths of a mm, clearly not exact and clearly not tenths
    assert 0.005 < rms < 0.06, rms
    assert max(errors) < 0.12
    # crossings 8 and 40 mm behind the tip, 0.014 mm each: a few hundredths of a degree
    assert 0.003 < float(np.mean(angles)) < 0.15, angles
    # the approach aims with the noisy axis events: it misses the centre by hundredths
    assert 0.0 < max(misses) < 1e-4


def test_same_seed_same_scan_and_no_mutation():
    q0, tip = ready("kr6")
    kin = kinematics("kr6")
    model = builtin_tools()["pointer"]
    plan = believed_off(model.T_flange_tool_true)
    q_copy, plan_copy = q0.copy(), plan.copy()
    ctrl = VirtualController(kin, tool=model, reference_tip_world_m=tip)
    ctrl.set_q(q0)
    before = ctrl.q_rad
    a = run_beam_scan(ctrl.kinematics, ctrl.q_rad, ctrl.beam_sensor, plan, tool_shape(model),
                      rng=np.random.default_rng(7))
    b = run_beam_scan(kin, q0, default_beam_sensor(tip), plan, tool_shape(model),
                      rng=np.random.default_rng(7))
    assert np.array_equal(ctrl.q_rad, before)  # the controller did not move
    assert np.array_equal(q0, q_copy) and np.array_equal(plan, plan_copy)
    assert len(a.events) == len(b.events)
    for ea, eb in zip(a.events, b.events):
        assert np.array_equal(ea.T_world_flange, eb.T_world_flange)
    assert a.duration_s == b.duration_s
    with pytest.raises(ValueError):
        a.q_end_rad[0] = 1.0  # frozen results


# ---------------------------------------------------------------------------------- durations
def test_duration_is_path_length_over_speed():
    q0, tip = ready("gp12")
    model = builtin_tools()["torch"]
    cfg = BeamScanConfig(scan_speed_mm_s=40.0, move_speed_mm_s=300.0)
    scan = run_beam_scan(kinematics("gp12"), q0, default_beam_sensor(tip), model.T_flange_tool_true,
                         tool_shape(model), config=cfg)
    T_ft = model.T_flange_tool_true
    total_t = total_l = 0.0
    for mv in scan.moves:
        f0, f1 = mv.T_world_flange_start, mv.T_world_flange_end
        flange = float(np.linalg.norm(f1[:3, 3] - f0[:3, 3]))
        if mv.kind == "move":
            tcp = float(np.linalg.norm((f1 @ T_ft)[:3, 3] - (f0 @ T_ft)[:3, 3]))
            length, speed = max(flange, tcp), 300.0
        else:
            length, speed = flange, 40.0
        assert mv.length_m == pytest.approx(length, abs=1e-12)
        total_l += length
        total_t += length * 1000.0 / speed
    assert scan.path_length_m == pytest.approx(total_l, rel=1e-12)
    assert scan.duration_s == pytest.approx(total_t, rel=1e-12)
    # a pass is radius + width/2 + margin to each side of the beam
    W = 0.012 + 0.00025 + 0.015
    assert [mv.length_m for mv in scan.moves if mv.kind == "pass"] == pytest.approx([2 * W] * 8)
    # seconds, not minutes: the industrial point of the device
    assert 5.0 < scan.duration_s < 60.0


# ---------------------------------------------------------------------------------- skips
def limited(robot: str, limits_deg: dict[int, tuple[float, float]]) -> RobotKinematics:
    """The robot with some joints' limits narrowed (joint index -> (low, high) deg)."""
    kin = RobotKinematics.from_urdf(kinematics(robot).urdf_path)
    kin.lower_rad = kin.lower_rad.copy()
    kin.upper_rad = kin.upper_rad.copy()
    for j, (lo, hi) in limits_deg.items():
        kin.lower_rad[j], kin.upper_rad[j] = math.radians(lo), math.radians(hi)
    return kin


def test_an_unreachable_orientation_is_skipped_with_words():
    q0, tip = ready("kr6")
    model = builtin_tools()["pointer"]
    full = run_beam_scan(kinematics("kr6"), q0, default_beam_sensor(tip), model.T_flange_tool_true,
                         tool_shape(model))
    q_tip = np.degrees([mv.q_end_rad for mv in full.moves if mv.kind == "approach"])
    # the hand turns by about 90 deg per orientation: a narrow A6 (and A4, so the wrist cannot
    # flip instead) leaves only the first two orientations in reach
    lo6, hi6 = sorted(q_tip[:2, 5])
    a4 = q_tip[:2, 3]
    kin = limited("kr6", {3: (a4.min() - 25.0, a4.max() + 25.0), 5: (lo6 - 25.0, hi6 + 25.0)})
    assert not any(lo6 - 25.0 <= v <= hi6 + 25.0 for v in q_tip[2:, 5])
    scan = run_beam_scan(kin, q0, default_beam_sensor(tip), model.T_flange_tool_true, tool_shape(model))
    assert len(scan.skipped) == 2
    assert all("skipped" in s and "out of reach" in s and "tried tilts of" in s for s in scan.skipped)
    assert scan.skipped[0].startswith("Orientation 3 (turned 180 deg about the tool axis) was skipped: ")
    assert scan.skipped[1].startswith("Orientation 4 (turned 270 deg about the tool axis) was skipped: ")
    qps = translator(PSEUDO_LANGUAGE)                    # said again in the reader's language
    for why in scan.skipped:
        said = in_language(why, qps)
        assert said.startswith("⟦") and english_words(said, {"TCP", "mm", "deg"}) == [], said
    assert set(scan.orientation_index) == {0, 1} and scan.n_orientations_done == 2
    # the skipped orientations left no moves or events behind; the motion stays continuous
    assert {mv.orientation for mv in scan.moves} == {0, 1}
    for prev, nxt in zip(scan.moves, scan.moves[1:]):
        assert np.array_equal(prev.q_end_rad, nxt.q_start_rad)
    # two orientations turned by 90 deg still determine everything
    tcp, d = solve(scan)
    assert np.linalg.norm(tcp - model.T_flange_tool_true[:3, 3] * 1000.0) < 1e-6
    assert angle_between_deg(d, model.T_flange_tool_true[:3, 0]) < 1e-6


def test_nothing_reachable_is_a_controller_error():
    q0, tip = ready("kr6")
    model = builtin_tools()["pointer"]
    far = BeamSensor(np.array([3.0, 0.0, 0.4]), np.array([1.0, 0.0, 0.0]))
    with pytest.raises(ControllerError, match="could not run at any tool orientation.*out of reach"):
        run_beam_scan(kinematics("kr6"), q0, far, model.T_flange_tool_true, tool_shape(model))


def test_tool_data_far_off_along_the_axis_says_so():
    q0, tip = ready("kr6")
    model = builtin_tools()["pointer"]
    plan = np.array(model.T_flange_tool_true)
    plan[:3, 3] += plan[:3, 0] * 0.03  # believed tip 30 mm beyond the real one
    with pytest.raises(ControllerError, match="did not break the beam"):
        run_beam_scan(kinematics("kr6"), q0, default_beam_sensor(tip), plan, tool_shape(model))


def test_config_and_tool_checks():
    with pytest.raises(ControllerError, match="n_orientations must be 3, 4 or 5"):
        BeamScanConfig(n_orientations=2)
    with pytest.raises(ControllerError, match="pass_heights_mm"):
        BeamScanConfig(pass_heights_mm=(10.0, 10.5))
    with pytest.raises(ControllerError, match="scan_speed_mm_s"):
        BeamScanConfig(scan_speed_mm_s=float("nan"))
    with pytest.raises(ControllerError, match="gripper has no tip"):
        tool_shape(builtin_tools()["gripper"])
    q0, tip = ready("kr6")
    vertical = BeamSensor(tip, np.array([0.0, 0.0, 1.0]))
    model = builtin_tools()["pointer"]
    with pytest.raises(ControllerError, match="roughly horizontal"):
        run_beam_scan(kinematics("kr6"), q0, vertical, model.T_flange_tool_true, tool_shape(model))
    with pytest.raises(ControllerError, match="true_kinematics must be the same robot"):
        run_beam_scan(kinematics("kr6"), q0, default_beam_sensor(tip), model.T_flange_tool_true,
                      tool_shape(model), true_kinematics=kinematics("gp12"))
    with pytest.raises(ControllerError, match="no proper rotation"):
        run_beam_scan(kinematics("kr6"), q0, default_beam_sensor(tip), np.diag([1.0, 1.0, -1.0, 1.0]),
                      tool_shape(model))


@pytest.mark.parametrize("n", [3, 5])
def test_three_and_five_orientations(n):
    q0, tip = ready("gp12")
    model = builtin_tools()["pointer"]
    scan = run_beam_scan(kinematics("gp12"), q0, default_beam_sensor(tip), model.T_flange_tool_true,
                         tool_shape(model), config=BeamScanConfig(n_orientations=n))
    assert len(scan.tip_indices) == n and scan.skipped == ()
    tcp, d = solve(scan)
    assert np.linalg.norm(tcp - model.T_flange_tool_true[:3, 3] * 1000.0) < 1e-6


# ---------------------------------------------------------------------------------- accuracy
@pytest.mark.parametrize("robot", ROBOTS)
def test_absolute_accuracy_records_model_poses_and_hits_the_physical_beam(robot):
    q0, tip = ready(robot)
    kin = kinematics(robot)
    true_kin = perturbed_kinematics(kin, draw_kinematic_errors(Scenario("robot_accuracy", seed=3), kin))
    model = builtin_tools()["torch"]
    T_true = model.T_flange_tool_true
    scan = run_beam_scan(kin, q0, default_beam_sensor(tip), T_true, tool_shape(model),
                         true_kinematics=true_kin)
    assert scan.skipped == ()
    for mv in scan.moves:
        for i in mv.event_indices:
            ev = scan.events[i]
            if ev.kind == "tip":  # recorded: the MODEL pose where the robot stopped
                assert np.allclose(ev.T_world_flange, kin.T_world_flange(mv.q_end_rad), atol=1e-9)
                # the PHYSICAL tip at those joint values is on the beam: off its centre by the
                # aiming error (the model's line is not quite the physical one): hundredths of a
                # mm, well inside the beam; the linearisation adds less than a micrometre
                assert ev.miss_distance < 1e-4
                T_phys = true_kin.T_world_flange(mv.q_end_rad)
                p = T_phys[:3, :3] @ T_true[:3, 3] + T_phys[:3, 3] - ev.beam_point
                assert np.linalg.norm(p - (p @ ev.beam_dir) * ev.beam_dir) == pytest.approx(
                    ev.miss_distance, abs=1e-6)
                assert np.allclose(scan.tip_world_m(i), T_phys[:3, :3] @ T_true[:3, 3] + T_phys[:3, 3], atol=1e-6)
            else:  # the PHYSICAL tool axis at the event's joint values meets the beam line
                q_ev = solve_ik(kin, ev.T_world_flange_exact, mv.q_start_rad).q_rad
                T_phys = true_kin.T_world_flange(q_ev)
                tip_w = T_phys[:3, :3] @ T_true[:3, 3] + T_phys[:3, 3]
                d_w = T_phys[:3, :3] @ T_true[:3, 0]
                n = np.cross(d_w, ev.beam_dir)
                assert abs((tip_w - ev.beam_point) @ n) / np.linalg.norm(n) < 1e-6
    tcp, _ = solve(scan)
    err = np.linalg.norm(tcp - T_true[:3, 3] * 1000.0)
    # the model's poses are not the physical ones: tenths of a mm off, no more
    assert 0.005 < err < 1.0, err


# ---------------------------------------------------------------------------------- controller
def test_controller_beam_sensor_follows_the_reference_tip_until_set():
    kin = kinematics("kr6")
    ctrl = VirtualController(kin, tool=builtin_tools()["pointer"])
    s0 = ctrl.beam_sensor
    assert ctrl.beam_sensor_is_default
    assert np.allclose(s0.point, ctrl.reference_tip_world_m + [0.0, -0.22, 0.0])
    assert np.allclose(s0.direction, [1.0, 0.0, 0.0])
    assert ctrl.beam_sensor is s0  # the same object while nothing moved (views compare identity)
    ctrl.set_reference_tip(ctrl.reference_tip_world_m + [0.05, 0.02, -0.03])
    assert ctrl.beam_sensor is not s0
    assert np.allclose(ctrl.beam_sensor.point, ctrl.reference_tip_world_m + [0.0, -0.22, 0.0])
    mine = BeamSensor(np.array([0.5, 0.3, 0.4]), np.array([0.0, 1.0, 0.0]), sigma=0.0)
    ctrl.set_beam_sensor(mine)
    assert ctrl.beam_sensor is mine and not ctrl.beam_sensor_is_default
    ctrl.set_reference_tip(ctrl.reference_tip_world_m + [0.01, 0.0, 0.0])
    assert ctrl.beam_sensor is mine  # set explicitly: stays where it was put
    ctrl.set_beam_sensor(None)
    assert np.allclose(ctrl.beam_sensor.point, ctrl.reference_tip_world_m + [0.0, -0.22, 0.0])
    with pytest.raises(ControllerError, match="expects a BeamSensor"):
        ctrl.set_beam_sensor("0,0,0")  # type: ignore[arg-type]


@pytest.mark.parametrize("robot", ROBOTS)
def test_default_sensor_is_clear_of_the_reference_tip_stand(robot):
    q0, tip = ready(robot)
    sensor = default_beam_sensor(tip)
    model = builtin_tools()["torch"]
    scan = run_beam_scan(kinematics(robot), q0, sensor, model.T_flange_tool_true, tool_shape(model))
    assert scan.skipped == ()
    # the tool tip stays far from the spike and its stand (a post below the spike) everywhere
    for mv in scan.moves:  # (the first starts where the robot was: over the spike)
        for T in (mv.T_world_flange_end,):
            p = (T @ model.T_flange_tool_true)[:3, 3]
            assert math.hypot(p[0] - tip[0], p[1] - tip[1]) > 0.15


def test_tip_sigma_makes_the_95_percent_radius_hold():
    """The tip events carry the sensor's noise and the aiming error of the approach
    (BeamScan.tip_sigma_m, 1.35 sigma for the default heights): with it, tcpcal's 95 % radius
    holds the true TCP in about 95 % of the scans; with the bare sensor sigma it is too small."""
    q0, tip = ready("kr6")
    model = builtin_tools()["torch"]
    T_true = model.T_flange_tool_true
    n, inside, inside_bare = 150, 0, 0
    for seed in range(n):
        scan = run_beam_scan(kinematics("kr6"), q0, default_beam_sensor(tip), T_true, tool_shape(model),
                             rng=np.random.default_rng(1000 + seed))
        assert scan.tip_sigma_m == pytest.approx(2e-5 * math.sqrt(1.0 + (1.25**2 + 0.25**2) / 2.0))
        rot, pos, b, u = scan_arrays_mm(scan.events)
        ti = list(scan.tip_indices)
        err = np.linalg.norm(solve_beam(rot[ti], pos[ti], b[ti], u[ti]).tcp - T_true[:3, 3] * 1000.0)
        inside += err <= solve_beam(rot[ti], pos[ti], b[ti], u[ti], sigma=scan.tip_sigma_m * 1000.0).ci95_radius
        inside_bare += err <= solve_beam(rot[ti], pos[ti], b[ti], u[ti], sigma=0.02).ci95_radius
    assert 0.90 <= inside / n <= 0.99, inside / n
    assert inside_bare / n < 0.85, inside_bare / n


@pytest.mark.parametrize("robot", ROBOTS)
def test_crossed_beams_give_axis_events_of_both_and_the_exact_tcp(robot):
    q0, tip = ready(robot)
    model = builtin_tools()["torch"]
    T_true = model.T_flange_tool_true
    single = default_beam_sensor(tip)
    crossed = BeamSensor(single.point, single.direction, second_direction=np.array([0.0, 1.0, 0.0]))
    scan = run_beam_scan(kinematics(robot), q0, crossed, believed_off(T_true), tool_shape(model))
    assert scan.skipped == ()
    beams = [scan.events[i].beam for i in scan.axis_indices]
    assert beams.count(0) == 8 and beams.count(1) == 8  # each pass crosses both beams
    # the passes run at 45 deg to both beams: W / sin 45
    W = (0.012 + 0.00025 + 0.015) / math.sqrt(0.5)
    assert [mv.length_m for mv in scan.moves if mv.kind == "pass"] == pytest.approx([2 * W] * 8)
    tcp, d = solve(scan)
    assert np.linalg.norm(tcp - T_true[:3, 3] * 1000.0) < 1e-6
    assert angle_between_deg(d, T_true[:3, 0]) < 1e-6
    # the tip meets the crossing point and breaks both beams: a tip event on each
    tip_beams = [scan.events[i].beam for i in scan.tip_indices]
    assert all(sorted(tip_beams[j:j + 2]) == [0, 1] for j in range(0, 8, 2))
    for i in scan.tip_indices:
        assert np.linalg.norm(scan.tip_world_m(i) - crossed.point) < 1e-9
        assert scan.events[i].miss_distance < 1e-9
    approach = [mv for mv in scan.moves if mv.kind == "approach"]
    assert [len(mv.event_indices) for mv in approach] == [2] * 4
    # so one orientation already fixes the TCP (two beams seen along different flange directions)
    rot, pos, b, u = scan_arrays_mm(scan.events)
    first = list(scan.tip_indices[:2])
    one = solve_beam(rot[first], pos[first], b[first], u[first]).tcp
    assert np.linalg.norm(np.asarray(one) - T_true[:3, 3] * 1000.0) < 1e-6


def test_an_orientation_out_of_reach_is_tried_turned_a_third_of_the_way():
    """Turns only need to differ: orientation 3 (180 deg) out of reach at every tilt is run at
    210 deg instead; orientation 4 is out of reach at all its tries and skipped with words."""
    q0, tip = ready("kr6")
    model = builtin_tools()["pointer"]
    full = run_beam_scan(kinematics("kr6"), q0, default_beam_sensor(tip), model.T_flange_tool_true,
                         tool_shape(model))
    a4 = np.degrees([mv.q_end_rad[3] for mv in full.moves if mv.kind == "approach"][:2])
    kin = limited("kr6", {3: (a4.min() - 25.0, a4.max() + 25.0), 5: (-45.0, 145.0)})
    scan = run_beam_scan(kin, q0, default_beam_sensor(tip), model.T_flange_tool_true, tool_shape(model))
    assert scan.orientation_index == (0, 0, 0, 1, 1, 1, 2, 2, 2)
    assert len(scan.skipped) == 1 and scan.skipped[0].startswith("Orientation 4 (turned 270 deg")
    assert "turns of 240 and 300 deg" in scan.skipped[0]

    def turn_deg(i: int) -> float:  # the flange's turn about WORLD Z (the tool points down)
        R = scan.events[i].T_world_flange[:3, :3]
        return math.degrees(math.atan2(R[1, 0], R[0, 0]))

    first, _, third = scan.tip_indices
    assert (turn_deg(third) - turn_deg(first)) % 360.0 == pytest.approx(210.0, abs=1e-6)
    tcp, d = solve(scan)
    assert np.linalg.norm(tcp - model.T_flange_tool_true[:3, 3] * 1000.0) < 1e-6
    assert angle_between_deg(d, model.T_flange_tool_true[:3, 0]) < 1e-6


def test_an_inclined_beam_scans_exactly():
    """A beam 25 deg off horizontal (a device on a sloping fixture): the tool still points
    straight down (its frame stays orthonormal), the passes run horizontally across the beam."""
    q0, tip = ready("kr6")
    model = builtin_tools()["torch"]
    T_true = model.T_flange_tool_true
    u = np.array([math.cos(math.radians(25.0)), 0.0, math.sin(math.radians(25.0))])
    sensor = BeamSensor(default_beam_sensor(tip).point, u)
    scan = run_beam_scan(kinematics("kr6"), q0, sensor, believed_off(T_true), tool_shape(model))
    assert scan.skipped == ()
    for mv in scan.moves:
        R = mv.T_world_flange_end[:3, :3]
        assert np.allclose(R.T @ R, np.eye(3), atol=1e-9)
    tcp, d = solve(scan)
    assert np.linalg.norm(tcp - T_true[:3, 3] * 1000.0) < 1e-6
    assert angle_between_deg(d, T_true[:3, 0]) < 1e-6
