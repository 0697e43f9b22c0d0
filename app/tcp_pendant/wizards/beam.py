"""The "Automatic (beam)" wizard (methods.md section 9).

A BullsEye / TRACC style calibration: the controller itself moves the mounted tool through a
light barrier at 3 to 5 tool orientations (sideways passes that cross the shaft, approaches
until the tip breaks the beam) and records the flange pose at each beam event. Tip events give
the TCP (``tcpcal.solve_beam``), axis events the tool direction (``tcpcal.solve_beam_axis``).

The state machine stays free of viser and of the controller (wizards import tcpcal only): it
has one step, run by the controller (role "scan", ``describe.BY_CONTROLLER``: no Record, no
auto-touch). Finish makes the caller run the scan (``CalibrationWorkflow.controller_job``; the
app runs it in a worker thread) and hand it in with :meth:`BeamWizard.give_scan` (any object
shaped like ``controller.beam_scan.BeamScan``), together with the rotation of the tool data the
controller planned with and the trainee's last manual calibration of the same tool (for the
comparison the result shows); only then can the wizard finish.

The beam measures the TCP and the tool's working direction (TOOL X), not the turn of the tool
about that direction: the TOOL frame the result saves is the planning (nominal) orientation
turned by the smallest rotation that brings its X onto the measured direction, and says so.

The session record stores the scan's events (recorded flange poses, beams), its duration and
path length, the planning rotation and the manual comparison in the wizard's params, so a
replay rebuilds the same result without a robot; all of it is checked and bounded on load (a
record is untrusted input). Figures derived from the hidden truth are kept under a ``"truth"``
key, which an honest (classroom) record drops.

Units: poses and beams in metres (as the controller gives them), fed to tcpcal in mm; every
``*_mm`` figure in mm, angles in degrees, times in seconds.
"""

from __future__ import annotations

import datetime as _dt
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, ClassVar, Literal

import numpy as np
from scipy.spatial.transform import Rotation

from tcpcal.beam import BeamAxisResult, BeamResult, solve_beam, solve_beam_axis
from tcpcal.errors import TcpcalError
from tcpcal.tool import Tool, abc_deg_from_rotation
from tcpcal.validation import read_only_array

from tcp_pendant.json_shapes import JsonRecord
from tcp_pendant.translation import N_
from tcp_pendant.wizards.base import (
    M_TO_MM,
    CalibrationFailedError,
    StartContext,
    StepInfo,
    StepSpec,
    Wizard,
    WizardError,
    WizardResult,
    WizardStateError,
    check_pose_m,
    finite_number,
    mm3,
)
from tcp_pendant.wizards.solver_words import solver_warnings
from tcp_pendant.wizards.describe import BY_CONTROLLER, StepRole, WizardOption, WizardStart

if TYPE_CHECKING:
    from tcp_pendant.controller.beam import BeamEvent
    from tcp_pendant.controller.beam_scan import BeamScan

__all__ = [
    "BeamWizard",
    "BeamWizardResult",
    "MAX_SCAN_EVENTS",
    "ManualComparison",
    "RecordedScan",
    "ScanEvent",
    "wall_time_s",
]

MAX_SCAN_EVENTS = 100
"""Most events a stored scan may hold (5 orientations x 3 events x 2 crossed beams is 30)."""
MAX_SKIPPED = 10
"""Most skipped-orientation reasons a stored scan may hold."""
MAX_BEAM_COORD_M = 100.0
"""Largest beam point coordinate a stored scan may give, metres (a cell is a few metres)."""
MAX_DURATION_S = 1e5
MAX_PATH_M = 1e4
MAX_WALL_TIME_S = 1e7
_MAX_TEXT = 200          # characters kept of a stored text (the record is untrusted input)
_GRADES = ("good", "fair", "poor")


def _vector(value: object, what: str, *, limit: float) -> np.ndarray:
    if not (isinstance(value, (list, tuple, np.ndarray)) and len(value) == 3):
        raise WizardError(f"The beam scan's {what} must be 3 numbers, got {value!r:.60}.")
    return np.array([finite_number(v, f"beam scan's {what}", low=-limit, high=limit) for v in value], dtype=float)


