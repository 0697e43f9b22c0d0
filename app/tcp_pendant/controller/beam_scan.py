"""The beam sensor's automatic scan: the motion a BullsEye / TRACC style device runs.

Pure functions of their arguments (no controller is read or changed), so a scan can run in a
worker thread on snapshots taken on the event loop. Metres and radians inside; the
configuration's speeds and distances are in mm and mm/s (the pendant's units).

**Who knows what.** The controller plans with its own (NOMINAL) robot model ``kinematics`` and
the tool data it *believes* (``T_flange_tool_plan``, possibly stale: a bent tool). The beam
sees the PHYSICAL tool (:class:`~tcp_pendant.controller.beam.ToolShape`, its true frame) on the
PHYSICAL robot (``true_kinematics``). The recorded events are MODEL flange poses (what a real
controller stores), so ``tcpcal.solve_beam`` / ``solve_beam_axis`` on them give what a real
device would report.

**The pattern** (per orientation k = 0 .. n-1, methods.md section 9 for why it observes the TCP
and the tool direction):

* Orientation: the (believed) tool X, the working direction, points down, tilted by
  ``(-1)^k tilt_deg`` about the beam direction ``u`` and turned ``360 k / n`` deg about its own
  axis (0/90/180/270 for n = 4). The turns about the tool axis are what observe everything: the
  beam direction seen in FLANGE (``w = R^T u``) turns with them, so the tip events fix the TCP
  in every flange direction, and the planes of the axis events turn by 90 deg (perpendicular:
  best conditioned tool direction). The alternating tilt about ``u`` changes neither ``w`` nor
  the planes (section 9: a turn about the beam adds nothing); it spreads the arm's wrist
  configurations, so an absolute-accuracy error of one configuration does not repeat in all.
  An orientation with a pose out of reach at its tilt is tried at the opposite tilt and at 0,
  then turned a third of the way towards either neighbour (30 deg for n = 4): the turns only
  need to differ.
* Two **sideways passes** (``pass``) across the beam, horizontally along ``a = unit(Z x u)``,
  from ``-W`` to ``+W`` and back, with the (believed) tool axis crossing the beam
  ``pass_heights_mm`` behind the believed tip: two **axis events** (``crossing_events``, entry
  and exit averaged). ``W = radius + width / 2 + pass_margin_mm``: a pass clears the shaft
  however wrong the believed tool data is within the margin. Two crossed beams: the passes run
  along the horizontal bisector that crosses both at the largest angle (45 deg for beams at
  right angles; ``W`` divided by that angle's sine) and record the axis events of both beams;
  the approach aims at the crossing point and records a tip event on each beam (so one
  orientation already fixes the TCP).
* At both axis events the PHYSICAL tool axis met the beam line, at the same flange orientation
  and the same position along ``u``. The flange positions at which the axis meets the beam form
  a straight line (in the plane across the beam, the flange offset is linear in the height of
  the crossing point): the line through the two recorded events. Moving the flange along it
  moves the tool along its own (physical) axis, keeping that axis through the beam line.
* The robot **retracts** (``move``) up beside the beam, moves **over** to the point of that
  line ``clearance_mm`` before the tip reaches the beam (tip above it), and **approaches**
  (``approach``) along the line at scan speed until the tip breaks the beam: one **tip event**
  (``tip_on_beam``), dead centre (its ``miss_distance`` is the recording noise only), whatever
  the error of the believed tool data within the pass margin. Then it retracts along the line.
* Between orientations the robot moves (``move``) above the beam to the next orientation,
  beside the beam, then down to the next pass start.

Each motion is a :class:`ScanMove` with its joint values at start and end (inverse kinematics
on the MODEL, ``approach.solve_ik``, seeded from the previous pose so the arm keeps its
configuration); an orientation with an unreachable pose, a main axis swinging by more than
``MAX_ARM_SWING_DEG`` (another arm configuration), a joint jump of more than
``MAX_JOINT_STEP_DEG`` within one straight motion, or a pass / approach that sees no event is
skipped, with the reason in plain words in :attr:`BeamScan.skipped`; its moves and events are
dropped and the next orientation starts where the last complete one ended. Collisions of the
moves between the steps with the device are not checked: they keep ``W`` sideways or
``clearance_mm`` above the beam.

**Absolute accuracy** (``true_kinematics`` differs): a local linearisation. During one straight
motion of the model, the physical flange follows it moved rigidly by the discrepancy
``D = T_true(q) T_model(q)^-1`` at the joints ``q`` of the travel where the event happens: a
straight line that touches the real (slightly curved) path there. ``D`` is first taken at the
motion's start, the event found, then ``D`` taken at the event and the event found again until
its travel settles (to 1e-11 m in two or three rounds). With ``D`` of the start alone the error
was up to 0.2 mm over a 55 mm pass: ``D`` turns by hundredths of a degree about the robot's
base, a metre away. The event's travel is recorded on the model's motion: ``T_model(q0)`` moved
by ``travel m``. The tip events' ``miss_distance`` and the markers are the physical ones.

**Repeatability**: the sensor's ``sigma`` per axis on each recorded position (``rng``; None:
exact data), drawn when the event is recorded and added to the recorded model pose (the average
of two recordings for a crossing's entry and exit).

**Duration** (what the scan takes on a real robot): ``sum(length_m / speed)`` over the moves,
passes and approaches at ``scan_speed_mm_s``, the others at ``move_speed_mm_s``. The length of
a straight pass or approach is the flange's travel; of a ``move`` (which may also turn the
tool) the longer of the flange's and the believed TCP's straight-line displacements.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from collections.abc import Callable
from typing import Literal

import numpy as np

from tcpcal.validation import read_only_array
from tcp_pendant.controller.approach import solve_ik
from tcp_pendant.controller.beam import (
    DEFAULT_SIGMA_M,
    DEFAULT_WIDTH_M,
    BeamEvent,
    BeamSensor,
    ToolShape,
    crossing_events,
    tip_on_beam,
)
from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.controller.kinematics import RobotKinematics
from tcp_pendant.controller.tools import ToolModel
from tcp_pendant.controller.words import Words
from tcp_pendant.translation import N_, Translator

__all__ = [
    "BEAM_TOOL_SHAPES",
    "MAX_ARM_SWING_DEG",
    "MAX_JOINT_STEP_DEG",
    "BeamDevice",
    "BeamScan",
    "BeamScanConfig",
    "ScanMove",
    "default_beam_sensor",
    "run_beam_scan",
    "scan_arrays_mm",
    "tool_shape",
]

MAX_JOINT_STEP_DEG = 60.0
"""A straight pass or approach whose joint values differ by more than this between its start and
end would flip the arm's configuration on the way: that orientation is skipped."""
MAX_ARM_SWING_DEG = 90.0
"""A move (after the first) that turns one of the three main axes by more than this would swing
the arm into another configuration (over the top, elbow down) in the middle of the scan: the
pose counts as out of reach."""

