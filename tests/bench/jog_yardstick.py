"""The jog algorithm as it was before the per-step speed work: the yardstick of
``bench_controller.py``'s jog-increment figures and of ``tests/controller/test_jog_state.py``
(the new code must land on the same joint angles and stop for the same reasons).

``legacy_follow_path`` is ``tcp_pendant.controller.jog.follow_path`` of that version (the
same math: damped least squares J-2 through ``J^T (J J^T + lambda^2 W^-2)^-1 e`` with
``np.linalg.solve``, a full pinocchio pass per Newton iteration, ``np.linalg.svd`` and
``np.linalg.det`` per sub-step); :class:`LegacyController` is a ``VirtualController`` whose
Cartesian jogs run it (keeping ``(q, sigma, det sign)`` of the last path as the controller then
did) and :class:`LegacyJogger` the pendant's ``Jogger`` with its translation (contact stop) as it
was. Not used by the app.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import pinocchio as pin

from tcp_pendant.controller import ControllerError, VirtualController
from tcp_pendant.controller.controller import _AXES, _finite
from tcp_pendant.controller.jog import (
    DEFAULT_SETTINGS,
    CartesianPath,
    JogFrame,
    JogResult,
    JogSettings,
    PathOutcome,
    StopReason,
    _null_space_step,
    singularity_message,
)
from tcp_pendant.controller.kinematics import RobotKinematics
from tcp_pendant.pendant.guidance import contact_stop
from tcp_pendant.pendant.jogging import CartesianAxis, Jogger

__all__ = ["LegacyController", "LegacyJogger", "legacy_follow_path"]


def _jacobian_and_pose(kin: RobotKinematics, q_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    J = pin.computeFrameJacobian(kin.model, kin.data, q_rad, kin._flange_id, pin.LOCAL_WORLD_ALIGNED)
    M = kin.data.oMf[kin._flange_id]
    return J, M.rotation.copy(), M.translation.copy()


def _at(path: CartesianPath, s: float) -> tuple[np.ndarray, np.ndarray]:
    """``CartesianPath.at`` as it was (``Exp(s w) R0`` also for ``w = 0``)."""
    return path.p0 + s * path.dp, pin.exp3(s * path.w) @ path.R0


def _limit_violation(kin: RobotKinematics, q_rad: np.ndarray, tol: float = 1e-12) -> tuple[int, str] | None:
    if bool(np.all(q_rad >= kin.lower_rad - tol)) and bool(np.all(q_rad <= kin.upper_rad + tol)):
        return None
    below = np.nonzero(q_rad < kin.lower_rad - tol)[0]
    above = np.nonzero(q_rad > kin.upper_rad + tol)[0]
    firsts = [(int(i), "lower") for i in below[:1]] + [(int(i), "upper") for i in above[:1]]
    return min(firsts) if firsts else None


def _sigma_min(J_flange: np.ndarray, settings: JogSettings) -> float:
    Js = J_flange.copy()
    Js[:3] /= settings.length_scale_m
    s = np.linalg.svd(Js, compute_uv=False)
    k = min(Js.shape) - 1
    return float(s[k]) if Js.shape[1] >= 6 else 0.0


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _det_sign(J_flange: np.ndarray) -> float:
    """Sign of ``det J_flange`` (+1 or -1; 0 when J is not square or exactly singular)."""
    if J_flange.shape[0] != J_flange.shape[1]:
        return 0.0
    return float(np.sign(np.linalg.det(J_flange)))


@dataclass
class _Attempt:
    q: np.ndarray
    sigma: float
    reason: StopReason | None
    message: str
    det_sign: float = 0.0


def _solve_substep(kin: RobotKinematics, q_start: np.ndarray, sigma_start: float,
                   t_f: np.ndarray, R_ft: np.ndarray, p_target: np.ndarray, R_target: np.ndarray,
                   cart_amount: float, settings: JogSettings, det_sign_start: float = 0.0,
                   q_rest: np.ndarray | None = None) -> _Attempt:
    """Damped Newton (J-2) from ``q_start`` to one target pose, then the safety checks.

    ``det_sign_start`` is :func:`_det_sign` at ``q_start`` (0: unknown or on a singularity);
    ``q_rest``: the rest configuration of a redundant arm's null-space step (J-3), None: none.
    """
    eps = settings.singular_eps
    lam2 = 0.0
    if sigma_start < eps:
        lam2 = settings.lambda_max ** 2 * (1.0 - (sigma_start / eps) ** 2)
    L = settings.length_scale_m
    w2 = np.array([L * L] * 3 + [1.0] * 3)  # W^-2: damping in the scaled metric
    q = q_start.copy()
    J = None
    converged = False
    allowance = max(settings.max_joint_gain * cart_amount, settings.min_joint_allowance_rad)
    for iteration in range(settings.max_iterations + 1):
        J, R_wf, p_wf = _jacobian_and_pose(kin, q)
        r = R_wf @ t_f
        e_p = p_target - (p_wf + r)
        e_r = pin.log3(R_target @ (R_wf @ R_ft).T)
        if math.sqrt(e_p @ e_p) < settings.tol_m and math.sqrt(e_r @ e_r) < settings.tol_rad:
            converged = True
            break
        Jt = J.copy()
        Jt[:3] -= _skew(r) @ J[3:]
        e = np.concatenate((e_p, e_r))
        A = Jt @ Jt.T
        if lam2 > 0.0:
            A[np.diag_indices(6)] += lam2 * w2
        try:
            dq = Jt.T @ np.linalg.solve(A, e)
        except np.linalg.LinAlgError:
            dq = Jt.T @ np.linalg.lstsq(A, e, rcond=None)[0]
        if iteration == 0 and q_rest is not None:
            dq = dq + _null_space_step(Jt, q, q_rest, settings.null_space_gain, 0.25 * allowance)
        q = q + dq
        if not np.isfinite(q).all():
            break
    jump = float(np.abs(q - q_start).max()) if np.isfinite(q).all() else math.inf
    if not converged or jump > allowance:
        if sigma_start < 2.0 * eps:
            return _Attempt(q_start, sigma_start, "singularity", singularity_message(kin, q_start, settings))
        if not converged:
            why = "target out of reach: no joint angles put the TCP on the path there"
        else:
            name = kin.joint_names[int(np.argmax(np.abs(q - q_start)))]
            why = (f"{name} would have to turn too fast: the path runs into the edge of the reach "
                   "or a singularity")
        return _Attempt(q_start, sigma_start, "unreachable", why)
    viol = _limit_violation(kin, q)
    if viol is not None:
        # the joint furthest beyond its limit is the one to name
        over = np.maximum(kin.lower_rad - q, q - kin.upper_rad)
        i = int(np.argmax(over))
        side = "lower" if q[i] < kin.lower_rad[i] else "upper"
        return _Attempt(q_start, sigma_start, "joint_limit", kin.limit_message(i, side))
    assert J is not None  # the Newton loop runs at least once
    sigma = _sigma_min(J, settings)
    if sigma < eps and sigma < sigma_start * (1.0 - 1e-9) - 1e-12:
        return _Attempt(q_start, sigma_start, "singularity", singularity_message(kin, q, settings))
    det_sign = _det_sign(J)
    if (det_sign * det_sign_start < 0.0 and sigma > settings.singular_zero
            and sigma_start > settings.singular_zero):
        # passed through a singularity into another configuration: name the one at the start
        return _Attempt(q_start, sigma_start, "singularity", singularity_message(kin, q_start, settings),
                        det_sign_start)
    return _Attempt(q, sigma, None, "", det_sign)


def legacy_follow_path(kin: RobotKinematics, q_rad: np.ndarray, T_flange_tcp: np.ndarray,
                path: CartesianPath, settings: JogSettings = DEFAULT_SETTINGS, *,
                sigma_start: float | None = None, q_rest: np.ndarray | None = None,
                det_sign_start: float | None = None) -> PathOutcome:
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

    Returns:
        The configuration reached, the fraction ``moved`` of the path, the stop reason and
        message (None and "" when the whole path was carried out), and ``sigma`` at the end.
    """
    t_f = np.ascontiguousarray(T_flange_tcp[:3, 3], dtype=float)
    R_ft = np.ascontiguousarray(T_flange_tcp[:3, :3], dtype=float)
    length_m = math.hypot(*path.dp.tolist())           # |dp|, |w|, |t_f|: math, no numpy call per jog step
    angle = math.hypot(*path.w.tolist())
    n = max(1, math.ceil(max(length_m / settings.max_substep_m, angle / settings.max_substep_rad) - 1e-9))
    # joint allowance per unit of flange motion: (mm of travel -> "deg") + rad of rotation; a
    # rotation about the TCP swings the flange by |w| |t| (module doc)
    lever_m = math.hypot(*t_f.tolist())
    unit = (length_m + angle * lever_m) * 1000.0 * math.radians(1.0) + angle

    q = np.array(q_rad, dtype=float)
    rest = np.asarray(q_rest, dtype=float) if q_rest is not None and kin.n_joints > 6 else None
    if sigma_start is None or det_sign_start is None:
        J0 = kin.jacobian_flange(q)
        sigma = _sigma_min(J0, settings) if sigma_start is None else float(sigma_start)
        det_sign = _det_sign(J0) if det_sign_start is None else float(det_sign_start)
    else:
        sigma, det_sign = float(sigma_start), float(det_sign_start)
    s_done = 0.0
    for k in range(1, n + 1):
        s_next = k / n
        p_t, R_t = _at(path, s_next)
        att = _solve_substep(kin, q, sigma, t_f, R_ft, p_t, R_t, unit * (s_next - s_done), settings,
                             det_sign, rest)
        if att.reason is None:
            q, sigma, det_sign, s_done = att.q, att.sigma, att.det_sign, s_next
            continue
        last = att
        lo, hi = s_done, s_next
        for _ in range(settings.bisections):
            mid = 0.5 * (lo + hi)
            p_t, R_t = _at(path, mid)
            a = _solve_substep(kin, q, sigma, t_f, R_ft, p_t, R_t, unit * (mid - lo), settings, det_sign,
                               rest)
            if a.reason is None:
                q, sigma, det_sign, lo = a.q, a.sigma, a.det_sign, mid
            else:
                hi, last = mid, a
        return PathOutcome(q, lo, last.reason, last.message, sigma, det_sign)
    return PathOutcome(q, 1.0, None, "", sigma, det_sign)


