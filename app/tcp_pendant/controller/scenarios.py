"""Systematic errors to teach with (training mode; the trainer picks one, off by default).

Three scenarios, each a lesson a real robot teaches (methods.md, "Systematic errors"):

* ``bent_tool``: the tool was bent in a crash. The physical tool's true TOOL frame moves (tip
  2-5 mm sideways, axis turned 1-3 deg towards that side) while the tool data in the library
  stays as it was: the stale data is wrong, a new calibration is right.
* ``robot_accuracy``: the physical robot differs from the controller's model by realistic
  offsets (each joint placement's length by 0.1-0.5 mm, each joint zero by 0.01-0.05 deg, random
  signs). The controller's NOMINAL model still does the readouts, the recorded flange poses
  and the jogs; the TRUE model decides where the tool tip really is. Perfect touches then leave
  residuals of a few tenths of a millimetre, as on an uncalibrated real arm.
* ``moved_reference``: the reference tip is knocked a few millimetres (2-5 mm, horizontally)
  after touch ``k``: the touches disagree and the residual is large.

The design is a frozen :class:`Scenario` (what the trainer chose: kind, seed, ranges), pure
draw functions that turn it into concrete, reproducible errors (:func:`draw_tool_bend`,
:func:`draw_kinematic_errors`, :func:`draw_reference_move`), pure builders of the perturbed
things (:func:`bent_tool_frame`, :func:`bent_tool`, :func:`perturbed_model`,
:func:`perturbed_kinematics`), :func:`realize` bundling them as a :class:`ScenarioWorld` (what a
controller needs) and :func:`explain`, the words shown after a result.

Metres and radians inside; the scenario's ranges and the explanations in mm and degrees.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np
import pinocchio as pin

from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.controller.kinematics import RobotKinematics
from tcp_pendant.controller.tools import ToolModel
from tcp_pendant.translation import ENGLISH, Translator

__all__ = [
    "DEFAULT_SEED_RANGE",
    "SCENARIO_KINDS",
    "SCENARIO_LABELS",
    "KinematicErrors",
    "ReferenceMove",
    "Scenario",
    "ScenarioKind",
    "ScenarioWorld",
    "ToolBend",
    "bent_tool",
    "bent_tool_frame",
    "draw_kinematic_errors",
    "draw_reference_move",
    "draw_tool_bend",
    "explain",
    "perturbed_kinematics",
    "perturbed_model",
    "realize",
]

ScenarioKind = Literal["off", "bent_tool", "robot_accuracy", "moved_reference"]
SCENARIO_KINDS: tuple[str, ...] = get_args(ScenarioKind)
SCENARIO_LABELS: dict[str, str] = {
    "off": "No systematic error",
    "bent_tool": "Bent tool (after a crash)",
    "robot_accuracy": "Robot absolute accuracy",
    "moved_reference": "Reference tip moved between touches",
}

DEFAULT_SEED_RANGE = range(20)
"""Seeds offered to the trainer (the app draws one of these when none is chosen); the tests
check the realistic figures (e.g. perfect-touch residuals 0.05-0.5 mm) for every one of them."""

_MIN_LENGTH_M = 1e-9  # a joint placement shorter than this has no "length" to perturb


def _check_range(value: tuple[float, float], what: str, unit: str, upper: float) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ControllerError(f"{what} must be two numbers (low, high) in {unit}, got {value!r}.") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 <= lo <= hi <= upper):
        raise ControllerError(f"{what} must satisfy 0 <= low <= high <= {upper:g} {unit}, got {value!r}.")
    return lo, hi


@dataclass(frozen=True)
class Scenario:
    """What the trainer chose (the defaults are realistic ranges).

    Attributes:
        kind: "off" (default), "bent_tool", "robot_accuracy" or "moved_reference".
        seed: picks the concrete errors (same seed, same errors); >= 0.
        bend_shift_mm: range of the bent tool's sideways tip shift, mm.
        bend_angle_deg: range of the bent tool's axis turn, degrees.
        link_length_mm: range of each joint placement's length error, mm.
        joint_zero_deg: range of each joint's zero offset, degrees.
        reference_shift_mm: range of the reference tip's horizontal move, mm.
        reference_moves_after_touch: the tip moves after this touch (1-based; >= 1).

    Raises:
        ControllerError: unknown kind, negative seed, a range that is not 0 <= low <= high
            within its bound, or a touch number below 1.
    """

    kind: ScenarioKind = "off"
    seed: int = 0
    bend_shift_mm: tuple[float, float] = (2.0, 5.0)
    bend_angle_deg: tuple[float, float] = (1.0, 3.0)
    link_length_mm: tuple[float, float] = (0.1, 0.5)
    joint_zero_deg: tuple[float, float] = (0.01, 0.05)
    reference_shift_mm: tuple[float, float] = (2.0, 5.0)
    reference_moves_after_touch: int = 2

    def __post_init__(self) -> None:
        if self.kind not in SCENARIO_KINDS:
            raise ControllerError(f"Unknown scenario {self.kind!r}; choose one of {', '.join(SCENARIO_KINDS)}.")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or self.seed < 0:
            raise ControllerError(f"The scenario seed must be a whole number >= 0, got {self.seed!r}.")
        for name, unit, upper in (("bend_shift_mm", "mm", 50.0), ("bend_angle_deg", "deg", 30.0),
                                  ("link_length_mm", "mm", 10.0), ("joint_zero_deg", "deg", 1.0),
                                  ("reference_shift_mm", "mm", 50.0)):
            object.__setattr__(self, name, _check_range(getattr(self, name), name, unit, upper))
        k = self.reference_moves_after_touch
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
            raise ControllerError(f"reference_moves_after_touch must be a touch number >= 1, got {k!r}.")

    def _rng(self, salt: int) -> np.random.Generator:
        return np.random.default_rng([int(self.seed), salt])


# ----------------------------------------------------------------------------- bent tool
@dataclass(frozen=True)
class ToolBend:
    """A crash bend of a tool, in the unbent true TOOL frame.

    The tip moves ``shift_mm`` sideways, perpendicular to the working direction (TOOL X), in
    the direction ``u = (0, cos phi, sin phi)`` (``phi = direction_deg``, from TOOL +Y towards
    +Z); the tool axes turn ``angle_deg`` about ``X x u``, so TOOL X tilts towards ``u`` as a
    bent neck does.
    """

    shift_mm: float
    angle_deg: float
    direction_deg: float

    def T_tool_bent(self) -> np.ndarray:
        """(4,4) the bent TOOL frame in the unbent true TOOL frame, metres."""
        phi = math.radians(self.direction_deg)
        u = np.array([0.0, math.cos(phi), math.sin(phi)])
        axis = np.cross([1.0, 0.0, 0.0], u)
        T = np.eye(4)
        T[:3, :3] = pin.exp3(axis * math.radians(self.angle_deg))
        T[:3, 3] = u * (self.shift_mm / 1000.0)
        return T


def draw_tool_bend(scenario: Scenario) -> ToolBend:
    """The bend of ``scenario`` (its ranges and seed; whatever its kind)."""
    rng = scenario._rng(1)
    return ToolBend(shift_mm=float(rng.uniform(*scenario.bend_shift_mm)),
                    angle_deg=float(rng.uniform(*scenario.bend_angle_deg)),
                    direction_deg=float(rng.uniform(0.0, 360.0)))


def bent_tool_frame(T_flange_tool_true: np.ndarray, bend: ToolBend) -> np.ndarray:
    """``T_flange_tool_true`` after the bend: ``T_flange_tool_true @ bend.T_tool_bent()`` (m)."""
    return np.asarray(T_flange_tool_true, dtype=float) @ bend.T_tool_bent()


def bent_tool(tool: ToolModel, bend: ToolBend) -> ToolModel:
    """The physical tool after the crash: same key, label and drawing, bent true TOOL frame.

    The label stays, so the trainee is not told; the drawing (the unbent URDF) differs from
    the bent frame by a few millimetres only.
    """
    return ToolModel(tool.key, tool.label, tool.urdf_path, bent_tool_frame(tool.T_flange_tool_true, bend))


# ----------------------------------------------------------------------------- robot accuracy
@dataclass(frozen=True)
class KinematicErrors:
    """The physical robot's differences from its model, per joint in pinocchio order.

    Attributes:
        length_offsets_mm: change of each joint placement's length (the translation from the
            parent joint to this joint, along itself), mm; 0 where that translation is zero.
        joint_zero_offsets_deg: joint zero errors, degrees (mm for a prismatic joint): the
            physical joint sits at ``q + offset`` when the controller commands ``q``.
    """

    length_offsets_mm: tuple[float, ...]
    joint_zero_offsets_deg: tuple[float, ...]


def draw_kinematic_errors(scenario: Scenario, kinematics: RobotKinematics) -> KinematicErrors:
    """Errors of ``scenario``'s ranges with random signs, one per joint of ``kinematics``."""
    rng = scenario._rng(2)
    n = kinematics.n_joints
    sign = rng.choice([-1.0, 1.0], size=(2, n))
    lengths = sign[0] * rng.uniform(*scenario.link_length_mm, size=n)
    zeros = sign[1] * rng.uniform(*scenario.joint_zero_deg, size=n)
    placements = kinematics.model.jointPlacements
    ids = _actuated_joint_ids(kinematics.model)
    lengths = [float(v) if np.linalg.norm(placements[ids[i]].translation) > _MIN_LENGTH_M else 0.0
               for i, v in enumerate(lengths)]
    return KinematicErrors(tuple(lengths), tuple(float(v) for v in zeros))