BEAM_TOOL_SHAPES: dict[str, tuple[float, float]] = {
    # key: (radius m, length m) of the shaft the beam crosses (from the tool meshes, in the
    # TOOL frame: the pointer's cone and shank within 50 mm of the tip fit in 6 mm, the torch's
    # wire, contact tip and nozzle within 100 mm in 12 mm)
    "pointer": (0.006, 0.15),
    "torch": (0.012, 0.10),
}
"""Shaft capsules of the built-in tools a beam can measure (the gripper has no tip)."""

_DEFAULT_SHAPE = (0.005, 0.10)
_REFINE_ROUNDS = 4
_NO_TIP_TOOLS = {"gripper": "the two-finger gripper has no tip the beam could see (its TCP is "
                            "in the air between the fingers); calibrate it with a touch method"}

DEFAULT_BEAM_OFFSET_M = np.array([0.0, -0.22, 0.0])
"""Where :func:`default_beam_sensor` puts the beam's point, from the reference tip (WORLD, m):
220 mm to the robot's right of the spike (clear of its stand), at its height."""


# ------------------------------------------------------------------------------ configuration
@dataclass(frozen=True)
class BeamScanConfig:
    """How the scan moves (mm, mm/s, deg: the pendant's units).

    Attributes:
        n_orientations: tool orientations (3..5): turns of ``360 / n`` deg about the tool axis.
        tilt_deg: tilt of the tool about the beam direction, alternating in sign (0..30 deg).
        scan_speed_mm_s: speed of passes and approaches (the beam is sampled at this speed).
        move_speed_mm_s: speed of the moves between them.
        pass_heights_mm: where the beam crosses the shaft on the two sideways passes, behind the
            believed tip along the tool axis (two different values > 0, within the shaft).
        pass_margin_mm: how far beyond the shaft's radius each pass starts and ends: the error
            of the believed tool data the scan tolerates sideways.
        clearance_mm: how far before the beam the tip starts its approach, and how far the tool
            retracts from the beam between the steps: the error of the believed tool data the
            scan tolerates along the tool axis.
    """

    n_orientations: int = 4
    tilt_deg: float = 10.0
    scan_speed_mm_s: float = 50.0
    move_speed_mm_s: float = 250.0
    pass_heights_mm: tuple[float, float] = (8.0, 40.0)
    pass_margin_mm: float = 15.0
    clearance_mm: float = 20.0

    def __post_init__(self) -> None:
        n = self.n_orientations
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 3 <= n <= 5:
            raise ControllerError(f"BeamScanConfig: n_orientations must be 3, 4 or 5, got {n!r}.")
        object.__setattr__(self, "n_orientations", int(n))

        def number(name: str, lo: float, hi: float) -> float:
            v = getattr(self, name)
            try:
                f = float(v)
            except (TypeError, ValueError):
                raise ControllerError(f"BeamScanConfig: {name} must be a number, got {v!r}.") from None
            if not (math.isfinite(f) and lo <= f <= hi):
                raise ControllerError(f"BeamScanConfig: {name} must be within {lo:g}..{hi:g}, "
                                      f"got {v!r}.")
            return f

        for name, lo, hi in (("tilt_deg", 0.0, 30.0), ("scan_speed_mm_s", 1.0, 2000.0),
                             ("move_speed_mm_s", 1.0, 5000.0), ("pass_margin_mm", 2.0, 100.0),
                             ("clearance_mm", 5.0, 200.0)):
            object.__setattr__(self, name, number(name, lo, hi))
        try:
            h = tuple(float(v) for v in self.pass_heights_mm)
        except (TypeError, ValueError):
            raise ControllerError("BeamScanConfig: pass_heights_mm must be two numbers (mm), got "
                                  f"{self.pass_heights_mm!r}.") from None
        if len(h) != 2 or not all(math.isfinite(v) and 0.5 <= v <= 500.0 for v in h) \
                or abs(h[1] - h[0]) < 2.0:
            raise ControllerError("BeamScanConfig: pass_heights_mm must be two heights within "
                                  f"0.5..500 mm, at least 2 mm apart, got {self.pass_heights_mm!r}.")
        object.__setattr__(self, "pass_heights_mm", h)


@dataclass(frozen=True, eq=False)
class ScanMove:
    """One straight motion of the scan (MODEL poses, what the controller commands).

    Attributes:
        kind: ``"move"`` (between the steps, at move speed), ``"approach"`` (the tip towards the
            beam, at scan speed; ends at the (last) tip event) or ``"pass"`` (sideways across the beam,
            at scan speed).
        q_start_rad, q_end_rad: joint values at the start and end (rad; model IK).
        T_world_flange_start, T_world_flange_end: (4, 4) model flange poses, m.
        length_m: path length (see the module docstring), m.
        speed_mm_s: the speed it runs at, mm/s.
        event_indices: indices into :attr:`BeamScan.events` of the events during this motion.
        orientation: the orientation index k it belongs to.
    """

    kind: Literal["move", "approach", "pass"]
    q_start_rad: np.ndarray
    q_end_rad: np.ndarray
    T_world_flange_start: np.ndarray
    T_world_flange_end: np.ndarray
    length_m: float
    speed_mm_s: float
    event_indices: tuple[int, ...] = ()
    orientation: int = 0

    @property
    def duration_s(self) -> float:
        """``length_m / speed``, s."""
        return self.length_m * 1000.0 / self.speed_mm_s


