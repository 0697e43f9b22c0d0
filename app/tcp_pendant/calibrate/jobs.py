"""The jobs the controller runs for a wizard before it can finish (no viser).

A wizard class names its job (``Wizard.controller_job``); :data:`JOBS` maps that name to the
function that takes it from the session's workflow, on viser's event loop, detached from the
session: the job holds its own copies of the robot models and the facts it needs, so
:meth:`ControllerJob.run` may run in a worker thread while the loop keeps jogging, and its
outcome is handed back on the loop (``CalibrationWorkflow.give_controller_job``). Adding a
method the controller runs is: its wizard class (naming its job), its job here, its words.

Metres and radians throughout; the controller is never moved by a job.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Protocol, cast

import numpy as np

from tcp_pendant.calibrate.autotouch import PoseProbe
from tcp_pendant.controller import RobotKinematics, T_flange_tool_m, builtin_tools
from tcp_pendant.controller.beam import BeamSensor, ToolShape
from tcp_pendant.translation import N_
from tcp_pendant.controller.beam_scan import BeamScan, BeamScanConfig, run_beam_scan, tool_shape
from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.controller.jog import JogSettings
from tcp_pendant.controller.spin import SpinCheckResult, spin_check
from tcp_pendant.wizards import (
    BeamWizard,
    ManualComparison,
    RecordedPose,
    TcpCheckWizard,
    Wizard,
    WizardResult,
    WizardStateError,
)
from tcp_pendant.wizards.check_reading import check_readable
from tcp_pendant.wizards.tcp_check import CheckFigures

if TYPE_CHECKING:
    from tcp_pendant.calibrate.workflow import CalibrationWorkflow

__all__ = ["EXERCISE_REFUSAL", "JOBS", "POSE_CHECKS", "BeamScanJob", "ControllerJob", "TcpCheckJob",
           "beam_scan_job", "spin_check_job", "spin_clearance"]

EXERCISE_REFUSAL = N_("{what} is off during the trainer's exercise: the beam sensor would measure the "
                    "exercise's tool for you. Calibrate it by touching the reference tip (XYZ 4-point, "
                    "XYZ reference or TCP & Z, X).")
"""Why a method that measures the tool by itself is refused in an exercise (``hide_truth``)."""


class ControllerJob(Protocol):
    """What a wizard on show waits for the controller to do (its step role is
    ``by_controller``, or it checks a touch), detached from the session: taken on the loop
    (:meth:`CalibrationWorkflow.controller_job`), :meth:`run` in a worker thread (pure: its
    own copies of the robot models; the controller is not moved), the outcome handed back on
    the loop (:meth:`CalibrationWorkflow.give_controller_job`)."""

    @property
    def wizard(self) -> Wizard:
        """The wizard that waits for the job."""

    @property
    def busy_text(self) -> str:
        """What the steps view says while the job runs (markdown, our words only)."""

    def run(self) -> Any:
        """Do the work (worker thread)."""

    def hand_in(self, outcome: Any) -> WizardResult | None:
        """Give ``outcome`` to the wizard and finish it (None when the wizard was left meanwhile:
        it keeps the outcome and shows it when resumed and finished)."""


@dataclass(frozen=True, eq=False)
class TcpCheckJob:
    """The six rotations a TCP check wizard waits for, detached from the session: its own
    copies of the robot models, so :meth:`run` (0.1-0.3 s) may run in a worker thread while the
    loop keeps jogging. Metres and radians; the controller is not moved."""

    busy_text: ClassVar[str] = "**Checking:** the controller turns the tool ±A, ±B, ±C about the TCP ..."

    wizard: TcpCheckWizard
    pose: RecordedPose            # the touch the check starts from
    kinematics: RobotKinematics
    true_kinematics: RobotKinematics
    q_rad: np.ndarray
    T_flange_tool_active: np.ndarray
    T_flange_tool_true: np.ndarray
    settings: JogSettings = field(repr=False)
    reading_only: bool = False
    """An exercise: the wizard gets a technician's reading only (``CheckFigures.as_reading``)."""

    def run(self) -> SpinCheckResult:
        """``controller.spin.spin_check`` from the recorded touch's joint angles."""
        return spin_check(self.kinematics, self.q_rad, self.T_flange_tool_active, self.T_flange_tool_true,
                          angle_deg=self.wizard.angle_deg, true_kinematics=self.true_kinematics,
                          settings=self.settings)

    def hand_in(self, outcome: SpinCheckResult) -> WizardResult | None:
        """The check to its wizard (from the recorded touch it started at), then Finish; in an
        exercise the reading only (no implied TCP error, no correction)."""
        figures = CheckFigures.of(outcome)
        self.wizard.give_check(figures.as_reading() if self.reading_only else figures, self.pose)
        if self.wizard.status == "in_progress":
            return self.wizard.finish()
        return None


