"""Touch guidance of the pendant (no viser): where the reference tip is, seen from the tool tip.

* :func:`jog_frame_rotation`: ``R_world_frame`` of a jog frame (WORLD, BASE, FLANGE, TOOL) for a
  robot's :class:`~tcp_pendant.controller.pose_state.PoseState` (the axes the X/Y/Z keys move
  along; TOOL is the active TCP's frame, as ``VirtualController.jog_cartesian`` uses).
* :func:`tip_offset_mm`: the reference tip relative to the mounted tool's true tip along the
  jog frame's axes (mm): jogging X by ``dx``, Y by ``dy`` and Z by ``dz`` brings the tips together
  (a translation moves every point of the tool alike).
* :func:`offset_markdown` and :func:`side_view_markdown`: the "ΔX n ΔY n ΔZ n mm" line and a
  magnified two-view drawing of the tips (text in a code block, auto-scaled so that 0.5 mm is
  several characters when close).
* :func:`collision_stop`: the same with the distance hidden, only for a step that would carry
  the tip more than ``touch.CRASH_DEPTH_MM`` past the reference tip (a collision).
* :func:`contact_stop`: the fraction of a translation after which the tool tip meets the
  reference tip (stop at contact, like a real touch-up), or None when the step does not pass
  through it.

Units: metres in, millimetres out (names say which).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tcp_pendant.controller.pose_state import PoseState
from tcp_pendant.controller.touch import CRASH_DEPTH_MM, CRASH_RADIUS_MM, TOUCH_TOLERANCE_MM
from tcp_pendant.translation import ENGLISH, Translator

__all__ = [
    "CLOSEUP_WITHIN_MM",
    "CONTACT_RADIUS_MM",
    "ContactStop",
    "collision_stop",
    "contact_stop",
    "direction_words",
    "jog_frame_rotation",
    "offset_markdown",
    "side_view_markdown",
    "tip_offset_mm",
    "tip_offset_xyz_mm",
]

CLOSEUP_WITHIN_MM = 20.0
"""The close-up is shown when the tips are closer than this (farther, the Δ line says enough)."""
CONTACT_RADIUS_MM = CRASH_RADIUS_MM
"""A translation whose tool-tip path passes closer than this to the reference tip stops where
it is closest (the tip touches); farther, the tip passes beside the spike."""

_STOPPED_HERE_M = 1e-6
"""A closest point this near the tip's start (m) is where the last press stopped it."""
_SCALES_MM = (0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0, 25.0, 50.0, 100.0)
_HALF_W, _HALF_H = 7, 2          # characters either side of the tool tip in the drawing


def jog_frame_rotation(state: PoseState, frame: str) -> np.ndarray:
    """``R_world_frame`` (3,3) of jog frame ``frame`` at ``state``.

    Raises:
        ValueError: an unknown frame.
    """
    f = str(frame).upper()
    if f == "WORLD":
        return np.eye(3)
    if f == "BASE":
        return np.asarray(state.T_world_base)[:3, :3]
    if f == "FLANGE":
        return np.asarray(state.T_world_flange)[:3, :3]
    if f == "TOOL":
        return np.asarray(state.T_world_tcp)[:3, :3]
    raise ValueError(f"Unknown jog frame {frame!r}; use WORLD, BASE, FLANGE or TOOL.")


def tip_offset_mm(state: PoseState, reference_tip_world_m: np.ndarray, frame: str) -> np.ndarray:
    """Reference tip minus the true tool tip, along the axes of jog frame ``frame`` (mm, (3,))."""
    return np.array(tip_offset_xyz_mm(state, reference_tip_world_m, frame))


def tip_offset_xyz_mm(state: PoseState, reference_tip_world_m: np.ndarray,
                      frame: str) -> tuple[float, float, float]:
    """:func:`tip_offset_mm` as three Python floats (the readout's every step).

    WORLD: ``(r - p) * 1000`` per axis on floats, the same IEEE operations as the array
    formula (``I^T d`` is ``d``, up to the sign of a zero); other frames ``R^T (r - p) * 1000``.
    """
    if str(frame).upper() == "WORLD":
        px, py, pz = np.asarray(state.T_world_tool_true)[:3, 3].tolist()
        rx, ry, rz = np.asarray(reference_tip_world_m, dtype=float).tolist()
        return (rx - px) * 1000.0, (ry - py) * 1000.0, (rz - pz) * 1000.0
    d_world_m = np.asarray(reference_tip_world_m, dtype=float) - np.asarray(state.T_world_tool_true)[:3, 3]
    x, y, z = (jog_frame_rotation(state, frame).T @ d_world_m * 1000.0).tolist()
    return x, y, z