def _actuated_joint_ids(model: pin.Model) -> list[int]:
    """pinocchio indices of the joints with a variable of their own (a mimic joint has none: it
    follows its leader and keeps its placement)."""
    return [j for j in range(1, model.njoints) if model.joints[j].shortname() != "JointModelMimic"]


def perturbed_model(model: pin.Model, errors: KinematicErrors) -> pin.Model:
    """A copy of ``model`` with ``errors`` built into its joint placements (``model`` unchanged).

    Actuated joint ``j`` (1-based, pinocchio order; mimic joints keep their placement) gets ``M_j' = (R_j, t_j (1 + dL_j / |t_j|)) *
    X_j(dq_j)``: its placement lengthened by ``dL_j`` along itself, then its own joint motion
    at the zero offset ``dq_j``, so ``FK'(q) = FK(q + dq)`` when every ``dL`` is zero.

    Raises:
        ControllerError: the error lists do not have one entry per joint.
    """
    ids = _actuated_joint_ids(model)
    n = len(ids)
    if len(errors.length_offsets_mm) != n or len(errors.joint_zero_offsets_deg) != n:
        raise ControllerError(f"The kinematic errors have {len(errors.length_offsets_mm)} lengths and "
                              f"{len(errors.joint_zero_offsets_deg)} zero offsets; the robot has {n} joints.")
    out = model.copy()
    for k, j in enumerate(ids, start=1):
        joint = out.joints[j]
        if joint.nq != 1:
            raise ControllerError(f"Joint {out.names[j]!r} has {joint.nq} position variables; only "
                                  "revolute and prismatic joints can be perturbed.")
        P = out.jointPlacements[j]
        t = np.array(P.translation)
        L = float(np.linalg.norm(t))
        dL = errors.length_offsets_mm[k - 1] / 1000.0
        if L > _MIN_LENGTH_M:
            t = t * (1.0 + dL / L)
        # the joint's own motion at q = offset; calc reads q at the joint's index in a full vector
        dq = errors.joint_zero_offsets_deg[k - 1]
        q = np.zeros(out.nq)
        prismatic = re.search(r"Prismatic|JointModelP[XYZ]$", joint.shortname()) is not None
        q[joint.idx_q] = dq / 1000.0 if prismatic else math.radians(dq)
        jdata = joint.createData()
        joint.calc(jdata, q)
        out.jointPlacements[j] = pin.SE3(np.array(P.rotation), t) * pin.SE3(jdata.M)
    return out


