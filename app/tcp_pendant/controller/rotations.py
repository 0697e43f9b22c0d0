"""Rotation conversions of the per-jog-step hot path (readout angles, scene quaternions).

The project's rule is scipy ``Rotation`` for rotation conversions; these two run on every jog
step of every session, where scipy's per-call object construction dominated the server's CPU
(measured on this machine: ``tcpcal.tool.abc_deg_from_rotation`` 200-1000 us per readout,
``Rotation.from_matrix(8 poses).as_quat()`` 100-280 us per scene update, against a whole jog
step of ~150 us). So they use pinocchio's C++ conversions (the library the app already uses
for kinematics), ~0.5 us and ~3 us per call, and keep the scipy/tcpcal definitions as the
reference: ``tests/app/test_pose_state.py`` checks them against scipy and tcpcal.
"""

from __future__ import annotations

import math

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


def quaternion_wxyz(R: np.ndarray) -> list[float]:
    """(w, x, y, z) unit quaternion of a rotation matrix (3,3), as a list.

    Same rotation as scipy's ``Rotation.from_matrix(R).as_quat()`` (which is (x, y, z, w));
    the sign of a quaternion is not meaningful (q and -q are one rotation).
    """
    x, y, z, w = pin.Quaternion(np.ascontiguousarray(R, dtype=float)).coeffs().tolist()
    return [w, x, y, z]


def quaternions_wxyz(R: np.ndarray) -> np.ndarray:
    """(w, x, y, z) quaternions of a stack of rotation matrices (N,3,3) -> (N,4)
    (:func:`quaternion_wxyz` of each)."""
    stack = np.asarray(R, dtype=float).reshape(-1, 3, 3)
    return np.array([quaternion_wxyz(m) for m in stack]).reshape(-1, 4)
