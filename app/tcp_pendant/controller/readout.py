"""Pose readout as a pendant shows it: X, Y, Z in mm and KUKA A, B, C in degrees.

``R = Rz(A) Ry(B) Rx(C)`` (intrinsic Z, Y', X''; scipy ``from_euler("ZYX", [A, B, C])``,
methods.md section 6); the conversion is tcpcal's :func:`tcpcal.tool.abc_deg_from_rotation`,
which stays exact next to gimbal lock (B = +-90 deg).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tcpcal.tool import abc_deg_from_rotation

__all__ = ["PoseReadout", "pose_readout"]


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

    def rows(self, decimals: int = 2) -> tuple[tuple[str, str, str], ...]:
        """``(label, value, unit)`` rows for the pendant, e.g. ``("X", "525.00", "mm")``.

        Values are rounded to ``decimals`` and ``-0.00`` is shown as ``0.00``.
        """
        def fmt(v: float) -> str:
            text = f"{v:.{decimals}f}"
            return text[1:] if text.startswith("-") and float(text) == 0.0 else text

        return (("X", fmt(self.x_mm), "mm"), ("Y", fmt(self.y_mm), "mm"), ("Z", fmt(self.z_mm), "mm"),
                ("A", fmt(self.a_deg), "deg"), ("B", fmt(self.b_deg), "deg"), ("C", fmt(self.c_deg), "deg"))

    def text(self, decimals: int = 2) -> str:
        """One line, e.g. ``"WORLD X 525.00 Y 0.00 Z 890.00 mm  A 0.00 B 90.00 C 0.00 deg"``."""
        r = self.rows(decimals)
        pos = " ".join(f"{lab} {val}" for lab, val, _ in r[:3])
        rot = " ".join(f"{lab} {val}" for lab, val, _ in r[3:])
        return f"{self.frame} {pos} mm  {rot} deg"

    def __str__(self) -> str:
        return self.text()


def pose_readout(T_frame_tcp: np.ndarray, frame: str) -> PoseReadout:
    """The readout of a (4,4) pose in metres, expressed in ``frame`` (label only)."""
    T = np.asarray(T_frame_tcp, dtype=float)
    x, y, z = (float(v) * 1000.0 for v in T[:3, 3])
    a, b, c = (float(v) for v in abc_deg_from_rotation(T[:3, :3]))
    return PoseReadout(frame, x, y, z, a, b, c)
