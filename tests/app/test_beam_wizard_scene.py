"""In the scene and the result panel: the "Automatic (beam)" wizard's result is
replayed on the robot (the film of its scan, the robot left at the scan's end, a marker per event
on the beam), the camera frames the sensor, "Replay scan" plays it again, another calibration
clears it, and the result text sets automatic against by hand with the errors of both against the
truth (training) or without them (an exercise). In-process server, headless websocket client."""

from __future__ import annotations


import numpy as np
import pytest

from support.app_page import AppPage
from support.wsclient import wait_until

from tcp_pendant.views.beam_replay import ScanPlayer


class Page(AppPage):
    def __init__(self, app) -> None:
        super().__init__(app)
        self.view = self.session.views["calibrate"]
        self.player = self.session.views["beam_player"]
        self.player.rate_hz = 400.0

    def xyz4_by_hand(self) -> None:
        v = self.view
        self.choose(v.method, "XYZ 4-point")
        self.click(v.start)
        for _ in range(4):
            self.click(v.steps.auto_touch)
        assert v.workflow.result is not None

    def beam(self) -> None:
        v = self.view
        self.choose(v.method, "Automatic (beam)")
        self.click(v.start)
        self.click(v.steps.next)                                 # Finish runs the scan in a worker
        wait_until(lambda: v.result.folder.visible and v.workflow.result is not None
                   and hasattr(v.workflow.result, "scan"), timeout=60, what="the beam result")

    def film_done(self) -> None:
        wait_until(lambda: not self.player.playing, timeout=60, what="the scan's film")


pytestmark = pytest.mark.app_page(cls=Page, seed=3)


def _in_view(framing, point: np.ndarray) -> bool:
    forward = framing.look_at - framing.position
    v = np.asarray(point, dtype=float) - framing.position
    angle = np.arccos(float(v @ forward) / (np.linalg.norm(v) * np.linalg.norm(forward)))
    return bool(angle < framing.fov_rad / 2.0)


def test_the_beam_result_is_replayed_framed_and_compared_with_the_manual_one(page) -> None:
    p = page()
    s, c, v = p.session, p.session.controller, p.view
    p.xyz4_by_hand()
    p.player.rate_hz = 5.0                                            # slow, to look at the film
    p.beam()
    res = v.workflow.result
    scan = res.scan
    assert p.player.scan is scan and p.player.owner is v.scene        # the wizard's film
    wait_until(lambda: p.player.frames_played >= 2, what="the film running")
    assert not v.scene.computed.visible and not v.scene.computed_label.visible   # the beam not hidden
    p.player.rate_hz = 400.0
    p.film_done()
    wait_until(lambda: v.scene.computed.visible, what="the triads back after the film")
    assert p.player.frames_played == len(p.player.frames) > len(scan.moves)
    np.testing.assert_allclose(c.q_rad, scan.q_end_rad, atol=1e-12)    # the robot stays at the scan's end
    markers = np.asarray(p.player.markers.points, dtype=float)
    assert len(markers) == len(scan.events)
    for m, ev, truth_point in zip(markers, scan.events, scan.beam_points_world_m):
        d = m - ev.beam_point
        assert np.linalg.norm(d - (d @ ev.beam_dir) * ev.beam_dir) < 1e-6   # on the beam line
        assert np.linalg.norm(m - truth_point) < 1e-3                      # where the tool met it
    rays = np.asarray(p.player.rays.points, dtype=float)               # flange -> beam, per event
    np.testing.assert_allclose(rays[:, 0], [ev.T_world_flange_exact[:3, 3] for ev in scan.events], atol=1e-5)
    np.testing.assert_allclose(rays[:, 1], markers, atol=1e-5)
    assert v.scene.computed.visible and v.scene.true_tool.visible     # the TOOL triads of the result
    assert _in_view(v.scene.last_framing, c.beam_sensor.point)         # the camera sees the sensor
    assert all(_in_view(v.scene.last_framing, m) for m in markers)
    # the result: events, real-robot time next to the manual time, the errors of both vs truth
    text = v.result.result_md.content
    assert f"**Events** ({len(scan.events)})" in text
    assert "on a real robot" in text and "(by Auto-touch)" in text and "(Auto-touch's clicks)" in text
    assert "| calibration | time | TCP error | direction error |" in text
    assert v.result.replay_scan.visible

    # Replay scan: the film again from the first move, ending at the scan's end
    with s.lock:
        c.set_q(scan.moves[0].q_start_rad)
        s.moved()
    p.click(v.result.replay_scan)
    assert p.player.scan is scan
    p.film_done()
    np.testing.assert_allclose(c.q_rad, scan.q_end_rad, atol=1e-12)

    # another calibration: the wizard's markers go
    p.click(v.steps.cancel)
    p.choose(v.method, "XYZ 4-point")
    p.click(v.start)
    assert p.player.scan is None and p.player.markers is None and p.player.rays is None


def test_in_an_exercise_the_beam_is_off_and_says_why(page) -> None:
    """The classroom's exercise hides the truth and asks for a calibration by touching: the
    Automatic (beam) wizard would measure the mystery tool, so Start refuses it in words."""
    p = page()
    p.session.wizard_commands.set_hide_truth(True)                                    # the classroom's exercise
    p.xyz4_by_hand()
    n_runs = len(p.view.workflow.runs)
    p.choose(p.view.method, "Automatic (beam)")
    p.click(p.view.start)
    assert p.notes and "off during the trainer's exercise" in p.notes[-1][1]
    assert len(p.view.workflow.runs) == n_runs and p.view.workflow.wizard.kind == "xyz4"
    assert not p.player.playing


def test_a_loaded_beam_record_shows_its_markers_without_moving_the_robot(page) -> None:
    p = page()
    s, c, v = p.session, p.session.controller, p.view
    p.beam()
    p.film_done()
    record = v.workflow.export_record(s.touches)
    with s.lock:                                                    # jog away, then load the record
        c.set_q(c.q_rad + np.radians([5, 0, 0, 0, 0, 0]))
        s.moved()
    q = c.q_rad
    with s.lock, s.batch():
        v.workflow.load_record(record)
        s.changed(wizard=True)
    res = v.workflow.result
    assert res is not None and not res.scan.moves                   # a stored scan: events only
    assert p.player.scan is res.scan and not p.player.playing
    assert len(np.asarray(p.player.markers.points)) == len(res.events)
    np.testing.assert_array_equal(c.q_rad, q)                       # the robot stays
    assert not v.result.replay_scan.visible                         # nothing to replay