def _rotation(value: object, what: str) -> np.ndarray:
    try:
        R = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise WizardError(f"The {what} must be a 3x3 rotation matrix.") from None
    if R.shape != (3, 3) or not np.isfinite(R).all() or not np.allclose(R.T @ R, np.eye(3), atol=1e-6) \
            or np.linalg.det(R) < 0.0:
        raise WizardError(f"The {what} must be a proper 3x3 rotation matrix (orthonormal, det +1).")
    return R


@dataclass(frozen=True, eq=False)
class ScanEvent:
    """One beam event of a scan, as the controller recorded it (names as ``BeamEvent``'s).

    Attributes:
        kind: "tip" (the tool tip on the beam line) or "axis" (the shaft crossed sideways,
            entry and exit averaged).
        T_world_flange: (4,4) recorded flange pose, WORLD, metres.
        beam: index of the beam that broke (0, or 1 for a second, crossed beam).
        beam_point: (3,) a point of that beam's line, WORLD, metres.
        beam_dir: (3,) its unit direction, WORLD.
        on_shaft: axis events: the beam crossed the cylindrical shaft (the average is on the
            tool axis; only these are used); tip events: True.
        orientation: the scan orientation (0-based) the event belongs to.
    """

    kind: Literal["tip", "axis"]
    T_world_flange: np.ndarray
    beam: int
    beam_point: np.ndarray
    beam_dir: np.ndarray
    on_shaft: bool
    orientation: int

    @classmethod
    def of(cls, event: BeamEvent, orientation: int) -> "ScanEvent":
        """From a ``controller.beam.BeamEvent``, checked as a stored one."""
        return cls.from_dict({"kind": event.kind, "T_world_flange_m": np.asarray(event.T_world_flange).tolist(),
                              "beam": int(event.beam), "beam_point_m": list(np.asarray(event.beam_point, float)),
                              "beam_dir": list(np.asarray(event.beam_dir, float)),
                              "on_shaft": bool(event.on_shaft), "orientation": int(orientation)})

    def to_dict(self) -> dict[str, object]:
        return {"kind": self.kind, "T_world_flange_m": self.T_world_flange.tolist(), "beam": self.beam,
                "beam_point_m": self.beam_point.tolist(), "beam_dir": self.beam_dir.tolist(),
                "on_shaft": self.on_shaft, "orientation": self.orientation}

    @classmethod
    def from_dict(cls, d: object) -> "ScanEvent":
        """Inverse of :meth:`to_dict`, checked (kind, a rigid pose, a finite beam point within
        100 m, a nonzero direction, beam 0 or 1, orientation 0..99).

        Raises:
            WizardError: naming what is wrong.
        """
        if not isinstance(d, Mapping):
            raise WizardError("Each stored beam event must be an object.")
        kind = d.get("kind")
        if kind not in ("tip", "axis"):
            raise WizardError(f"A stored beam event's kind must be \"tip\" or \"axis\", got {kind!r:.40}.")
        T = check_pose_m(d.get("T_world_flange_m"), what="flange pose of a beam event")
        beam = d.get("beam", 0)
        if isinstance(beam, bool) or beam not in (0, 1):
            raise WizardError(f"A stored beam event's beam must be 0 or 1, got {beam!r:.40}.")
        orientation = d.get("orientation", 0)
        if isinstance(orientation, bool) or not isinstance(orientation, int) or not 0 <= orientation < 100:
            raise WizardError(f"A stored beam event's orientation must be a whole number 0..99, got "
                              f"{orientation!r:.40}.")
        b = _vector(d.get("beam_point_m"), "beam point (m)", limit=MAX_BEAM_COORD_M)
        u = _vector(d.get("beam_dir"), "beam direction", limit=1e6)
        n = float(np.linalg.norm(u))
        if not n > 1e-9:
            raise WizardError("A stored beam event's beam direction is the zero vector.")
        return cls(kind, read_only_array(T), int(beam), read_only_array(b), read_only_array(u / n), bool(d.get("on_shaft", True)),
                   int(orientation))


