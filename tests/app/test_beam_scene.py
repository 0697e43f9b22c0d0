"""In a session: the scene draws the controller's beam sensor (its default
place beside the reference tip), follows it when the reference tip is knocked or another sensor
is set, and the overview camera sees it. In-process server, headless websocket client."""

from __future__ import annotations


import numpy as np
import pytest

from support.app_page import AppPage

from tcp_pendant.controller.beam import BeamSensor
from tcp_pendant.views.scene import overview_pose

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def beam_on_screen(p: AppPage) -> np.ndarray:
    return np.asarray(p.session.views["scene"].beam_stand.beam_handle.points, dtype=float)


def test_the_scene_draws_the_controllers_beam_and_follows_it(page) -> None:
    p = page()
    s, c = p.session, p.session.controller
    stand = s.views["scene"].beam_stand
    (seg,) = beam_on_screen(p)
    np.testing.assert_allclose(seg.mean(axis=0), c.beam_sensor.point, atol=1e-6)
    d = (seg[1] - seg[0]) / np.linalg.norm(seg[1] - seg[0])
    assert abs(float(d @ c.beam_sensor.direction)) == pytest.approx(1.0, abs=1e-6)
    assert stand.label.text == "beam sensor"
    # the default sensor follows the reference tip (a knocked stand, a moved tip)
    tip = c.reference_tip_world_m + [0.01, -0.02, 0.0]
    with s.lock:
        c.set_reference_tip(tip)
        s.refresh()
    np.testing.assert_allclose(beam_on_screen(p)[0].mean(axis=0), c.beam_sensor.point, atol=1e-6)
    # a sensor set explicitly, crossed beams: two lines
    crossed = BeamSensor(point=(0.5, -0.3, 0.35), direction=(1.0, 1.0, 0.0), second_direction=(1.0, -1.0, 0.0))
    with s.lock:
        c.set_beam_sensor(crossed)
        s.refresh()
    segs = beam_on_screen(p)
    assert segs.shape == (2, 2, 3)
    np.testing.assert_allclose(segs.mean(axis=1), [crossed.point, crossed.point], atol=1e-6)


@pytest.mark.parametrize("robot", ["kr6", "gp12"])
def test_the_overview_sees_the_beam_sensor(page, robot) -> None:
    p = page(robot=robot)
    c = p.session.controller
    position, look_at = overview_pose(c.reference_tip_world_m)
    g = p.session.views["scene"].beam_stand.geometry
    # every end of the beam and of the stand's column is well inside the overview camera's view:
    # within 25 deg of its axis up/down and sideways (viser's field of view is 75 deg; the panel
    # covers the right of the canvas)
    forward = (look_at - position) / np.linalg.norm(look_at - position)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    for point in [*g.beams.reshape(-1, 3), *g.column]:
        v = point - position
        vertical = np.degrees(np.arctan2(v @ up, v @ forward))
        sideways = np.degrees(np.arctan2(v @ right, v @ forward))
        assert abs(vertical) < 25.0 and abs(sideways) < 25.0, (point, vertical, sideways)
