"""Replaying a beam scan in the 3D scene: the robot goes through the scan's moves, the
beam turns red while the tool breaks it, a marker stays where each event met the beam.

:func:`replay_frames` is pure: from a ``BeamScan`` (``controller.beam_scan``: its ``moves``
with their joint values and the events each move produced) it makes a short film of joint
values, a few per move in proportion to the time the move takes on the real robot, with a
held frame at each event, whose beam is then broken. :func:`event_points_world` gives the
markers' points (on the beam line).

:class:`ScanPlayer` (one per session, built with its views and handed to those that play films) plays such a film on viser's event
loop at :attr:`ScanPlayer.rate_hz`: each frame sets the controller's joints
(``VirtualController.set_q``, the model's joint values the scan planned) and emits the
session's ``pose`` change, so every view shows the robot where the scan had it; the broken
beam turns red (the scene's stand, ``BeamStandNodes.set_broken``), the break point, the markers
and each event's ray are the player's own nodes under ``/beam_scan``. The controller is left at the
scan's end (or where the caller asked it to return), and the film's end is one more ``pose``
change (``Session.refresh``: the scene shows its gizmo and TOOL triads again). A jog, the gizmo
or a new scan during the replay stops it (the robot stays where the user put it); without a
running event loop (a test calling from its own thread) the last frame is applied at once.

The player is shared by the Calibrate tab's scene (the "Automatic (beam)" wizard's result) and
the Tool tab's TCP service ("Check with beam"): one robot, one film at a time.
"""

from __future__ import annotations

import asyncio
import logging
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import viser

from tcp_pendant.session import Session
from tcp_pendant.views.beam_stand import BROKEN_RGB, BeamStandNodes
from tcp_pendant.views.gui_util import target_of

if TYPE_CHECKING:
    from tcp_pendant.controller.beam import BeamEvent
    from tcp_pendant.controller.beam_scan import BeamScan, ScanMove
    from tcp_pendant.wizards.beam import RecordedScan, ScanEvent

__all__ = ["BROKEN_RGB", "ReplayFrame", "ScanPlayer", "beam_view_direction", "event_points_world", "replay_frames",
           "scan_spheres"]

log = logging.getLogger(__name__)

TIP_EVENT_RGB = (255, 150, 0)
AXIS_EVENT_RGB = (210, 60, 230)
MAX_FRAMES = 110
"""Longest film, frames (9 s at 12 Hz); holds at the events included."""
HOLD_FRAMES = 3
"""Frames an event's broken beam is held (0.25 s at 12 Hz)."""
RETURN_FRAMES = 8


@dataclass(frozen=True, eq=False)
class ReplayFrame:
    """One frame of a scan's replay.

    Attributes:
        q_rad: the robot's joints (model), rad.
        broken_event: the event whose beam is broken in this frame (index into ``scan.events``),
            or None (every beam clear).
        shown: the events that have happened by this frame (their markers are shown).
    """

    q_rad: np.ndarray
    broken_event: int | None
    shown: tuple[int, ...]


def _event_fraction(move: ScanMove, event: BeamEvent | ScanEvent) -> tuple[float, float, float]:
    """(fraction of the move where the event was recorded, where the beam broke, where it was
    clear again) along the move's straight flange line; the exit is 1 for a tip event (the
    tip stays in the beam until the next move pulls it out)."""
    p0 = np.asarray(move.T_world_flange_start, dtype=float)[:3, 3]
    p1 = np.asarray(move.T_world_flange_end, dtype=float)[:3, 3]
    d = p1 - p0
    length = float(np.linalg.norm(d))
    if length < 1e-9:
        return 1.0, 1.0, 1.0
    pe = _flange(event)[:3, 3]
    f = float(np.clip((pe - p0) @ d / (length * length), 0.0, 1.0))
    travel = float(getattr(event, "travel", 0.0))
    entry = float(np.clip(f - max(travel - float(getattr(event, "entry_travel", travel)), 0.0) / length, 0.0, f))
    exit_travel = float(getattr(event, "exit_travel", np.nan))
    if event.kind == "axis" and np.isfinite(exit_travel):
        exit_ = float(np.clip(f + max(exit_travel - travel, 0.0) / length, f, 1.0))
    else:
        exit_ = 1.0
    return f, entry, exit_


def _flange(event: BeamEvent | ScanEvent) -> np.ndarray:
    """The event's flange pose without the recording noise when it has one (a live
    ``BeamEvent``), else the recorded one (a stored scan's event)."""
    T = getattr(event, "T_world_flange_exact", None)
    return np.asarray(event.T_world_flange if T is None else T, dtype=float)