@dataclass(frozen=True, eq=False)
class RecordedScan:
    """What the wizard keeps of a scan (and what a replay rebuilds): its events, how long it
    takes on a real robot and what could not be run. Attribute names follow
    ``controller.beam_scan.BeamScan`` where they exist; ``moves`` is empty (a record keeps no
    motion to animate).

    Attributes:
        events: the events in order.
        duration_s: time the scan takes on a real robot (sum of move length / speed), s.
        path_length_m: the flange's path length, m.
        skipped: plain-words reasons for orientations that could not be run.
    """

    events: tuple[ScanEvent, ...]
    duration_s: float
    path_length_m: float
    skipped: tuple[str, ...] = ()
    moves: tuple[object, ...] = field(default=())
    q_end_rad: np.ndarray | None = None

    @property
    def orientation_index(self) -> tuple[int, ...]:
        """The scan orientation of each event (0-based)."""
        return tuple(e.orientation for e in self.events)

    @classmethod
    def of(cls, scan: BeamScan | RecordedScan) -> "RecordedScan":
        """From a ``controller.beam_scan.BeamScan``, checked as a stored one."""
        if isinstance(scan, RecordedScan):
            return scan
        events = tuple(scan.events)
        index = tuple(getattr(scan, "orientation_index", ())) or (0,) * len(events)
        if len(index) != len(events):
            raise WizardError("The scan gives an orientation for each event; it does not here.")
        out = cls.from_dict({"events": [ScanEvent.of(e, int(k)).to_dict() for e, k in zip(events, index)],
                             "duration_s": float(scan.duration_s), "path_length_m": float(scan.path_length_m),
                             "skipped": [str(s) for s in getattr(scan, "skipped", ())]})
        return out

    def to_dict(self) -> dict[str, object]:
        return {"events": [e.to_dict() for e in self.events], "duration_s": self.duration_s,
                "path_length_m": self.path_length_m, "skipped": list(self.skipped)}

    @classmethod
    def from_dict(cls, d: object) -> "RecordedScan":
        """Inverse of :meth:`to_dict`, checked and bounded (at most :data:`MAX_SCAN_EVENTS`
        events, :data:`MAX_SKIPPED` reasons of at most 200 characters, finite times).

        Raises:
            WizardError: naming what is wrong.
        """
        if not isinstance(d, Mapping):
            raise WizardError("The stored beam scan must be an object.")
        events = d.get("events")
        if not isinstance(events, list) or len(events) > MAX_SCAN_EVENTS:
            raise WizardError(f"The stored beam scan's events must be a list of at most {MAX_SCAN_EVENTS}.")
        skipped = d.get("skipped", [])
        if not isinstance(skipped, list) or len(skipped) > MAX_SKIPPED:
            raise WizardError(f"The stored beam scan's skipped orientations must be a list of at most {MAX_SKIPPED}.")
        return cls(tuple(ScanEvent.from_dict(e) for e in events),
                   finite_number(d.get("duration_s"), "beam scan's duration (s)", low=0.0, high=MAX_DURATION_S),
                   finite_number(d.get("path_length_m"), "beam scan's path length (m)", low=0.0, high=MAX_PATH_M),
                   tuple(str(s)[:_MAX_TEXT] for s in skipped))


def _parse_time(text: str) -> _dt.datetime | None:
    try:
        t = _dt.datetime.fromisoformat(str(text).replace("Z", "+00:00"))
    except ValueError:
        return None
    return t if t.tzinfo is not None else t.replace(tzinfo=_dt.timezone.utc)


def wall_time_s(started_at: str, finished_at: str) -> float | None:
    """Seconds from ``started_at`` to ``finished_at`` (ISO 8601), None if unreadable."""
    a, b = _parse_time(started_at), _parse_time(finished_at)
    if a is None or b is None:
        return None
    return max((b - a).total_seconds(), 0.0)


