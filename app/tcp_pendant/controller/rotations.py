"""Rotation conversions of the per-jog-step hot path (readout angles, scene quaternions).

The project's rule is scipy ``Rotation`` for rotation conversions; these two run on every jog
step of every session, where scipy's per-call object construction dominated the server's CPU
(measured on this machine: ``tcpcal.tool.abc_deg_from_rotation`` 200-1000 us per readout,
``Rotation.from_matrix(8 poses).as_quat()`` 100-280 us per scene update, against a whole jog
step of ~150 us). So the readout angles use pinocchio's C++ conversion (the library the app
already uses for kinematics), ~0.5 us per call, and the scene quaternions the float operations
of pinocchio's (Eigen's) quaternion-from-matrix in Python floats, bit for bit its result at
~1 us a node; the scipy/tcpcal definitions stay the reference: ``tests/app/test_pose_state.py``
checks them against scipy, tcpcal and pinocchio.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from tcpcal.tool import abc_deg_from_rotation

__all__ = ["GIMBAL_LOCK_COS_B", "kuka_abc_deg", "quaternion_wxyz", "quaternions_wxyz"]

GIMBAL_LOCK_COS_B = 1e-5
"""Below this cos(B) (B within ~0.0006 deg of +-90 deg) A and C are ill-defined (only A - C or
A + C is); there the readout uses tcpcal's conversion, which picks the same split as every
other readout of the project (``controller.readout``)."""


def kuka_abc_deg(R: np.ndarray) -> tuple[float, float, float]:
    """KUKA A, B, C (degrees) of a rotation matrix, ``R = Rz(A) Ry(B) Rx(C)``.

    Same result as :func:`tcpcal.tool.abc_deg_from_rotation` (methods.md section 6): A and C
    in (-180, 180], B in [-90, 90], rounded to 12 decimals, ``-0.0`` as ``0.0``. Away from
    gimbal lock pinocchio's ``rpy.matrixToRpy`` (roll, pitch, yaw = C, B, A for this
    convention) agrees with tcpcal to ~1e-12 deg; within :data:`GIMBAL_LOCK_COS_B` of the
    lock tcpcal's conversion is used.

    Args:
        R: (3,3) proper rotation matrix.
    """
    R = np.asarray(R, dtype=float)
    if math.hypot(R[0, 0], R[1, 0]) < GIMBAL_LOCK_COS_B:
        a, b, c = (float(v) for v in abc_deg_from_rotation(R))
        return a, b, c
    c_rad, b_rad, a_rad = pin.rpy.matrixToRpy(R)
    out = []
    for v in (a_rad, b_rad, c_rad):
        d = round(math.degrees(float(v)), 12) + 0.0      # + 0.0 turns -0.0 into 0.0
        out.append(180.0 if d == -180.0 else d)
    return out[0], out[1], out[2]


def quaternion_wxyz(R: np.ndarray | Sequence[Sequence[float]]) -> list[float]:
    """(w, x, y, z) unit quaternion of a rotation matrix, as a list.

    Args:
        R: (3,3) array, or its rows as Python floats (e.g. ``T.tolist()`` of a (4,4) pose:
            only the top-left 3x3 is read).

    Same rotation as scipy's ``Rotation.from_matrix(R).as_quat()`` (which is (x, y, z, w));
    the sign of a quaternion is not meaningful (q and -q are one rotation). Computed as
    Eigen's quaternion-from-matrix does (pinocchio's ``pin.Quaternion(R)``): for trace
    ``t = R00 + (R11 + R22) > 0``, ``w = sqrt(t + 1) / 2`` and ``(x, y, z) = (R21 - R12, R02 - R20,
    R10 - R01) / (4 w)``; else from the largest diagonal entry ``i`` (cyclic ``j, k``):
    ``q_i = sqrt(R_ii - R_jj - R_kk + 1) / 2``, ``w = (R_kj - R_jk) / (4 q_i)``,
    ``q_j = (R_ji + R_ij) / (4 q_i)``, ``q_k = (R_ki + R_ik) / (4 q_i)``. The same floating-point
    operations in the same order, in Python floats: bit for bit pinocchio's result
    (``tests/app/test_pose_state.py``) at a third of its cost per call (no array conversion),
    which the scene pays for every link a jog step turns.
    """
    m = R.tolist() if isinstance(R, np.ndarray) else R
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = m[0][:3], m[1][:3], m[2][:3]
    t = m00 + (m11 + m22)                      # Eigen's trace() sums in this order
    if t > 0.0:
        t = math.sqrt(t + 1.0)
        w = 0.5 * t
        t = 0.5 / t
        return [w, (m21 - m12) * t, (m02 - m20) * t, (m10 - m01) * t]
    i = 1 if m11 > m00 else 0
    if m22 > (m11 if i else m00):
        i = 2
    if i == 0:
        t = math.sqrt(m00 - m11 - m22 + 1.0)
        x = 0.5 * t
        t = 0.5 / t
        return [(m21 - m12) * t, x, (m10 + m01) * t, (m20 + m02) * t]
    if i == 1:
        t = math.sqrt(m11 - m22 - m00 + 1.0)
        y = 0.5 * t
        t = 0.5 / t
        return [(m02 - m20) * t, (m01 + m10) * t, y, (m21 + m12) * t]
    t = math.sqrt(m22 - m00 - m11 + 1.0)
    z = 0.5 * t
    t = 0.5 / t
    return [(m10 - m01) * t, (m02 + m20) * t, (m12 + m21) * t, z]


def quaternions_wxyz(R: np.ndarray) -> np.ndarray:
    """(w, x, y, z) quaternions of a stack of rotation matrices (N,3,3) -> (N,4)
    (:func:`quaternion_wxyz` of each)."""
    stack = np.asarray(R, dtype=float).reshape(-1, 3, 3)
    return np.array([quaternion_wxyz(m) for m in stack]).reshape(-1, 4)