@dataclass(frozen=True, eq=False)
class BeamScan:
    """The result of :func:`run_beam_scan`.

    Attributes:
        events: the recorded events in order; their ``T_world_flange`` is the MODEL flange pose
            the controller records (with the repeatability noise).
        orientation_index: per event, the orientation k it was recorded at.
        moves: every straight motion in order (what the scene animates).
        path_length_m: sum of the moves' lengths, m.
        duration_s: what the scan takes on a real robot: ``sum(length / speed)``, s.
        skipped: plain-words reasons, one per orientation that could not be run.
        q_end_rad: joint values at the end of the scan (rad).
        beam_points_world_m: (N, 3) per event, where the PHYSICAL tool met the beam line in
            WORLD, m (tip events: the tip; axis events: the beam line's point nearest the tool
            axis): the markers of the scene.
        sensor: the sensor the scan ran on.
        n_orientations_planned: orientations asked for.
        config: the configuration the scan ran with.
    """

    events: tuple[BeamEvent, ...]
    orientation_index: tuple[int, ...]
    moves: tuple[ScanMove, ...]
    path_length_m: float
    duration_s: float
    skipped: tuple[str, ...]
    q_end_rad: np.ndarray
    beam_points_world_m: np.ndarray
    sensor: BeamSensor
    n_orientations_planned: int = 4
    config: BeamScanConfig = field(default_factory=BeamScanConfig)

    @property
    def tip_sigma_m(self) -> float:
        """Effective repeatability of a tip event across the beam, m.

        A tip event's recorded pose has the sensor's ``sigma`` per axis; besides, the approach
        is aimed along the line through the two (noisy) axis events, extrapolated from the
        heights ``h1 < h2`` to the tip, so the tip misses the beam's centre by the aiming error
        ``(1 + r) e1 - r e2`` (``r = h1 / (h2 - h1)``, ``e_i`` of ``sigma / sqrt(2)`` per axis),
        and the reported tip is off the line by that miss. Both together::

            sigma_tip = sigma sqrt(1 + ((1 + r)^2 + r^2) / 2)

        (1.35 sigma for the default heights 8 and 40 mm): the sigma to give ``solve_beam``.
        """
        h1, h2 = sorted(self.config.pass_heights_mm)
        r = h1 / (h2 - h1)
        return self.sensor.sigma * math.sqrt(1.0 + ((1.0 + r) ** 2 + r * r) / 2.0)

    def tip_world_m(self, i: int) -> np.ndarray:
        """(3,) WORLD point (m) where event ``i`` broke the beam (a copy)."""
        return np.array(self.beam_points_world_m[i], dtype=float)

    @property
    def tip_indices(self) -> tuple[int, ...]:
        """Indices of the tip events."""
        return tuple(i for i, ev in enumerate(self.events) if ev.kind == "tip")

    @property
    def axis_indices(self) -> tuple[int, ...]:
        """Indices of the axis events."""
        return tuple(i for i, ev in enumerate(self.events) if ev.kind == "axis")

    @property
    def n_orientations_done(self) -> int:
        """Orientations that were run (not skipped)."""
        return len(set(self.orientation_index))