_OFFSETS = {(fx, fy, fz): f"{fx}  ΔY {fy}  ΔZ {fz}"
            for fx in ("%+.2f", "%+.1f") for fy in ("%+.2f", "%+.1f") for fz in ("%+.2f", "%+.1f")}
"""The three numbers of the Δ line in one template per choice of decimals (two under 100 mm)."""


def offset_markdown(delta_mm: np.ndarray | tuple[float, float, float], frame: str, *,
                    tr: Translator = ENGLISH) -> str:
    """``ΔX +1.20  ΔY -0.40  ΔZ -3.00 mm`` to the tip (TOOL): the jog along each axis of the jog
    frame that brings the tool tip onto the reference tip (two decimals with the sign, one from
    100 mm on; a zero as ``0.00``); the words in ``tr``'s language, the numbers as they are."""
    x, y, z = delta_mm                       # floats or numpy floats: the same text
    # the numbers in one pass (each "%+.2f" under 100 mm, else "%+.1f"); a zero is then
    # "+0.00" or "-0.00", which can only be a whole number of this text (a sign starts each
    # number, and a "%+.1f" one is at least 100 or not finite)
    text = (_OFFSETS[("%+.2f" if abs(x) < 100 else "%+.1f", "%+.2f" if abs(y) < 100 else "%+.1f",
                      "%+.2f" if abs(z) < 100 else "%+.1f")] % (x, y, z))
    if "0.00" in text:
        text = text.replace("+0.00", "0.00").replace("-0.00", "0.00")
    return tr.gettext("{offsets} to the tip ({frame})").format(offsets=f"`ΔX {text} mm`", frame=frame)


def direction_words(delta_mm: np.ndarray, frame: str) -> str:
    """Where the reference tip is from the tool tip, largest component first, e.g.
    ``"2.10 mm −X, 0.60 mm +Z (WORLD)"`` (components under 0.05 mm left out)."""
    d = np.asarray(delta_mm, dtype=float)
    parts = [f"{abs(d[i]):.2f} mm {'+' if d[i] > 0 else '−'}{'XYZ'[i]}"
             for i in np.argsort(-np.abs(d)) if abs(d[i]) >= 0.05]
    return (", ".join(parts) or "0.00 mm") + f" ({frame})"


def _scale(delta_mm: np.ndarray) -> float:
    need = max(abs(float(delta_mm[0])) / _HALF_W, abs(float(delta_mm[1])) / _HALF_W,
               abs(float(delta_mm[2])) / _HALF_H)
    return next((s for s in _SCALES_MM if s >= need), _SCALES_MM[-1])


def side_view_markdown(delta_mm: np.ndarray | tuple[float, float, float], frame: str) -> str:
    """Two magnified views of the tips around the tool tip ``+`` (a code block): the reference
    tip ``o`` (``@`` when they share a character; at the border when it is out of range). Left:
    X across, Z up; right: Y across, Z up (the jog frame's axes). The scale (mm per character,
    on the last line) shrinks as the tips close in: 0.1 mm at the finest."""
    d = np.asarray(delta_mm, dtype=float)
    s = _scale(d)

    def panel(h: float, v: float) -> list[str]:
        col = int(np.clip(round(h / s), -_HALF_W, _HALF_W)) + _HALF_W
        row = _HALF_H - int(np.clip(round(v / s), -_HALF_H, _HALF_H))
        grid = [["·"] * (2 * _HALF_W + 1) for _ in range(2 * _HALF_H + 1)]
        grid[_HALF_H][_HALF_W] = "+"
        grid[row][col] = "@" if (row, col) == (_HALF_H, _HALF_W) else "o"
        return ["".join(r) for r in grid]

    left, right = panel(d[0], d[2]), panel(d[1], d[2])
    lines = [f"{a}   {b}" for a, b in zip(left, right)]
    lines[0] += "  Z↑"
    lines.append(f"{'X→':^{2 * _HALF_W + 1}}   {'Y→':^{2 * _HALF_W + 1}}  {s:g} mm/char")
    return "```\n" + "\n".join(lines) + "\n```"