@dataclass(frozen=True, eq=False)
class BeamScanJob:
    """The scan an Automatic (beam) wizard waits for, detached from the session: the robot
    models (own copies), the joints where it starts, the beam sensor, the tool data the
    controller plans with and the physical tool the beam sees, so :meth:`run` may run in a
    worker thread. Metres and radians; the controller is not moved.

    Attributes:
        wizard: the beam wizard.
        kinematics: the controller's (nominal) model; true_kinematics: the physical robot.
        q_start_rad: joints where the scan starts.
        sensor: the beam device; shape: the physical (true) tool the beam sees.
        T_flange_tool_plan: (4,4) the tool data the controller plans with, m.
        config: the scan's speeds and orientations (from the wizard's options).
        seed: seed of the sensor's repeatability noise (None: exact events).
        manual: the trainee's last manual calibration of the same tool, or None.
    """

    busy_text: ClassVar[str] = ("**Scanning:** the controller moves the tool through the beam at each "
                                "orientation and records every beam event ...")

    wizard: BeamWizard
    kinematics: RobotKinematics
    true_kinematics: RobotKinematics
    q_start_rad: np.ndarray
    sensor: BeamSensor
    shape: ToolShape
    T_flange_tool_plan: np.ndarray
    config: BeamScanConfig
    seed: int | None = None
    manual: ManualComparison | None = None

    def run(self) -> BeamScan:
        """``controller.beam_scan.run_beam_scan`` from the start joints.

        Raises:
            ControllerError: nothing could be scanned (the reasons in words).
        """
        rng = None if self.seed is None else np.random.default_rng(self.seed)
        return run_beam_scan(self.kinematics, self.q_start_rad, self.sensor, self.T_flange_tool_plan,
                             self.shape, true_kinematics=self.true_kinematics, config=self.config, rng=rng)

    def hand_in(self, outcome: BeamScan) -> WizardResult | None:
        """The scan to its wizard (with the planning orientation and the manual comparison),
        then Finish (a ``CalibrationFailedError`` when the events cannot give a TCP)."""
        self.wizard.give_scan(outcome, R_flange_tool_base=self.T_flange_tool_plan[:3, :3], manual=self.manual)
        if self.wizard.status == "in_progress":
            return self.wizard.finish()
        return None


def spin_check_job(workflow: CalibrationWorkflow, wizard: Wizard) -> TcpCheckJob | None:
    """The six rotations the TCP check on show waits for (None: nothing to check), from its
    recorded touch (the joints there, as recorded) with the checked tool data as the active TCP
    and the mounted tool's truth.

    Raises:
        WizardStateError: the touch's joint angles are unknown (a resumed record) and the
            robot is no longer there: record the touch again.
    """
    check = cast(TcpCheckWizard, wizard)          # the class that names this job ("spin_check")
    if not check.check_pending:
        return None
    pose, c = check.recorded_pose, workflow.controller
    assert pose is not None                      # check_pending: a touch is recorded
    q = workflow.joints_at_record(pose)
    if q is None and np.allclose(c.T_world_flange(), pose.T_world_flange_m, atol=1e-7):
        q = c.q_rad.copy()
    if q is None:
        raise WizardStateError(workflow.translator.gettext(
            "The robot is not at the recorded touch any more: press Record again "
            "with the tool tip on the reference tip, then Finish."))
    nominal, physical = c.kinematics_for_worker()
    if workflow.hide_truth:                   # an exercise: read against the reference tip
        tip = (physical.T_world_flange(q) @ np.asarray(c.mounted_tool.T_flange_tool_true))[:3, 3]
        try:
            check_readable(float(np.linalg.norm(tip - c.reference_tip_world_m)) * 1000.0, tr=workflow.translator)
        except ValueError as exc:
            raise WizardStateError(workflow.translator.gettext("{reason} Record the touch there, then Finish.").format(
                reason=exc)) from None
    return TcpCheckJob(check, pose, nominal, physical, np.array(q, dtype=float), T_flange_tool_m(check.tool),
                       np.array(c.mounted_tool.T_flange_tool_true, dtype=float), c.settings,
                       reading_only=workflow.hide_truth)