class LegacyController(VirtualController):
    """A ``VirtualController`` whose Cartesian jogs (``jog_cartesian`` as it was) and gizmo moves
    follow :func:`legacy_follow_path`."""

    _legacy_sigma: tuple[np.ndarray, float, float] | None = None

    def _legacy_frame_rotation(self, frame: JogFrame) -> np.ndarray:
        if frame is JogFrame.WORLD:
            return np.eye(3)
        if frame is JogFrame.BASE:
            return self._T_world_base[:3, :3].copy()
        if frame is JogFrame.FLANGE:
            return self.T_world_flange()[:3, :3]
        return self.T_world_tcp()[:3, :3]

    def jog_cartesian(self, frame: JogFrame | str, axis: Literal["X", "Y", "Z", "A", "B", "C"],
                      amount: float) -> JogResult:
        """Jog the active TCP by one increment in a jog frame.

        X, Y, Z: translate the TCP by ``amount`` mm along that axis of ``frame``.
        A, B, C: rotate the tool by ``amount`` degrees about the TCP, about the Z (A), Y (B) or
        X (C) axis of ``frame`` (KUKA habit: A, B, C are the angles about Z, Y, X). FLANGE
        and TOOL axes are taken at the start of the increment.

        The motion follows ``jog.follow_path`` (J-1, J-2): the TCP stays on its line to
        < 0.01 mm with the orientation held to < 0.001 deg; a rotation keeps the TCP fixed;
        it stops at joint limits and singularities with ``stopped_by`` and the message, and
        never jumps configuration. The app makes continuous jogging from small increments
        (speed * override * dt).
        """
        try:
            jf = JogFrame(frame.upper() if isinstance(frame, str) else frame)
        except ValueError:
            raise ControllerError(f"Unknown jog frame {frame!r}; use WORLD, BASE, FLANGE or TOOL.") from None
        ax = str(axis).upper()
        if ax not in _AXES:
            raise ControllerError(f"Unknown jog axis {axis!r}; use X, Y, Z (mm) or A, B, C (deg).")
        amt = _finite(amount, "jog amount")
        if amt == 0.0:
            return JogResult(True, 1.0, None, "")
        direction = self._legacy_frame_rotation(jf)[:, _AXES[ax]]
        T0 = self.T_world_tcp()
        if ax in "XYZ":
            path = CartesianPath(T0[:3, 3], T0[:3, :3], direction * (amt / 1000.0), np.zeros(3))
        else:
            path = CartesianPath(T0[:3, 3], T0[:3, :3], np.zeros(3), direction * math.radians(amt))
        return self._follow(path, self._T_flange_tool)

    def _follow(self, path: CartesianPath, T_flange_tcp: np.ndarray) -> JogResult:
        known = self._legacy_sigma is not None and np.array_equal(self._legacy_sigma[0], self._q)
        sigma, det_sign = ((self._legacy_sigma[1], self._legacy_sigma[2])
                           if known and self._legacy_sigma is not None else (None, None))
        out = legacy_follow_path(self.kinematics, self._q, T_flange_tcp, path, self.settings,
                                 sigma_start=sigma, q_rest=self._rest_q, det_sign_start=det_sign)
        self._q = out.q_rad
        self._legacy_sigma = (out.q_rad.copy(), out.sigma, out.det_sign)
        if out.stopped_by is None:
            return JogResult(True, 1.0, None, "")
        return JogResult(False, float(out.moved), out.stopped_by, out.message)


class LegacyJogger(Jogger):
    """The pendant's ``Jogger`` with ``_translate`` as it was (``contact_stop`` on every press)."""

    def _translate(self, ax: CartesianAxis, amount_mm: float) -> JogResult:
        """A translation of ``amount_mm`` along axis ``ax`` of the jog frame, stopped at contact
        (module docstring)."""
        c = self.controller
        if not self.stop_at_contact:
            return c.jog_cartesian(self.settings.frame, ax, amount_mm)
        step_m = self.frame_rotation()[:, "XYZ".index(ax)] * (amount_mm / 1000.0)
        stop = contact_stop(c.T_world_tool_true()[:3, 3], step_m, c.reference_tip_world_m)
        if stop is None:
            return c.jog_cartesian(self.settings.frame, ax, amount_mm)
        res = c.jog_cartesian(self.settings.frame, ax, amount_mm * stop.fraction)
        if not res.ok:
            return res
        return JogResult(False, stop.fraction, "contact",
                         f"Stopped at the reference tip after {abs(amount_mm) * stop.fraction:.2f} of "
                         f"{abs(amount_mm):g} mm (touch-up: the tool tip touches it). Press again to go on.")
