"""The TCP check (spin test): reorient the tool about the ACTIVE TCP and watch the TRUE tip.

A technician checks a TCP on a real robot by putting the tool tip on a fixed spike and jogging
A, B, C in the TOOL frame: the controller turns the tool about its TCP, so a correct TCP stays
on the spike and a wrong one swings off it. This module does that with the virtual controller's
own jog machinery (``jog.follow_path``, the same sub-stepped damped least squares and safety
rules as a pendant jog) and measures where the hidden true tip goes (methods.md, "TCP check").

Rotation axes (decided as KUKA's pendant does with the TOOL frame selected; ABB's reorient in
the tool frame behaves the same): A turns about the active TOOL frame's Z axis, B about its Y
axis, C about its X axis, each through the active TCP and with the axes taken at the start of
the test. The six rotations are +A, -A, +B, -B, +C, -C, each started from the start
configuration (the technician returns to the start pose between rotations).

Let ``R0`` be the active TOOL orientation at the start, ``e`` the true tip in active TOOL
coordinates (the TCP error, mm) and ``Rot_i`` the rotation by ``theta_i`` about TOOL axis
``k_i``. With the nominal robot the true tip moves by::

    d_i = R0 (Rot_i - I) e,     |d_i| = 2 |sin(theta_i / 2)| |e_perp,i|               (SC-1)

(``e_perp,i`` the part of ``e`` perpendicular to ``k_i``). Stacking the reached rotations,
``e`` is the least-squares solution of ``(Rot_i - I) e = R0^T d_i`` (SC-2); ``|e|`` is the
implied TCP error and ``R_flange_tool e`` the correction to add to the tool data's TCP. The
RMS of what (SC-2) leaves unexplained (``fit_rms_mm``) is ~0 for a pure TCP error and grows
with errors no TCP can explain (robot absolute accuracy, ``scenarios.py``).

Units: the controller's metres and radians inside; the result in mm and degrees.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np
import pinocchio as pin

from tcpcal.validation import read_only_array
from tcp_pendant.controller.checks import check_pose
from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.controller.jog import DEFAULT_SETTINGS, CartesianPath, JogSettings, follow_path
from tcp_pendant.controller.kinematics import RobotKinematics
from tcp_pendant.controller.words import in_language
from tcp_pendant.translation import ENGLISH, Translator

if TYPE_CHECKING:
    from tcp_pendant.controller.controller import VirtualController

__all__ = [
    "DEFAULT_SPIN_ANGLE_DEG",
    "MAX_SPIN_ANGLE_DEG",
    "SPIN_AXES",
    "SpinCheckResult",
    "SpinRotation",
    "spin_check",
    "spin_check_of",
]

DEFAULT_SPIN_ANGLE_DEG = 30.0
MAX_SPIN_ANGLE_DEG = 90.0
SpinAxis = Literal["A", "B", "C"]
SPIN_AXES: dict[SpinAxis, int] = {"A": 2, "B": 1, "C": 0}
"""Spin axis -> index of the active TOOL frame axis it turns about (A: Z, B: Y, C: X)."""


@dataclass(frozen=True)
class SpinRotation:
    """One rotation of the TCP check.

    Attributes:
        label: as the pendant names it, e.g. "+A 30°".
        axis: "A" (about TOOL Z), "B" (TOOL Y) or "C" (TOOL X).
        angle_deg: signed rotation angle commanded, degrees.
        reached: the whole rotation was carried out.
        moved: fraction of the rotation carried out (1.0 when reached).
        stopped_by: "joint_limit" | "singularity" | "unreachable" | None (as ``JogResult``).
        message: the controller's words when it stopped early ("" when reached).
        deviation_mm: how far the true tip is from its start point at the end of the motion, mm.
        deviation_world_mm: that displacement in WORLD axes, (3,) mm.
        deviation_tool_mm: the same in the active TOOL axes at the start, (3,) mm.
        q_rad: joint angles at the end of the motion (rad; m for prismatic joints).
    """

    label: str
    axis: SpinAxis
    angle_deg: float
    reached: bool
    moved: float
    stopped_by: str | None
    message: str
    deviation_mm: float
    deviation_world_mm: np.ndarray
    deviation_tool_mm: np.ndarray
    q_rad: np.ndarray


@dataclass(frozen=True)
class SpinCheckResult:
    """The TCP check: six rotations about the active TCP and what they imply.

    Attributes:
        angle_deg: the rotation angle used (positive), degrees.
        rotations: +A, -A, +B, -B, +C, -C in that order.
        max_deviation_mm: largest ``deviation_mm`` of the reached rotations, mm (nan if none).
        implied_offset_tool_mm: ``e`` of (SC-2): the true tip relative to the active TCP in
            active TOOL axes, mm; None when the reached rotations do not determine it (fewer
            than two different axes reached).
        implied_offset_flange_mm: ``R_flange_tool e``, FLANGE axes, mm: add it to the tool
            data's ``tcp_mm`` to move the active TCP onto the true tip; None as above.
        implied_tcp_error_mm: ``|e|``, mm; None as above.
        fit_rms_mm: RMS over the reached rotations' coordinates of ``(Rot_i - I) e - R0^T d_i``,
            mm: what a TCP error cannot explain (~0 on an exact robot); None as above.
        q_start_rad: the start configuration (the robot is back there after the test).
    """

    angle_deg: float
    rotations: tuple[SpinRotation, ...]
    max_deviation_mm: float
    implied_offset_tool_mm: np.ndarray | None
    implied_offset_flange_mm: np.ndarray | None
    implied_tcp_error_mm: float | None
    fit_rms_mm: float | None
    q_start_rad: np.ndarray

    @property
    def all_reached(self) -> bool:
        """Every rotation was carried out completely."""
        return all(r.reached for r in self.rotations)

    def summary(self, tr: Translator = ENGLISH) -> str:
        """Plain words in ``tr``'s language (escape before putting them into markdown)."""
        _ = tr.gettext
        lines = []
        for r in self.rotations:
            if r.reached:
                lines.append(_("{rotation}: the tip moved {deviation} mm").format(
                    rotation=r.label, deviation=f"{r.deviation_mm:.3f}"))
            else:
                lines.append(_("{rotation}: not reached ({why}); {done} % done, the tip moved {deviation} mm").format(
                    rotation=r.label, why=in_language(r.message, tr) or r.stopped_by, done=f"{r.moved * 100:.0f}",
                    deviation=f"{r.deviation_mm:.3f}"))
        if self.implied_tcp_error_mm is None:
            lines.append(_("The reached rotations do not determine the TCP error: at least two of A, B, C "
                           "must be reached; move the robot away from its joint limits and singularities "
                           "and check again."))
        else:
            lines.append(_("Largest deviation {deviation} mm; implied TCP error {error} mm.").format(
                deviation=f"{self.max_deviation_mm:.3f}", error=f"{self.implied_tcp_error_mm:.3f}"))
        return "\n".join(lines)