def perturbed_kinematics(kinematics: RobotKinematics, errors: KinematicErrors) -> RobotKinematics:
    """The physical robot: ``kinematics`` with :func:`perturbed_model` (same URDF, links, limits)."""
    return RobotKinematics(perturbed_model(kinematics.model, errors), kinematics.urdf_path,
                           kinematics.flange_link, kinematics.base_link, kinematics.description)


# ----------------------------------------------------------------------------- moved reference
@dataclass(frozen=True)
class ReferenceMove:
    """The reference tip is knocked after touch ``after_touch`` (1-based).

    Attributes:
        after_touch: touches 1..after_touch are at the original tip, later ones at the moved one.
        shift_mm: the move in WORLD axes, mm (horizontal: z = 0).
    """

    after_touch: int
    shift_mm: tuple[float, float, float]

    def tip_world_m(self, tip_world_m: np.ndarray, touches_recorded: int) -> np.ndarray:
        """Where the tip is when ``touches_recorded`` touches have been recorded (metres)."""
        tip = np.asarray(tip_world_m, dtype=float)
        if touches_recorded >= self.after_touch:
            return tip + np.asarray(self.shift_mm) / 1000.0
        return tip.copy()


def draw_reference_move(scenario: Scenario) -> ReferenceMove:
    """The reference move of ``scenario`` (its range, touch number and seed)."""
    rng = scenario._rng(3)
    s = float(rng.uniform(*scenario.reference_shift_mm))
    a = float(rng.uniform(0.0, 2.0 * math.pi))
    return ReferenceMove(int(scenario.reference_moves_after_touch), (s * math.cos(a), s * math.sin(a), 0.0))