@dataclass(frozen=True)
class ContactStop:
    """Where a translation meets the reference tip.

    Attributes:
        fraction: part of the step to carry out (0..1) to stop at contact.
        miss_mm: how far the tool tip's path passes from the reference tip (mm).
    """

    fraction: float
    miss_mm: float


def contact_stop(tip_world_m: np.ndarray, step_world_m: np.ndarray,
                 reference_tip_world_m: np.ndarray) -> ContactStop | None:
    """The stop of a straight translation ``step_world_m`` of the tool tip at ``tip_world_m``
    (both metres) at the reference tip: the step would carry the tip *past* its closest point
    to the reference tip, and that point is within :data:`CONTACT_RADIUS_MM` of it, and the tip
    is not touching already (then it may go on: the trainee was warned at contact). None: the
    step goes on (it ends before the reference tip, passes beside it, or starts at it)."""
    gap_m = np.asarray(reference_tip_world_m, dtype=float) - np.asarray(tip_world_m, dtype=float)
    if math.hypot(*gap_m.tolist()) * 1000.0 <= TOUCH_TOLERANCE_MM:
        return None                                   # at contact already: the next press goes on
    near = _closest_in_step(tip_world_m, step_world_m, reference_tip_world_m)
    return None if near is None else ContactStop(near[0], near[2])


def collision_stop(tip_world_m: np.ndarray, step_world_m: np.ndarray,
                   reference_tip_world_m: np.ndarray) -> ContactStop | None:
    """With the distance hidden: the stop of a straight translation ``step_world_m`` of the tool
    tip at ``tip_world_m`` (metres) where it meets the reference tip, when it would otherwise
    carry the tip more than ``CRASH_DEPTH_MM`` past its closest point to it and that point is
    within :data:`CONTACT_RADIUS_MM` (a real robot would collide there). None: the step ends
    before the tip, passes beside it, overshoots it by no more than a firm touch does, or starts
    where the last press stopped it (that press warned: this one goes on through).

    Unlike :func:`contact_stop` a start within the touch tolerance is no exemption: from 0.3 mm
    above the tip a 1 mm press would go 0.7 mm through."""
    near = _closest_in_step(tip_world_m, step_world_m, reference_tip_world_m)
    if near is None:
        return None
    t, length_m, miss_mm = near
    if (1.0 - t) * length_m * 1000.0 <= CRASH_DEPTH_MM:
        return None
    return ContactStop(t, miss_mm)


def _closest_in_step(tip_world_m: np.ndarray, step_world_m: np.ndarray,
                     reference_tip_world_m: np.ndarray) -> tuple[float, float, float] | None:
    """The point of a straight translation ``step_world_m`` of the tip at ``tip_world_m`` closest
    to the reference tip (all metres), for :func:`contact_stop` and :func:`collision_stop`:
    ``(t, |step| in m, miss in mm)`` with the point at ``tip + t step``, ``t = (r - p)·s / |s|²``.
    None: an empty step, the closest point not inside the step (``0 < t < 1``), the tip stopped
    there by the last press, or a miss over :data:`CONTACT_RADIUS_MM`."""
    p = np.asarray(tip_world_m, dtype=float)
    step = np.asarray(step_world_m, dtype=float)
    r = np.asarray(reference_tip_world_m, dtype=float)
    length2 = float(step @ step)
    if length2 <= 0.0:
        return None
    t = float((r - p) @ step) / length2
    length = math.sqrt(length2)
    if not 0.0 < t < 1.0 or t * length < _STOPPED_HERE_M:
        return None                                   # outside this step, or stopped here by the last press
    miss_mm = math.hypot(*(p + t * step - r).tolist()) * 1000.0
    if miss_mm > CONTACT_RADIUS_MM or not math.isfinite(miss_mm):
        return None
    return t, length, miss_mm
