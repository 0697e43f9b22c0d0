"""Pose readout as a pendant shows it: X, Y, Z in mm and KUKA A, B, C in degrees (numbers).

``R = Rz(A) Ry(B) Rx(C)`` (intrinsic Z, Y', X''; scipy ``from_euler("ZYX", [A, B, C])``,
methods.md section 6). One path computes it: :func:`readout_in_frame`, used by both
``VirtualController.readout`` and ``PoseState.readout`` (the jog's hot path), with the angles
by :func:`tcp_pendant.controller.rotations.kuka_abc_deg` (pinocchio, checked against tcpcal's
``abc_deg_from_rotation`` in tests/app/test_pose_state.py, exact next to gimbal lock too). The
text the pendant shows is made from these numbers in one place, ``tcp_pendant.pendant.formatting``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.controller.rotations import kuka_abc_deg

__all__ = ["READOUT_FRAMES", "PoseReadout", "readout_in_frame"]

READOUT_FRAMES = ("WORLD", "BASE")


@dataclass(frozen=True)
class PoseReadout:
    """A TCP pose in one frame.

    Attributes:
        frame: "WORLD" or "BASE".
        x_mm, y_mm, z_mm: TCP position, mm.
        a_deg, b_deg, c_deg: KUKA A, B, C of the TCP orientation, degrees (A in (-180, 180],
            B in [-90, 90], C in (-180, 180]).
    """

    frame: str
    x_mm: float
    y_mm: float
    z_mm: float
    a_deg: float
    b_deg: float
    c_deg: float


def readout_in_frame(T_world_tcp: np.ndarray, T_world_base: np.ndarray, frame: str) -> PoseReadout:
    """The readout of the TCP pose ``T_world_tcp`` (4x4, metres) in WORLD or BASE.

    Raises:
        ControllerError: another frame.
    """
    f = str(frame).upper()
    if f == "WORLD":
        T = np.asarray(T_world_tcp, dtype=float)
    elif f == "BASE":
        T = np.linalg.inv(np.asarray(T_world_base, dtype=float)) @ np.asarray(T_world_tcp, dtype=float)
    else:
        raise ControllerError(f"Readout frame must be WORLD or BASE, got {frame!r}.")
    a, b, c = kuka_abc_deg(T[:3, :3])
    return PoseReadout(f, float(T[0, 3]) * 1000.0, float(T[1, 3]) * 1000.0, float(T[2, 3]) * 1000.0, a, b, c)
