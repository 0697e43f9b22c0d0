"""Training mode auto-touch: let the virtual controller perform the current step of any wizard.

For demos ("a full 4-point calibration in four clicks"): the controller's ``auto_approach``
moves the hidden true TOOL frame onto the reference tip from a chosen or random direction,
with a simulated operator error (Gaussian, ``sigma_mm`` per axis, 0-2 mm), then the flange pose
is recorded into the wizard. What a step asks of the controller is not known here: each wizard
declares its step roles with an auto-touch role (``tcp_pendant.wizards.describe.AutoRole``,
read through ``Wizard.auto_role(step)``):

* ``reference_in_tool_mm(distance_mm)``: ``auto_approach(tip_offset_tool_mm=...)`` puts the
  reference tip there in true TOOL coordinates ((0, 0, 0): a touch; (-d, 0, 0): on the tool's
  -X axis; (0, 0, d): on its +Z axis ahead of the TCP; ...);
* ``tilt_range_deg``: the tilt of a random direction; ``keeps_orientation``: after the first
  step, the direction of the wizard's previous auto-touch is reused (``previous_direction_deg``,
  which the caller keeps: the workflow, per run; the outcome says the direction used), as an
  operator jogging along tool axes keeps the orientation;
* ``align_world``: ``move_true_tool_to`` the (PA-1) orientation, tip ``hover_mm`` above the
  reference tip, with an angular error (``angle_sigma_deg`` per axis, about the tool axes; by
  default the operator error ``sigma_mm`` seen over ``ANGLE_LEVER_MM``, see
  :func:`operator_angle_sigma_deg`); ``free_turn_about_x``: a random turn about tool X (5D).

``d`` is ``distance_mm`` (60 mm by default). The controller must have the physical tool the
step asks for mounted: auto-touch mounts it (from ``tools``, default ``builtin_tools()``,
through ``mount``: the session's command in the app) and tells the wizard. This module keeps
no state of its own.

A pose reached may still not serve the step (a TCP check's rotations stopped at a joint limit
from there: ``calibrate.jobs.POSE_CHECKS``). That check is a :data:`PoseProbe`, detached from
the controller, so the app runs it in its job pool: :func:`auto_touch_steps` is Auto-touch as a
generator that yields each probe and is sent its answer (the app awaits the probe between two
sends, off viser's event loop); :func:`auto_touch` runs the probes in place (tests, scripts).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Generator, Mapping
from dataclasses import dataclass
from typing import ParamSpec, TypeVar

import numpy as np
from scipy.spatial.transform import Rotation

from tcp_pendant.controller import ToolModel, VirtualController, builtin_tools
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.wizards.abc_world import R_WORLD_TOOL_TARGET
from tcp_pendant.wizards.base import StepInfo, Wizard, WizardError, WizardStateError
from tcp_pendant.wizards.describe import AutoRole

DEFAULT_DISTANCE_MM = 60.0
MIN_RETRY_DISTANCE_MM = 20.0
"""Shortest distance off the tip a retried axis step uses (mm): the three-point wizard's
minimum displacement (``three_point.MIN_DISPLACEMENT_MM``), so the retry is still accepted."""
ANGLE_LEVER_MM = 100.0
"""Lever over which an operator judges "parallel" by eye: an operator error of ``sigma_mm``
(position, per axis) is taken as an alignment error of ``atan(sigma_mm / ANGLE_LEVER_MM)``
per tool axis (1 mm: 0.57 deg; 2 mm: 1.15 deg)."""


def operator_angle_sigma_deg(sigma_mm: float) -> float:
    """The simulated alignment error per tool axis (deg) matching an operator error of
    ``sigma_mm`` (mm per axis): ``atan(sigma_mm / ANGLE_LEVER_MM)``."""
    return float(np.degrees(np.arctan2(float(sigma_mm), ANGLE_LEVER_MM)))


@dataclass(frozen=True)
class AutoTouchOutcome:
    """What one auto-touch did.

    Attributes:
        ok: the controller reached the pose and the pose was recorded.
        step_index: 0-based step it was for.
        role: the step's role.
        tilt_deg, azimuth_deg, spin_deg: approach direction used (None for ``parallel``).
        message: plain words (the controller's message on failure).
        attempts: controller calls made (random directions are retried when unreachable).
    """

    ok: bool
    step_index: int
    role: str
    tilt_deg: float | None
    azimuth_deg: float | None
    spin_deg: float | None
    message: str
    attempts: int

    @property
    def direction_deg(self) -> tuple[float, float, float] | None:
        """(tilt, azimuth, spin) used, deg (None for ``parallel`` or a failure): give it back as
        ``previous_direction_deg`` for the wizard's next step."""
        if self.tilt_deg is None or self.azimuth_deg is None or self.spin_deg is None:
            return None
        return (self.tilt_deg, self.azimuth_deg, self.spin_deg)


def _ensure_mounted(wizard: Wizard, controller: VirtualController, step: StepInfo,
                    tools: Mapping[str, ToolModel] | None, mount: Callable[[ToolModel], None] | None) -> None:
    key = step.mount_tool_key
    if key is not None and getattr(controller.mounted_tool, "key", None) != key:
        if tools is None:
            tools = builtin_tools()
        if key not in tools:
            raise WizardError(f"The step needs the tool '{key}', which is not among {sorted(tools)}.")
        (controller.mount_tool if mount is None else mount)(tools[key])
    wizard.note_mounted_tool(getattr(controller.mounted_tool, "key", None))


PoseProbe = Callable[[], "str | None"]
"""Why the pose reached does not serve the step (None: it serves): a check detached from the
controller (its own copies of the robot model and the joints), safe to run in a worker thread."""
AutoTouchSteps = Generator[PoseProbe, "str | None", AutoTouchOutcome]
"""Auto-touch as a generator (:func:`auto_touch_steps`): it yields pose probes, is sent their
answers and returns the outcome."""

R = TypeVar("R")
P = ParamSpec("P")
MOVED_DURING_PROBE = N_("The robot was moved while Auto-touch checked the pose it reached; nothing was "
                      "recorded. Press Auto-touch again.")


def run_probes(steps: Generator[PoseProbe, "str | None", R]) -> R:
    """Drive a generator of :func:`auto_touch_steps` to its end, running each probe it yields
    here, and return what it returns."""
    try:
        probe = next(steps)
        while True:
            probe = steps.send(probe())
    except StopIteration as stop:
        return stop.value


def in_place(steps: Callable[P, Generator[PoseProbe, "str | None", R]]) -> Callable[P, R]:
    """``steps`` (a generator function yielding pose probes) as a plain function that runs each
    probe in place (:func:`run_probes`): same arguments, its generator's return value."""
    @functools.wraps(steps)
    def run(*args: P.args, **kwargs: P.kwargs) -> R:
        return run_probes(steps(*args, **kwargs))
    return run


def auto_touch_steps(wizard: Wizard, controller: VirtualController, *,
                     direction_deg: tuple[float, float, float] | None = None, sigma_mm: float = 0.0,
                     angle_sigma_deg: float | None = None, distance_mm: float = DEFAULT_DISTANCE_MM,
                     hover_mm: float = 30.0, rng: np.random.Generator | None = None, advance: bool = True,
                     tools: Mapping[str, ToolModel] | None = None, max_attempts: int = 12,
                     previous_direction_deg: tuple[float, float, float] | None = None,
                     mount: Callable[[ToolModel], None] | None = None,
                     pose_check: Callable[[], PoseProbe] | None = None) -> AutoTouchSteps:
    """Perform the wizard's current step with the controller and record the flange pose (a
    generator: it yields the :data:`PoseProbe` of each pose reached, when ``pose_check`` is
    given, and must be sent the probe's answer; it returns the outcome).

    Args:
        wizard: any wizard, in progress.
        controller: a ``tcp_pendant.controller.VirtualController``.
        direction_deg: (tilt, azimuth, spin) in degrees (see ``VirtualController.auto_approach``);
            None: random (tilt in the role's ``tilt_range_deg``: 20-50 deg for touches, 5-30 deg
            for steps that keep the orientation, azimuth 0-360, spin -90..90), retried up to
            ``max_attempts`` times when unreachable.
        sigma_mm: simulated operator position error, per axis (0-2 mm in the pendant).
        angle_sigma_deg: simulated angular error per tool axis for ``parallel`` steps (deg);
            None: :func:`operator_angle_sigma_deg` of ``sigma_mm`` (0 when ``sigma_mm`` is 0).
        distance_mm: displacement of the steps off the touch (three-point, TCP & Z, X).
        hover_mm: height of the tip above the reference tip for ``parallel`` steps.
        rng: random generator (seed it for reproducible demos and tests).
        advance: after recording, go to the next step (never finishes the wizard: Finish is
            the user's click).
        tools: physical tools by key, to mount the one the step needs.
        previous_direction_deg: the direction of this wizard's previous auto-touch
            (``AutoTouchOutcome.direction_deg``), reused by the steps whose role keeps the
            orientation (three-point steps 2 and 3, TCP & Z, X's z and x).
        mount: how to mount a tool (default ``controller.mount_tool``; the app passes the
            session's command, which signals the change).
        pose_check: after a reached approach, called where the robot stands: the probe of why
            that pose does not serve the step (its answer None: it does), e.g. a TCP check's
            rotations that cannot be made from it; such a pose is not recorded and the next
            direction is tried (``calibrate.jobs.POSE_CHECKS``). When the robot moved or the
            wizard's step changed while the probe ran, nothing is recorded (the outcome says so).
    """
    if wizard.status != "in_progress":
        raise _cannot(wizard)
    angle_sigma_deg = _angle_sigma_deg(sigma_mm, angle_sigma_deg)
    rng = np.random.default_rng() if rng is None else rng
    step = wizard.step
    _ensure_mounted(wizard, controller, step, tools, mount)
    if not wizard.can_record:
        raise _cannot(wizard)
    role = wizard.auto_role(step)
    if role.align_world:
        return _align_with_world(wizard, controller, step, role, sigma_mm=sigma_mm, angle_sigma_deg=angle_sigma_deg,
                                 hover_mm=hover_mm, rng=rng, advance=advance)
    keeps = role.keeps_orientation and step.index > 0     # the previous auto-touch's direction
    fixed = direction_deg or (previous_direction_deg if keeps else None)
    attempts = 0
    last_message = ""
    for d_mm, use_fixed in _approach_plan(role, distance_mm, fixed, chosen=direction_deg is not None):
        offset = role.reference_in_tool_mm(d_mm)
        for _attempt in range(1 if use_fixed else max_attempts):
            attempts += 1
            tilt, azimuth, spin = _direction_deg(fixed if use_fixed else None, role, rng)
            res = controller.auto_approach(tilt_deg=tilt, azimuth_deg=azimuth, spin_deg=spin,
                                           sigma_mm=sigma_mm, tip_offset_tool_mm=offset, rng=rng)
            refused = None
            if res.ok and pose_check is not None:
                q_reached = controller.q_rad.copy()
                refused = yield pose_check()
                if _moved(controller, q_reached, wizard, step):
                    moved = wizard.translator.gettext(MOVED_DURING_PROBE)
                    return AutoTouchOutcome(False, step.index, step.role, None, None, None, moved, attempts)
            if refused is not None:            # reached, but unfit for what the step is for
                last_message = refused
                continue
            if res.ok:
                _record(wizard, controller, advance)
                return _touched(step, (tilt, azimuth, spin), d_mm, distance_mm, attempts,
                                redrawn=fixed is not None and not use_fixed, tr=wizard.translator)
            last_message = res.message
    return _failed(step, attempts, last_message, wizard.translator)


def _failed(step: StepInfo, attempts: int, reason: str, tr: Translator) -> AutoTouchOutcome:
    """No approach of ``attempts`` reached the step; ``reason``: the controller's last words."""
    words = tr.ngettext("Auto-touch failed after {n} attempt: {reason}",
                        "Auto-touch failed after {n} attempts: {reason}", attempts)
    return AutoTouchOutcome(False, step.index, step.role, None, None, None,
                            words.format(n=attempts, reason=reason), attempts)


def _cannot(wizard: Wizard) -> WizardStateError:
    """Auto-touch refused: why Record is disabled (``Wizard.blocked_reason``), in the wizard's language."""
    return WizardStateError(wizard.translator.gettext("Cannot auto-touch: {reason}").format(
        reason=wizard.blocked_reason))


def _angle_sigma_deg(sigma_mm: float, angle_sigma_deg: float | None) -> float:
    """The angular error per tool axis (deg) of ``parallel`` steps: ``angle_sigma_deg``, or
    None: :func:`operator_angle_sigma_deg` of ``sigma_mm``.

    Raises:
        WizardError: ``sigma_mm`` out of 0..10 mm or the angle out of 0..30 deg.
    """
    if angle_sigma_deg is None and np.isfinite(sigma_mm):
        angle_sigma_deg = operator_angle_sigma_deg(sigma_mm)
    if not 0.0 <= sigma_mm <= 10.0 or angle_sigma_deg is None or not 0.0 <= angle_sigma_deg <= 30.0:
        raise WizardError(f"sigma_mm must be in 0..10 mm and angle_sigma_deg in 0..30 deg, "
                          f"got {sigma_mm} and {angle_sigma_deg}.")
    return angle_sigma_deg


def _direction_deg(fixed: tuple[float, float, float] | None, role: AutoRole,
                   rng: np.random.Generator) -> tuple[float, float, float]:
    """The approach (tilt, azimuth, spin; deg): ``fixed``, or None: a random one (tilt in the
    role's ``tilt_range_deg``, azimuth 0-360, spin -90..90)."""
    if fixed is not None:
        return float(fixed[0]), float(fixed[1]), float(fixed[2])
    lo, hi = role.tilt_range_deg
    return rng.uniform(lo, hi), rng.uniform(0.0, 360.0), rng.uniform(-90.0, 90.0)


def _touched(step: StepInfo, direction_deg: tuple[float, float, float], d_mm: float, distance_mm: float,
             attempts: int, *, redrawn: bool, tr: Translator = ENGLISH) -> AutoTouchOutcome:
    """The outcome of a step recorded from ``direction_deg`` with the reference ``d_mm`` off the
    tip (shorter than the ``distance_mm`` asked: it was out of reach; ``redrawn``: the previous
    orientation was, and a new one was drawn)."""
    _ = tr.gettext
    tilt, azimuth, spin = direction_deg
    words = _("Step {k} recorded: {title} (tilt {tilt}°, azimuth {azimuth}°).").format(
        k=step.index + 1, title=step.title, tilt=f"{tilt:.0f}", azimuth=f"{azimuth:.0f}")
    if d_mm != distance_mm:
        words += " " + _("The reference is {d} mm off the tip: {distance} mm was out of reach.").format(
            d=f"{d_mm:g}", distance=f"{distance_mm:g}")
    elif redrawn:
        words += " " + _("The previous orientation was out of reach: a new one was drawn.")
    return AutoTouchOutcome(True, step.index, step.role, tilt, azimuth, spin, words, attempts)


def _moved(controller: VirtualController, q_reached: np.ndarray, wizard: Wizard, step: StepInfo) -> bool:
    """While a pose probe ran, the robot left the joints ``q_reached`` (rad) or the wizard left
    ``step``: the pose is not recorded."""
    return (not np.array_equal(controller.q_rad, q_reached) or wizard.status != "in_progress"
            or wizard.step_index != step.index)


def _record(wizard: Wizard, controller: VirtualController, advance: bool) -> None:
    """Record the flange pose where the controller stands; with ``advance`` go to the next step
    (never past the last: Finish is the user's click)."""
    wizard.record(controller.T_world_flange())
    if advance and not wizard.on_last_step:
        wizard.next()


def _approach_plan(role: AutoRole, distance_mm: float, fixed: tuple[float, float, float] | None, *,
                   chosen: bool) -> list[tuple[float, bool]]:
    """The approaches to try, in order: (distance of the reference off the tip in mm, whether
    to use the ``fixed`` direction; else random ones). A fixed direction gets one try per
    distance. A step that keeps the orientation and puts the reference off the tip (TCP & Z,
    X's z and x, three-point's axes) may be out of reach at the full distance while a shorter
    back-off along the same axis is not (a ~2 % case at 60 mm on the KR 6 with the torch): as an
    operator would, it retries at half the distance and at :data:`MIN_RETRY_DISTANCE_MM`. Where
    the solve takes each pose's own rotation (``any_orientation_solves``) and the direction was
    not ``chosen`` by the user, new random directions at the full distance come last."""
    plan: list[tuple[float, bool]] = [(distance_mm, fixed is not None)]
    if fixed is not None and any(role.reference_in_tool_mm(1.0)):
        shorter_mm = sorted({max(distance_mm / 2.0, MIN_RETRY_DISTANCE_MM), MIN_RETRY_DISTANCE_MM}, reverse=True)
        plan += [(d, True) for d in shorter_mm if d < distance_mm]
    if fixed is not None and not chosen and role.any_orientation_solves:
        plan.append((distance_mm, False))
    return plan


def _align_with_world(wizard: Wizard, controller: VirtualController, step: StepInfo, role: AutoRole, *,
                      sigma_mm: float, angle_sigma_deg: float, hover_mm: float, rng: np.random.Generator,
                      advance: bool) -> AutoTouchOutcome:
    """An ``align_world`` step: the true tool at the (PA-1) orientation (a random turn about tool
    X for a 5D tool), off by a random rotation of ``angle_sigma_deg`` per axis, its tip
    ``hover_mm`` above the reference tip; recorded."""
    R = R_WORLD_TOOL_TARGET.copy()
    if role.free_turn_about_x:
        R = R @ Rotation.from_euler("x", rng.uniform(-60.0, 60.0), degrees=True).as_matrix()
    misalignment_deg = 0.0
    if angle_sigma_deg > 0.0:
        rotvec_deg = rng.normal(0.0, angle_sigma_deg, 3)
        misalignment_deg = float(np.linalg.norm(rotvec_deg))
        R = R @ Rotation.from_rotvec(rotvec_deg, degrees=True).as_matrix()
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = np.asarray(controller.reference_tip_world_m, dtype=float) + [0.0, 0.0, hover_mm / 1000.0]
    _ = wizard.translator.gettext
    res = controller.move_true_tool_to(T)
    if not res.ok:
        return AutoTouchOutcome(False, step.index, step.role, None, None, None,
                                _("Could not align the tool with WORLD: {reason}").format(reason=res.message), 1)
    _record(wizard, controller, advance)
    words = (_("Tool aligned with WORLD exactly and recorded.") if angle_sigma_deg == 0.0 else
             _("Tool aligned with WORLD by eye, {off}° off (σ {sigma_deg}° per axis = operator error "
               "{sigma_mm} mm over {lever} mm) and recorded.").format(
                 off=f"{misalignment_deg:.2f}", sigma_deg=f"{angle_sigma_deg:.2f}", sigma_mm=f"{sigma_mm:g}",
                 lever=f"{ANGLE_LEVER_MM:.0f}"))
    return AutoTouchOutcome(True, step.index, step.role, None, None, None, words, 1)


auto_touch = in_place(auto_touch_steps)
"""Auto-touch with each pose probe run in place: :func:`auto_touch_steps`' arguments, its outcome."""
