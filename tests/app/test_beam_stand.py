"""In the scene: the beam sensor's stand (``views.beam_stand``): the beam drawn on
the sensor's line between the heads, the fork open and clear around the beam (the tool plunges
into it), a column down to the floor, crossed beams with a second pair of posts, and the scene
nodes redrawn only when the sensor's geometry changed."""

from __future__ import annotations

import numpy as np
import pytest

from tcp_pendant.controller.beam import BeamSensor
from tcp_pendant.views.beam_stand import (
    BEAM_RGB,
    BROKEN_RGB,
    FORK_DEPTH_M,
    HALF_GAP_M,
    BeamStandNodes,
    sensor_key,
    stand_frame,
    stand_geometry,
)

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _box_contains(box, points: np.ndarray, margin: float = 0.0) -> np.ndarray:
    local = (points - box.centre) @ box.R_world_box          # rows: box coordinates
    half = np.asarray(box.dimensions) / 2.0 + margin
    return np.all(np.abs(local) <= half, axis=-1)


def _line_distance(p: np.ndarray, b: np.ndarray, u: np.ndarray) -> np.ndarray:
    d = p - b
    return np.linalg.norm(d - np.outer(d @ u, u), axis=1)


@pytest.mark.parametrize("direction", [(0.0, 1.0, 0.0), (1.0, 1.0, 0.0), (1.0, 0.0, 0.3)])
def test_the_beam_is_drawn_on_the_sensor_line_between_the_heads(direction) -> None:
    sensor = BeamSensor(point=(0.6, -0.3, 0.35), direction=direction)
    g = stand_geometry(sensor)
    b, u = np.asarray(sensor.point), np.asarray(sensor.direction)
    (seg,) = g.beams
    np.testing.assert_allclose(_line_distance(seg, b, u), 0.0, atol=1e-12)   # on the line
    np.testing.assert_allclose(seg.mean(axis=0), b, atol=1e-12)              # centred on b
    assert 0.08 < np.linalg.norm(seg[1] - seg[0]) < 2 * HALF_GAP_M
    heads = [box for box in g.boxes if box.name.endswith("head")]
    assert len(heads) == 2
    for end in seg:                                    # each end touches a head (emitter, receiver)
        assert any(_box_contains(h, end[None], margin=1e-9)[0] for h in heads)


def test_the_fork_is_open_around_the_beam_and_stands_on_the_floor() -> None:
    sensor = BeamSensor(point=(0.55, 0.2, 0.4), direction=(0.0, 1.0, 0.0))
    g = stand_geometry(sensor)
    b = np.asarray(sensor.point)
    R = stand_frame(sensor.direction)
    # the room the scan needs: along the beam inside the gap, across it, from 90 mm below to above
    rng = np.random.default_rng(3)
    local = rng.uniform([-0.8 * HALF_GAP_M, -0.1, -0.9 * FORK_DEPTH_M], [0.8 * HALF_GAP_M, 0.1, 0.15], (4000, 3))
    pts = b + local @ R.T
    for box in g.boxes:
        hit = _box_contains(box, pts)
        assert not hit.any(), f"{box.name} is in the fork's opening"
    # the posts reach below the beam by the fork depth, and something holds the fork up
    posts = [box for box in g.boxes if box.name.endswith("post")]
    assert len(posts) == 2
    lowest = min(box.centre[2] - box.dimensions[2] / 2.0 for box in posts)
    assert lowest == pytest.approx(b[2] - FORK_DEPTH_M, abs=1e-9)
    bottom, top = g.column
    assert bottom[2] == 0.0 and top[2] == pytest.approx(lowest - 0.016, abs=1e-9)
    np.testing.assert_allclose(bottom[:2], b[:2])
    assert g.label_position[2] < b[2]


def test_a_low_sensor_has_no_column_and_a_vertical_beam_gets_a_frame() -> None:
    g = stand_geometry(BeamSensor(point=(0.5, 0.0, 0.05), direction=(1.0, 0.0, 0.0)))
    assert g.column is None
    R = stand_frame(np.array([0.0, 0.0, 1.0]))
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0)
    np.testing.assert_allclose(R[:, 0], (0.0, 0.0, 1.0))


def test_crossed_beams_get_a_second_pair_of_posts() -> None:
    sensor = BeamSensor(point=(0.6, 0.0, 0.3), direction=(1.0, 1.0, 0.0), second_direction=(1.0, -1.0, 0.0))
    g = stand_geometry(sensor)
    assert g.beams.shape == (2, 2, 3)
    b = np.asarray(sensor.point)
    for seg, (_, u) in zip(g.beams, sensor.beams):
        np.testing.assert_allclose(_line_distance(seg, b, np.asarray(u)), 0.0, atol=1e-12)
    assert sum(box.name.endswith("post") for box in g.boxes) == 4
    # neither beam runs through a post or a head
    for seg in g.beams:
        line = seg[0] + np.linspace(0.0, 1.0, 200)[:, None] * (seg[1] - seg[0])
        for box in g.boxes:
            assert not _box_contains(box, line, margin=-1e-6).any(), box.name


class _Handle:
    def __init__(self, log: list, name: str) -> None:
        self.log, self.name = log, name

    def remove(self) -> None:
        self.log.append(("remove", self.name))


class _Scene:
    def __init__(self) -> None:
        self.log: list = []

    def __getattr__(self, what: str):
        def add(name, *a, **k):
            self.log.append((what, name))
            return _Handle(self.log, name)
        return add


def test_the_nodes_are_redrawn_only_when_the_sensor_changed() -> None:
    scene = _Scene()
    s1 = BeamSensor(point=(0.6, 0.0, 0.3), direction=(0.0, 1.0, 0.0))
    nodes = BeamStandNodes(scene, s1)
    added = [n for w, n in scene.log if w.startswith("add_")]
    assert "/beam_sensor/beam" in added and "/beam_sensor/label" in added and "/beam_sensor/column" in added
    n_log = len(scene.log)
    same = BeamSensor(point=(0.6, 0.0, 0.3), direction=(0.0, 2.0, 0.0))    # another object, equal geometry
    assert sensor_key(same) == sensor_key(s1)
    assert nodes.show(same) is False and len(scene.log) == n_log
    moved = BeamSensor(point=(0.6, 0.001, 0.3), direction=(0.0, 1.0, 0.0))
    assert nodes.show(moved) is True
    removed = {n for w, n in scene.log[n_log:] if w == "remove"}
    assert removed == set(added)                       # the old nodes went, new ones came
    assert nodes.show(None) is True and nodes.geometry is None


def test_a_broken_beam_is_drawn_red_and_only_that_one() -> None:
    sensor = BeamSensor(point=(0.6, 0.0, 0.3), direction=(1.0, 1.0, 0.0), second_direction=(1.0, -1.0, 0.0))
    nodes = BeamStandNodes(_Scene(), sensor)
    nodes.set_broken(1)                                    # the fake handle keeps what is assigned
    colors = np.asarray(nodes.beam_handle.colors)
    np.testing.assert_array_equal(colors[1], [BROKEN_RGB, BROKEN_RGB])
    np.testing.assert_array_equal(colors[0], [BEAM_RGB, BEAM_RGB])
    nodes.set_broken(None)
    assert (np.asarray(nodes.beam_handle.colors) == BEAM_RGB).all()
    nodes.set_broken(0)
    nodes.show(BeamSensor(point=(0.6, 0.1, 0.3), direction=(1.0, 0.0, 0.0)))   # a new sensor: drawn intact
    assert nodes.broken is None