@dataclass(frozen=True)
class ManualComparison:
    """The trainee's last finished manual calibration of the same physical tool in the session,
    for the result's "automatic vs manual" lesson.

    Attributes:
        title: its method's label ("XYZ 4-point").
        kind: its wizard kind.
        run_number: its number in the session (1-based, as the Resume list counts).
        wall_time_s: wall time from its start to its result, s.
        position_error_mm: its TCP error against the true tool, mm (None: no truth known).
        direction_error_deg: the error of its tool X (working direction), deg (None: it
            calibrated no orientation, or no truth).
        grade: its grade against the truth ("good" | "fair" | "poor"), or None.
        touches / auto_touches: its recorded touches, and how many of them Auto-touch made
            (0: all by hand; the lesson says who did the work).
    """

    title: str
    kind: str
    run_number: int
    wall_time_s: float
    position_error_mm: float | None = None
    direction_error_deg: float | None = None
    grade: str | None = None
    touches: int = 0
    auto_touches: int = 0

    def to_dict(self) -> dict[str, object]:
        """JSON-ready; the truth-derived figures under ``"truth"`` (an honest record drops it)."""
        truth = None
        if self.position_error_mm is not None:
            truth = {"position_error_mm": self.position_error_mm,
                     "direction_error_deg": self.direction_error_deg, "grade": self.grade}
        return {"title": self.title, "kind": self.kind, "run_number": self.run_number,
                "wall_time_s": self.wall_time_s, "touches": self.touches, "auto_touches": self.auto_touches,
                "truth": truth}

    @classmethod
    def from_dict(cls, d: object) -> "ManualComparison":
        """Inverse of :meth:`to_dict`, checked (texts cut to 200 characters, finite figures).

        Raises:
            WizardError: naming what is wrong.
        """
        if not isinstance(d, Mapping):
            raise WizardError("The stored manual calibration must be an object.")
        n = d.get("run_number")
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= 100_000:
            raise WizardError(f"The stored manual calibration's number must be a whole number >= 1, got {n!r:.40}.")
        truth = d.get("truth")
        pos = ang = grade = None
        if truth is not None:
            if not isinstance(truth, Mapping):
                raise WizardError("The stored manual calibration's truth must be an object or null.")
            pos = finite_number(truth.get("position_error_mm"), "beam scan's manual position error (mm)", low=0.0, high=1e6)
            if truth.get("direction_error_deg") is not None:
                ang = finite_number(truth.get("direction_error_deg"), "beam scan's manual direction error (deg)", low=0.0, high=180.0)
            grade = truth.get("grade")
            if grade is not None and grade not in _GRADES:
                raise WizardError(f"The stored manual calibration's grade must be one of {_GRADES}, got {grade!r:.40}.")
        counts = []
        for key in ("touches", "auto_touches"):          # optional: records before they were kept
            v = d.get(key, 0)
            if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v <= 1000:
                raise WizardError(f"The stored manual calibration's {key} must be a whole number 0..1000, "
                                  f"got {v!r:.40}.")
            counts.append(v)
        return cls(str(d.get("title", ""))[:_MAX_TEXT], str(d.get("kind", ""))[:_MAX_TEXT], n,
                   finite_number(d.get("wall_time_s"), "beam scan's manual wall time (s)", low=0.0, high=MAX_WALL_TIME_S),
                   pos, ang, grade, counts[0], min(counts[1], counts[0]))


@dataclass(frozen=True, eq=False, kw_only=True)
class BeamWizardResult(WizardResult):
    """The beam wizard's result. Lengths in mm (FLANGE), angles in degrees, times in seconds.

    ``tcp_mm`` and ``ci95_mm`` are the TCP solve's; ``per_touch_error_mm`` its residual per tip
    event (distance of the computed tip from the beam line); ``rotation`` / ``abc_deg`` the
    TOOL frame to save (see the module docstring).

    Attributes:
        scan: the scan (the controller's ``BeamScan`` when run here; a :class:`RecordedScan`,
            without moves, after a replay).
        events: the scan's events as the wizard used them.
        beam_result: ``tcpcal.solve_beam``'s result (tip events).
        axis_result: ``tcpcal.solve_beam_axis``'s result (axis events), None when the tool
            direction could not be measured.
        direction_flange: the measured tool direction (unit, FLANGE), None as above.
        direction_ci95_deg: its 95 % cone half-angle (NaN without redundancy), None as above.
        direction_turn_deg: the angle the planning orientation's X was turned by.
        R_flange_tool_base: (3,3) the planning (nominal) orientation the saved frame starts from.
        tip_event_indices, axis_event_indices: indices into ``events`` of the events used.
        duration_s: the scan's time on a real robot.
        path_length_m: its path length, m.
        manual: the trainee's last manual calibration of the same tool, or None.
    """

    scan: BeamScan | RecordedScan
    events: tuple[ScanEvent, ...]
    beam_result: BeamResult
    axis_result: BeamAxisResult | None
    direction_flange: tuple[float, float, float] | None
    direction_ci95_deg: float | None
    direction_turn_deg: float | None
    R_flange_tool_base: np.ndarray
    tip_event_indices: tuple[int, ...]
    axis_event_indices: tuple[int, ...]
    duration_s: float
    path_length_m: float
    manual: ManualComparison | None = None

    @property
    def figures(self) -> dict[str, float]:
        """The base figures plus the beam's: events, direction 95 % cone, scan time."""
        out = super().figures
        out["n_tip_events"] = float(len(self.tip_event_indices))
        out["n_axis_events"] = float(len(self.axis_event_indices))
        if self.direction_ci95_deg is not None and math.isfinite(self.direction_ci95_deg):
            out["direction_ci95_deg"] = float(self.direction_ci95_deg)
        out["scan_duration_s"] = float(self.duration_s)
        return out

    def event_points_world_m(self) -> tuple[np.ndarray, ...]:
        """Where each event met the beam by the measured tool (WORLD, metres), for a marker:
        tip events the computed tip; axis events the point of the measured tool axis closest to
        the beam line (the computed tip when the direction was not measured)."""
        t = np.asarray(self.tcp_mm, dtype=float) / M_TO_MM
        d = None if self.direction_flange is None else np.asarray(self.direction_flange, dtype=float)
        out = []
        for e in self.events:
            R, f = e.T_world_flange[:3, :3], e.T_world_flange[:3, 3]
            tip = R @ t + f
            if e.kind == "axis" and d is not None:
                a = R @ d                                  # the tool axis tip + lam a vs the beam line
                w, g = e.beam_dir, tip - e.beam_point
                den = 1.0 - float(a @ w) ** 2
                if den > 1e-12:
                    lam = (float(g @ w) * float(a @ w) - float(g @ a)) / den
                    tip = tip + lam * a
            out.append(tip)
        return tuple(out)


