"""In a session: ``views.beam_replay.ScanPlayer`` plays a scan's film on
viser's event loop (the controller goes through the frames and stays at the scan's end, the red
beam shows at the events, the markers stay), stops when the user moves the robot, and clears
only its owner's film. In-process server, headless websocket client as the browser."""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from types import SimpleNamespace

import numpy as np
import pytest

from support.app_page import AppPage
from support.wsclient import wait_until

from tcp_pendant.views.beam_replay import ScanPlayer


class Page(AppPage):
    def on_loop(self, fn: Callable[[], object]) -> object:
        """Run ``fn()`` on the server's event loop (as a GUI callback would) and return its value."""
        loop = self.session.views["tools"].check._impl.gui_api._event_loop

        async def call() -> object:
            return fn()

        return asyncio.run_coroutine_threadsafe(call(), loop).result(timeout=30)


pytestmark = [pytest.mark.app_page(cls=Page), pytest.mark.shares_cpu]  # asserts no time, latency or load (tests/conftest.py)


def fake_scan(p: Page) -> SimpleNamespace:
    """Three small joint moves from where the robot is; one tip event in the second."""
    c = p.session.controller
    q0 = c.q_rad
    qs = [q0, q0 + np.radians([2, 1, -1, 0, 1, 0]), q0 + np.radians([3, 2, -2, 1, 2, 1]),
          q0 + np.radians([4, 1, -1, 1, 0, 1])]
    T = []
    for q in qs:
        c.set_q(q)
        T.append(c.T_world_flange())
    c.set_q(q0)
    b = T[2][:3, 3] + [0.0, 0.0, -0.1]
    event = SimpleNamespace(kind="tip", beam_point=b, beam_dir=np.array([0.0, 1.0, 0.0]), T_world_flange_exact=T[2],
                            T_world_flange=T[2], travel=0.0, entry_travel=0.0, exit_travel=float("nan"))
    moves = tuple(SimpleNamespace(kind="move", q_start_rad=qs[i], q_end_rad=qs[i + 1], T_world_flange_start=T[i],
                                  T_world_flange_end=T[i + 1], length_m=float(np.linalg.norm(T[i + 1][:3, 3] - T[i][:3, 3])),
                                  speed_mm_s=50.0, event_indices=(0,) if i == 1 else ())
                  for i in range(3))
    return SimpleNamespace(moves=moves, events=(event,), q_end_rad=qs[3], tip_world_m=lambda i: b + [0.003, 0.01, 0.0])


def test_the_film_moves_the_robot_through_the_scan_and_leaves_it_at_the_end(page) -> None:
    p = page()
    player = p.session.views["beam_player"]
    views = p.session.views                                          # one per session, handed to each
    assert views["scene"].player is player and views["beam_check"].player is player
    assert views["calibrate"].scene.player is player
    player.rate_hz = 200.0
    scan = fake_scan(p)
    seen: list[tuple[np.ndarray, bool]] = []
    stand = p.session.views["scene"].beam_stand
    p.session.subscribe(lambda ch: seen.append((p.session.controller.q_rad, stand.broken is not None)))
    p.on_loop(lambda: player.play(scan, owner="me"))
    wait_until(lambda: not player.playing, what="the film played out")
    np.testing.assert_allclose(p.session.controller.q_rad, scan.q_end_rad)
    assert player.frames_played == len(player.frames) >= 4
    assert len(seen) >= len(player.frames)                       # one pose signal per frame
    assert any(red for _, red in seen)                            # the beam was red at the event
    assert stand.broken is None and not player.break_point.visible   # and clear at the end
    np.testing.assert_array_equal(np.asarray(stand.beam_handle.colors)[0, 0], (0, 160, 40))
    np.testing.assert_allclose(player.markers.points, [scan.tip_world_m(0) - [0.003, 0.0, 0.0]], atol=1e-6)   # on the beam
    player.clear(owner="someone else")                            # not theirs: stays
    assert player.markers is not None and player.scan is scan
    player.clear(owner="me")
    assert player.markers is None and player.scan is None


def test_a_jog_during_the_film_stops_it_where_the_user_put_the_robot(page) -> None:
    p = page()
    player = p.session.views["beam_player"]
    player.rate_hz = 4.0
    scan = fake_scan(p)
    p.on_loop(lambda: player.play(scan))
    wait_until(lambda: player.frames_played >= 1, what="the first frame")
    mine = scan.moves[0].q_start_rad + np.radians([0, 0, 0, 0, 0, 5])

    def jog() -> None:
        with p.session.lock:
            p.session.controller.set_q(mine)
            p.session.moved()
    p.on_loop(jog)
    wait_until(lambda: not player.playing, what="the film stopped")
    assert player.frames_played < len(player.frames)
    np.testing.assert_allclose(p.session.controller.q_rad, mine)   # the user's pose stays


def test_off_the_loop_the_last_frame_is_shown_at_once(page) -> None:
    p = page()
    player = p.session.views["beam_player"]
    scan = fake_scan(p)
    home = p.session.controller.q_rad
    player.play(scan, return_to=home)                             # a test's own thread: no running loop
    assert not player.playing and player.frames_played == len(player.frames)
    np.testing.assert_allclose(p.session.controller.q_rad, home)
    assert player.markers is not None and p.session.views["scene"].beam_stand.broken is None


def test_a_stored_scan_without_moves_only_shows_its_markers(page) -> None:
    p = page()
    player = p.session.views["beam_player"]
    live = fake_scan(p)
    q = p.session.controller.q_rad
    stored = SimpleNamespace(events=live.events, moves=(), q_end_rad=None)     # a record's RecordedScan
    points = np.array([[0.5, 0.1, 0.4]])
    p.on_loop(lambda: player.play(stored, points=points))
    assert not player.playing and player.frames == ()
    np.testing.assert_array_equal(p.session.controller.q_rad, q)              # the robot did not move
    b = live.events[0].beam_point
    np.testing.assert_allclose(player.markers.points, [[b[0], 0.1, b[2]]], atol=1e-6)   # on the beam line


def test_the_gizmo_and_the_tool_triad_step_aside_while_the_film_plays(page) -> None:
    p = page()
    scene = p.session.views["scene"]
    player = p.session.views["beam_player"]
    player.rate_hz = 5.0
    scan = fake_scan(p)
    assert scene.gizmo.visible
    p.on_loop(lambda: player.play(scan))
    wait_until(lambda: player.frames_played >= 1, what="the first frame")
    assert not scene.gizmo.visible and not scene._active_label.visible   # they would hide the beam
    player.rate_hz = 400.0
    wait_until(lambda: not player.playing, what="the film's end")
    wait_until(lambda: scene.gizmo.visible, what="the gizmo back")
    assert scene._active_label.visible
