"""The virtual beam sensor: a BullsEye / TRACC style through-beam light barrier.

Pure numpy geometry, no viser and no controller class: it takes flange poses
(``T_world_flange``, 4x4, metres) and a tool description (:class:`ToolShape`: the true TOOL
frame and a capsule around the tool's axis) and says where along a commanded straight motion
the beam breaks. The events it returns are what ``tcpcal.solve_beam`` / ``solve_beam_axis``
take (methods.md section 9).

Physical model:

* A beam is the line ``{b + s u}`` in WORLD (metres), of finite ``width`` (diameter).
* **Tip events** (:func:`tip_on_beam`): the tool tip is exact (a sharp point or a wire end;
  the shaft is not checked). Moving the flange along a straight line, the tip enters the beam
  when it comes within ``width / 2`` of the line; the device knows its width and the approach,
  so it reports the pose half a width further on, where an aimed tip is on the centre line.
  A path that passes the line at a distance ``miss`` (``0 < miss <= width / 2``) still breaks
  the beam, but the reported tip is then off the line by about ``miss``: the event says how far
  (``miss_distance``).
* **Axis events** (:func:`crossing_events`): the tool's shaft, a capsule of ``radius`` about the
  segment from ``length`` behind the tip to the tip, breaks the beam while it is within
  ``width / 2`` of the line. Moving sideways, entry and exit are averaged (BEAM-3): there the
  tool axis meets the beam line, whatever the radius and the width, as long as the beam
  crosses the cylindrical part (``on_shaft``).
* **Repeatability**: each recorded flange position gets isotropic Gaussian noise of deviation
  ``sigma`` per axis (sensor trigger and robot together; default 0.02 mm) when a random
  generator is given; an averaged crossing therefore has ``sigma / sqrt(2)``.
* Optionally a **second beam** through the same point (crossed beams); an event names the beam
  that broke first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from tcpcal.validation import read_only_array
from tcp_pendant.controller.checks import check_pose
from tcp_pendant.controller.errors import ControllerError

__all__ = [
    "DEFAULT_SIGMA_M",
    "DEFAULT_WIDTH_M",
    "BeamEvent",
    "BeamSensor",
    "ToolShape",
    "crossing_events",
    "tip_on_beam",
]

DEFAULT_WIDTH_M: float = 0.5e-3
"""Beam diameter: through-beam barriers of TCP devices use beams of a fraction of a mm."""
DEFAULT_SIGMA_M: float = 2e-5
"""Repeatability of a recorded event: 0.02 mm per axis (the default)."""


def _unit(v: object, name: str) -> np.ndarray:
    arr = np.asarray(v, dtype=float)
    if arr.shape != (3,) or not np.isfinite(arr).all():
        raise ControllerError(f"Beam sensor: {name} must be 3 finite numbers, got {v!r}.")
    n = float(np.linalg.norm(arr))
    if n == 0.0:
        raise ControllerError(f"Beam sensor: {name} is the zero vector; give the beam's "
                              "direction in WORLD (e.g. 0,1,0).")
    return arr / n


@dataclass(frozen=True, eq=False)
class BeamSensor:
    """A through-beam light barrier in WORLD (metres).

    Attributes:
        point: (3,) a point ``b`` of the beam line (the crossing point with a second beam).
        direction: (3,) unit direction ``u`` of the beam (normalised on creation).
        width: beam diameter, m (default 0.5 mm).
        sigma: repeatability of a recorded event per axis, m (default 0.02 mm).
        second_direction: (3,) unit direction of an optional second beam through ``point``
            (crossed beams), or None.
    """

    point: np.ndarray
    direction: np.ndarray
    width: float = DEFAULT_WIDTH_M
    sigma: float = DEFAULT_SIGMA_M
    second_direction: np.ndarray | None = field(default=None)

    def __post_init__(self) -> None:
        p = np.asarray(self.point, dtype=float)
        if p.shape != (3,) or not np.isfinite(p).all():
            raise ControllerError(f"Beam sensor: point must be 3 finite numbers (m), got "
                                  f"{self.point!r}.")
        object.__setattr__(self, "point", read_only_array(p))
        u = _unit(self.direction, "direction")
        object.__setattr__(self, "direction", read_only_array(u))
        for name in ("width", "sigma"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v >= 0.0):
                raise ControllerError(f"Beam sensor: {name} must be a finite number >= 0 (m), "
                                      f"got {getattr(self, name)!r}.")
            object.__setattr__(self, name, v)
        if self.second_direction is not None:
            u2 = _unit(self.second_direction, "second_direction")
            if float(np.linalg.norm(np.cross(u, u2))) < 1e-3:
                raise ControllerError("Beam sensor: the second beam is parallel to the first; "
                                      "crossed beams need different directions.")
            object.__setattr__(self, "second_direction", read_only_array(u2))

    @property
    def beams(self) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        """``((b, u),)`` or ``((b, u), (b, u2))`` for crossed beams."""
        if self.second_direction is None:
            return ((self.point, self.direction),)
        return ((self.point, self.direction), (self.point, self.second_direction))


@dataclass(frozen=True, eq=False)
class ToolShape:
    """What of the mounted tool the beam can see.

    Attributes:
        T_flange_tool: (4, 4) the tool's TRUE frame in FLANGE (m): origin at the tip, X along
            the working direction (KUKA, methods.md section 1), pointing out of the tip.
        radius: radius of the shaft capsule, m (e.g. 0.6 mm for a 1.2 mm welding wire).
        length: length of the shaft segment behind the tip, m.
    """

    T_flange_tool: np.ndarray
    radius: float = 1e-3
    length: float = 0.1

    def __post_init__(self) -> None:
        T = np.asarray(self.T_flange_tool, dtype=float)
        if T.shape != (4, 4) or not np.isfinite(T).all():
            raise ControllerError("ToolShape: T_flange_tool must be a finite 4x4 matrix.")
        R = T[:3, :3]
        if np.abs(R.T @ R - np.eye(3)).max() > 1e-9 or np.linalg.det(R) < 0:
            raise ControllerError("ToolShape: T_flange_tool has no proper rotation.")
        object.__setattr__(self, "T_flange_tool", read_only_array(T))
        for name, low in (("radius", 0.0), ("length", 1e-9)):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v >= low):
                raise ControllerError(f"ToolShape: {name} must be a finite number >= {low:g} "
                                      f"(m), got {getattr(self, name)!r}.")
            object.__setattr__(self, name, v)

    @property
    def tip(self) -> np.ndarray:
        """(3,) the tip (true TCP) in FLANGE, m."""
        return self.T_flange_tool[:3, 3]

    @property
    def axis(self) -> np.ndarray:
        """(3,) unit tool direction in FLANGE (tool X), pointing out of the tip."""
        return self.T_flange_tool[:3, 0]


@dataclass(frozen=True, eq=False)
class BeamEvent:
    """One recorded beam event.

    Attributes:
        kind: ``"tip"`` (the tip on the beam line) or ``"axis"`` (a sideways crossing of the
            shaft, entry and exit averaged).
        T_world_flange: (4, 4) the recorded flange pose (with the repeatability noise), m.
        T_world_flange_exact: (4, 4) the same without noise.
        beam: index of the beam that broke (0, or 1 for the second beam).
        beam_point: (3,) that beam's point ``b`` in WORLD, m.
        beam_dir: (3,) that beam's unit direction ``u`` in WORLD.
        travel: distance the flange moved from the start pose to the event, m.
        entry_travel: travel at which the beam was first broken, m.
        exit_travel: travel at which it was clear again (axis events), else NaN.
        miss_distance: tip events: the least distance between the tip's path and the beam
            line, m (0 for an aimed approach; the reported tip is off the line by about this).
            Axis events: NaN.
        on_shaft: axis events: the beam crossed the cylindrical part of the shaft from entry
            to exit, so the average is on the tool axis; tip events: True.
    """

    kind: Literal["tip", "axis"]
    T_world_flange: np.ndarray
    T_world_flange_exact: np.ndarray
    beam: int
    beam_point: np.ndarray
    beam_dir: np.ndarray
    travel: float
    entry_travel: float
    exit_travel: float
    miss_distance: float
    on_shaft: bool


def _direction(direction: object) -> np.ndarray:
    d = np.asarray(direction, dtype=float)
    if d.shape != (3,) or not np.isfinite(d).all() or float(np.linalg.norm(d)) == 0.0:
        raise ControllerError(f"the motion direction must be 3 finite numbers, not all zero, "
                              f"got {direction!r}.")
    return d / float(np.linalg.norm(d))


def _record(T_start: np.ndarray, m: np.ndarray, travel: float, sigma: float,
            rng: np.random.Generator | None, n_avg: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Exact and recorded flange pose after ``travel`` along ``m`` (noise averaged over
    ``n_avg`` recordings)."""
    exact = T_start.copy()
    exact[:3, 3] = T_start[:3, 3] + travel * m
    noisy = exact.copy()
    if rng is not None and sigma > 0.0:
        noisy[:3, 3] += rng.normal(0.0, sigma, (n_avg, 3)).mean(axis=0)
    return read_only_array(exact), read_only_array(noisy)


