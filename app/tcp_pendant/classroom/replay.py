"""A trainee's calibration as the gradebook keeps it, ready to draw again (no viser).

The trainer's dashboard replays a calibration in 3D (``views.dashboard_replay``): the robot at
each touch (its joint angles), each touch's flange pose, the approach of the tool at it (flange origin to where the tool tip was: the
true TOOL frame's tip, else the computed one), the computed TOOL frame and the true one, and the
reference tip (the mean of the true tip positions: where the tip really was at the touches).
Everything comes from the gradebook (touches, truth, result), so it works for a trainee who is
not connected and after a restart. Metres in WORLD; the result's TCP is kept in mm as stored.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from tcp_pendant.classroom.gradebook import Gradebook

__all__ = ["CalibrationReplay", "ReplayTouch", "calibration_replay", "T_flange_tool_m"]


@dataclass(frozen=True, eq=False)
class ReplayTouch:
    """One recorded touch.

    Attributes:
        step_index: 0-based wizard step.
        T_world_flange_m: (4, 4) flange pose, metres.
        auto: done by Auto-touch.
        overwritten: a later touch of the same step replaced it.
        tip_world_m: (3,) where the tool tip was (true TOOL frame, else the computed one), or None.
        joints_deg: the robot's joint angles at the touch, degrees (None: not kept).
    """

    step_index: int
    T_world_flange_m: np.ndarray
    auto: bool
    overwritten: bool
    tip_world_m: np.ndarray | None
    joints_deg: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class CalibrationReplay:
    """A calibration to draw (:func:`calibration_replay`).

    Attributes:
        calibration_id, trainee, method, status: what it is.
        touches: every touch in recording order (overwritten ones included).
        T_flange_tool_result_m: (4, 4) the computed TOOL frame (metres), or None (not finished).
        T_flange_tool_true_m: (4, 4) the true TOOL frame, or None (no truth kept).
        reference_world_m: (3,) the reference tip (mean true tip position at the counted
            touches; the computed tips' mean without a truth), or None (no touch).
        position_error_mm / grade: the result against the truth (None: none).
    """

    calibration_id: int
    trainee: str
    method: str
    status: str
    touches: tuple[ReplayTouch, ...]
    T_flange_tool_result_m: np.ndarray | None
    T_flange_tool_true_m: np.ndarray | None
    reference_world_m: np.ndarray | None
    position_error_mm: float | None
    grade: str | None


def T_flange_tool_m(tcp_mm: object, abc_deg: object | None) -> np.ndarray:
    """The TOOL frame from a stored TCP (mm) and KUKA A, B, C (deg; None: no rotation), metres."""
    T = np.eye(4)
    T[:3, 3] = np.asarray(tcp_mm, dtype=float) / 1000.0
    if abc_deg is not None:
        T[:3, :3] = Rotation.from_euler("ZYX", np.asarray(abc_deg, dtype=float), degrees=True).as_matrix()
    return T


def _truth(truth: object) -> np.ndarray | None:
    T = truth.get("T_flange_tool_true_m") if isinstance(truth, dict) else None
    if T is None:
        return None
    out = np.asarray(T, dtype=float)
    return out if out.shape == (4, 4) and np.all(np.isfinite(out)) else None


def _joints(value: object) -> np.ndarray | None:
    try:
        q = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        return None
    return q if q.size > 0 and np.all(np.isfinite(q)) else None


def calibration_replay(gradebook: Gradebook, calibration_id: int) -> CalibrationReplay:
    """Calibration ``calibration_id`` from ``gradebook`` (see the module docstring).

    Raises:
        GradebookError: no such calibration.
    """
    info = gradebook.records.calibration_result(calibration_id)
    true_T = _truth(gradebook.records.truth(calibration_id))
    result_T = None if info["tcp_mm"] is None else T_flange_tool_m(info["tcp_mm"], info["abc_deg"])
    tip_T = true_T if true_T is not None else result_T
    touches = []
    for t in gradebook.records.touches(calibration_id):
        T = np.asarray(t["T_world_flange_m"], dtype=float)
        tip = None if tip_T is None else (T @ tip_T)[:3, 3]
        touches.append(ReplayTouch(int(t["step_index"]), T, bool(t["auto"]),
                                   t["overwritten_by_touch_id"] is not None, tip, _joints(t.get("joints_deg"))))
    counted = [t.tip_world_m for t in touches if not t.overwritten and t.tip_world_m is not None]
    reference = np.mean(counted, axis=0) if counted else None
    return CalibrationReplay(int(calibration_id), str(info["trainee"]), str(info["method"]), str(info["status"]),
                             tuple(touches), result_T, true_T, reference, info["position_error_mm"], info["grade"])