def _check_angle(angle_deg: float) -> float:
    try:
        a = float(angle_deg)
    except (TypeError, ValueError):
        raise ControllerError(f"The spin angle must be a number of degrees, got {angle_deg!r}.") from None
    if not math.isfinite(a) or not 0.0 < a <= MAX_SPIN_ANGLE_DEG:
        raise ControllerError(f"The spin angle must be above 0 and at most {MAX_SPIN_ANGLE_DEG:g} degrees "
                              f"(technicians use 10-45), got {angle_deg!r}.")
    return a


def _label(sign: float, axis: str, angle_deg: float) -> str:
    return f"{'+' if sign > 0 else '-'}{axis} {angle_deg:g}°"


def _true_tip(kin: RobotKinematics, q: np.ndarray, T_flange_tool_true: np.ndarray) -> np.ndarray:
    return (kin.T_world_flange(q) @ T_flange_tool_true)[:3, 3]


def _start_joints(kin: RobotKinematics, q_rad: Sequence[float] | np.ndarray) -> np.ndarray:
    """The start configuration checked (rad; m for prismatic joints) and clipped onto the limits
    it is within to 1e-9.

    Raises:
        ControllerError: wrong length, not finite, or beyond a limit (names the joint).
    """
    q0 = kin.check_q(q_rad).copy()
    viol = kin.limit_violation(q0, tol=1e-9)
    if viol is not None:
        i, side = viol
        limit = (kin.lower_rad if side == "lower" else kin.upper_rad)[i]
        raise ControllerError(f"{kin.joint_names[i]} = {kin.format_joint(i, q0[i])} is beyond its {side} "
                              f"limit {kin.format_joint(i, limit)}; start the TCP check within the limits.")
    return np.clip(q0, kin.lower_rad, kin.upper_rad)


def _implied_offset(rows: list[np.ndarray], rhs: list[np.ndarray], R_flange_tool: np.ndarray
                    ) -> tuple[np.ndarray | None, np.ndarray | None, float | None, float | None]:
    """The TCP offset ``e`` (TOOL frame, mm) that explains the deviations of the rotations
    reached: the least-squares solution of ``(exp(theta_k) - I) e = d_k`` stacked over them
    (``rows`` and ``rhs``); returns ``e`` in TOOL and in FLANGE (``R_flange_tool e``), its
    norm and the fit's RMS residual (mm), all None without a rotation reached or when the
    rotations do not determine ``e`` (rank below 3)."""
    if not rows:
        return None, None, None, None
    A = np.vstack(rows)
    b = np.concatenate(rhs)
    e, _, rank, _ = np.linalg.lstsq(A, b, rcond=None)
    if rank != 3:
        return None, None, None, None
    return (read_only_array(e), read_only_array(R_flange_tool @ e), float(np.linalg.norm(e)),
            float(np.sqrt(np.mean((A @ e - b) ** 2))))