def _move_seconds(move: ScanMove) -> float:
    speed = float(move.speed_mm_s)
    return float(move.length_m) * 1000.0 / speed if speed > 0 else 0.0


def replay_frames(scan: BeamScan | RecordedScan, *, max_frames: int = MAX_FRAMES, hold_frames: int = HOLD_FRAMES,
                  return_to: np.ndarray | None = None) -> tuple[ReplayFrame, ...]:
    """The film of ``scan`` (see the module docstring).

    Each move gets frames in proportion to its real duration (length / speed), at least one
    (its end); within a move the joints are interpolated linearly (the scan's approaches and
    passes are short straight lines at a fixed orientation). Each event gets ``hold_frames``
    frames at its recorded position with its beam broken; frames between an axis event's entry
    and exit (and after a tip event's entry in its move) show the beam broken too.

    Args:
        scan: a ``BeamScan``.
        max_frames: the most frames (events' holds and the return included).
        hold_frames: frames per event.
        return_to: joints to go back to after the scan (rad), or None (stay at its end).

    Returns:
        The frames in order (at least one: the scan's end, or ``return_to``); none for a stored
        scan (no moves and no end joints: nothing to play).
    """
    moves = tuple(getattr(scan, "moves", ()))
    events: tuple[BeamEvent | ScanEvent, ...] = tuple(scan.events)
    if not moves and getattr(scan, "q_end_rad", None) is None:
        return ()
    q_end = np.asarray(scan.q_end_rad, dtype=float)
    n_return = RETURN_FRAMES if return_to is not None else 0
    budget = max(max_frames - hold_frames * len(events) - n_return - 1, len(moves))
    seconds = np.array([_move_seconds(m) for m in moves], dtype=float)
    total = float(seconds.sum())
    if moves and total > 0:
        per_move = np.maximum(1, np.floor(seconds / total * budget)).astype(int)
    else:
        per_move = np.ones(len(moves), dtype=int)
    while per_move.sum() > budget and per_move.max() > 1:
        per_move[int(np.argmax(per_move))] -= 1
    frames: list[ReplayFrame] = []
    shown: tuple[int, ...] = ()
    if moves:
        frames.append(ReplayFrame(np.asarray(moves[0].q_start_rad, dtype=float).copy(), None, shown))
    for m, n in zip(moves, per_move):
        q0 = np.asarray(m.q_start_rad, dtype=float)
        q1 = np.asarray(m.q_end_rad, dtype=float)
        spans = {int(i): _event_fraction(m, events[int(i)]) for i in m.event_indices if 0 <= int(i) < len(events)}
        stops = [(k / n, None) for k in range(1, n + 1)] + [(f, i) for i, (f, _, _) in spans.items()]
        stops.sort(key=lambda s: (s[0], s[1] is None))
        for f, event in stops:
            q = q0 + (q1 - q0) * f
            if event is not None:
                if event not in shown:
                    shown = tuple(sorted((*shown, event)))
                frames.extend(ReplayFrame(q, event, shown) for _ in range(max(hold_frames, 1)))
                continue
            broken = next((i for i, (_, a, b) in spans.items() if a <= f <= b), None)
            if broken is not None and broken not in shown:
                shown = tuple(sorted((*shown, broken)))
            frames.append(ReplayFrame(q, broken, shown))
    all_events = tuple(range(len(events)))
    if not frames or not np.allclose(frames[-1].q_rad, q_end, atol=1e-12):
        frames.append(ReplayFrame(q_end.copy(), None, all_events))
    if return_to is not None:
        back = np.asarray(return_to, dtype=float)
        frames.extend(ReplayFrame(q_end + (back - q_end) * (k / n_return), None, all_events)
                      for k in range(1, n_return + 1))
    last = frames[-1]
    frames[-1] = ReplayFrame(last.q_rad, None, all_events)   # the film ends clear, every marker shown
    return tuple(frames)


def _on_beam(point: np.ndarray, b: np.ndarray, u: np.ndarray) -> np.ndarray:
    return b + float((point - b) @ u) * u