def beam_scan_job(workflow: CalibrationWorkflow, wizard: Wizard) -> BeamScanJob | None:
    """The scan the beam wizard on show waits for (None: none waiting), from the robot's joints
    now, on the session's beam sensor, planned with the mounted tool's nominal (catalogue) data
    for a built-in tool, else with the active tool data; the beam sees the physical tool (its
    true frame, bent by a scenario). The noise seed comes from the workflow's ``rng`` (a seeded
    session scans reproducibly).

    Raises:
        WizardStateError: the beam cannot measure the mounted tool (the gripper), no tool data
            to plan with (a tool of no catalogue and no active tool data), or a classroom
            exercise runs (``hide_truth``: the scan would measure its tool).
    """
    beam = cast(BeamWizard, wizard)               # the class that names this job ("beam_scan")
    if not beam.scan_pending:
        return None
    if workflow.hide_truth:     # an exercise began after the wizard was opened
        _ = workflow.translator.gettext
        raise WizardStateError(_(EXERCISE_REFUSAL).format(what=_("The Automatic (beam) scan")))
    c = workflow.controller
    mounted = c.mounted_tool
    try:
        shape = tool_shape(mounted)
    except ControllerError as exc:
        raise WizardStateError(workflow.translator.gettext(
            "{reason} Mount the pointer or the torch on the Tool tab.").format(reason=exc)) from exc
    catalogue = builtin_tools().get(mounted.key)
    if catalogue is not None:
        T_plan = np.array(catalogue.T_flange_tool_true, dtype=float)
    elif c.active_tool is not None:
        T_plan = T_flange_tool_m(c.active_tool)
    else:
        raise WizardStateError(workflow.translator.gettext(
            "The controller needs approximate tool data of the {tool} "
            "to plan the scan: calibrate it by hand or enter its data on the Tool tab, "
            "make it active, then press Finish again.").format(tool=mounted.label.lower()))
    nominal, physical = c.kinematics_for_worker()
    try:
        config = BeamScanConfig(n_orientations=beam.n_orientations, scan_speed_mm_s=beam.scan_speed_mm_s)
    except ControllerError as exc:
        raise WizardStateError(str(exc)) from exc
    return BeamScanJob(beam, nominal, physical, c.q_rad.copy(), c.beam_sensor, shape, T_plan, config,
                       seed=int(workflow.rng.integers(2**31)), manual=workflow.manual_comparison())


def spin_clearance(workflow: CalibrationWorkflow, wizard: Wizard) -> Callable[[], PoseProbe]:
    """For Auto-touch of a TCP check: a pose serves only when all six rotations of the check
    can be made from it (a rotation stopped at a joint limit proves nothing). Called where
    Auto-touch's approach left the robot, it takes the probe of that pose: the check's
    rotations on its own copy of the controller's model from the joints now (0.05-0.3 s; the
    controller is not moved), which names the rotations that cannot be made; detached, so the
    app runs it in its job pool (``WizardCommands.auto_touch_in_pool``)."""
    check = cast(TcpCheckWizard, wizard)          # the class that names this job ("spin_check")
    c = workflow.controller

    def take() -> PoseProbe:
        kinematics, _ = c.kinematics_for_worker()
        q, T_tool = c.q_rad.copy(), T_flange_tool_m(check.tool)
        T_true = np.array(c.mounted_tool.T_flange_tool_true, dtype=float)
        angle_deg, settings = check.angle_deg, c.settings

        def probe() -> str | None:
            result = spin_check(kinematics, q, T_tool, T_true, angle_deg=angle_deg, settings=settings)
            missing = [r.label for r in result.rotations if not r.reached]
            return None if not missing else f"{', '.join(missing)} of the check could not be made from that pose"

        return probe

    return take


POSE_CHECKS: dict[str, Callable[[CalibrationWorkflow, Wizard], Callable[[], PoseProbe]]] = {
    "spin_check": spin_clearance,
}
"""``Wizard.controller_job`` name -> what takes the probe that Auto-touch's pose serves that job
(``autotouch.PoseProbe``, run in a worker)."""


JOBS: dict[str, Callable[[CalibrationWorkflow, Wizard], ControllerJob | None]] = {
    "spin_check": spin_check_job,
    "beam_scan": beam_scan_job,
}
"""``Wizard.controller_job`` name -> the function that takes that job from the workflow."""