def _minimal_turn(x_from: np.ndarray, x_to: np.ndarray) -> Rotation:
    """The smallest rotation taking unit ``x_from`` onto unit ``x_to``."""
    axis = np.cross(x_from, x_to)
    s, c = float(np.linalg.norm(axis)), float(x_from @ x_to)
    if s < 1e-15:
        if c > 0.0:
            return Rotation.identity()
        perp = np.cross(x_from, [1.0, 0.0, 0.0] if abs(x_from[0]) < 0.9 else [0.0, 1.0, 0.0])
        return Rotation.from_rotvec(math.pi * perp / np.linalg.norm(perp))
    return Rotation.from_rotvec(axis / s * math.atan2(s, c))


class BeamWizard(Wizard):
    """Automatic (beam) calibration of the mounted tool (see the module docstring).

    Args:
        n_orientations: tool orientations the scan runs (3..5).
        scan_speed_mm_s: speed of the measuring motions, mm/s (5..250).
    """

    kind: ClassVar[str] = "beam"
    title: ClassVar[str] = N_("Automatic (beam)")
    blurb: ClassVar[str] = N_("Calibrates the **TCP and the tool direction** automatically, as BullsEye / "
                            "TRACC: the controller moves the tool through a light beam at 3 to 5 "
                            "orientations and records the flange pose at every beam break. Shows the "
                            "events, the time the scan takes on a real robot and your manual "
                            "calibration of the same tool side by side.")
    calibrates: ClassVar[str] = N_("the TCP and the tool direction")
    rank: ClassVar[int] = 60
    math_view: ClassVar[str | None] = "beam"
    in_exercises: ClassVar[bool] = False
    controller_job: ClassVar[str | None] = "beam_scan"
    result_view: ClassVar[Literal["touches", "spin_check", "beam_scan"]] = "beam_scan"
    """The scan measures the tool by itself: refused in a classroom exercise."""
    MIN_ORIENTATIONS: ClassVar[int] = 3
    MAX_ORIENTATIONS: ClassVar[int] = 5
    step_roles = (StepRole("scan", N_("the controller runs the beam scan itself"), BY_CONTROLLER),)
    options = (
        WizardOption("n_orientations", N_("Scan orientations"), "int", default=4, minimum=MIN_ORIENTATIONS,
                     maximum=MAX_ORIENTATIONS,
                     hint=N_("Tool orientations the scan runs (each: two sideways passes and one tip approach).")),
        WizardOption("scan_speed_mm_s", N_("Scan speed (mm/s)"), "int", default=50, minimum=5, maximum=250,
                     hint=N_("Speed of the measuring motions through the beam (real devices: 20-100 mm/s).")),
    )
    needs_tool = "mounted"

    def __init__(self, *, n_orientations: int = 4, scan_speed_mm_s: float = 50.0) -> None:
        super().__init__()
        n = finite_number(n_orientations, "beam scan's number of orientations")
        if n != int(n) or not self.MIN_ORIENTATIONS <= n <= self.MAX_ORIENTATIONS:
            raise WizardError(f"The beam scan runs {self.MIN_ORIENTATIONS} to {self.MAX_ORIENTATIONS} "
                              f"orientations, got {n_orientations!r:.40}.")
        speed = finite_number(scan_speed_mm_s, "beam scan's scan speed (mm/s)")
        if not 5.0 <= speed <= 250.0:
            raise WizardError(f"The scan speed must be 5 to 250 mm/s, got {scan_speed_mm_s!r:.40}.")
        self.n_orientations = int(n)
        self.scan_speed_mm_s = speed
        self._scan: RecordedScan | None = None
        self._live_scan: BeamScan | RecordedScan | None = None
        self._R_base: np.ndarray | None = None
        self._manual: ManualComparison | None = None

    @classmethod
    def start(cls, ctx: StartContext, options: JsonRecord) -> WizardStart:
        """For the mounted tool (its truth grades the TCP and the tool direction)."""
        return WizardStart(cls(n_orientations=options.get("n_orientations", 4),
                               scan_speed_mm_s=options.get("scan_speed_mm_s", 50)),
                           true_tool=ctx.mounted_tool)

    # ----- the one step: the controller's ----------------------------------------------------
    def _step_specs(self) -> list[StepSpec]:
        _ = self._tr.gettext
        return [StepSpec(role="scan", title=_("Beam scan"),
                         instruction=_("Nothing to touch: press Finish and the controller runs the scan "
                                       "itself. At {n} tool orientations it passes the "
                                       "shaft sideways through the beam twice and approaches until the tip "
                                       "breaks it, recording the flange pose at every event "
                                       "(measuring motions at {speed} mm/s).").format(
                                           n=self.n_orientations, speed=f"{self.scan_speed_mm_s:g}"))]

    @property
    def blocked_reason(self) -> str | None:
        """Record is never possible: the controller records the scan's events itself."""
        base = super().blocked_reason
        if base is not None or self._status != "in_progress":
            return base
        return self._tr.gettext("The controller runs this step itself: press Finish to run the scan "
                                "(nothing to record by hand).")

    @property
    def can_next(self) -> bool:
        """Finish is possible while in progress (it runs the scan when none is handed in yet)."""
        return self._status == "in_progress"

    @property
    def scan_pending(self) -> bool:
        """In progress without a scan: Finish must run one first (the workflow's controller job)."""
        return self._status == "in_progress" and self._scan is None

    @property
    def scan(self) -> RecordedScan | None:
        """The scan handed in (what the wizard keeps of it), or None."""
        return self._scan

    @property
    def R_flange_tool_base(self) -> np.ndarray | None:
        """The planning (nominal) orientation handed in with the scan, or None."""
        return None if self._R_base is None else self._R_base.copy()

    @property
    def manual(self) -> ManualComparison | None:
        return self._manual

    def give_scan(self, scan: BeamScan | RecordedScan, *, R_flange_tool_base: np.ndarray,
                  manual: ManualComparison | None = None) -> None:
        """Hand in the scan the controller ran (a ``BeamScan`` or :class:`RecordedScan`).

        Args:
            scan: the scan.
            R_flange_tool_base: (3,3) the orientation of the tool data the controller planned
                with (the saved frame is this one turned onto the measured direction).
            manual: the trainee's last manual calibration of the same tool, or None.

        Raises:
            WizardStateError: the wizard is finished (a wizard cancelled half-way keeps the scan
                and shows it when resumed and finished).
            WizardError: a malformed scan (names what).
        """
        if self.finished_result is not None:
            raise WizardStateError(self._tr.gettext("The beam wizard is finished already; press Back to scan again."))
        recorded = RecordedScan.of(scan)
        R = _rotation(R_flange_tool_base, "planning tool orientation")
        if manual is not None and not isinstance(manual, ManualComparison):
            raise WizardError("The manual calibration to compare with must be a ManualComparison.")
        self._scan, self._live_scan, self._R_base, self._manual = recorded, scan, R, manual

    # No pose is ever recorded (``recorded_poses`` stays empty: the classroom counts no touch);
    # the step counts as done once a scan is handed in.
    def _info(self, i: int, spec: StepSpec, n: int) -> StepInfo:
        return replace(super()._info(i, spec, n), recorded=self._scan is not None)

    @property
    def progress(self) -> float:
        """0 before the scan, 0.5 with the scan handed in, 1 with the result."""
        return ((self._scan is not None) + (self._status == "complete")) / 2.0

    def next(self) -> StepInfo | WizardResult:
        """Finish (the only step); refused with words before a scan was handed in."""
        if self._status != "in_progress":
            raise self._next_refusal()
        return self.finish()

    def finish(self) -> WizardResult:
        """Compute the result from the scan handed in; refused with words before one was.

        Raises:
            WizardStateError: no scan yet, or the wizard was cancelled.
            CalibrationFailedError: the events cannot give a TCP (the wizard stays on its step).
        """
        if self._status == "cancelled":
            raise self._cancelled_refusal()
        if self._scan is None:
            raise self._no_scan_refusal()
        try:
            result = self._compute([])
        except TcpcalError as exc:
            raise CalibrationFailedError(str(exc), exc) from exc
        self._result, self._status, self._index = result, "complete", 0
        return result

    def clear_step(self) -> None:
        """Forget the scan (a new Finish runs another one)."""
        super().clear_step()
        self._scan = self._live_scan = None

    def back(self) -> StepInfo:
        """From the result back to the scan step, forgetting the scan: Finish scans again (the
        scan is the controller's, nothing the trainee recorded is lost)."""
        was_complete = self._status == "complete"
        step = super().back()
        if was_complete:
            self.clear_step()
        return step

    def _no_scan_refusal(self) -> WizardStateError:
        return WizardStateError(self._tr.gettext("Run the scan first: press Finish (the controller moves the tool "
                                                 "through the beam)."))

    # ----- result -------------------------------------------------------------------------
    def _recompute(self) -> WizardResult | None:
        """The result from the scan handed in (no recorded poses)."""
        return None if self._scan is None else self._compute([])

    def _compute(self, poses: list[np.ndarray]) -> WizardResult:
        scan, R_base = self._scan, self._R_base
        if scan is None or R_base is None:
            raise self._no_scan_refusal()
        _, n_ = self._tr.gettext, self._tr.ngettext
        events = scan.events
        tips = tuple(i for i, e in enumerate(events) if e.kind == "tip")
        if len(tips) < 2:
            skipped = "; ".join(scan.skipped)
            few = n_("The scan gave {n} tip event; the TCP needs at least 2 at orientations turned "
                     "about the tool axis. Move the robot so the beam device is within reach and scan again.",
                     "The scan gave {n} tip events; the TCP needs at least 2 at orientations turned "
                     "about the tool axis. Move the robot so the beam device is within reach and scan again.",
                     len(tips)).format(n=len(tips))
            if skipped:
                few = _("{words} (skipped: {skipped})").format(words=few.removesuffix("."), skipped=skipped)
            raise CalibrationFailedError(few)

        def arrays(idx: Sequence[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
            T = np.array([events[i].T_world_flange for i in idx])
            return (T[:, :3, :3], T[:, :3, 3] * M_TO_MM, np.array([events[i].beam_point for i in idx]) * M_TO_MM,
                    np.array([events[i].beam_dir for i in idx]))

        res = solve_beam(*arrays(tips))
        warnings = solver_warnings(res.warnings, tr=self._tr)
        axes = tuple(i for i, e in enumerate(events) if e.kind == "axis" and e.on_shaft)
        axis_res: BeamAxisResult | None = None
        if len(axes) >= 2:
            try:
                axis_res = solve_beam_axis(*arrays(axes), res.tcp)
                warnings.extend(solver_warnings(axis_res.warnings, tr=self._tr))
            except TcpcalError as exc:
                warnings.append(_("The tool direction could not be measured: {reason}").format(reason=exc))
        else:
            warnings.append(n_("The scan gave {n} usable sideways crossing; the tool direction "
                               "needs 2 at orientations turned about the tool axis.",
                               "The scan gave {n} usable sideways crossings; the tool direction "
                               "needs 2 at orientations turned about the tool axis.", len(axes)).format(n=len(axes)))
        for reason in scan.skipped:
            warnings.append(_("Skipped: {reason}").format(reason=reason))
        R_new, turn = R_base, None
        direction = ci_deg = None
        if axis_res is not None:
            d = np.asarray(axis_res.direction, dtype=float)
            x0 = R_base[:, 0] / np.linalg.norm(R_base[:, 0])
            R_new = _minimal_turn(x0, d).as_matrix() @ R_base
            turn = float(np.degrees(math.atan2(float(np.linalg.norm(np.cross(x0, d))), float(x0 @ d))))
            direction, ci_deg = mm3(d), float(axis_res.ci95_angle_deg)
        notes = ((_("The beam measures the TCP and the tool direction (TOOL X), not the turn about it: the "
                    "TOOL frame to save is the planning orientation turned by the smallest rotation that "
                    "puts its X on the measured direction.") if turn is not None else
                  _("The beam measures the TCP and the tool direction (TOOL X), not the turn about it: the "
                    "TOOL frame to save is the planning orientation turned by nothing (the direction was "
                    "not measured).")),)
        scan_obj = self._live_scan if self._live_scan is not None else scan
        return BeamWizardResult(
            wizard=self.kind, method="beam", tcp_mm=mm3(res.tcp),
            abc_deg=mm3(abc_deg_from_rotation(R_new)), rotation=np.array(R_new), tcp_result=res,  # type: ignore[arg-type]
            per_touch_error_mm=tuple(float(e) for e in res.residuals),
            mean_error_mm=float(res.mean_error), max_error_mm=float(res.max_error),
            rms_error_mm=float(res.rms_error), ci95_mm=float(res.ci95_radius),
            warnings=tuple(warnings), notes=notes,
            scan=scan_obj, events=events, beam_result=res, axis_result=axis_res,
            direction_flange=direction, direction_ci95_deg=ci_deg, direction_turn_deg=turn,
            R_flange_tool_base=read_only_array(R_base), tip_event_indices=tips, axis_event_indices=axes,
            duration_s=scan.duration_s, path_length_m=scan.path_length_m, manual=self._manual)

    def to_tool(self, name: str) -> Tool:
        """The tool with the measured TCP and the planning orientation turned onto the measured
        direction (calibration method "beam")."""
        res = self._require_result()
        assert res.abc_deg is not None
        return Tool(name=name, tcp_mm=res.tcp_mm, abc_deg=res.abc_deg,
                    calibration=self._calibration(res, res.figures))

    # ----- serialisation ------------------------------------------------------------------
    def _params(self) -> dict[str, object]:
        return {"n_orientations": self.n_orientations, "scan_speed_mm_s": self.scan_speed_mm_s,
                "scan": None if self._scan is None else self._scan.to_dict(),
                "R_flange_tool_base": None if self._R_base is None else self._R_base.tolist(),
                "manual": None if self._manual is None else self._manual.to_dict()}

    @classmethod
    def _from_params(cls, params: JsonRecord) -> "BeamWizard":
        if not isinstance(params, Mapping):
            raise WizardError("The beam wizard's stored params must be an object.")
        return cls(n_orientations=params.get("n_orientations", 4),
                   scan_speed_mm_s=params.get("scan_speed_mm_s", 50.0))

    def _load_state(self, d: JsonRecord) -> None:
        """The stored scan is handed in before the base class finishes a complete wizard (a
        replay runs no robot); scan, planning orientation and manual comparison are checked."""
        params = d.get("params")
        stored = params.get("scan") if isinstance(params, Mapping) else None
        if stored is None:
            super()._load_state({**d, "poses": {}, "resume_status": "in_progress",
                                 "status": d.get("status") if d.get("status") == "cancelled" else "in_progress"})
            return
        assert isinstance(params, Mapping)
        scan = RecordedScan.from_dict(stored)
        R = _rotation(params.get("R_flange_tool_base"), "stored planning tool orientation")
        manual = params.get("manual")
        super()._load_state({**d, "poses": {}, "resume_status": "in_progress", "status": "in_progress"})
        self.give_scan(scan, R_flange_tool_base=R,
                       manual=None if manual is None else ManualComparison.from_dict(manual))
        if d.get("resume_status", d.get("status")) == "complete":
            self.finish()
        if d.get("status") == "cancelled":
            self.cancel()