def event_points_world(scan: BeamScan | RecordedScan, points: np.ndarray | None = None) -> np.ndarray:
    """(N, 3) where each event met its beam (WORLD, m), projected onto the event's beam line:
    ``points`` (N, 3) if given, else the scan's point for the event (``BeamScan.tip_world_m(i)``:
    where the physical tool met the beam), else (a stored scan) the flange's position."""
    events: tuple[BeamEvent | ScanEvent, ...] = tuple(scan.events)
    out = np.zeros((len(events), 3))
    tip = getattr(scan, "tip_world_m", None)
    for i, ev in enumerate(events):
        b = np.asarray(ev.beam_point, dtype=float)
        u = np.asarray(ev.beam_dir, dtype=float)
        if points is not None:
            p = np.asarray(points[i], dtype=float)
        else:
            p = np.asarray(tip(i), dtype=float) if callable(tip) else _flange(ev)[:3, 3]
        out[i] = _on_beam(p, b, u)
    return out


def beam_view_direction(beam_point: np.ndarray, beam_dir: np.ndarray) -> np.ndarray:
    """From the scan toward the camera (WORLD, not normalised) to see a beam broadside: across
    it from the side away from the robot's root (WORLD's origin), a little along it, from above."""
    b = np.asarray(beam_point, dtype=float)
    u = np.asarray(beam_dir, dtype=float)
    side = np.cross([0.0, 0.0, 1.0], u)
    if np.linalg.norm(side) < 1e-6:                     # a vertical beam: any horizontal side
        side = np.array([0.0, -1.0, 0.0])
    side /= np.linalg.norm(side)
    if float(side @ b) < 0.0:
        side = -side
    return side + 0.35 * u * (1.0 if float(u @ b) >= 0.0 else -1.0) + np.array([0.0, 0.0, 0.5])


