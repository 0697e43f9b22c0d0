"""Inverse kinematics of a TCP pose and the auto-approach target (demos, auto-touch).

Metres and radians. Two pieces:

* :func:`approach_pose`: the true TOOL pose that puts the reference tip at a given offset in
  TOOL coordinates, seen from a direction (tilt, azimuth, spin)::

      R_world_tool = Rz(azimuth) Ry(-tilt) R_down Rx(spin),
      R_down = [[0, 0, 1], [0, 1, 0], [-1, 0, 0]]   (tool X down, Y along Y, Z along X: PA-1)
      p_world_tool = r - R_world_tool o + n,   n ~ N(0, sigma^2 I)                   (AA-1)

  so tool X points ``tilt`` away from WORLD -Z, turned ``azimuth`` about WORLD Z, and the tool
  is turned ``spin`` about its own X. ``o`` is the tip offset in TOOL coordinates (0 = the true
  TCP on the reference tip) and ``n`` the simulated operator error (WORLD axes).

* :func:`solve_ik`: damped Newton iterations (J-2 of ``jog.py``, without the path) from the
  current configuration, then from home, then from a few deterministic pseudo-random seeds
  inside the limits; iterates are clipped to the joint limits, steps are capped at 0.3 rad
  per joint, and a solution counts when the pose error is below 1e-12 m and 1e-12 rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.spatial.transform import Rotation

from tcp_pendant.controller.kinematics import RobotKinematics

__all__ = ["R_DOWN", "IkSolution", "approach_pose", "approach_rotation", "solve_ik"]

R_DOWN = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
"""Tool X along WORLD -Z, tool Y along WORLD Y, tool Z along WORLD X (PA-1)."""

_SEED_RNG_SEED = 20240522


def approach_rotation(tilt_deg: float, azimuth_deg: float, spin_deg: float = 0.0) -> np.ndarray:
    """``R_world_tool`` of (AA-1)."""
    return (Rotation.from_euler("z", azimuth_deg, degrees=True)
            * Rotation.from_euler("y", -tilt_deg, degrees=True)
            * Rotation.from_matrix(R_DOWN)
            * Rotation.from_euler("x", spin_deg, degrees=True)).as_matrix()


def approach_pose(tip_world_m: np.ndarray, *, tilt_deg: float, azimuth_deg: float,
                  spin_deg: float = 0.0, tip_offset_tool_mm: np.ndarray = np.zeros(3),
                  noise_world_mm: np.ndarray = np.zeros(3)) -> np.ndarray:
    """``T_world_tool`` (4,4, metres) of (AA-1)."""
    R = approach_rotation(tilt_deg, azimuth_deg, spin_deg)
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = (np.asarray(tip_world_m, dtype=float)
                - R @ (np.asarray(tip_offset_tool_mm, dtype=float) / 1000.0)
                + np.asarray(noise_world_mm, dtype=float) / 1000.0)
    return T


@dataclass(frozen=True)
class IkSolution:
    """Result of :func:`solve_ik`.

    Attributes:
        ok: a configuration within the limits reaches the pose.
        q_rad: that configuration (the start configuration when not ok).
        position_error_m, rotation_error_rad: remaining error of the best attempt.
        seeds_tried: number of start configurations used.
    """

    ok: bool
    q_rad: np.ndarray
    position_error_m: float
    rotation_error_rad: float
    seeds_tried: int


def _ik_from(kin: RobotKinematics, q0: np.ndarray, t_f: np.ndarray, R_ft: np.ndarray,
             p_target: np.ndarray, R_target: np.ndarray, *, max_iterations: int,
             tol: float) -> tuple[np.ndarray, float, float]:
    lo, hi = kin.lower_rad, kin.upper_rad
    q = np.clip(q0, lo, hi)
    w2 = np.array([0.09] * 3 + [1.0] * 3)
    ep = er = math.inf
    lam2 = 1e-6
    prev = math.inf
    for _ in range(max_iterations):
        J, R_wf, p_wf = kin.jacobian_and_pose(q)
        r = R_wf @ t_f
        e_p = p_target - (p_wf + r)
        e_r = pin.log3(R_target @ (R_wf @ R_ft).T)
        ep, er = math.sqrt(e_p @ e_p), math.sqrt(e_r @ e_r)
        if ep < tol and er < tol:
            break
        # Levenberg-style damping: shrink when the error falls, grow when it does not
        cost = ep * ep / 0.09 + er * er
        lam2 = max(lam2 * 0.3, 1e-12) if cost < prev else min(lam2 * 10.0, 1.0)
        prev = min(prev, cost)
        Jt = J.copy()
        Jt[:3] -= np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]]) @ J[3:]
        A = Jt @ Jt.T
        A[np.diag_indices(6)] += lam2 * w2
        dq = Jt.T @ np.linalg.solve(A, np.concatenate((e_p, e_r)))
        biggest = float(np.abs(dq).max())
        if biggest > 0.3:
            dq *= 0.3 / biggest
        q = np.clip(q + dq, lo, hi)
    return q, ep, er


def solve_ik(kin: RobotKinematics, T_world_tcp: np.ndarray, q_start: np.ndarray, *,
             T_flange_tcp: np.ndarray | None = None, n_random_seeds: int = 24,
             max_iterations: int = 150, tol: float = 1e-12) -> IkSolution:
    """Joint angles that put the TCP (``T_flange_tcp``, default the flange) at ``T_world_tcp``.

    Tries ``q_start`` first (so the solution stays on the current arm configuration when it
    can), then home, then ``n_random_seeds`` deterministic seeds (the same every call).
    """
    T_ft = np.eye(4) if T_flange_tcp is None else np.asarray(T_flange_tcp, dtype=float)
    t_f, R_ft = T_ft[:3, 3].copy(), T_ft[:3, :3].copy()
    p_target = np.asarray(T_world_tcp, dtype=float)[:3, 3].copy()
    R_target = np.asarray(T_world_tcp, dtype=float)[:3, :3].copy()
    rng = np.random.default_rng(_SEED_RNG_SEED)
    span = kin.upper_rad - kin.lower_rad
    mid = 0.5 * (kin.upper_rad + kin.lower_rad)
    seeds = [np.asarray(q_start, dtype=float), np.asarray(kin.home_rad, dtype=float)]
    best = (math.inf, q_start, math.inf, math.inf)
    tried = 0
    for k in range(2 + n_random_seeds):
        q0 = seeds[k] if k < 2 else mid + rng.uniform(-0.4, 0.4, kin.n_joints) * np.minimum(span, 2 * math.pi)
        tried += 1
        q, ep, er = _ik_from(kin, q0, t_f, R_ft, p_target, R_target,
                             max_iterations=max_iterations, tol=tol)
        if ep < tol and er < tol:
            return IkSolution(True, q, ep, er, tried)
        if ep / 0.3 + er < best[0]:
            best = (ep / 0.3 + er, q, ep, er)
    return IkSolution(False, np.asarray(q_start, dtype=float).copy(), best[2], best[3], tried)
