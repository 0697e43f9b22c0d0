"""Touch geometry: how the mounted tool's true tip sits relative to the reference tip.

Let ``r`` be the reference tip and ``T = T_world_tooltrue`` the hidden true TOOL frame (origin
at the true TCP, X along the working direction, pointing out of the tool; the tool's body
lies behind the TCP, along -X). The reference tip in true TOOL coordinates is

    u = R^T (r - p) = (u_x, u_y, u_z),   lateral distance rho = sqrt(u_y^2 + u_z^2).

* ``distance_mm = |u|``; ``touching`` when ``distance_mm <= 0.5`` (TOUCH_TOLERANCE_MM).
* ``penetration_mm = -u_x`` when the reference tip is *behind* the TCP (``u_x < 0``) within
  the tip's lateral radius ``rho <= 2 mm`` (CRASH_RADIUS_MM) and no deeper than 20 mm
  (CRASH_ZONE_DEPTH_MM), else 0.
* ``crashed`` when ``penetration_mm > 0.5`` (CRASH_DEPTH_MM): the tool tip has been driven
  *through* the spike - on a real robot the spike or the tool would have broken.

The crash zone is the tool's tip region only (a 2 mm radius, 20 mm long cylinder behind the
TCP along -X). Deeper along -X the reference tip counts as touching the tool's shank, which is
what the three-point method asks for when it puts the reference tip on the tool's -X axis
(methods.md section 5, typically 50-100 mm behind the TCP); that is not reported as a crash.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "CRASH_DEPTH_MM",
    "CRASH_RADIUS_MM",
    "CRASH_ZONE_DEPTH_MM",
    "TOUCH_TOLERANCE_MM",
    "TouchGeometry",
    "touch_geometry",
]

TOUCH_TOLERANCE_MM = 0.5
CRASH_DEPTH_MM = 0.5
CRASH_RADIUS_MM = 2.0
CRASH_ZONE_DEPTH_MM = 20.0
_CRASH_ZONE_REACH_MM = math.hypot(CRASH_ZONE_DEPTH_MM, CRASH_RADIUS_MM) * (1.0 + 1e-9)
"""Farthest a point of the crash zone is from the TCP (with a margin for rounding), mm."""


@dataclass(frozen=True)
class TouchGeometry:
    """Reference tip relative to the true tool tip (see the module docstring).

    Attributes:
        distance_mm: distance true TCP - reference tip, mm.
        touching: ``distance_mm <= 0.5``.
        crashed: the tool tip went through the reference tip (``penetration_mm > 0.5``).
        penetration_mm: depth of the reference tip behind the TCP inside the tip zone, mm (>= 0).
    """

    distance_mm: float
    touching: bool
    crashed: bool
    penetration_mm: float


def touch_geometry(T_world_tooltrue: np.ndarray, tip_world_m: np.ndarray) -> TouchGeometry:
    """Touch geometry of a true TOOL pose (4,4, metres) and a reference tip (3,, metres).

    ``R^T (r - p)`` is one numpy product (the same operations, so the same numbers, on every
    path); the rest is Python floats, and the crash zone's test is skipped where it cannot hold (farther
    than the zone's far corner, ``hypot(CRASH_ZONE_DEPTH_MM, CRASH_RADIUS_MM)``: penetration 0)."""
    T = np.asarray(T_world_tooltrue, dtype=float)
    ux, uy, uz = (T[:3, :3].T @ (np.asarray(tip_world_m, dtype=float) - T[:3, 3])).tolist()
    ux, uy, uz = ux * 1000.0, uy * 1000.0, uz * 1000.0      # m -> mm (the products numpy's * 1000 makes)
    distance = math.hypot(ux, uy, uz)            # |u| (math: no numpy call per step)
    penetration = 0.0
    if distance <= _CRASH_ZONE_REACH_MM:
        depth = -ux
        if depth > 0.0 and depth <= CRASH_ZONE_DEPTH_MM and math.hypot(uy, uz) <= CRASH_RADIUS_MM:
            penetration = depth
    return TouchGeometry(distance_mm=distance, touching=distance <= TOUCH_TOLERANCE_MM,
                         crashed=penetration > CRASH_DEPTH_MM, penetration_mm=penetration)
