"""Cartesian motion of a TCP along a straight path: damped least squares on pinocchio Jacobians.

Metres and radians inside. The path of the TCP pose (position ``p``, rotation ``R``, WORLD =
the robot's root frame) is

    p(s) = p0 + s dp,     R(s) = Exp(s w) R0,     s in [0, 1]                     (J-1)

with ``w`` a rotation vector in WORLD axes: a translation jog has ``w = 0``; a rotation jog
has ``dp = 0`` (the TCP stays put) and ``w = angle * axis``; a gizmo drag has both.

**Sub-steps.** The path is cut into ``n = ceil(max(|dp| / 2 mm, |w| / 1 deg))`` equal
sub-steps. Each sub-step solves the pose ``(p(s_k), R(s_k))`` exactly, starting from the
previous configuration, by damped Newton iterations

    e = [p* - p_tcp ; log(R* R_tcp^T)],    dq = J^T (J J^T + lambda^2 W^-2)^-1 e      (J-2)

where ``J`` is the TCP Jacobian ``[Jv - [R_wf t]x Jw ; Jw]`` built from pinocchio's flange
Jacobian (LOCAL_WORLD_ALIGNED) and the TCP offset ``t`` (FLANGE coordinates), and
``W = diag(1/L, 1/L, 1/L, 1, 1, 1)`` (L = 0.3 m) makes metres and radians comparable.
Iterations stop at 1e-10 m / 1e-10 rad, so every accepted sub-step puts the TCP on the line
(and the orientation on its path) to far better than 0.01 mm / 0.001 deg. The damping
``lambda^2 = lambda_max^2 (1 - (sigma_min / eps)^2)`` is non-zero only when the smallest
singular value ``sigma_min`` of the scaled flange Jacobian ``W J_flange`` is below
``eps`` (Nakamura-Chiaverini), so far from singularities (J-2) is the Newton step.

**Redundant arms** (more than six joints, e.g. a 7-axis KUKA iiwa). (J-2) is then the
damped least-squares step of minimum joint norm: it moves only as much as the TCP needs, which
leaves the arm's self-motion (the elbow turning about the shoulder-wrist line) to drift. The
first Newton iteration of each sub-step adds a null-space step towards the *rest*
configuration ``q_rest`` (the session's ready pose)

    dq += N k (q_rest - q),    N = I - J^+ J,   J^+ = J^T (J J^T)^-1                  (J-3)

with ``k = null_space_gain`` (0.05), scaled down so that no joint moves more than a quarter of the
sub-step's joint allowance (the jump rule below); ``N`` projects it onto the joint motions the TCP
does not feel, so the path is unchanged and the later iterations (pure J-2) converge as before.
The elbow thus stays near where the arm started (well conditioned, clear of the limits) however
long one jogs. Six-joint arms have no null space and skip (J-3).

**Safety rules** (a sub-step is *rejected*, the robot stays at the last accepted sub-step):
  * no convergence within the iteration budget (target off the reachable set);
  * a joint change above ``max_joint_gain`` (5 deg per mm or deg of *flange* motion): the
    configuration would jump (this is what happens next to a singularity or on a flip). The
    flange motion of a sub-step is bounded by ``|dp| + |w| |t|`` (mm) plus ``|w|`` (deg): a
    rotation about a TCP ``|t|`` away from the flange swings the flange on a circle of radius
    ``|t|``, so a long torch turning about its tip legitimately moves the axes a lot;
  * a joint outside its limits -> ``stopped_by="joint_limit"``, e.g. "A5 at its limit +120.0 deg";
  * ``sigma_min`` below ``eps`` (sin 2 deg, i.e. A5 within about 2 deg of 0 on a KR 6) *and*
    decreasing -> ``stopped_by="singularity"``. A motion that keeps or increases
    ``sigma_min`` is allowed, so a robot sitting exactly in a singularity (KUKA HOME has A5 = 0)
    can still jog in the directions it can follow;
  * for a six-joint arm, a sign change of ``det J_flange`` between the start and the end of the
    sub-step (both ``sigma_min`` above ``singular_zero``) -> ``stopped_by="singularity"``: the
    arm would pass *through* a singularity into another configuration (wrist flip through
    A5 = 0, elbow through the stretched arm, shoulder over the A1 axis). ``det J`` changes
    sign exactly on the singular set, so this catches the continuous crossings that start inside
    the ``eps`` zone (where ``sigma_min`` need not decrease: +0.5 deg -> -0.5 deg), and the
    joint-change rule above catches the jumps.

A rejected sub-step is bisected (up to 8 times) so the robot stops close to the limit or the
singularity; ``moved`` is the fraction of the path carried out.

**Cost of a step** (a pendant increment is one sub-step; a class sends thousands a second). Every
sub-step converges to the tolerances above under the same rules; what is saved is repeated work:
  * :func:`follow_path` returns the kinematics of the configuration it ended on
    (:class:`FlangeState`: the flange Jacobian and pose of the last Newton iteration, sigma_min,
    the det sign and the Jacobian's LU factors), and takes it as ``start`` of the next path: the
    first iteration then needs no pinocchio pass. It is used only on the same robot at exactly
    the same ``q`` with the same settings (``FlangeState.valid_for``); the controller drops it
    whenever ``q``, the tool data or the physical model are set any other way.
  * Six joints and ``lambda = 0``: (J-2) is the Newton step ``dq = J_tcp^-1 e``, solved as
    ``J_flange dq = [e_p + r x e_r; e_r]`` (``J_tcp = [I -[r]x; 0 I] J_flange``) by one LU solve
    (LAPACK ``gesv``, or ``getrs`` with the start's factors). The damped form (J-2 with
    ``lambda > 0``), a singular ``J`` and redundant arms take the formula above.
  * a sub-step of the same increment as the one that ended at the start (a key pressed again)
    takes its first step with the Jacobian extrapolated to its middle (``_solve_substep``): a
    0.1 mm press then converges after one step, one pinocchio pass in all.
  * sigma_min and the det sign at the end of a sub-step: by Weyl's inequality
    ``sigma_min(W J) >= sigma_start - ||W (J - J_start)||_F``; while this bound is at least
    ``2 eps`` no singularity rule can fire and ``det J`` cannot have changed sign, so the bound
    stands in for sigma_min (``PathOutcome.sigma``) and the sign is kept; the SVD and the LU
    (``det J = (-1)^swaps prod diag U``, as ``np.linalg.det``) run when it falls below.
  * a translation keeps ``R0`` (no ``Exp(0)``); a zero TCP offset or an identity TCP rotation
    skips its product (bit for bit the same); convergence, limit and jump tests on Python floats.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass
from enum import Enum
from typing import Literal, NamedTuple

import numpy as np
import pinocchio as pin
from scipy.linalg import lapack

from tcp_pendant.controller.kinematics import RobotKinematics
from tcp_pendant.controller.words import Words
from tcp_pendant.translation import N_

__all__ = [
    "JogFrame",
    "JogResult",
    "JogSettings",
    "CartesianPath",
    "FlangeState",
    "PathOutcome",
    "follow_path",
    "singularity_message",
    "smallest_singular_value",
    "tcp_pose",
]

StopReason = Literal["joint_limit", "singularity", "unreachable", "contact", "collision"]
"""Why a motion stopped early; "contact": the pendant's stop at the reference tip, "collision":
its stop there with the distance hidden (``tcp_pendant.pendant.jogging``)."""


class JogFrame(str, Enum):
    """Jog coordinate systems (the pendant's frame selector).

    WORLD: the robot's root frame. BASE: the work-object frame ``T_world_base``.
    FLANGE: the flange frame at the start of the step. TOOL: the active TOOL frame (tool data
    the controller believes) at the start of the step.
    """

    WORLD = "WORLD"
    BASE = "BASE"
    FLANGE = "FLANGE"
    TOOL = "TOOL"


@dataclass(frozen=True)
class JogResult:
    """Outcome of one motion command.

    Attributes:
        ok: the whole commanded motion was carried out.
        moved: fraction of the commanded step carried out, 0..1.
        stopped_by: why it stopped early (None when ok).
        message: plain words for the pendant's message line, e.g. "A5 at its limit +120.0 deg".
    """

    ok: bool
    moved: float
    stopped_by: StopReason | None
    message: str


@dataclass(frozen=True)
class JogSettings:
    """Tuning of :func:`follow_path` (units in the names)."""

    max_substep_m: float = 0.002
    max_substep_rad: float = math.radians(1.0)
    max_joint_gain: float = 5.0
    """Largest joint change per sub-step, in deg per (mm + deg) of flange motion (see the module doc)."""
    min_joint_allowance_rad: float = math.radians(0.02)
    tol_m: float = 1e-10
    tol_rad: float = 1e-10
    max_iterations: int = 15
    length_scale_m: float = 0.3
    singular_eps: float = math.sin(math.radians(2.0))
    lambda_max: float = 0.002
    bisections: int = 8
    singular_zero: float = 1e-7
    """``sigma_min`` below which a configuration counts as *on* the singularity (no det sign)."""
    null_space_gain: float = 0.05
    """``k`` of (J-3): the share of the way to the rest configuration a redundant arm's
    self-motion goes per sub-step (at most a quarter of the joint allowance)."""


DEFAULT_SETTINGS = JogSettings()


@dataclass(frozen=True)
class CartesianPath:
    """The TCP pose path (J-1): ``p(s) = p0 + s dp``, ``R(s) = Exp(s w) R0`` (WORLD, metres)."""

    p0: np.ndarray
    R0: np.ndarray
    dp: np.ndarray
    w: np.ndarray

    def at(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """Target (p, R) at path parameter ``s`` (a translation, ``w = 0``: ``R0`` itself, not a
        copy: ``Exp(0) R0 = R0`` exactly)."""
        if not self.w.any():
            return self.p0 + s * self.dp, self.R0
        return self.p0 + s * self.dp, pin.exp3(s * self.w) @ self.R0


class FlangeState(NamedTuple):
    """What the kinematics gave at one configuration: the flange Jacobian, pose and the numbers
    the safety rules need, so that the next path starting there needs no pinocchio pass.

    Only valid for ``q_rad`` on the robot ``kin`` (compare both exactly before use,
    :meth:`valid_for`); the arrays are never written to. (A named tuple: immutable, and built
    once per sub-step at a fraction of a frozen dataclass's cost.)
    """

    kin: RobotKinematics
    q_rad: np.ndarray
    q_list: list[float]
    """``q_rad.tolist()``: the exact key (a list compare costs less than ``np.array_equal``)."""
    J: np.ndarray
    """(6, n) flange Jacobian, LOCAL_WORLD_ALIGNED (``RobotKinematics.jacobian_flange``)."""
    R_wf: np.ndarray
    p_wf: np.ndarray
    sigma: float
    """:func:`smallest_singular_value` at ``q_rad``, or a lower bound of it ``>= 2 singular_eps``
    (``PathOutcome.sigma``)."""
    det_sign: float
    """The sign of ``det J`` (``_lu_det_sign``: +1, -1; 0 singular or not square)."""
    lu: tuple[np.ndarray, np.ndarray] | None = None
    """LAPACK ``getrf`` factors of ``J`` (square ``J`` only), for the first Newton step."""

    settings: JogSettings = DEFAULT_SETTINGS
    """The tuning ``sigma`` was computed with (its ``W`` and ``eps``)."""
    J_before: np.ndarray | None = None
    """The flange Jacobian at the start of the sub-step that ended here (None: not known)."""
    step: list[float] | None = None
    """That sub-step's Cartesian increment ``[dp; dw]`` (m, rad, WORLD)."""

    def valid_for(self, kin: RobotKinematics, q_rad: np.ndarray,
                  settings: JogSettings = DEFAULT_SETTINGS) -> bool:
        """True when this state was computed on ``kin`` at exactly ``q_rad`` with ``settings``."""
        return (kin is self.kin and self.q_list == q_rad.tolist()
                and (settings is self.settings or settings == self.settings))


@dataclass(frozen=True)
class PathOutcome:
    """Result of :func:`follow_path`: final configuration and how far it got."""

    q_rad: np.ndarray
    moved: float
    stopped_by: StopReason | None
    message: str
    sigma: float
    """:func:`smallest_singular_value` at ``q_rad``, or a lower bound of it that is at least
    ``2 singular_eps`` (``_sigma_bound``: all the singularity rules need to know then)."""
    det_sign: float = 0.0
    """Sign of ``det J_flange`` at ``q_rad`` (``_lu_det_sign``: +1, -1; 0 singular or not square)."""
    state: FlangeState | None = None
    """The kinematics at ``q_rad`` (the last Newton iteration's), to start the next path from."""


def tcp_pose(kin: RobotKinematics, q_rad: np.ndarray, T_flange_tcp: np.ndarray) -> np.ndarray:
    """``T_world_tcp = T_world_flange(q) @ T_flange_tcp`` (WORLD = root frame), metres."""
    return kin.T_world_flange(q_rad) @ T_flange_tcp


def smallest_singular_value(kin: RobotKinematics, q_rad: np.ndarray,
                            settings: JogSettings = DEFAULT_SETTINGS) -> float:
    """Smallest singular value of the scaled flange Jacobian ``W J_flange`` (see module doc)."""
    J = kin.jacobian_flange(q_rad)
    return _sigma_min(J, settings)


def _sigma_min(J_flange: np.ndarray, settings: JogSettings) -> float:
    if J_flange.shape[1] < 6:
        return 0.0
    # rows 0-2 divided by L (as W J), one LAPACK gesdd call (what np.linalg.svd runs, without its
    # wrapper's per-call cost)
    Js = J_flange / _row_scale(settings.length_scale_m)
    s = lapack.dgesdd(Js, compute_uv=0)[1]
    return float(s[min(Js.shape) - 1])


_ROW_SCALES: dict[float, np.ndarray] = {}


def _row_scale(length_scale_m: float) -> np.ndarray:
    """(6, 1) column ``[L, L, L, 1, 1, 1]``: ``J / it`` is ``W J`` of the module doc."""
    col = _ROW_SCALES.get(length_scale_m)
    if col is None:
        col = _ROW_SCALES[length_scale_m] = np.array([[length_scale_m]] * 3 + [[1.0]] * 3)
    return col


def singularity_message(kin: RobotKinematics, q_rad: np.ndarray,
                        settings: JogSettings = DEFAULT_SETTINGS) -> str:
    """Name the singularity from the joint motion that does not move the flange.

    The right singular vector ``v`` of the smallest singular value of ``W J_flange`` is the
    joint motion the flange cannot feel. For a six-axis arm: if it involves axis 1 the wrist
    centre is on axis 1 (shoulder singularity); if it involves axes 2-3 the arm is stretched
    or folded (elbow); otherwise only wrist axes turn against each other (axes 4 and 6
    aligned, axis 5 near 0: wrist singularity). E.g. "A5 near 0.4 deg: wrist singularity
    (A4 and A6 aligned)".
    """
    names = kin.joint_names
    Js = kin.jacobian_flange(q_rad).copy()
    Js[:3] /= settings.length_scale_m
    _, _, vt = np.linalg.svd(Js)
    v = np.abs(vt[min(Js.shape) - 1]) if Js.shape[1] >= 6 else np.abs(vt[-1])
    if len(names) != 6:
        moving = [names[i] for i in np.nonzero(v > 0.3)[0]]
        if not moving:
            return Words(N_("near a singularity: the joints cannot move the TCP freely"))
        joints: str = moving[0]
        for name in moving[1:]:                            # "A1 and A2 and A3"
            joints = Words(N_("{first} and {second}"), first=joints, second=name)
        return Words(N_("near a singularity: {joints} cannot move the TCP freely"), joints=joints)
    deg = np.degrees(q_rad)
    if v[0] > 0.3:
        return Words(N_("wrist centre near the {joint} axis: shoulder singularity"), joint=names[0])
    if v[1] + v[2] > 0.3:
        return Words(N_("{joint} near {angle} deg: arm stretched (elbow singularity)"), joint=names[2],
                     angle=f"{deg[2]:.1f}")
    return Words(N_("{joint} near {angle} deg: wrist singularity ({first} and {second} aligned)"),
                 joint=names[4], angle=f"{deg[4]:.1f}", first=names[3], second=names[5])


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _lu_det_sign(J_flange: np.ndarray) -> tuple[float, tuple[np.ndarray, np.ndarray] | None]:
    """Sign of ``det J_flange`` (+1 or -1; 0 when J is not square or exactly singular) from an LU
    factorisation ``P J = L U`` (what ``np.linalg.det`` does: ``det J = (-1)^(row swaps) prod
    diag U``), and the factors for a later solve with ``J`` (None when J is not square or
    exactly singular)."""
    if J_flange.shape[0] != J_flange.shape[1]:
        return 0.0, None
    lu, piv, info = lapack.dgetrf(J_flange)
    negative = sum(1 for i, p in enumerate(piv.tolist()) if p != i)
    for d in lu.diagonal().tolist():
        if d == 0.0 or d != d:
            return (0.0 if d == 0.0 else math.nan), None
        if d < 0.0:
            negative += 1
    return (-1.0 if negative % 2 else 1.0), ((lu, piv) if info == 0 else None)


@dataclass
class _Attempt:
    q: np.ndarray
    sigma: float
    reason: StopReason | None
    message: str
    det_sign: float = 0.0
    state: FlangeState | None = None
    """The kinematics at ``q`` (accepted attempts only)."""


def _sigma_bound(J: np.ndarray, start: FlangeState | None, sigma_start: float, det_sign_start: float,
                 settings: JogSettings) -> float | None:
    """A lower bound of ``sigma_min(W J)`` from the start's, when it is at least ``2 eps``; else None.

    Weyl's inequality for singular values: ``sigma_min(W J) >= sigma_min(W J0) - ||W (J - J0)||_2``,
    and ``||W D||_2 <= ||W D||_F`` (``J0 = start.J``; the factor ``1 + 1e-12`` covers rounding).
    ``sigma_start`` is sigma_min at the start (or a lower bound of it). A bound ``>= 2 eps`` decides every singularity rule as the exact value would
    (none fires; ``sigma_start < 2 eps`` is false), and as every matrix on the segment from
    ``W J0`` to ``W J`` then has ``sigma_min > 0``, ``det J`` kept its sign (``det_sign_start``).
    None (compute sigma and the det sign exactly): no start state, an unknown start sign on a
    square Jacobian, or a bound below ``2 eps``.
    """
    if start is None or (det_sign_start == 0.0 and J.shape[0] == J.shape[1]):
        return None
    eps2 = 2.0 * settings.singular_eps
    if sigma_start < eps2:
        return None
    if J is start.J:
        return sigma_start
    d = (J - start.J) / _row_scale(settings.length_scale_m)          # W (J - J0)
    drift = math.sqrt(float(np.vdot(d, d))) * (1.0 + 1e-12)
    bound = sigma_start - drift
    return bound if bound >= eps2 else None


def _same_step(previous: list[float] | None, step: list[float]) -> bool:
    """The two Cartesian increments agree to 1e-6 of the larger component (rounding of the frame
    axes aside, the same key pressed again)."""
    if previous is None:
        return False
    tol = 1e-6 * max(map(abs, step))
    return tol > 0.0 and all(abs(a - b) <= tol for a, b in zip(previous, step))


def _null_space_step(Jt: np.ndarray, q: np.ndarray, q_rest: np.ndarray, gain: float,
                     cap: float) -> np.ndarray:
    """(J-3): ``N k (q_rest - q)``, its largest joint change at most ``cap`` (rad)."""
    z = gain * (q_rest - q)
    try:
        pinv = Jt.T @ np.linalg.solve(Jt @ Jt.T, Jt)
    except np.linalg.LinAlgError:
        return np.zeros_like(q)
    dq = z - pinv @ z
    biggest = float(np.abs(dq).max())
    return dq * (cap / biggest) if biggest > cap else dq


class _Newton(NamedTuple):
    """Where the Newton iterations of one sub-step ended: ``q`` and the kinematics of the last
    iteration there (the Jacobian, flange pose, LU factors of the start's Jacobian if the
    start converged at once), and whether it converged."""

    q: np.ndarray
    q_list: list[float]
    J: np.ndarray
    R_wf: np.ndarray
    p_wf: np.ndarray
    lu: tuple[np.ndarray, np.ndarray] | None
    converged: bool


def _solve_substep(kin: RobotKinematics, q_start: np.ndarray, sigma_start: float,
                   t_f: np.ndarray | None, R_ft: np.ndarray | None, p_target: np.ndarray,
                   R_target: np.ndarray, cart_amount: float, settings: JogSettings,
                   det_sign_start: float = 0.0, q_rest: np.ndarray | None = None,
                   start: FlangeState | None = None, step: list[float] | None = None) -> _Attempt:
    """Damped Newton (J-2) from ``q_start`` to one target pose (:func:`_newton`), then the
    safety checks (:func:`_checked`).

    ``t_f``, ``R_ft``: the TCP in FLANGE coordinates; None for a zero offset and an identity
    rotation (the products with them are skipped: they would change no bit).
    ``det_sign_start`` is :func:`_det_sign` at ``q_start`` (0: unknown or on a singularity);
    ``q_rest``: the rest configuration of a redundant arm's null-space step (J-3), None: none;
    ``start``: the kinematics at ``q_start`` (its first iteration then needs no pinocchio pass);
    ``step``: this sub-step's Cartesian increment ``[dp; dw]`` (the midpoint step of
    :func:`_newton`).
    """
    eps = settings.singular_eps
    lam2 = 0.0
    if sigma_start < eps:
        lam2 = settings.lambda_max ** 2 * (1.0 - (sigma_start / eps) ** 2)
    allowance = max(settings.max_joint_gain * cart_amount, settings.min_joint_allowance_rad)
    nt = _newton(kin, q_start, t_f, R_ft, p_target, R_target, settings, lam2, allowance, q_rest, start, step)
    return _checked(kin, q_start, sigma_start, nt, allowance, settings, det_sign_start, start, step)


def _newton(kin: RobotKinematics, q_start: np.ndarray, t_f: np.ndarray | None, R_ft: np.ndarray | None,
            p_target: np.ndarray, R_target: np.ndarray, settings: JogSettings, lam2: float,
            allowance: float, q_rest: np.ndarray | None, start: FlangeState | None,
            step: list[float] | None) -> _Newton:
    """The damped Newton iterations (J-2) of one sub-step, from ``q_start`` (arguments as
    :func:`_solve_substep`; ``lam2`` the damping, ``allowance`` the joint allowance in rad).

    With ``lambda = 0`` on a square Jacobian (a six-joint arm away from singularities) (J-2) is
    the Newton step ``dq = J_tcp^-1 e``; it is solved as ``J_flange dq = [e_p + r x e_r; e_r]``
    (``J_tcp = [I -[r]x; 0 I] J_flange``, ``r = R_wf t``), one LU solve with the flange Jacobian
    (whose factors the previous sub-step left in ``start``).

    Midpoint first step: when ``start`` ended a sub-step of the same increment (a pendant key
    pressed again), the first Newton step uses the Jacobian extrapolated to the middle of this
    one, ``J(q0 + dq/2) ~ J0 + (J0 - J_before) / 2`` (the joint step repeats to second order).
    ``f(q0 + dq) = f(q0) + J(q0 + dq/2) dq + O(|dq|^3)``, so a 0.1 mm press lands within about
    1e-12 m after one step (plain Newton: 1e-8 m, a second step). The iteration and its
    convergence test are otherwise unchanged.
    """
    direct = lam2 == 0.0 and q_rest is None and q_start.shape[0] == 6 and kin.n_joints == 6
    tol_m, tol_rad = settings.tol_m, settings.tol_rad
    q = q_start
    J = R_wf = p_wf = None
    lu: tuple[np.ndarray, np.ndarray] | None = None
    q_list: list[float] = []
    converged = False
    # R* (R_wf R_ft)^T = (R* R_ft^T) R_wf^T: the TCP rotation folded into the target once
    R_goal = R_target if R_ft is None else R_target @ R_ft.T
    J_mid = None
    if (direct and start is not None and start.J_before is not None and step is not None
            and _same_step(start.step, step)):
        J_mid = 1.5 * start.J - 0.5 * start.J_before
    for iteration in range(settings.max_iterations + 1):
        if iteration == 0 and start is not None:
            J, R_wf, p_wf, lu = start.J, start.R_wf, start.p_wf, start.lu
        else:
            J, R_wf, p_wf = kin.jacobian_and_pose(q)
            lu = None
        r = None if t_f is None else R_wf @ t_f
        e_p = p_target - p_wf if r is None else p_target - (p_wf + r)
        e_r = pin.log3(R_goal @ R_wf.T)
        ep, er = e_p.tolist(), e_r.tolist()
        if math.hypot(*ep) < tol_m and math.hypot(*er) < tol_rad:
            converged = True
            break
        dq = None
        if direct:
            if r is not None:
                rx, ry, rz = r.tolist()
                ex, ey, ez = er
                ep = [ep[0] + ry * ez - rz * ey, ep[1] + rz * ex - rx * ez, ep[2] + rx * ey - ry * ex]
            b = np.array(ep + er)
            if iteration == 0 and J_mid is not None:
                x, info = lapack.dgesv(J_mid, b)[2:]
            elif lu is not None:
                x, info = lapack.dgetrs(lu[0], lu[1], b)
            else:
                x, info = lapack.dgesv(J, b)[2:]
            if info == 0:
                dq = x
        if dq is None:
            dq = _damped_step(J, r, e_p, e_r, lam2, settings)
            if iteration == 0 and q_rest is not None:
                Jt = J if r is None else _tcp_jacobian(J, r)
                dq = dq + _null_space_step(Jt, q, q_rest, settings.null_space_gain, 0.25 * allowance)
        q = q + dq
        q_list = q.tolist()
        if not all(map(math.isfinite, q_list)):
            break
    assert J is not None and R_wf is not None and p_wf is not None  # the loop runs at least once
    return _Newton(q, q_list, J, R_wf, p_wf, lu, converged)


def _tcp_jacobian(J_flange: np.ndarray, r: np.ndarray) -> np.ndarray:
    """``J_tcp = [Jv - [r]x Jw ; Jw]`` of the flange Jacobian and the TCP offset ``r`` (WORLD)."""
    Jt = J_flange.copy()
    Jt[:3] -= _skew(r) @ J_flange[3:]
    return Jt


def _damped_step(J: np.ndarray, r: np.ndarray | None, e_p: np.ndarray, e_r: np.ndarray, lam2: float,
                 settings: JogSettings) -> np.ndarray:
    """(J-2) in its damped least-squares form: ``dq = J^T (J J^T + lambda^2 W^-2)^-1 e``."""
    Jt = J.copy() if r is None else _tcp_jacobian(J, r)
    e = np.concatenate((e_p, e_r))
    A = Jt @ Jt.T
    if lam2 > 0.0:
        L = settings.length_scale_m
        A[np.diag_indices(6)] += lam2 * np.array([L * L] * 3 + [1.0] * 3)  # W^-2: damping in the scaled metric
    try:
        return Jt.T @ np.linalg.solve(A, e)
    except np.linalg.LinAlgError:
        return Jt.T @ np.linalg.lstsq(A, e, rcond=None)[0]


def _checked(kin: RobotKinematics, q_start: np.ndarray, sigma_start: float, nt: _Newton, allowance: float,
             settings: JogSettings, det_sign_start: float, start: FlangeState | None,
             step: list[float] | None) -> _Attempt:
    """The safety rules of the module docstring on the Newton result ``nt``: the sub-step is
    accepted (an attempt without a reason, with the kinematics at its end) or rejected (the
    robot stays at ``q_start``, the reason and its words)."""
    eps = settings.singular_eps
    q, q_list, J, converged = nt.q, nt.q_list, nt.J, nt.converged
    # max |q - q_start| (the q of the last update is the one that converged), Python floats
    jump = (0.0 if q is q_start else max(map(abs, map(operator.sub, q_list, q_start.tolist())))) \
        if converged else math.inf
    if not converged or jump > allowance:
        if sigma_start < 2.0 * eps:
            return _Attempt(q_start, sigma_start, "singularity", singularity_message(kin, q_start, settings))
        if not converged:
            why = Words(N_("target out of reach: no joint angles put the TCP on the path there"))
        else:
            name = kin.joint_names[int(np.argmax(np.abs(q - q_start)))]
            why = Words(N_("{joint} would have to turn too fast: the path runs into the edge of the reach "
                           "or a singularity"), joint=name)
        return _Attempt(q_start, sigma_start, "unreachable", why)
    viol = kin.limit_violation(q)
    if viol is not None:
        # the joint furthest beyond its limit is the one to name
        over = np.maximum(kin.lower_rad - q, q - kin.upper_rad)
        i = int(np.argmax(over))
        side = "lower" if q[i] < kin.lower_rad[i] else "upper"
        return _Attempt(q_start, sigma_start, "joint_limit", kin.limit_message(i, side))
    lu = nt.lu
    bound = _sigma_bound(J, start, sigma_start, det_sign_start, settings)
    if bound is not None:
        # sigma >= bound >= 2 eps: the sigma rule cannot fire, the det sign cannot have changed
        sigma, det_sign, lu = bound, det_sign_start, None
    else:
        sigma = _sigma_min(J, settings)
        if sigma < eps and sigma < sigma_start * (1.0 - 1e-9) - 1e-12:
            return _Attempt(q_start, sigma_start, "singularity", singularity_message(kin, q, settings))
        if lu is not None and start is not None:   # converged at the start: J is the start's, its sign known
            det_sign = start.det_sign
        else:
            det_sign, lu = _lu_det_sign(J)
        if (det_sign * det_sign_start < 0.0 and sigma > settings.singular_zero
                and sigma_start > settings.singular_zero):
            # passed through a singularity into another configuration: name the one at the start
            return _Attempt(q_start, sigma_start, "singularity", singularity_message(kin, q_start, settings),
                            det_sign_start)
    q_out = q.copy() if q is q_start else q
    return _Attempt(q_out, sigma, None, "", det_sign,
                    FlangeState(kin, q_out, q_out.tolist(), J, nt.R_wf, nt.p_wf, sigma, det_sign, lu, settings,
                                None if start is None else start.J, step))


def follow_path(kin: RobotKinematics, q_rad: np.ndarray, T_flange_tcp: np.ndarray,
                path: CartesianPath, settings: JogSettings = DEFAULT_SETTINGS, *,
                sigma_start: float | None = None, q_rest: np.ndarray | None = None,
                det_sign_start: float | None = None, start: FlangeState | None = None) -> PathOutcome:
    """Move the TCP along ``path`` (J-1) from configuration ``q_rad`` under the safety rules.

    Args:
        kin: the robot.
        q_rad: start configuration; the TCP must be at ``path.at(0)``.
        T_flange_tcp: (4,4) TCP in FLANGE coordinates, metres.
        path: the Cartesian path.
        sigma_start: :func:`smallest_singular_value` at ``q_rad`` if the caller knows it
            (saves one SVD per jog step: the controller keeps it from the previous step).
        q_rest: rest configuration of a redundant arm (J-3); ignored for six joints or fewer.
        det_sign_start: the sign of ``det J_flange`` at ``q_rad`` if the caller knows it
            (``PathOutcome.det_sign`` of the previous path); with ``sigma_start`` it saves the
            Jacobian at the start, one pinocchio pass per jog step.
        start: the kinematics at ``q_rad`` (``PathOutcome.state`` of the previous path): its
            sigma and det sign, and the Jacobian and pose for the first Newton iteration (one
            pinocchio pass less). Used only when it was computed on ``kin`` at exactly
            ``q_rad`` with ``settings`` (``FlangeState.valid_for``); it overrides
            ``sigma_start``/``det_sign_start``.

    Returns:
        The configuration reached, the fraction ``moved`` of the path, the stop reason and
        message (None and "" when the whole path was carried out), ``sigma`` at the end and
        the kinematics there (``state``; None when the path did not move from ``q_rad``
        and no ``start`` was given).
    """
    t_list = T_flange_tcp[:3, 3].tolist()
    R_list = T_flange_tcp[:3, :3].tolist()
    # a zero offset / identity rotation: skip the products with them (bit for bit the same)
    t_f = None if t_list == [0.0, 0.0, 0.0] else T_flange_tcp[:3, 3]        # views: only read
    R_ft = None if R_list == _IDENTITY_ROWS else T_flange_tcp[:3, :3]
    dp_w = path.dp.tolist() + path.w.tolist()
    length_m = math.hypot(*dp_w[:3])           # |dp|, |w|, |t_f|: math, no numpy call per jog step
    angle = math.hypot(*dp_w[3:])
    n = max(1, math.ceil(max(length_m / settings.max_substep_m, angle / settings.max_substep_rad) - 1e-9))
    # joint allowance per unit of flange motion: (mm of travel -> "deg") + rad of rotation; a
    # rotation about the TCP swings the flange by |w| |t| (module doc)
    lever_m = math.hypot(*t_list)
    unit = (length_m + angle * lever_m) * 1000.0 * math.radians(1.0) + angle

    q = np.array(q_rad, dtype=float)
    rest = np.asarray(q_rest, dtype=float) if q_rest is not None and kin.n_joints > 6 else None
    state = start if start is not None and start.valid_for(kin, q, settings) else None
    if state is not None:
        sigma, det_sign = state.sigma, state.det_sign
    elif sigma_start is None or det_sign_start is None:
        J0 = kin.jacobian_flange(q)
        sigma = _sigma_min(J0, settings) if sigma_start is None else float(sigma_start)
        det_sign = _lu_det_sign(J0)[0] if det_sign_start is None else float(det_sign_start)
    else:
        sigma, det_sign = float(sigma_start), float(det_sign_start)
    s_done = 0.0
    p0, dp, w, R0 = path.p0, path.dp, path.w, path.R0
    for k in range(1, n + 1):
        s_next = k / n
        # path.at(s_next); a translation (|w| = 0) keeps R0: Exp(0) R0 = R0 exactly
        p_t, R_t = p0 + s_next * dp, (R0 if angle == 0.0 else pin.exp3(s_next * w) @ R0)
        att = _solve_substep(kin, q, sigma, t_f, R_ft, p_t, R_t, unit * (s_next - s_done), settings,
                             det_sign, rest, state, [(s_next - s_done) * v for v in dp_w])
        if att.reason is None:
            q, sigma, det_sign, s_done, state = att.q, att.sigma, att.det_sign, s_next, att.state
            continue
        last = att
        lo, hi = s_done, s_next
        for _ in range(settings.bisections):
            mid = 0.5 * (lo + hi)
            p_t, R_t = path.at(mid)
            a = _solve_substep(kin, q, sigma, t_f, R_ft, p_t, R_t, unit * (mid - lo), settings, det_sign,
                               rest, state, [(mid - lo) * v for v in dp_w])
            if a.reason is None:
                q, sigma, det_sign, lo, state = a.q, a.sigma, a.det_sign, mid, a.state
            else:
                hi, last = mid, a
        return PathOutcome(q, lo, last.reason, last.message, sigma, det_sign, state)
    return PathOutcome(q, 1.0, None, "", sigma, det_sign, state)


_IDENTITY_ROWS = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
