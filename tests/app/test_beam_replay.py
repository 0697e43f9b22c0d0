"""In the scene: the film of a beam scan (``views.beam_replay.replay_frames``)
and the event markers' points. The scan here is built from the sensor's own geometry
(``controller.beam``: ``tip_on_beam``, ``crossing_events``) on straight flange moves whose
"joints" are the flange position itself, so a frame's joints say exactly where the flange is."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from tcp_pendant.controller.beam import BeamSensor, ToolShape, crossing_events, tip_on_beam
from tcp_pendant.views.beam_replay import replay_frames

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

SENSOR = BeamSensor(point=(0.6, 0.0, 0.3), direction=(0.0, 1.0, 0.0))
SHAPE = ToolShape(np.array([[0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.15],
                            [0.0, 0.0, 0.0, 1.0]]))                  # tool X = flange +Z, tip 150 mm out


def _flange_down(p: np.ndarray) -> np.ndarray:
    """Flange pose at ``p`` with its Z pointing down (the tool hangs below it)."""
    T = np.eye(4)
    T[:3, :3] = np.diag([1.0, -1.0, -1.0])
    T[:3, 3] = p
    return T


def _move(kind: str, p0, p1, speed: float, events: tuple[int, ...] = ()) -> SimpleNamespace:
    p0, p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
    return SimpleNamespace(kind=kind, q_start_rad=p0.copy(), q_end_rad=p1.copy(),
                           T_world_flange_start=_flange_down(p0), T_world_flange_end=_flange_down(p1),
                           length_m=float(np.linalg.norm(p1 - p0)), speed_mm_s=speed, event_indices=events)


def _scan() -> SimpleNamespace:
    """A move from far away, a vertical approach until the tip breaks the beam, a retract, and
    a sideways pass across the beam with the shaft: one tip event, one axis event."""
    b = np.asarray(SENSOR.point)
    tip_local = _flange_down(np.zeros(3))[:3, :3] @ SHAPE.tip           # tip below the flange
    above = b - tip_local + [0.0, 0.0, 0.05]                            # tip 50 mm above the beam
    tip_ev = tip_on_beam(_flange_down(above), (0.0, 0.0, -1.0), SENSOR, SHAPE)
    stop = tip_ev.T_world_flange_exact[:3, 3]
    side0 = b - tip_local + [-0.05, 0.0, -0.02]                         # shaft 20 mm above the tip
    (ax_ev,) = crossing_events(_flange_down(side0), (1.0, 0.0, 0.0), SENSOR, SHAPE, max_travel=0.1)
    far = above + [0.3, 0.2, 0.2]
    moves = (_move("move", far, above, 250.0), _move("approach", above, stop, 50.0, (0,)),
             _move("move", stop, above, 250.0), _move("move", above, side0, 250.0),
             _move("pass", side0, side0 + [0.1, 0.0, 0.0], 50.0, (1,)))
    events = (tip_ev, ax_ev)
    tips = [ev.T_world_flange_exact[:3, :3] @ SHAPE.tip + ev.T_world_flange_exact[:3, 3] for ev in events]
    return SimpleNamespace(moves=moves, events=events, q_end_rad=moves[-1].q_end_rad,
                           tip_world_m=lambda i: tips[i])


def test_the_film_goes_from_the_first_move_to_the_scan_end_and_holds_each_event() -> None:
    scan = _scan()
    frames = replay_frames(scan, max_frames=60, hold_frames=3)
    assert len(frames) <= 60
    np.testing.assert_allclose(frames[0].q_rad, scan.moves[0].q_start_rad)
    np.testing.assert_allclose(frames[-1].q_rad, scan.q_end_rad)
    assert frames[0].broken_event is None and frames[-1].broken_event is None
    assert frames[-1].shown == (0, 1)
    for i, ev in enumerate(scan.events):
        at = [f for f in frames if f.broken_event == i and np.allclose(f.q_rad, ev.T_world_flange_exact[:3, 3])]
        assert len(at) >= 3, f"event {i} is not held where the controller recorded it"
        first = next(k for k, f in enumerate(frames) if i in f.shown)
        assert all(i in f.shown for f in frames[first:])                # a marker stays once shown
        assert all(i not in f.shown for f in frames[:first])


def test_the_beam_is_red_only_while_the_tool_is_in_it() -> None:
    scan = _scan()
    frames = replay_frames(scan, max_frames=400, hold_frames=2)
    b, u = np.asarray(SENSOR.point), np.asarray(SENSOR.direction)
    reach = SHAPE.radius + SENSOR.width / 2.0
    seen_axis_broken = False
    for f in frames:
        T = _flange_down(f.q_rad)
        tip = T[:3, :3] @ SHAPE.tip + T[:3, 3]
        back = T[:3, :3] @ (SHAPE.tip - SHAPE.length * SHAPE.axis) + T[:3, 3]
        # distance from the shaft segment to the beam line
        lam = np.linspace(0.0, 1.0, 2001)[:, None]
        seg = back + lam * (tip - back)
        d = seg - b
        dist = float(np.min(np.linalg.norm(d - np.outer(d @ u, u), axis=1)))
        if f.broken_event == 1:                                         # the sideways pass
            seen_axis_broken = True
            assert dist <= reach + 1e-4
        elif f.broken_event is None and frames.index(f) > 0:
            in_pass = np.allclose(f.q_rad[1:], scan.moves[4].q_start_rad[1:])
            if in_pass:
                assert dist > reach - 1e-4                              # clear frames of the pass are clear
    assert seen_axis_broken


def test_frames_follow_the_real_robot_time_and_fit_the_budget() -> None:
    scan = _scan()
    frames = replay_frames(scan, max_frames=80, hold_frames=3)
    assert len(frames) <= 80

    def frames_in(m) -> int:
        lo, hi = np.minimum(m.q_start_rad, m.q_end_rad), np.maximum(m.q_start_rad, m.q_end_rad)
        d = m.q_end_rad - m.q_start_rad
        return sum(1 for f in frames if f.broken_event is None and np.all(f.q_rad >= lo - 1e-12)
                   and np.all(f.q_rad <= hi + 1e-12) and np.linalg.norm(np.cross(f.q_rad - m.q_start_rad, d)) < 1e-9
                   and not np.allclose(f.q_rad, m.q_start_rad))
    seconds = [m.length_m * 1000 / m.speed_mm_s for m in scan.moves]
    slow, fast = scan.moves[4], scan.moves[0]                           # the 50 mm/s pass, the 250 mm/s move
    assert seconds[4] > seconds[0]
    assert frames_in(slow) > frames_in(fast) >= 1


def test_a_return_ends_where_the_robot_was_and_a_scan_without_moves_is_its_end() -> None:
    scan = _scan()
    home = np.array([0.2, -0.4, 0.9])
    frames = replay_frames(scan, return_to=home)
    np.testing.assert_allclose(frames[-1].q_rad, home)
    assert frames[-1].shown == (0, 1)
    empty = SimpleNamespace(moves=(), events=(), q_end_rad=np.array([0.1, 0.2, 0.3]), tip_world_m=None)
    (only,) = replay_frames(empty)
    np.testing.assert_allclose(only.q_rad, [0.1, 0.2, 0.3])
    assert only.broken_event is None and only.shown == ()


def test_event_markers_lie_on_the_beam_where_the_tool_met_it() -> None:
    from tcp_pendant.views.beam_replay import event_points_world

    scan = _scan()
    pts = event_points_world(scan)
    b, u = np.asarray(SENSOR.point), np.asarray(SENSOR.direction)
    d = pts - b
    np.testing.assert_allclose(np.linalg.norm(d - np.outer(d @ u, u), axis=1), 0.0, atol=1e-12)
    # the tip event's marker is the tip (on the centre line when aimed)
    np.testing.assert_allclose(pts[0], scan.tip_world_m(0), atol=1e-9)
    assert pytest.approx(0.0, abs=1e-9) == float(np.linalg.norm(pts[0] - b - ((pts[0] - b) @ u) * u))
