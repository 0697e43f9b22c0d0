"""Where a robot of someone else's description starts: its reference tip and its ready pose.

Metres and radians. Our built-in robots (joint names in ``kinematics.KNOWN_HOMES_DEG``) have
hand-chosen placements (``server.default_reference_tip_mm``, ``server.ready_configuration``);
any other robot gets them computed from its model here:

* **Reach test** (:func:`unreachable_directions`): a reference tip is reachable when the
  mounted tool's true TCP can be put on it from every direction of :data:`XYZ4_DIRECTIONS`
  (tool X tilted 35 deg from straight down at four azimuths and 20 deg at the four between: the
  middle of the XYZ 4-point auto-touch's tilts, 20-50 deg at any azimuth, ``calibrate.autotouch``,
  which draws again when one is out of reach), each an IK solution within the joint limits
  (``approach.solve_ik``), and the flange can hover pointing down ``READY_HOVER_M`` above it.
* **Default tip** (:func:`reachable_reference_tip`): the first point of a grid in front of the
  robot (``+X`` of its root frame, ``y = 0``) that passes the reach test, tried nearest first to
  55 % of the horizontal reach at 30 % of it high (``R`` = 95th percentile of the flange's
  distance from the base axis over 400 deterministic random configurations); never below
  ``MIN_TIP_HEIGHT_M``.
* **Ready pose** (:func:`best_hover_configuration`): the flange pointing straight down
  ``READY_HOVER_M`` above the tip, turned about the vertical in 45 deg steps and solved from
  several seeds; of the solutions at least :data:`LIMIT_MARGIN_RAD` inside every limit and with
  ``sigma_min(W J) >= 2 eps`` (``jog``: not near a singularity), those within 10 % of the
  largest manipulability ``sqrt(det(W J J^T W))`` (``W = diag(1/L, 1/L, 1/L, 1, 1, 1)``, as in
  ``jog``), of these the ones with the links highest (mean height of the link origins within
  20 mm of the highest: elbow up, away from the table), and of those the one nearest HOME (the
  wrist a technician would choose, not one turned half a turn for the same dexterity). For a redundant (7-axis) arm the seeds explore its
  self-motion, so the elbow ends up where the arm is dexterous.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tcp_pendant.controller.approach import approach_pose, solve_ik
from tcp_pendant.controller.jog import DEFAULT_SETTINGS, JogSettings
from tcp_pendant.controller.kinematics import RobotKinematics

__all__ = [
    "LIMIT_MARGIN_RAD",
    "MIN_TIP_HEIGHT_M",
    "READY_HOVER_M",
    "XYZ4_DIRECTIONS",
    "TipReach",
    "best_hover_configuration",
    "hover_pose",
    "manipulability",
    "reachable_reference_tip",
    "sampled_reach_m",
    "unreachable_directions",
]

MIN_TIP_HEIGHT_M = 0.15
"""The reference tip stands at least this high above the floor (its stand must be visible and
the tool must reach it from the side)."""
READY_HOVER_M = 0.25
"""Generic robots start with the flange this far above the reference tip, pointing down."""
LIMIT_MARGIN_RAD = math.radians(10.0)
"""A ready pose keeps every revolute joint this far inside its limits (10 % of the range for a
prismatic joint, or of a narrower range)."""

XYZ4_DIRECTIONS: tuple[tuple[float, float], ...] = (
    (35.0, 0.0), (35.0, 90.0), (35.0, 180.0), (35.0, 270.0),
    (20.0, 45.0), (20.0, 135.0), (20.0, 225.0), (20.0, 315.0),
)
"""(tilt, azimuth) in degrees of the reach test (``approach.approach_pose``, spin 0)."""

_HOVER_YAWS_DEG = tuple(range(0, 360, 45))
_R_DOWN_FLANGE = np.diag([1.0, -1.0, -1.0])          # flange Z along WORLD -Z, X along WORLD X


@dataclass(frozen=True)
class TipReach:
    """Result of :func:`unreachable_directions`.

    Attributes:
        hover_ok: the flange can hover pointing down ``READY_HOVER_M`` above the tip.
        failed: the (tilt, azimuth) directions with no IK solution.
        q_hover_rad: the hover configuration found (None when not ``hover_ok``).
    """

    hover_ok: bool
    failed: tuple[tuple[float, float], ...]
    q_hover_rad: np.ndarray | None

    @property
    def ok(self) -> bool:
        return self.hover_ok and not self.failed


def sampled_reach_m(kinematics: RobotKinematics, n: int = 400) -> float:
    """Horizontal reach of the flange (m): the 95th percentile of its distance from the base
    axis over ``n`` deterministic random configurations within the limits."""
    rng = np.random.default_rng(20261123)
    lo, hi = kinematics.lower_rad, kinematics.upper_rad
    span = np.minimum(hi - lo, 2 * np.pi)
    mid = 0.5 * (lo + hi)
    qs = mid + (rng.uniform(size=(n, kinematics.n_joints)) - 0.5) * span
    p = np.array([kinematics.T_world_flange(q)[:3, 3] for q in qs])
    return float(np.percentile(np.hypot(p[:, 0], p[:, 1]), 95))


def hover_pose(tip_world_m: np.ndarray, yaw_deg: float = 0.0) -> np.ndarray:
    """``T_world_flange`` pointing straight down ``READY_HOVER_M`` above the tip, turned
    ``yaw_deg`` about WORLD Z."""
    c, s = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
    T = np.eye(4)
    T[:3, :3] = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ _R_DOWN_FLANGE
    T[:3, 3] = np.asarray(tip_world_m, dtype=float) + [0.0, 0.0, READY_HOVER_M]
    return T


def manipulability(kinematics: RobotKinematics, q_rad: np.ndarray,
                   settings: JogSettings = DEFAULT_SETTINGS) -> tuple[float, float]:
    """(``sqrt(det(Js Js^T))``, smallest singular value of ``Js``), ``Js = W J_flange``."""
    J = kinematics.jacobian_flange(q_rad).copy()
    J[:3] /= settings.length_scale_m
    s = np.linalg.svd(J, compute_uv=False)
    if J.shape[1] < 6:
        return 0.0, 0.0
    return float(np.prod(s[:6])), float(s[5])


def _limit_margin_ok(kinematics: RobotKinematics, q: np.ndarray) -> bool:
    span = kinematics.upper_rad - kinematics.lower_rad
    margin = np.where(kinematics.revolute, np.minimum(LIMIT_MARGIN_RAD, 0.1 * span), 0.1 * span)
    return bool(np.all(q >= kinematics.lower_rad + margin) and np.all(q <= kinematics.upper_rad - margin))


def _seeds(kinematics: RobotKinematics, n: int) -> list[np.ndarray]:
    rng = np.random.default_rng(20261201)
    lo, hi = kinematics.lower_rad, kinematics.upper_rad
    span = np.minimum(hi - lo, 2 * np.pi)
    mid = 0.5 * (lo + hi)
    out = [np.asarray(kinematics.home_rad, dtype=float), mid]
    out += [mid + rng.uniform(-0.35, 0.35, kinematics.n_joints) * span for _ in range(n)]
    return out


def best_hover_configuration(kinematics: RobotKinematics, tip_world_m: np.ndarray, *,
                             n_seeds: int = 6, settings: JogSettings = DEFAULT_SETTINGS) -> np.ndarray | None:
    """The ready pose of the module doc, or None when the hover pose has no solution."""
    good: list[tuple[float, np.ndarray]] = []
    fallback: tuple[float, np.ndarray] | None = None
    for yaw in _HOVER_YAWS_DEG:
        T = hover_pose(tip_world_m, yaw)
        for q0 in _seeds(kinematics, n_seeds):
            sol = solve_ik(kinematics, T, q0, n_random_seeds=0)
            if not sol.ok:
                continue
            q = np.asarray(sol.q_rad, dtype=float)
            w, sigma = manipulability(kinematics, q, settings)
            if fallback is None or w > fallback[0]:
                fallback = (w, q)
            if sigma >= 2.0 * settings.singular_eps and _limit_margin_ok(kinematics, q):
                good.append((w, q))
    if not good:
        return None if fallback is None else fallback[1]
    # of the nearly best (within 10 %): elbow up (links highest), then the one nearest home (the
    # wrist a technician would choose, not A4 turned half a turn for the same dexterity)
    w_best = max(w for w, _ in good)
    near = [q for w, q in good if w >= 0.9 * w_best]
    height = [float(np.mean([T[2, 3] for T in kinematics.link_poses(q).values()])) for q in near]
    high = [q for q, h in zip(near, height) if h >= max(height) - 0.02]
    home = np.asarray(kinematics.home_rad, dtype=float)
    return min(high, key=lambda q: float(np.linalg.norm(q - home)))


def unreachable_directions(kinematics: RobotKinematics, tip_world_m: np.ndarray,
                           T_flange_tool: np.ndarray, *, n_random_seeds: int = 24,
                           stop_at_first: bool = False, max_iterations: int = 150,
                           order: tuple[tuple[float, float], ...] = XYZ4_DIRECTIONS) -> TipReach:
    """The reach test of the module doc for one tip (WORLD, m) with the tool ``T_flange_tool``
    (its true TCP in FLANGE, (4,4) m); ``stop_at_first``: stop at the first failure (a search),
    trying the directions in ``order``."""
    tip = np.asarray(tip_world_m, dtype=float)
    q_home = np.asarray(kinematics.home_rad, dtype=float)
    q_mid = 0.5 * (kinematics.lower_rad + kinematics.upper_rad)   # HOME may be stretched out
    hover = None
    for yaw in (0.0, 90.0, 180.0, 270.0):
        sol = solve_ik(kinematics, hover_pose(tip, yaw), q_mid, n_random_seeds=max(2, n_random_seeds // 4),
                       max_iterations=max_iterations)
        if sol.ok:
            hover = np.asarray(sol.q_rad, dtype=float)
            break
    if hover is None and stop_at_first:
        return TipReach(False, (), None)
    seed = hover if hover is not None else q_home
    failed = []
    for tilt, azimuth in order:
        T = approach_pose(tip, tilt_deg=tilt, azimuth_deg=azimuth)
        sol = solve_ik(kinematics, T, seed, T_flange_tcp=T_flange_tool, n_random_seeds=n_random_seeds,
                       max_iterations=max_iterations)
        if not sol.ok:
            failed.append((tilt, azimuth))
            if stop_at_first:
                break
    return TipReach(hover is not None, tuple(failed), hover)


def _candidates(kinematics: RobotKinematics) -> list[np.ndarray]:
    """Grid points in front of the robot, nearest first to (0.55 R, 0, 0.3 R)."""
    reach = sampled_reach_m(kinematics)
    pts = []
    for fx in (0.25, 0.35, 0.45, 0.55, 0.65, 0.75):
        for fz in (0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6):
            z = max(MIN_TIP_HEIGHT_M, fz * reach)
            pts.append(np.array([fx * reach, 0.0, z]))
    unique = {tuple(np.round(p, 6)): p for p in pts}
    target = np.array([0.55 * reach, 0.0, max(MIN_TIP_HEIGHT_M, 0.3 * reach)])
    return sorted(unique.values(), key=lambda p: float(np.linalg.norm(p - target)))


_TIP_MEMO: dict[tuple[str, str, bytes], np.ndarray] = {}
"""Default tips already searched, by (URDF text, flange link, tool): a pendant started twice on
one robot (tests, a restart in one process) does not search again."""


def reachable_reference_tip(kinematics: RobotKinematics, T_flange_tool: np.ndarray) -> np.ndarray:
    """The default tip of the module doc (WORLD, m); when no grid point passes, the first whose
    hover pose has a solution (the start then warns).

    The search tries each point with few IK seeds and iterations and stops at its first failing
    direction, the directions that failed most often so far first (a robot that cannot reach a
    point from one side usually cannot reach its neighbours from it either)."""
    key = (kinematics.description.urdf_xml, kinematics.flange_link,
           np.asarray(T_flange_tool, dtype=float).tobytes())
    if key in _TIP_MEMO:
        return _TIP_MEMO[key].copy()
    fails = {d: 0 for d in XYZ4_DIRECTIONS}
    first_hover: np.ndarray | None = None
    found: np.ndarray | None = None
    for p in _candidates(kinematics):
        order = tuple(sorted(XYZ4_DIRECTIONS, key=lambda d: -fails[d]))
        reach = unreachable_directions(kinematics, p, T_flange_tool, n_random_seeds=6, stop_at_first=True,
                                       max_iterations=60, order=order)
        if reach.ok:
            found = p
            break
        for d in reach.failed:
            fails[d] += 1
        if reach.hover_ok and first_hover is None:
            first_hover = p
    tip = found if found is not None else first_hover if first_hover is not None else _candidates(kinematics)[0]
    if len(_TIP_MEMO) > 8:
        _TIP_MEMO.clear()
    _TIP_MEMO[key] = tip
    return tip.copy()