def tip_on_beam(T_world_flange_start: object, direction: object, sensor: BeamSensor,
                tool: ToolShape, *, max_travel: float = 0.2,
                rng: np.random.Generator | None = None) -> BeamEvent | None:
    """The tip event of a straight approach: where the tool tip reaches a beam's centre line.

    The flange moves from ``T_world_flange_start`` along ``direction`` (WORLD, keeping its
    orientation) by at most ``max_travel``. The tip ``p(tau) = tip0 + tau m`` enters a beam
    when its distance ``|P (p(tau) - b)|`` (``P = I - u u^T``) reaches ``width / 2``: a
    quadratic in ``tau``, solved exactly. The reported travel is ``tau_in + (width / 2) / |P m|``,
    where an aimed tip is on the centre line (the device's width compensation).

    Args:
        T_world_flange_start: (4, 4) flange pose where the approach starts, m; the tip must be
            outside every beam there.
        direction: (3,) motion direction in WORLD (normalised).
        sensor: the beam sensor.
        tool: the mounted tool (only its tip is used).
        max_travel: longest motion, m.
        rng: random generator for the repeatability noise (``sensor.sigma``); None: exact.

    Returns:
        The :class:`BeamEvent` of the first beam broken, or None if the tip misses every beam
        within ``max_travel``.

    Raises:
        ControllerError: bad poses or directions, or the tip already in a beam at the start.
    """
    T0 = check_pose(T_world_flange_start, "T_world_flange_start")
    m = _direction(direction)
    tip0 = T0[:3, :3] @ tool.tip + T0[:3, 3]
    half = sensor.width / 2.0
    best: tuple[float, float, float, int] | None = None  # (event travel, entry, miss, beam)
    for k, (b, u) in enumerate(sensor.beams):
        q = tip0 - b
        q = q - (q @ u) * u  # P (tip0 - b)
        pm = m - (m @ u) * u  # P m
        a = float(pm @ pm)
        c = float(q @ q) - half * half
        if c < 0.0:
            raise ControllerError(f"the tip is already in beam {k} at the start of the approach; "
                                  "start further away.")
        if a < 1e-18:
            continue  # moving along the beam: its distance never changes
        bq = 2.0 * float(q @ pm)
        tau_closest = -bq / (2.0 * a)
        miss = math.sqrt(max(float(q @ q) - a * tau_closest * tau_closest, 0.0))
        disc = bq * bq - 4.0 * a * c
        if disc < 0.0 or tau_closest < 0.0:
            continue  # misses the beam, or moves away from it
        root = math.sqrt(disc)
        # the smaller root, without cancellation (c >= 0 and bq < 0 here)
        tau_in = (2.0 * c) / (-bq + root) if -bq + root > 0.0 else tau_closest
        travel = tau_in + half / math.sqrt(a)
        if tau_in > max_travel:
            continue
        if best is None or tau_in < best[1]:
            best = (travel, tau_in, miss, k)
    if best is None:
        return None
    travel, tau_in, miss, k = best
    exact, noisy = _record(T0, m, travel, sensor.sigma, rng)
    b, u = sensor.beams[k]
    return BeamEvent(kind="tip", T_world_flange=noisy, T_world_flange_exact=exact, beam=k,
                     beam_point=b, beam_dir=u, travel=travel, entry_travel=tau_in,
                     exit_travel=math.nan, miss_distance=miss, on_shaft=True)


