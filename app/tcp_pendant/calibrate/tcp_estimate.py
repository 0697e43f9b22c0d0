"""The wizard's own estimate of the TCP from the touches recorded so far, to tilt about (no viser).

With no tool data active the rotation keys turn the tool about the flange, so a 45° tilt swings
the tool tip away from the reference tip by about ``2 sin(22.5°) L`` (~100-140 mm for a 150-
180 mm pointer) and the trainee jogs it back over every increment. Once an XYZ 4-point has two
touches in different orientations, the touches themselves say most of where the tip is: every
touch ``i`` puts the same unknown TCP ``t`` (FLANGE, mm) on the same unknown reference tip ``r``,
``R_i t + f_i = r`` (methods.md, 4P-1), so for touches ``i`` and 1

    (R_i - R_1) t = f_1 - f_i                                   (3 equations per touch pair)

:func:`tcp_estimate` solves the stacked pairs by least squares (``numpy.linalg.lstsq``). Two
touches leave the component of ``t`` along the axis they were tilted about unobserved (``R_2 -
R_1 = R_1 (R_1^T R_2 - I)`` is singular along it): the minimum-norm solution sets it to zero,
which for a straight pointer (its tip on the flange axis) misses little. Made the active tool
data (``TcpEstimate.tool``, named as the wizard's estimate, never the truth), the rotation keys
turn about it, and the next tilt swings the tip only by the estimate's error.

It is the trainee's own touches and nothing else (no hidden TCP, no distance), so in an exercise
it gives nothing the touches did not earn: a finished calibration still needs all four touches,
and the grade is the finished result's. Units: mm (the pendant's), from the wizard's metres.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from tcp_pendant.translation import ENGLISH, Translator
from tcpcal.tool import Tool

__all__ = ["ESTIMATE_NAME", "MIN_TOUCHES", "TcpEstimate", "tcp_estimate"]

MIN_TOUCHES = 2
"""Touches (in different orientations) an estimate needs."""
ESTIMATE_NAME = "Estimate, {n} touches"
"""The tool data's name in English (:meth:`TcpEstimate.tool` names it in the session's
language): the readout says whose numbers are active."""
_MIN_TURN = 1e-3
"""Touches whose flange orientations differ by less than this (``|R_i - R_1|``, ~0.06°) say
nothing about ``t``."""


@dataclass(frozen=True)
class TcpEstimate:
    """The wizard's estimate of the TCP.

    Attributes:
        tcp_mm: (x, y, z) in FLANGE, mm.
        touches: how many recorded touches it comes from.
    """

    tcp_mm: tuple[float, float, float]
    touches: int

    def tool(self, *, tr: Translator = ENGLISH) -> Tool:
        """As tool data to activate (orientation A = B = C = 0: the flange's), named in ``tr``'s
        language (:data:`ESTIMATE_NAME` in English)."""
        name = tr.ngettext("Estimate, {n} touch", "Estimate, {n} touches", self.touches).format(n=self.touches)
        return Tool(name=name, tcp_mm=self.tcp_mm)


def tcp_estimate(wizard: Any) -> TcpEstimate | None:
    """The estimate from an XYZ 4-point wizard's recorded touches (module docstring), or None:
    not an XYZ 4-point, fewer than :data:`MIN_TOUCHES` touches, or all in one orientation."""
    if wizard is None or getattr(wizard, "kind", "") != "xyz4":
        return None
    poses = wizard.recorded_poses
    rows = [np.asarray(poses[i].T_world_flange_m, dtype=float) for i in wizard.solver_touch_steps() if i in poses]
    if len(rows) < MIN_TOUCHES:
        return None
    R1, f1 = rows[0][:3, :3], rows[0][:3, 3] * 1000.0
    pairs = [(T[:3, :3] - R1, f1 - T[:3, 3] * 1000.0) for T in rows[1:]]
    pairs = [(A, b) for A, b in pairs if float(np.abs(A).max()) >= _MIN_TURN]
    if not pairs:
        return None
    A = np.vstack([a for a, _ in pairs])
    b = np.concatenate([v for _, v in pairs])
    t, *_ = np.linalg.lstsq(A, b, rcond=None)          # minimum norm along what no tilt observed
    return TcpEstimate((float(t[0]), float(t[1]), float(t[2])), len(rows))