def scan_arrays_mm(events: tuple[BeamEvent, ...] | list[BeamEvent]
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(rotations (N,3,3), positions (N,3) mm, beam points (N,3) mm, beam dirs (N,3))`` of
    events: the arguments of ``tcpcal.solve_beam`` / ``solve_beam_axis`` in mm."""
    rot = np.array([ev.T_world_flange[:3, :3] for ev in events]).reshape(-1, 3, 3)
    pos = np.array([ev.T_world_flange[:3, 3] for ev in events]).reshape(-1, 3) * 1000.0
    b = np.array([ev.beam_point for ev in events]).reshape(-1, 3) * 1000.0
    u = np.array([ev.beam_dir for ev in events]).reshape(-1, 3)
    return rot, pos, b, u


# ------------------------------------------------------------------------------ helpers
def tool_shape(tool_model: ToolModel, T_flange_tool_true: np.ndarray | None = None) -> ToolShape:
    """What the beam sees of a physical tool: its true frame and shaft capsule.

    Args:
        tool_model: the mounted tool (its key picks the radius, :data:`BEAM_TOOL_SHAPES`; other
            keys get a 5 mm radius, 100 mm shaft).
        T_flange_tool_true: (4, 4) the true TOOL frame, m, when it differs from the model's
            (a bent tool); default ``tool_model.T_flange_tool_true``.

    Raises:
        ControllerError: a tool without a tip (the gripper), in plain words.
    """
    if tool_model.key in _NO_TIP_TOOLS:
        raise ControllerError(f"The beam sensor cannot measure this tool: "
                              f"{_NO_TIP_TOOLS[tool_model.key]}.")
    radius, length = BEAM_TOOL_SHAPES.get(tool_model.key, _DEFAULT_SHAPE)
    T = tool_model.T_flange_tool_true if T_flange_tool_true is None else T_flange_tool_true
    return ToolShape(np.asarray(T, dtype=float), radius=radius, length=length)


@dataclass(frozen=True)
class BeamDevice:
    """What kind of beam device stands beside the reference tip (the start options
    ``--beam-width``, ``--beam-repeatability``, ``--beam-crossed``).

    Attributes:
        width_m: beam diameter, m (0.05 to 5 mm).
        sigma_m: repeatability of a recorded event per axis, m (0 to 1 mm).
        crossed: a second beam along WORLD Y through the same point (crossed beams).
    """

    width_m: float = DEFAULT_WIDTH_M
    sigma_m: float = DEFAULT_SIGMA_M
    crossed: bool = False

    def __post_init__(self) -> None:
        w, sg = float(self.width_m), float(self.sigma_m)
        if not (math.isfinite(w) and 0.05e-3 <= w <= 5e-3):
            raise ControllerError(f"The beam width must be 0.05 to 5 mm, got {w * 1000:g} mm.")
        if not (math.isfinite(sg) and 0.0 <= sg <= 1e-3):
            raise ControllerError(f"The beam repeatability must be 0 to 1 mm, got {sg * 1000:g} mm.")
        object.__setattr__(self, "width_m", w)
        object.__setattr__(self, "sigma_m", sg)
        object.__setattr__(self, "crossed", bool(self.crossed))


def default_beam_sensor(reference_tip_world_m: np.ndarray, device: BeamDevice = BeamDevice()) -> BeamSensor:
    """The beam device where it stands by default: a horizontal beam along WORLD X (away from
    the robot), :data:`DEFAULT_BEAM_OFFSET_M` from the reference tip (clear of its stand,
    reachable for the whole scan on the KR 6 and the GP12 with the default reference tip).

    Args:
        reference_tip_world_m: (3,) the reference tip, WORLD, m.
        device: the beam's width, repeatability and whether a second beam along WORLD Y
            crosses it (default: one 0.5 mm beam, 0.02 mm).
    """
    tip = np.asarray(reference_tip_world_m, dtype=float)
    if tip.shape != (3,) or not np.isfinite(tip).all():
        raise ControllerError(f"reference_tip_world_m must be 3 finite numbers (m), got "
                              f"{reference_tip_world_m!r}.")
    return BeamSensor(tip + DEFAULT_BEAM_OFFSET_M, np.array([1.0, 0.0, 0.0]), width=device.width_m,
                      sigma=device.sigma_m,
                      second_direction=np.array([0.0, 1.0, 0.0]) if device.crossed else None)


def _pass_direction(sensor: BeamSensor) -> tuple[np.ndarray, float]:
    """The horizontal direction of the sideways passes and the least sine of its angle with a
    beam: across the beam (``unit(Z x u)``); for crossed beams the horizontal bisector that
    crosses both at the largest angle (45 deg for beams at right angles)."""
    up = np.array([0.0, 0.0, 1.0])
    flat = []
    for _, u_k in sensor.beams:
        h = u_k - (u_k @ up) * up
        flat.append(h / np.linalg.norm(h))
    if len(flat) == 1:
        candidates = [np.cross(up, flat[0])]
    else:
        candidates = [flat[0] + flat[1], flat[0] - flat[1], np.cross(up, flat[0])]
    best, best_sin = candidates[0], -1.0
    for cand in candidates:
        n = float(np.linalg.norm(cand))
        if n < 1e-9:
            continue
        cand = cand / n
        sin_min = min(float(np.linalg.norm(np.cross(cand, u_k))) for _, u_k in sensor.beams)
        if sin_min > best_sin + 1e-12:
            best, best_sin = cand, sin_min
    return best, best_sin


def _aim_at_crossing(f1: np.ndarray, f2: np.ndarray, e1: np.ndarray, e2: np.ndarray,
                     sensor: BeamSensor, f_start: np.ndarray, m: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Crossed beams: the approach line on which the tool axis goes through both beams.

    At one orientation the flange positions at which the tool axis meets beam k fill a plane
    (spanned by the beam direction ``u_k`` and the tool axis); the two axis events of beam k lie
    in it. The two planes meet in the line of flange positions that keep the axis through the
    crossing point. Returns the approach start projected onto that line and its direction
    (the beam-0 line's start and direction when the planes are nearly parallel).
    """
    (_, u0), (_, u1) = sensor.beams
    n0 = np.cross(u0, f2 - f1)
    n1 = np.cross(u1, e2 - e1)
    if min(float(np.linalg.norm(n0)), float(np.linalg.norm(n1))) < 1e-9:
        return f_start, m
    n0, n1 = n0 / np.linalg.norm(n0), n1 / np.linalg.norm(n1)
    d = np.cross(n0, n1)
    if float(np.linalg.norm(d)) < 0.1:
        return f_start, m
    d /= np.linalg.norm(d)
    if float(d @ m) < 0.0:
        d = -d
    p = np.linalg.solve(np.array([n0, n1, d]), np.array([n0 @ f1, n1 @ e1, d @ f_start]))
    return p, d


def _rot(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix about a unit axis (Rodrigues)."""
    k = axis / np.linalg.norm(axis)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * K @ K


def _pose(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


class _Skip(Exception):
    """An orientation cannot be run (message in plain words); ``reach``: a pose out of reach,
    which another tilt or turn may avoid."""

    def __init__(self, message: Words, *, reach: bool = False) -> None:
        super().__init__(message)
        self.reach = reach


@dataclass
class _Planner:
    """Mutable bookkeeping of one scan (private; the result is frozen)."""

    kin: RobotKinematics
    true_kin: RobotKinematics
    T_ft_plan: np.ndarray
    sensor: BeamSensor
    shape: ToolShape
    config: BeamScanConfig
    rng: np.random.Generator | None
    q: np.ndarray
    T: np.ndarray  # current model flange pose
    moves: list[ScanMove] = field(default_factory=list)
    events: list[BeamEvent] = field(default_factory=list)
    points: list[np.ndarray] = field(default_factory=list)
    orient: list[int] = field(default_factory=list)

    def ik(self, T_target: np.ndarray, what: str) -> np.ndarray:
        sol = solve_ik(self.kin, T_target, self.q)
        p = (T_target[:3, :3] @ self.T_ft_plan[:3, 3] + T_target[:3, 3]) * 1000.0
        where = Words(N_("TCP at {x}, {y}, {z} mm"), x=f"{p[0]:.0f}", y=f"{p[1]:.0f}", z=f"{p[2]:.0f}")
        if not sol.ok:
            raise _Skip(Words(N_("{what} is out of reach ({where}: no configuration within the joint "
                                 "limits gets there)"), what=Words(what), where=where), reach=True)
        if self.moves and float(np.abs(sol.q_rad[:3] - self.q[:3]).max()) > math.radians(MAX_ARM_SWING_DEG):
            raise _Skip(Words(N_("{what} is out of reach without swinging the arm into another "
                                 "configuration ({where})"), what=Words(what), where=where), reach=True)
        return sol.q_rad

    def tcp(self, T: np.ndarray) -> np.ndarray:
        return T[:3, :3] @ self.T_ft_plan[:3, 3] + T[:3, 3]

    def add_move(self, kind: Literal["move", "approach", "pass"], T_end: np.ndarray, q_end: np.ndarray, k: int, *,
                 length: float | None = None, events: tuple[int, ...] = ()) -> None:
        if length is None:
            length = max(float(np.linalg.norm(T_end[:3, 3] - self.T[:3, 3])),
                         float(np.linalg.norm(self.tcp(T_end) - self.tcp(self.T))))
        speed = self.config.move_speed_mm_s if kind == "move" else self.config.scan_speed_mm_s
        self.moves.append(ScanMove(
            kind=kind, q_start_rad=read_only_array(self.q), q_end_rad=read_only_array(q_end),
            T_world_flange_start=read_only_array(self.T), T_world_flange_end=read_only_array(T_end),
            length_m=float(length), speed_mm_s=float(speed), event_indices=events, orientation=k))
        self.q, self.T = np.array(q_end, dtype=float), np.array(T_end, dtype=float)

    def move_to(self, T_end: np.ndarray, k: int, what: str) -> None:
        self.add_move("move", T_end, self.ik(T_end, what), k)

    def physical_line(self, q0: np.ndarray, T_model0: np.ndarray, m: np.ndarray, tau: float
                      ) -> tuple[np.ndarray, np.ndarray]:
        """The physical flange's straight motion that touches the real one at travel ``tau`` of
        the model's straight motion (``T_model0``, direction ``m``, from joints ``q0``): start
        pose (at travel 0) and direction, ``D T_model(s)`` with ``D = T_true(q) T_model(q)^-1``
        at the joints ``q`` of travel ``tau`` (the linearisation of the module docstring)."""
        if self.true_kin is self.kin:
            return T_model0, m
        q = q0
        if tau != 0.0:
            T_tau = T_model0.copy()
            T_tau[:3, 3] += tau * m
            sol = solve_ik(self.kin, T_tau, q0)
            if sol.ok:
                q = sol.q_rad
        D = self.true_kin.T_world_flange(q) @ np.linalg.inv(self.kin.T_world_flange(q))
        return D @ T_model0, D[:3, :3] @ m

    def refine(self, ev: BeamEvent, q0: np.ndarray, T_model0: np.ndarray, m: np.ndarray,
               find: Callable[[np.ndarray, np.ndarray], BeamEvent | None]) -> BeamEvent:
        """An event found on the line linearised at the motion's start, found again on the line
        linearised at the event itself until its travel settles (absolute accuracy only; two or
        three rounds: the linearisation error shrinks by ~1e-2 a round)."""
        if self.true_kin is self.kin:
            return ev
        for _ in range(_REFINE_ROUNDS):
            again = find(*self.physical_line(q0, T_model0, m, ev.travel))
            if again is None:
                break
            settled = abs(again.travel - ev.travel) < 1e-11
            ev = again
            if settled:
                break
        return ev

    def record(self, ev: BeamEvent, T_model0: np.ndarray, m: np.ndarray, k: int) -> int:
        """Turn an event on the physical motion into the recorded model event."""
        exact = T_model0.copy()
        exact[:3, 3] = T_model0[:3, 3] + ev.travel * m
        noisy = exact.copy()
        if self.rng is not None and self.sensor.sigma > 0.0:  # entry and exit of a crossing averaged
            n_avg = 2 if ev.kind == "axis" else 1
            noisy[:3, 3] += self.rng.normal(0.0, self.sensor.sigma, (n_avg, 3)).mean(axis=0)
        T_phys = ev.T_world_flange_exact
        if ev.kind == "tip":
            point = T_phys[:3, :3] @ self.shape.tip + T_phys[:3, 3]
        else:
            tip = T_phys[:3, :3] @ self.shape.tip + T_phys[:3, 3]
            d = T_phys[:3, :3] @ self.shape.axis
            b, u = ev.beam_point, ev.beam_dir
            # the beam line's point nearest the tool axis
            w0 = b - tip
            bu, bd, ud = w0 @ u, w0 @ d, float(u @ d)
            s = (ud * bd - bu) / max(1.0 - ud * ud, 1e-12)
            point = b + s * u
        recorded = BeamEvent(
            kind=ev.kind, T_world_flange=read_only_array(noisy),
            T_world_flange_exact=read_only_array(exact), beam=ev.beam, beam_point=ev.beam_point,
            beam_dir=ev.beam_dir, travel=ev.travel, entry_travel=ev.entry_travel,
            exit_travel=ev.exit_travel, miss_distance=ev.miss_distance, on_shaft=ev.on_shaft)
        self.events.append(recorded)
        self.points.append(np.asarray(point, dtype=float))
        self.orient.append(k)
        return len(self.events) - 1

    def straight(self, kind: str, T_end: np.ndarray, k: int, what: str) -> np.ndarray:
        """IK of a straight pass / approach end; refuses a configuration flip on the way."""
        q_end = self.ik(T_end, what)
        if float(np.abs(q_end - self.q).max()) > math.radians(MAX_JOINT_STEP_DEG):
            raise _Skip(Words(N_("{what} would flip the arm's configuration on the way"), what=Words(what)),
                        reach=True)
        return q_end


# ------------------------------------------------------------------------------ the scan
def _same_beam(beam: int, detect: Callable[..., object], sensor: BeamSensor, shape: ToolShape,
               max_travel: float) -> Callable[[np.ndarray, np.ndarray], BeamEvent | None]:
    """``find(T_start, direction)`` for :meth:`_Planner.refine`: the event of ``beam`` that
    ``detect`` (``crossing_events`` or ``tip_on_beam``) finds on that line, exact."""

    def find(T_start: np.ndarray, direction: np.ndarray) -> BeamEvent | None:
        out = detect(T_start, direction, sensor, shape, max_travel=max_travel)
        events = out if isinstance(out, tuple) else (out,)
        return next((ev for ev in events if ev is not None and ev.beam == beam), None)

    return find


@dataclass(frozen=True, eq=False)
class _ScanFrame:
    """What every orientation of one scan shares (metres): the pass direction ``a`` (across the
    beams), half a pass ``W``, the heights ``h1`` and ``h2`` behind the believed tip at which the
    passes cross the beam, the ``clear``-ance of the approach start, the tool orientation before
    its tilt and turn ``R_base`` (tool X down, Y along the beam) and the inverse of the believed
    tool data ``T_ft_inv``."""

    a: np.ndarray
    W: float
    h1: float
    h2: float
    clear: float
    R_base: np.ndarray
    T_ft_inv: np.ndarray


def _scan_frame(sensor: BeamSensor, shape: ToolShape, c: BeamScanConfig, T_ft: np.ndarray) -> _ScanFrame:
    """The scan's shared geometry (:class:`_ScanFrame`).

    Raises:
        ControllerError: a beam within 30 deg of vertical.
    """
    u = np.array(sensor.direction)
    up = np.array([0.0, 0.0, 1.0])
    for k_beam, (_, u_k) in enumerate(sensor.beams):
        if float(np.linalg.norm(np.cross(up, u_k))) < 0.5:
            raise ControllerError(f"Beam {k_beam} must be roughly horizontal for the scan (it is within "
                                  "30 deg of vertical); set the beam sensor's direction across WORLD Z.")
    a, sin_min = _pass_direction(sensor)
    # half a pass: the shaft's radius, half the beam and the margin, measured across every beam
    W = (shape.radius + sensor.width / 2.0 + c.pass_margin_mm / 1000.0) / sin_min
    h1, h2 = (v / 1000.0 for v in c.pass_heights_mm)
    # tool X down, tool Y along the beam's horizontal direction, tool Z = X x Y
    u_flat = (u - (u @ up) * up) / np.linalg.norm(u - (u @ up) * up)
    R_base = np.column_stack((-up, u_flat, np.cross(-up, u_flat)))
    return _ScanFrame(a, W, h1, h2, c.clearance_mm / 1000.0, R_base, np.linalg.inv(T_ft))


def _scan_orientation(P: _Planner, k: int, spin: float, tilt: float, F: _ScanFrame) -> None:
    """One orientation of the scan (module docstring): the two passes, then the approach along
    the line of flange positions that keeps the tool axis on the beam; raises _Skip with the
    reason."""
    sensor = P.sensor
    b, u = np.array(sensor.point), np.array(sensor.direction)
    R_tool = _rot(u, math.radians(tilt)) @ F.R_base @ _rot(np.array([1.0, 0.0, 0.0]), math.radians(spin))
    x_w = R_tool[:, 0]  # believed working direction in WORLD (down-ish)

    def flange(tip: np.ndarray) -> np.ndarray:
        return _pose(R_tool, tip) @ F.T_ft_inv

    lift = F.clear + F.h2  # above everything of the beam device the tool may meet
    P.move_to(flange(b - F.W * F.a - lift * x_w), k, N_("The pose above the beam"))
    P.move_to(flange(b + F.h1 * x_w - F.W * F.a), k, N_("The start of the first pass"))
    f_axis, f_second = _passes(P, k, flange, x_w, F)
    # the line of flange positions that keeps the tool axis on the beam:
    # f(h) = f1 + (h - h1) / (h2 - h1) (f2 - f1)
    f1, f2 = f_axis
    g = (f2 - f1) / (F.h2 - F.h1)  # flange motion per unit of forward travel
    glen = float(np.linalg.norm(g))
    if glen < 0.5:
        raise _Skip(Words(N_("the passes put the tool axis along the beam")))
    m = g / glen
    f_start = f1 + (-F.clear - F.h1) * g
    if len(f_second) == 2:
        f_start, m = _aim_at_crossing(f1, f2, f_second[0], f_second[1], sensor, f_start, m)
    # retract beside the beam, then over to the approach start
    P.move_to(flange(b - F.W * F.a - F.clear * x_w), k, N_("The retract after the passes"))
    T_start = P.T.copy()
    T_start[:3, 3] = f_start
    T_start[:3, :3] = R_tool @ F.T_ft_inv[:3, :3]
    P.move_to(T_start, k, N_("The approach start"))
    _approach(P, k, T_start, m, max_travel=2.0 * F.clear * glen)


def _passes(P: _Planner, k: int, flange: Callable[[np.ndarray], np.ndarray], x_w: np.ndarray,
            F: _ScanFrame) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """The two sideways passes across the beam (the robot at the first one's start): their axis
    events recorded; returns the flange positions of the scanned beam's two axis events and of
    the second beam's (crossed beams; else none). Raises _Skip with the reason."""
    sensor, shape, c = P.sensor, P.shape, P.config
    b, a, W = np.array(sensor.point), F.a, F.W
    f_axis: list[np.ndarray] = []
    f_second: list[np.ndarray] = []  # the second beam's axis events (crossed beams)
    for j, (h, sgn) in enumerate(((F.h1, 1.0), (F.h2, -1.0))):
        if j == 1:
            P.move_to(flange(b + h * x_w + W * a), k, N_("The start of the second pass"))
        m = sgn * a
        T0 = P.T.copy()
        T_end = T0.copy()
        T_end[:3, 3] += 2.0 * W * m
        q_end = P.straight("pass", T_end, k, N_("The first pass") if j == 0 else N_("The second pass"))
        try:
            found = crossing_events(*P.physical_line(P.q, T0, m, 0.0), sensor, shape, max_travel=2.0 * W)
            found = tuple(P.refine(ev, P.q, T0, m, _same_beam(ev.beam, crossing_events, sensor, shape, 2.0 * W))
                          for ev in found)
        except ControllerError as exc:
            raise _Skip(Words(N_("the first pass did not cross the beam cleanly ({why})") if j == 0 else
                              N_("the second pass did not cross the beam cleanly ({why})"), why=_said(exc))) from None
        mine = [ev for ev in found if ev.beam == 0]
        found = tuple(ev for ev in found if ev.on_shaft)  # a crossing beyond the shaft is no axis event
        if not mine or not mine[0].on_shaft:
            raise _Skip(Words((N_("the first pass did not break the beam: the tool data is too far off for a "
                                  "pass margin of {margin} mm") if j == 0 else
                               N_("the second pass did not break the beam: the tool data is too far off for a "
                                  "pass margin of {margin} mm")) if not mine else
                              (N_("the first pass crossed the beam beyond the tool's shaft") if j == 0 else
                               N_("the second pass crossed the beam beyond the tool's shaft")),
                              margin=f"{c.pass_margin_mm:g}"))
        idx = tuple(P.record(ev, T0, m, k) for ev in found)
        for i in idx:
            (f_axis if P.events[i].beam == 0 else f_second).append(P.events[i].T_world_flange[:3, 3].copy())
        P.add_move("pass", T_end, q_end, k, length=2.0 * W, events=idx)
    return f_axis, f_second


def _approach(P: _Planner, k: int, T_start: np.ndarray, m: np.ndarray, *, max_travel: float) -> None:
    """The approach from ``T_start`` along ``m`` until the tip breaks the beam (crossed beams:
    both), its tip events recorded, and the retract to ``T_start``. Raises _Skip with the reason."""
    sensor, shape, c = P.sensor, P.shape, P.config
    try:
        ev = tip_on_beam(*P.physical_line(P.q, T_start, m, 0.0), sensor, shape, max_travel=max_travel)
        if ev is not None:
            ev = P.refine(ev, P.q, T_start, m, _same_beam(ev.beam, tip_on_beam, sensor, shape, max_travel))
    except ControllerError as exc:
        raise _Skip(Words(N_("the approach could not start clear of the beam ({why})"), why=_said(exc))) from None
    if ev is None:
        raise _Skip(Words(N_("the tip did not reach the beam on the approach: the tool "
                             "data is more than {clearance} mm off along the tool axis"), clearance=f"{c.clearance_mm:g}"))
    tips = [ev]
    if sensor.second_direction is not None:
        # crossed beams: the tip aimed at the crossing point breaks the other beam too; the
        # controller records both (two constraints across two beams: methods.md section 9)
        other = 1 - ev.beam
        b_o, u_o = sensor.beams[other]
        one = BeamSensor(b_o, u_o, width=sensor.width, sigma=sensor.sigma)
        try:
            ev2 = tip_on_beam(*P.physical_line(P.q, T_start, m, 0.0), one, shape, max_travel=max_travel)
            if ev2 is not None:
                ev2 = P.refine(ev2, P.q, T_start, m, _same_beam(0, tip_on_beam, one, shape, max_travel))
        except ControllerError:
            ev2 = None
        if ev2 is not None and ev2.miss_distance <= sensor.width / 4.0:
            tips.append(dataclasses.replace(ev2, beam=other))
    T_ev = T_start.copy()
    travel = max(e.travel for e in tips)  # the robot stops when the last beam broke
    T_ev[:3, 3] += travel * m
    q_ev = P.straight("approach", T_ev, k, N_("The approach"))
    idx = tuple(P.record(e, T_start, m, k) for e in sorted(tips, key=lambda e: e.travel))
    P.add_move("approach", T_ev, q_ev, k, length=travel, events=idx)
    P.move_to(T_start, k, N_("The retract after the approach"))


_NOTHING = Words.by(lambda tr: "")
"""No words (an empty msgid would say the catalog's header)."""


def _said(exc: BaseException) -> str:
    """An exception's words, :class:`Words` kept (said again in the reader's language)."""
    return exc.args[0] if len(exc.args) == 1 and isinstance(exc.args[0], Words) else str(exc)


def _lower_first(words: Words) -> Words:
    """``words`` starting in lower case inside a sentence, as English writes it; a translation
    as its translator wrote it."""
    def say(tr: Translator) -> str:
        said = words.text(tr)
        return said[:1].lower() + said[1:] if said == str(words) else said
    return Words.by(say)


def _scan_or_skip(P: _Planner, k: int, F: _ScanFrame) -> Words | None:
    """Scan orientation ``k``: None when done, else why it was skipped (a sentence); the moves
    and events of a try that failed are dropped. The tilt about the beam observes nothing
    (module docstring) and the turns only need to differ: when a pose of this orientation is
    out of reach, the other tilts and then turns a third of the way to the neighbours are
    tried before it is skipped."""
    c, n = P.config, P.config.n_orientations
    spin = 360.0 * k / n
    sign = 1.0 if k % 2 == 0 else -1.0
    tilts = (sign * c.tilt_deg, -sign * c.tilt_deg, 0.0) if c.tilt_deg > 0.0 else (0.0,)
    step = 120.0 / n
    tries = [(tilt, spin) for tilt in tilts] + [(0.0, spin + step), (0.0, spin - step)]
    saved = (P.q.copy(), P.T.copy(), len(P.moves), len(P.events))
    first_reason = _NOTHING
    for tilt, turn in tries:
        try:
            _scan_orientation(P, k, turn, tilt, F)
            return None
        except _Skip as exc:
            P.q, P.T = saved[0].copy(), saved[1].copy()
            del P.moves[saved[2]:]
            del P.events[saved[3]:], P.points[saved[3]:], P.orient[saved[3]:]
            if not exc.reach:  # the tool data or the beam: another pose does not help
                first_reason = exc.args[0]
                break
            first_reason = first_reason or exc.args[0]
    tried = ", ".join(f"{t:+.0f}" for t in tilts)
    more = Words.by(lambda tr: " " + tr.gettext("(tried tilts of {tilts} deg about the beam and turns of {turn_a} and "
                                                "{turn_b} deg)").format(tilts=tried, turn_a=f"{spin - step:.0f}",
                                                                        turn_b=f"{spin + step:.0f}")
                    ) if "out of reach" in first_reason else _NOTHING
    return Words(N_("Orientation {n} (turned {spin} deg about the tool axis) was skipped: {reason}{more}."),
                 n=str(k + 1), spin=f"{spin:.0f}", reason=_lower_first(first_reason), more=more)


def _checked_scan(kinematics: RobotKinematics, q_start_rad: np.ndarray, sensor: BeamSensor,
                  T_flange_tool_plan: np.ndarray, shape: ToolShape, true_kinematics: RobotKinematics | None,
                  config: BeamScanConfig) -> tuple[RobotKinematics, np.ndarray, np.ndarray]:
    """:func:`run_beam_scan`'s arguments checked: the physical robot, the start joints (rad) and
    the believed tool data (4x4, m).

    Raises:
        ControllerError: what is wrong with them.
    """
    if not isinstance(kinematics, RobotKinematics):
        raise ControllerError("run_beam_scan: kinematics must be a RobotKinematics.")
    true_kin = kinematics if true_kinematics is None else true_kinematics
    if not isinstance(true_kin, RobotKinematics) or tuple(true_kin.joint_names) != tuple(kinematics.joint_names):
        raise ControllerError("run_beam_scan: true_kinematics must be the same robot as the model (a "
                              "RobotKinematics with the same joints).")
    if not isinstance(sensor, BeamSensor) or not isinstance(shape, ToolShape):
        raise ControllerError("run_beam_scan: give a BeamSensor and a ToolShape.")
    if not isinstance(config, BeamScanConfig):
        raise ControllerError("run_beam_scan: config must be a BeamScanConfig.")
    q0 = kinematics.check_q(q_start_rad)
    T_ft = np.asarray(T_flange_tool_plan, dtype=float)
    if T_ft.shape != (4, 4) or not np.isfinite(T_ft).all():
        raise ControllerError("run_beam_scan: T_flange_tool_plan must be a finite 4x4 pose (m).")
    R_ft = T_ft[:3, :3]
    if np.abs(R_ft.T @ R_ft - np.eye(3)).max() > 1e-6 or np.linalg.det(R_ft) <= 0.0:
        raise ControllerError("run_beam_scan: T_flange_tool_plan has no proper rotation.")
    return true_kin, q0, T_ft


def run_beam_scan(kinematics: RobotKinematics, q_start_rad: np.ndarray, sensor: BeamSensor,
                  T_flange_tool_plan: np.ndarray, shape: ToolShape, *,
                  true_kinematics: RobotKinematics | None = None,
                  config: BeamScanConfig = BeamScanConfig(),
                  rng: np.random.Generator | None = None) -> BeamScan:
    """Run the automatic beam scan (the module docstring describes the pattern).

    Args:
        kinematics: the controller's (nominal) robot model: plans, IK, recorded poses.
        q_start_rad: joint values where the scan starts (rad).
        sensor: the beam device (its first beam is scanned; events of a second beam crossed
            on the way are recorded too).
        T_flange_tool_plan: (4, 4) the tool data the controller believes, m.
        shape: the physical tool the beam sees (its TRUE frame).
        true_kinematics: the physical robot (default: the model itself).
        config: the scan's speeds and distances.
        rng: random generator for the repeatability noise (``sensor.sigma``); None: exact.

    Returns:
        A frozen :class:`BeamScan`.

    Raises:
        ControllerError: bad arguments, or no orientation could be scanned (the reasons).
    """
    true_kin, q0, T_ft = _checked_scan(kinematics, q_start_rad, sensor, T_flange_tool_plan, shape,
                                       true_kinematics, config)
    F = _scan_frame(sensor, shape, config, T_ft)
    P = _Planner(kin=kinematics, true_kin=true_kin, T_ft_plan=T_ft, sensor=sensor, shape=shape,
                 config=config, rng=rng, q=q0.copy(), T=kinematics.T_world_flange(q0))
    n = config.n_orientations
    skipped = [why for why in (_scan_or_skip(P, k, F) for k in range(n)) if why is not None]
    if not P.events:
        raise ControllerError(Words.by(lambda tr: " ".join((
            tr.gettext("The beam scan could not run at any tool orientation:"), *(why.text(tr) for why in skipped),
            tr.gettext("Move the beam sensor closer to the robot or check the tool data.")))))
    length = float(sum(mv.length_m for mv in P.moves))
    duration = float(sum(mv.duration_s for mv in P.moves))
    return BeamScan(
        events=tuple(P.events), orientation_index=tuple(P.orient), moves=tuple(P.moves),
        path_length_m=length, duration_s=duration, skipped=tuple(skipped),
        q_end_rad=read_only_array(P.q), beam_points_world_m=read_only_array(np.array(P.points)),
        sensor=sensor, n_orientations_planned=n, config=config)