def scan_spheres(scan: BeamScan | RecordedScan, points: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(centres, radii) in WORLD m of what a camera should show of a scan: the flange at each
    event (with room for the wrist), the event points, the beam and the fork below it."""
    events: tuple[BeamEvent | ScanEvent, ...] = tuple(scan.events)
    b = np.asarray(events[0].beam_point, dtype=float)
    centres = [_flange(ev)[:3, 3] for ev in events]
    centres += [*event_points_world(scan, points), b, b - [0.0, 0.0, 0.12]]
    radii = [0.06] * len(events) + [0.01] * len(events) + [0.1, 0.06]
    return np.array(centres, dtype=float), np.array(radii, dtype=float)


class ScanPlayer:
    """Plays scans in one session's scene (see the module docstring). Get it with :meth:`of`."""

    ROOT = "/beam_scan"
    rate_hz: float = 12.0
    """Frames per second of the replay (tests may raise it)."""

    def __init__(self, session: Session, stand: BeamStandNodes | None = None) -> None:
        self.session = session
        self.stand = stand
        """The scene's beam stand (``views.beam_stand.BeamStandNodes``: its beam turns red), or None."""
        scene = target_of(session).scene
        self.scene = scene
        self.break_point = scene.add_icosphere(f"{self.ROOT}/break_point", radius=0.005, color=BROKEN_RGB,
                                               visible=False, cast_shadow=False, receive_shadow=False)
        self.markers: viser.PointCloudHandle | None = None
        """The event markers (a point cloud on the beam; None: none shown)."""
        self.rays: viser.LineSegmentsHandle | None = None
        """Each shown event's ray, flange -> marker (line segments; None: none shown)."""
        self._scan: BeamScan | RecordedScan | None = None
        self._points = np.zeros((0, 3))
        self._task: asyncio.Task[None] | None = None
        self._generation = 0
        self._last_q: np.ndarray | None = None
        self.owner: object | None = None
        """Who started the film on show (the views clear only their own)."""
        self.frames: tuple[ReplayFrame, ...] = ()
        self.frames_played = 0
        self.done = threading.Event()
        """Set when the film on show has ended (played out, stopped or cleared)."""
        self.done.set()
        self._shown_state: tuple[int | None, tuple[int, ...]] | None = None
        session.on_close(self._on_close)

    @property
    def playing(self) -> bool:
        return not self.done.is_set()

    @property
    def scan(self) -> BeamScan | RecordedScan | None:
        """The scan on show (None: nothing shown)."""
        return self._scan

    # ------------------------------------------------------------ commands
    def play(self, scan: BeamScan | RecordedScan, *, owner: object | None = None,
             return_to: np.ndarray | None = None,
             points: np.ndarray | None = None) -> None:
        """Replay ``scan`` from its first move (on the loop: a task at :attr:`rate_hz`; off the
        loop: its last frame at once). A film already playing stops first. A stored scan (no
        moves) only shows its markers; ``points``: the markers' points (see
        :func:`event_points_world`)."""
        self.stop()
        self._generation += 1
        self._scan, self.owner = scan, owner
        self._points = event_points_world(scan, points)
        self.frames = replay_frames(scan, return_to=return_to)
        self.frames_played = 0
        self._shown_state = None
        if not self.frames:
            self._show(None, tuple(range(len(scan.events))))
            return
        self.done.clear()
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:
            loop = None
        if loop is None:
            self._apply(len(self.frames) - 1)
            self._finish()
            return
        self._last_q = None
        self._task = loop.create_task(self._run(self._generation))

    def stop(self) -> None:
        """Stop the film where it is (the markers of the events so far stay)."""
        self._generation += 1
        task, self._task = self._task, None
        if task is not None and not task.done():
            task.cancel()
        self._finish()

    def _on_close(self) -> None:
        """The session closed: the film's task ends, nothing more is drawn."""
        self._generation += 1
        task, self._task = self._task, None
        if task is not None and not task.done():
            task.cancel()
        self.done.set()

    def clear(self, owner: object | None = None) -> None:
        """Stop and remove the red beam and the markers (only ``owner``'s film, if given)."""
        if owner is not None and owner is not self.owner:
            return
        self.stop()
        self._scan, self.owner = None, None
        self._points = np.zeros((0, 3))
        self._show(None, ())

    # ------------------------------------------------------------ the film
    def _finish(self) -> None:
        if self._scan is not None and self.frames:
            self._show(None, self.frames[-1].shown if self.frames_played >= len(self.frames) else self._shown())
        self.done.set()

    def _shown(self) -> tuple[int, ...]:
        return () if self._shown_state is None else self._shown_state[1]

    async def _run(self, generation: int) -> None:
        s = self.session
        try:
            for i in range(len(self.frames)):
                if generation != self._generation or s.closed:
                    return
                with s.lock:
                    if generation != self._generation or s.closed:
                        return
                    if self._last_q is not None and not np.array_equal(s.controller.q_rad, self._last_q):
                        log.info("beam scan replay stopped at frame %d of %d: the robot was moved",
                                 i, len(self.frames))
                        return                          # the user moved the robot: the film stops
                    self._apply(i)
                await asyncio.sleep(1.0 / max(self.rate_hz, 1e-3))
        except asyncio.CancelledError:
            raise
        except Exception:  # the film must never take the server down
            log.exception("beam scan replay failed")
        finally:
            if generation == self._generation:
                self._task = None
                with s.lock:
                    self._finish()
                    s.refresh()                         # the views see the film's end (triads back)

    def _apply(self, i: int) -> None:
        frame = self.frames[i]
        s = self.session
        s.motion.set_joints(frame.q_rad, status=False)
        self._last_q = s.controller.q_rad
        self.frames_played = i + 1
        self._show(frame.broken_event, frame.shown)

    def _stand(self) -> BeamStandNodes | None:
        return self.stand

    def _show(self, broken: int | None, shown: tuple[int, ...]) -> None:
        """The red beam of event ``broken`` (None: hidden) and the markers of ``shown``."""
        state = (broken, shown)
        if state == self._shown_state:
            return
        self._shown_state = state
        scan = self._scan
        stand = self._stand()
        if broken is None or scan is None:
            if stand is not None:
                stand.set_broken(None)
            self.break_point.visible = False
        else:
            if stand is not None:
                stand.set_broken(int(getattr(scan.events[broken], "beam", 0)))
            x, y, z = (float(v) for v in self._points[broken])
            self.break_point.position = (x, y, z)
            self.break_point.visible = True
        for h in (self.markers, self.rays):
            if h is not None:
                h.remove()
        self.markers = self.rays = None
        if shown and scan is not None:
            idx = list(shown)
            colors = np.array([TIP_EVENT_RGB if scan.events[i].kind == "tip" else AXIS_EVENT_RGB for i in idx],
                              dtype=np.uint8)
            self.markers = self.scene.add_point_cloud(f"{self.ROOT}/events", points=self._points[idx],
                                                       colors=colors, point_size=0.008, point_shape="circle",
                                                       precision="float32")
            # each event's ray: from the flange where the controller recorded it to where the tool met
            # the beam, a fan of the scan's orientations converging on the beam
            flanges = np.array([_flange(scan.events[i])[:3, 3] for i in idx])
            segs = np.stack([flanges, self._points[idx]], axis=1)
            self.rays = self.scene.add_line_segments(f"{self.ROOT}/rays", points=segs,
                                                      colors=np.repeat(colors[:, None, :], 2, axis=1),
                                                      thickness=1.5, thickness_units="screen")