# ----------------------------------------------------------------------------- together
@dataclass(frozen=True, eq=False)
class ScenarioWorld:
    """What the controller needs to play a scenario.

    Attributes:
        scenario: the trainer's choice.
        true_kinematics: the physical robot (the nominal model itself unless robot_accuracy):
            for where the true tip is (``touch_geometry``, ``T_world_tool_true``).
        tool_true: the physical tool (bent for bent_tool; else the given tool).
        tool_bend, kinematic_errors, reference_move: the drawn errors of this kind (None
            for the others).
    """

    scenario: Scenario
    true_kinematics: RobotKinematics
    tool_true: ToolModel
    tool_bend: ToolBend | None = None
    kinematic_errors: KinematicErrors | None = None
    reference_move: ReferenceMove | None = None


def realize(scenario: Scenario, kinematics: RobotKinematics, tool: ToolModel) -> ScenarioWorld:
    """Draw the scenario's errors for this robot and tool and build the physical world."""
    if scenario.kind == "bent_tool":
        bend = draw_tool_bend(scenario)
        return ScenarioWorld(scenario, kinematics, bent_tool(tool, bend), tool_bend=bend)
    if scenario.kind == "robot_accuracy":
        errors = draw_kinematic_errors(scenario, kinematics)
        return ScenarioWorld(scenario, perturbed_kinematics(kinematics, errors), tool, kinematic_errors=errors)
    if scenario.kind == "moved_reference":
        return ScenarioWorld(scenario, kinematics, tool, reference_move=draw_reference_move(scenario))
    return ScenarioWorld(scenario, kinematics, tool)


def explain(world: ScenarioWorld | Scenario, *, tr: Translator = ENGLISH) -> str:
    """Plain words for after a result: the error, how it shows in the result, how the TCP check
    reveals it, in ``tr``'s language. Numbers when given a :class:`ScenarioWorld`. Escape before
    markdown."""
    _ = tr.gettext
    w = world if isinstance(world, ScenarioWorld) else None
    kind = world.scenario.kind if isinstance(world, ScenarioWorld) else world.kind
    if kind == "bent_tool":
        if w is not None and w.tool_bend is not None:
            what = _("The tool was bent in a crash: its tip moved {shift} mm sideways and its axis turned "
                     "{angle}°, while the tool data in the library stayed as it was.").format(
                shift=f"{w.tool_bend.shift_mm:.1f}", angle=f"{w.tool_bend.angle_deg:.1f}")
        else:
            what = _("The tool was bent in a crash, while the tool data in the library stayed as it was.")
        return what + " " + _(
            "In a new calibration the touches agree (small residual) and the TCP comes out away from "
            "the saved one: the new TCP is right and the saved data is stale; working with the saved "
            "data puts every point off by the bend. "
            "The TCP check with the saved data shows it: the tip swings off the reference by "
            "2·sin(angle/2) times the sideways error on each rotation, and the implied TCP error is "
            "the size of the bend; with the new calibration it drops to your touching accuracy.")
    if kind == "robot_accuracy":
        return _("The robot differs from its model as a real, uncalibrated arm does: each link length by "
                 "0.1-0.5 mm and each joint zero by 0.01-0.05°. "
                 "Even perfect touches leave a residual of a few tenths of a millimetre and the TCP is off by "
                 "a few tenths; calibrating again gives the same picture, because it is the robot's absolute "
                 "accuracy, not your touching. "
                 "The TCP check shows tenths of a millimetre that no TCP correction removes (the implied TCP "
                 "error stays and the fit of the six rotations leaves a remainder): only a robot calibration "
                 "(mastering, absolute-accuracy option) improves it.")
    if kind == "moved_reference":
        if w is not None and w.reference_move is not None:
            what = _("The reference tip was knocked {shift} mm after touch {touch}.").format(
                shift=f"{float(np.linalg.norm(w.reference_move.shift_mm)):.1f}", touch=w.reference_move.after_touch)
        else:
            what = _("The reference tip was knocked after one of the touches.")
        return what + " " + _(
            "The touches after the move disagree with the earlier ones: the residual is large (the solver "
            "may flag outliers) and the TCP can be wrong by millimetres. Remove the touches after the move "
            "or calibrate again with the tip fixed. "
            "The TCP check needs no reference tip (the tool turns about its own TCP), so it shows the "
            "wrong TCP directly: the implied TCP error is how far the computed TCP is off.")
    return _("No systematic error: the residual reflects only your touching accuracy.")
