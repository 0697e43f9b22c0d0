"""The virtual beam sensor (tcp_pendant.controller.beam): its events against the geometry and
against tcpcal's beam solve (methods.md section 9). Metres inside, mm for tcpcal."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcpcal import solve_beam, solve_beam_axis
from tcp_pendant.controller.beam import BeamSensor, ToolShape, crossing_events, tip_on_beam
from tcp_pendant.controller.errors import ControllerError

B = np.array([0.9, 0.1, 0.3])  # beam point, WORLD m
U = np.array([0.0, 1.0, 0.0])  # beam along WORLD Y
X = np.array([1.0, 0.0, 0.0])
Z = np.array([0.0, 0.0, 1.0])
D_TOOL = np.array([0.1, -0.05, 1.0]) / np.linalg.norm([0.1, -0.05, 1.0])  # tool X in FLANGE
TIP = np.array([0.012, -0.008, 0.18])


def make_tool(radius: float = 0.6e-3, length: float = 0.1) -> ToolShape:
    R = Rotation.align_vectors([D_TOOL], [X])[0].as_matrix()  # tool X -> D_TOOL
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = TIP
    return ToolShape(T, radius=radius, length=length)


def scan_rotations(spins=(0.0, 90.0, 180.0, 270.0), tilts=(0.0, 25.0, -25.0)) -> list[np.ndarray]:
    """Flange Z down, turned about it, tilted about WORLD X (across the beam)."""
    down = Rotation.from_euler("y", 180.0, degrees=True)
    return [(Rotation.from_euler("x", tilt, degrees=True) * down
             * Rotation.from_euler("z", spin, degrees=True)).as_matrix()
            for spin in spins for tilt in tilts]


def pose(R: np.ndarray, f: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = f
    return T


def line_distance(p: np.ndarray, b: np.ndarray = B, u: np.ndarray = U) -> float:
    q = p - b
    return float(np.linalg.norm(q - (q @ u) * u))


def tip_scan(sensor: BeamSensor, tool: ToolShape, rng: np.random.Generator | None = None):
    """Vertical approaches from 30 mm above a point of the beam, aimed with the true tip."""
    events = []
    for i, R in enumerate(scan_rotations()):
        target = B + (i - 5) * 0.002 * U
        start = pose(R, target + 0.03 * Z - R @ tool.tip)
        ev = tip_on_beam(start, -Z, sensor, tool, max_travel=0.1, rng=rng)
        assert ev is not None
        events.append(ev)
    return events


def as_mm(events) -> tuple[np.ndarray, np.ndarray]:
    rot = np.array([ev.T_world_flange[:3, :3] for ev in events])
    pos = np.array([ev.T_world_flange[:3, 3] for ev in events]) * 1000.0
    return rot, pos


# ---------------------------------------------------------------------------------- tips
def test_tip_events_land_the_tip_on_the_beam_line():
    tool = make_tool()
    sensor = BeamSensor(B, U)
    events = tip_scan(sensor, tool)
    for ev in events:
        tip = ev.T_world_flange_exact[:3, :3] @ tool.tip + ev.T_world_flange_exact[:3, 3]
        assert line_distance(tip) < 1e-9
        assert ev.kind == "tip" and ev.beam == 0 and ev.miss_distance < 1e-9
        # the tip entered the beam half a width before the centre line (vertical approach)
        assert ev.travel == pytest.approx(0.03, abs=1e-9)
        assert ev.travel - ev.entry_travel == pytest.approx(sensor.width / 2, abs=1e-12)
        np.testing.assert_array_equal(ev.T_world_flange, ev.T_world_flange_exact)  # rng None


def test_solving_exact_tip_events_gives_the_true_tcp():
    tool = make_tool()
    rot, pos = as_mm(tip_scan(BeamSensor(B, U), tool))
    res = solve_beam(rot, pos, B * 1000.0, U)
    np.testing.assert_allclose(res.tcp, TIP * 1000.0, atol=1e-6)  # mm: 1e-9 m
    assert res.max_error < 1e-6


def test_noisy_tip_events_err_at_the_predicted_95_radius():
    """sigma = 0.02 mm: over seeded scans the TCP error is inside the predicted 95 % radius
    about 95 % of the time and its RMS equals the Cramer-Rao figure."""
    tool = make_tool()
    sensor = BeamSensor(B, U, sigma=2e-5)
    rng = np.random.default_rng(2024)
    errs, inside, trials = [], 0, 300
    for _ in range(trials):
        rot, pos = as_mm(tip_scan(sensor, tool, rng))
        res = solve_beam(rot, pos, B * 1000.0, U, sigma=0.02)
        err = float(np.linalg.norm(res.tcp - TIP * 1000.0))
        errs.append(err)
        inside += err <= res.ci95_radius
    rms_predicted = math.sqrt(float(np.trace(res.covariance)))
    assert math.sqrt(np.mean(np.square(errs))) == pytest.approx(rms_predicted, rel=0.12)
    assert 0.91 <= inside / trials <= 0.99
    assert 0.01 < res.ci95_radius < 0.1  # mm: a few hundredths, as the real devices


def test_a_path_that_misses_the_beam_gives_no_event_and_a_near_miss_says_so():
    tool = make_tool()
    sensor = BeamSensor(B, U, width=0.5e-3)
    R = scan_rotations()[0]
    far = pose(R, B + 0.03 * Z + 0.001 * X - R @ tool.tip)  # 1 mm beside the line
    assert tip_on_beam(far, -Z, sensor, tool) is None
    near = pose(R, B + 0.03 * Z + 0.0001 * X - R @ tool.tip)  # 0.1 mm beside it: breaks
    ev = tip_on_beam(near, -Z, sensor, tool)
    assert ev is not None and ev.miss_distance == pytest.approx(1e-4, abs=1e-12)
    assert tip_on_beam(near, Z, sensor, tool) is None  # moving away
    assert tip_on_beam(near, -Z, sensor, tool, max_travel=0.02) is None  # too short


def test_the_tip_in_the_beam_at_the_start_is_refused():
    tool = make_tool()
    R = scan_rotations()[0]
    with pytest.raises(ControllerError, match="already in beam 0"):
        tip_on_beam(pose(R, B - R @ tool.tip), -Z, BeamSensor(B, U), tool)


def test_crossed_beams_report_the_beam_broken_first():
    tool = make_tool()
    sensor = BeamSensor(B, U, second_direction=X)
    R = scan_rotations()[0]
    on_second = B + 0.01 * X  # on beam 1, 10 mm from the crossing
    ev = tip_on_beam(pose(R, on_second + 0.03 * Z - R @ tool.tip), -Z, sensor, tool)
    assert ev.beam == 1 and np.allclose(ev.beam_dir, X)
    tip = R @ tool.tip + ev.T_world_flange_exact[:3, 3]
    assert line_distance(tip, B, X) < 1e-9
    ev0 = tip_on_beam(pose(R, B + 0.01 * U + 0.03 * Z - R @ tool.tip), -Z, sensor, tool)
    assert ev0.beam == 0


# ----------------------------------------------------------------------------- crossings
def axis_scan(sensor: BeamSensor, tool: ToolShape, heights=(0.02, 0.06),
              spins=(0.0, 90.0, 200.0), rng: np.random.Generator | None = None):
    """Sideways passes along WORLD X through the beam, the shaft at `heights` behind the tip."""
    events = []
    for i, R in enumerate(scan_rotations(spins=spins, tilts=(0.0,))):
        for h in heights:
            p = tool.tip - h * tool.axis  # the axis point that should cross the beam
            start = pose(R, B + (i * 0.003) * U - 0.03 * X - R @ p)
            found = crossing_events(start, X, sensor, tool, max_travel=0.06, rng=rng)
            assert len(found) == 1
            events.append(found[0])
    return events


def axis_distance_to_beam(ev, tool: ToolShape) -> float:
    R, f = ev.T_world_flange_exact[:3, :3], ev.T_world_flange_exact[:3, 3]
    a, d = R @ tool.tip + f, R @ tool.axis
    n = np.cross(d, U)
    return abs(float((a - B) @ n)) / float(np.linalg.norm(n))


def test_crossing_midpoint_puts_the_tool_axis_on_the_beam_whatever_radius_and_width():
    ref = None
    for radius, width in ((0.6e-3, 0.5e-3), (3e-3, 2e-3)):
        tool = make_tool(radius=radius)
        events = axis_scan(BeamSensor(B, U, width=width), tool)
        for ev in events:
            assert ev.kind == "axis" and ev.on_shaft
            assert axis_distance_to_beam(ev, tool) < 1e-9
            assert ev.exit_travel - ev.entry_travel > 2 * radius  # the shaft's width at least
        travels = np.array([ev.travel for ev in events])
        if ref is None:
            ref = travels
        else:
            np.testing.assert_allclose(travels, ref, atol=1e-10)
            assert travels.size == 6


def test_axis_events_give_the_tool_direction():
    tool = make_tool()
    events = axis_scan(BeamSensor(B, U), tool)
    rot, pos = as_mm(events)
    res = solve_beam_axis(rot, pos, B * 1000.0, U, TIP * 1000.0)
    np.testing.assert_allclose(res.direction, tool.axis, atol=1e-9)
    np.testing.assert_allclose(np.sort(-res.axis_distances), [20, 20, 20, 60, 60, 60], atol=1e-6)


def test_noisy_axis_events_give_the_direction_within_its_cone():
    tool = make_tool()
    sensor = BeamSensor(B, U, sigma=2e-5)
    rng = np.random.default_rng(99)
    inside, trials = 0, 60
    for _ in range(trials):
        rot, pos = as_mm(axis_scan(sensor, tool, spins=(0.0, 90.0, 180.0, 270.0), rng=rng))
        res = solve_beam_axis(rot, pos, B * 1000.0, U, TIP * 1000.0, sigma=0.02 / math.sqrt(2))
        ang = math.degrees(math.acos(min(1.0, float(res.direction @ tool.axis))))
        inside += ang <= res.ci95_angle_deg
    assert inside / trials >= 0.85
    assert res.ci95_angle_deg < 0.2


def test_a_crossing_at_the_rounded_tip_is_not_on_the_shaft():
    tool = make_tool(radius=2e-3)
    R = scan_rotations()[0]
    start = pose(R, B - 0.03 * X - R @ (tool.tip + 0.001 * tool.axis))  # beam 1 mm past the tip
    (ev,) = crossing_events(start, X, BeamSensor(B, U), tool, max_travel=0.06)
    assert not ev.on_shaft


def test_crossing_a_pass_that_does_not_leave_the_beam_is_refused():
    tool = make_tool()
    R = scan_rotations()[0]
    p = tool.tip - 0.03 * tool.axis
    with pytest.raises(ControllerError, match="still in beam 0"):
        crossing_events(pose(R, B - 0.01 * X - R @ p), X, BeamSensor(B, U), tool, max_travel=0.0102)
    with pytest.raises(ControllerError, match="already in beam 0"):
        crossing_events(pose(R, B - R @ p), X, BeamSensor(B, U), tool)
    assert crossing_events(pose(R, B + 0.01 * Z - R @ tool.tip), X, BeamSensor(B, U), tool) == ()


# ----------------------------------------------------------------------------- validation
@pytest.mark.parametrize("kwargs, match", [
    ({"direction": (0.0, 0.0, 0.0)}, "zero vector"),
    ({"direction": (1.0, np.nan, 0.0)}, "finite"),
    ({"width": -1e-3}, "width"),
    ({"sigma": math.inf}, "sigma"),
    ({"second_direction": (0.0, 2.0, 0.0)}, "parallel"),
])
def test_bad_sensor_settings_are_refused(kwargs, match):
    args = {"point": B, "direction": U, **kwargs}
    with pytest.raises(ControllerError, match=match):
        BeamSensor(**args)


def test_sensor_normalises_and_freezes_its_direction():
    s = BeamSensor(B, 3.0 * U)
    np.testing.assert_allclose(s.direction, U)
    with pytest.raises(ValueError):
        s.direction[0] = 1.0
    assert s.width == 0.5e-3 and s.sigma == 2e-5
