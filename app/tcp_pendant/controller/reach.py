"""Can the robot make a suggested tilt from where it stands? Checked on the robot model.

A tilt the pendant suggests is one press sequence of a rotation key (A, B or C: about the Z, Y
or X axis of a jog frame, through the active TCP) by ``angle_deg``, followed by the translation
that brings the mounted tool's true tip back onto the reference tip (with no tool data the TCP
is the flange, so a tilt swings the tip away). It is *reachable* when, on the controller's model
(``VirtualController.kinematics``, the one the jog keys move):

1. the rotation runs to its end under the jog's own safety rules (``jog.follow_path``: joint
   limits, no passage through a singularity, no configuration jump);
2. the straight translation of the TCP by ``r - p_tip`` (reference tip minus the true tool tip
   after the turn, WORLD) runs to its end under the same rules: the tip is still reachable;
3. at the end the smallest singular value of the scaled flange Jacobian is at least
   :data:`WRIST_MARGIN_SIGMA` (about ``sin 6 deg``: A5 at least ~6 deg from 0 on a KR 6, three
   times the jog's own stop at ~2 deg) and every joint is at least :data:`LIMIT_MARGIN_DEG` from
   its limits, so the fine jogging that follows does not stop at once.

The check follows the path with coarser sub-steps than a key press (10 mm / 5 deg,
:data:`CHECK_SETTINGS`; the jump rule scales with the sub-step), a few milliseconds per tilt.
Metres and radians inside, degrees in the names that say so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tcp_pendant.controller.controller import VirtualController
from tcp_pendant.controller.jog import (
    CartesianPath,
    JogSettings,
    follow_path,
    singularity_message,
    smallest_singular_value,
)
from tcp_pendant.controller.words import Words
from tcp_pendant.translation import N_

__all__ = ["CHECK_SETTINGS", "LIMIT_MARGIN_DEG", "ROTATION_KEYS", "WRIST_MARGIN_SIGMA", "TiltReach",
           "frame_axes", "tilt_reach"]

WRIST_MARGIN_SIGMA = math.sin(math.radians(6.0))
"""Least smallest singular value of ``W J_flange`` at the end of a suggested tilt."""
LIMIT_MARGIN_DEG = 3.0
"""Least distance of every revolute joint from its limits at the end of a suggested tilt (deg)."""
CHECK_SETTINGS = JogSettings(max_substep_m=0.01, max_substep_rad=math.radians(5.0))
"""The jog's rules with coarser sub-steps (the check of a path, not a press)."""
ROTATION_KEYS = {"A": 2, "B": 1, "C": 0}
"""The jog frame axis each rotation key turns about (KUKA: A about Z, B about Y, C about X)."""


@dataclass(frozen=True)
class TiltReach:
    """One tilt checked on the model.

    Attributes:
        frame: the jog frame of the key ("WORLD", "BASE", "FLANGE", "TOOL").
        key: "A", "B" or "C"; sign: +1 or -1; angle_deg: the turn, degrees.
        reachable: all three conditions of the module docstring hold.
        why: when not reachable, what stops it in words ("A5 at its limit +120.0 deg", ...).
    """

    frame: str
    key: str
    sign: int
    angle_deg: float
    reachable: bool
    why: str


def frame_axes(controller: VirtualController, frame: str) -> np.ndarray:
    """``R_world_frame`` (3,3) of a jog frame now, as ``VirtualController.jog_cartesian`` takes it."""
    f = frame.upper()
    if f == "WORLD":
        return np.eye(3)
    if f == "BASE":
        return np.asarray(controller.T_world_base)[:3, :3]
    if f == "FLANGE":
        return controller.T_world_flange()[:3, :3]
    return controller.T_world_tcp()[:3, :3]


def _margin_problem(controller: VirtualController, q: np.ndarray) -> str:
    """"" when ``q`` keeps the margins of the module docstring, else what is too close."""
    kin = controller.kinematics
    if smallest_singular_value(kin, q) < WRIST_MARGIN_SIGMA:
        return Words(N_("too close to a singularity there ({why})"), why=singularity_message(kin, q))
    margin = math.radians(LIMIT_MARGIN_DEG)
    for i in range(kin.n_joints):
        if not kin.revolute[i]:
            continue
        if q[i] - kin.lower_rad[i] < margin or kin.upper_rad[i] - q[i] < margin:
            side = "lower" if q[i] - kin.lower_rad[i] < margin else "upper"
            return Words(N_("{limit} there"), limit=kin.limit_message(i, side))
    return ""


def tilt_reach(controller: VirtualController, frame: str, key: str, sign: int,
               angle_deg: float) -> TiltReach:
    """Check one tilt (module docstring) from the controller's current configuration; the
    controller is not moved."""
    kin = controller.kinematics
    T_flange_tcp = controller.T_flange_tool
    T_wf = controller.T_world_flange()
    T0 = T_wf @ T_flange_tcp
    axis = frame_axes(controller, frame)[:, ROTATION_KEYS[key]]
    w = axis * (sign * math.radians(angle_deg))
    turn = follow_path(kin, controller.q_rad, T_flange_tcp, CartesianPath(T0[:3, 3], T0[:3, :3], np.zeros(3), w),
                       CHECK_SETTINGS, q_rest=controller.rest_q_rad)
    name = f"{key} {'+' if sign > 0 else '−'}"
    if turn.stopped_by is not None:
        return TiltReach(frame, key, sign, angle_deg, False, turn.message)
    q1 = turn.q_rad
    tip1 = (controller.true_kinematics.T_world_flange(q1) @ controller.mounted_tool.T_flange_tool_true)[:3, 3]
    T1 = kin.T_world_flange(q1) @ T_flange_tcp
    dp = np.asarray(controller.reference_tip_world_m, dtype=float) - tip1
    back = follow_path(kin, q1, T_flange_tcp, CartesianPath(T1[:3, 3], T1[:3, :3], dp, np.zeros(3)),
                       CHECK_SETTINGS, q_rest=controller.rest_q_rad)
    if back.stopped_by is not None:
        return TiltReach(frame, key, sign, angle_deg, False,
                         Words(N_("after {key} the reference tip is out of reach ({why})"), key=name,
                               why=back.message))
    problem = _margin_problem(controller, back.q_rad)
    return TiltReach(frame, key, sign, angle_deg, not problem, problem)