def _segment_distance(p0: np.ndarray, e: np.ndarray, b: np.ndarray, u: np.ndarray
                      ) -> tuple[float, float]:
    """Distance from the segment ``p0 + lam e`` (``lam`` in [0, 1]) to the line ``{b + s u}``
    and the ``lam`` of the closest point."""
    q = p0 - b
    q = q - (q @ u) * u
    pe = e - (e @ u) * u
    den = float(pe @ pe)
    lam = 0.0 if den < 1e-30 else min(max(-float(q @ pe) / den, 0.0), 1.0)
    r = q + lam * pe
    return float(math.sqrt(r @ r)), lam


def crossing_events(T_world_flange_start: object, direction: object, sensor: BeamSensor,
                    tool: ToolShape, *, max_travel: float = 0.2,
                    rng: np.random.Generator | None = None) -> tuple[BeamEvent, ...]:
    """Axis events of a sideways pass: the shaft crossing each beam, entry and exit averaged.

    The flange moves along ``direction`` by ``max_travel`` keeping its orientation. For each
    beam the distance between the shaft segment and the beam line is convex in the travel; the
    shaft breaks the beam while it is at most ``radius + width / 2``. Entry and exit are found
    by bracketing root finding to 1e-13 m; their average (BEAM-3) is the event, where the tool
    axis meets the beam line if the beam crossed the cylindrical part (``on_shaft``). Entry and
    exit are each recorded with the repeatability noise, so the average has ``sigma/sqrt(2)``.

    Args:
        T_world_flange_start: (4, 4) flange pose at the start of the pass, m (shaft clear of
            every beam).
        direction: (3,) motion direction in WORLD (normalised); across the beam.
        sensor: the beam sensor.
        tool: the mounted tool's shaft.
        max_travel: length of the pass, m (the shaft must be clear again at its end).
        rng: random generator for the noise; None: exact.

    Returns:
        One event per beam crossed during the pass, in order of entry (empty: no beam broken).

    Raises:
        ControllerError: bad poses or directions; the shaft in a beam at the start or still in
            it at the end of the pass.
    """
    T0 = check_pose(T_world_flange_start, "T_world_flange_start")
    m = _direction(direction)
    R = T0[:3, :3]
    back = R @ (tool.tip - tool.length * tool.axis) + T0[:3, 3]  # segment start at tau = 0
    e = R @ (tool.length * tool.axis)
    reach = tool.radius + sensor.width / 2.0
    events: list[BeamEvent] = []
    for k, (b, u) in enumerate(sensor.beams):
        def gap(tau: float, b: np.ndarray = b, u: np.ndarray = u) -> float:
            return _segment_distance(back + tau * m, e, b, u)[0] - reach

        if gap(0.0) <= 0.0:
            raise ControllerError(f"the tool is already in beam {k} at the start of the pass; "
                                  "start further away.")
        found = minimize_scalar(gap, bounds=(0.0, max_travel), method="bounded",
                                options={"xatol": 1e-12})
        tau_min = float(found.x)
        if gap(tau_min) > 0.0:
            continue  # the shaft passes the beam without breaking it
        if gap(max_travel) <= 0.0:
            raise ControllerError(f"the tool is still in beam {k} at the end of the pass; make "
                                  "the pass longer.")
        tau_in = brentq(gap, 0.0, tau_min, xtol=1e-13, rtol=4 * np.finfo(float).eps)
        tau_out = brentq(gap, tau_min, max_travel, xtol=1e-13, rtol=4 * np.finfo(float).eps)
        lam_in = _segment_distance(back + tau_in * m, e, b, u)[1]
        lam_out = _segment_distance(back + tau_out * m, e, b, u)[1]
        on_shaft = 0.0 < lam_in < 1.0 and 0.0 < lam_out < 1.0
        travel = 0.5 * (tau_in + tau_out)
        exact, noisy = _record(T0, m, travel, sensor.sigma, rng, n_avg=2)  # entry, exit
        events.append(BeamEvent(
            kind="axis", T_world_flange=noisy, T_world_flange_exact=exact, beam=k,
            beam_point=b, beam_dir=u, travel=travel, entry_travel=tau_in, exit_travel=tau_out,
            miss_distance=math.nan, on_shaft=on_shaft))
    events.sort(key=lambda ev: ev.entry_travel)
    return tuple(events)