def spin_check(kinematics: RobotKinematics, q_rad: Sequence[float] | np.ndarray,
               T_flange_tool_active: np.ndarray, T_flange_tool_true: np.ndarray, *,
               angle_deg: float = DEFAULT_SPIN_ANGLE_DEG,
               true_kinematics: RobotKinematics | None = None,
               settings: JogSettings = DEFAULT_SETTINGS) -> SpinCheckResult:
    """Run the TCP check from configuration ``q_rad`` (see the module docstring).

    Args:
        kinematics: the controller's (nominal) robot model: it plans the motion about the
            active TCP, as a real controller does with its own model.
        q_rad: start configuration (rad; m for prismatic joints), within the limits.
        T_flange_tool_active: (4,4) the active tool data in FLANGE coordinates, metres.
        T_flange_tool_true: (4,4) the physical tool's true TOOL frame in FLANGE, metres.
        angle_deg: rotation angle, degrees, in (0, 90]; default 30.
        true_kinematics: the physical robot when it differs from the model (absolute-accuracy
            scenario, ``scenarios.py``); default ``kinematics``.
        settings: jog tuning (``jog.JogSettings``).

    Returns:
        A :class:`SpinCheckResult`. A rotation that stops at a joint limit or singularity is
        reported with ``reached=False`` and the controller's message, never raised.

    Raises:
        ControllerError: bad angle, malformed matrices, joint values of the wrong length, not
            finite or outside the limits, or a ``true_kinematics`` with other joints.
    """
    angle = _check_angle(angle_deg)
    kin = kinematics
    true_kin = kin if true_kinematics is None else true_kinematics
    if true_kin.joint_names != kin.joint_names:
        raise ControllerError(f"true_kinematics has joints {', '.join(true_kin.joint_names)} but the "
                              f"model has {', '.join(kin.joint_names)}; give the same robot.")
    T_active = check_pose(T_flange_tool_active, "T_flange_tool_active")
    T_true = check_pose(T_flange_tool_true, "T_flange_tool_true")
    q0 = _start_joints(kin, q_rad)

    T0 = kin.T_world_flange(q0) @ T_active
    R0, p0 = T0[:3, :3].copy(), T0[:3, 3].copy()
    tip0 = _true_tip(true_kin, q0, T_true)
    theta = math.radians(angle)

    rotations: list[SpinRotation] = []
    rows: list[np.ndarray] = []
    rhs: list[np.ndarray] = []
    for axis, k in SPIN_AXES.items():
        for sign in (1.0, -1.0):
            w = R0[:, k] * (sign * theta)
            out = follow_path(kin, q0, T_active, CartesianPath(p0, R0, np.zeros(3), w), settings)
            d_world = (_true_tip(true_kin, out.q_rad, T_true) - tip0) * 1000.0
            d_tool = R0.T @ d_world
            reached = out.stopped_by is None
            rotations.append(SpinRotation(
                label=_label(sign, axis, angle), axis=axis, angle_deg=sign * angle, reached=reached,
                moved=float(out.moved), stopped_by=out.stopped_by, message=out.message,
                deviation_mm=float(np.linalg.norm(d_world)), deviation_world_mm=read_only_array(d_world),
                deviation_tool_mm=read_only_array(d_tool), q_rad=read_only_array(out.q_rad)))
            if reached:
                axis_tool = np.zeros(3)
                axis_tool[k] = sign * theta
                rows.append(pin.exp3(axis_tool) - np.eye(3))
                rhs.append(d_tool)

    reached_dev = [r.deviation_mm for r in rotations if r.reached]
    max_dev = max(reached_dev) if reached_dev else math.nan
    e_tool, e_flange, err, rms = _implied_offset(rows, rhs, T_active[:3, :3])
    return SpinCheckResult(angle_deg=angle, rotations=tuple(rotations), max_deviation_mm=float(max_dev),
                           implied_offset_tool_mm=e_tool, implied_offset_flange_mm=e_flange,
                           implied_tcp_error_mm=err, fit_rms_mm=rms, q_start_rad=read_only_array(q0))


def spin_check_of(controller: "VirtualController", *, angle_deg: float = DEFAULT_SPIN_ANGLE_DEG,
                  true_kinematics: RobotKinematics | None = None) -> SpinCheckResult:
    """:func:`spin_check` of a controller's current state; the controller is not moved.

    Uses its kinematics, joint angles, jog settings, active tool data (``T_flange_tool``) and
    the mounted tool's ``T_flange_tool_true``.
    """
    return spin_check(controller.kinematics, controller.q_rad, controller.T_flange_tool,
                      controller.mounted_tool.T_flange_tool_true, angle_deg=angle_deg,
                      true_kinematics=true_kinematics, settings=controller.settings)
