"""The Calibrate menu's logic, without viser: which wizard is open, the physical tool each step
needs, training mode (truth, auto-touch), saving to the tool library and the session record.

A :class:`CalibrationWorkflow` belongs to one pendant session. It owns the wizards started in
that session (``runs``: each a :class:`~tcp_pendant.wizards.session_record.WizardRun` with the
hidden true TOOL frame of the tool it calibrates) and the auto-touch memory of each run; it
reads the session's :class:`~tcp_pendant.controller.VirtualController`, drives it for
auto-touch, and writes the server's shared :class:`tcpcal.ToolLibrary` only in :meth:`save`.
The mounted tool and the active tool data are not its own: it changes them through a
:class:`ToolState` (the app's ``Session``, whose commands emit the change signal; without one,
:class:`ControllerToolState` writes the controller directly). The open wizard is told which
tool is mounted explicitly, by the commands that may have changed it
(:meth:`CalibrationWorkflow.note_mounted_tool`; the app also calls it on the session's ``tool``
change): reading :attr:`CalibrationWorkflow.wizard` has no side effect. The views (``tcp_pendant.views.wizard_*``) only render it and
forward clicks; every figure comes from the wizards, which call ``tcpcal``.

The workflow holds small owners, one job each, and delegates to them: ``run_list.RunList``
(the runs and the one on show), ``touch_memory.TouchMemory`` (joints at record, Auto-touch's
steps and directions), ``run_log.RunLog`` (events, touch facts, the failed Finish),
``auto_touch_driver.AutoTouchDriver`` (training mode's Auto-touch) and ``run_result.RunResult``
(the result on show, its truth and Save); ``finish_checks`` and ``run_lessons`` are functions.

Units: the controller speaks metres (``T_world_flange``); the wizards hand millimetres to
``tcpcal``; everything shown is in mm and degrees.

Nothing already saved is lost: the library is only written by :meth:`save` (one atomic
``ToolLibrary.save``), a cancelled wizard keeps its poses and can be resumed, and starting
another wizard only cancels (never deletes) the one that was open.
"""

from __future__ import annotations

from collections.abc import Generator, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any, Protocol, cast

import numpy as np

from tcp_pendant.controller import ToolModel, VirtualController, builtin_tools
from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.calibrate.auto_touch_driver import AutoTouchDriver
from tcp_pendant.calibrate.autotouch import AutoTouchOutcome, PoseProbe, run_probes
from tcp_pendant.calibrate.jobs import EXERCISE_REFUSAL, JOBS, ControllerJob
from tcp_pendant.calibrate.finish_checks import touches_short, wrong_tool_touch
from tcp_pendant.calibrate.pendant_rules import UNRESTRICTED, RuleRefusal, check_calibrated_tool
from tcp_pendant.calibrate.run_lessons import manual_comparison
from tcp_pendant.calibrate.run_list import RunList
from tcp_pendant.calibrate.run_log import RunLog
from tcp_pendant.calibrate.run_result import RunResult
from tcp_pendant.calibrate.touch_memory import TouchMemory
from tcp_pendant.events import (
    RunCancelled,
    RunResumed,
    RunStarted,
    SessionEvent,
)
from tcp_pendant.wizards import (
    CalibrationFailedError,
    ManualComparison,
    Wizard,
    WizardError,
    WizardResult,
    WizardStateError,
    Xyz4Wizard,
    wizard_class,
)
from tcp_pendant.wizards.base import RecordedPose
from tcp_pendant.wizards.session_record import (
    LoadedRecord,
    ReplayCheck,
    WizardRun,
    load_and_replay,
    session_from_controller,
)
from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.wizards.truth import TruthComparison
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

__all__ = [
    "AUTO_SIGMA_MAX_MM",
    "AutoTouchRequest",
    "CalibrationWorkflow",
    "ControllerToolState",
    "ToolState",
]

AUTO_SIGMA_MAX_MM = 2.0
"""Largest simulated operator error the pendant offers (its slider runs 0-2 mm)."""


@dataclass(frozen=True)
class AutoTouchRequest:
    """What the training-mode "Auto-touch" button asks for.

    Attributes:
        tilt_deg, azimuth_deg: approach direction (see ``VirtualController.auto_approach``:
            tool X tilted ``tilt_deg`` from straight down, turned ``azimuth_deg`` about WORLD Z);
            None for both: a random direction.
        sigma_mm: simulated operator error, mm per axis (0 to ``AUTO_SIGMA_MAX_MM``).
    """

    tilt_deg: float | None = None
    azimuth_deg: float | None = None
    sigma_mm: float = 0.0

    def __post_init__(self) -> None:
        if (self.tilt_deg is None) != (self.azimuth_deg is None):
            raise WizardError("Give both tilt and azimuth for a chosen direction, or neither for a random one.")
        for what, v in (("tilt", self.tilt_deg), ("azimuth", self.azimuth_deg)):
            if v is not None and not np.isfinite(v):
                raise WizardError(f"The auto-touch {what} must be a finite number of degrees, got {v}.")
        if not (np.isfinite(self.sigma_mm) and 0.0 <= self.sigma_mm <= AUTO_SIGMA_MAX_MM):
            raise WizardError(f"The simulated operator error must be 0 to {AUTO_SIGMA_MAX_MM:g} mm, "
                              f"got {self.sigma_mm}.")

    @property
    def direction_deg(self) -> tuple[float, float, float] | None:
        """(tilt, azimuth, spin) for ``auto_touch``; None: random."""
        if self.tilt_deg is None or self.azimuth_deg is None:
            return None
        return (float(self.tilt_deg), float(self.azimuth_deg), 0.0)


class ToolState(Protocol):
    """Who owns the mounted tool and the active tool data (the app's ``Session``)."""

    def mount_tool(self, tool: ToolModel) -> None:
        """Bolt the physical ``tool`` on."""

    def mount_step_tool(self, tool: ToolModel) -> None:
        """Bolt on the physical ``tool`` that the current step of the run on show asks for
        (the owner may allow it where :meth:`mount_tool` is refused: an exercise's reference
        tool)."""

    def set_active_data(self, tool: Tool | None, slot: int | None = None) -> None:
        """Make ``tool`` (from library ``slot``) the active tool data."""

    def apply_saved(self, slot: int, tool: Tool) -> None:
        """``tool`` was just saved in ``slot``: make it the active tool data."""


class ControllerToolState:
    """:class:`ToolState` without a session: writes the controller (scripts and tests)."""

    def __init__(self, controller: VirtualController) -> None:
        self.controller = controller

    def mount_tool(self, tool: ToolModel) -> None:
        self.controller.mount_tool(tool)

    def mount_step_tool(self, tool: ToolModel) -> None:
        self.controller.mount_tool(tool)

    def set_active_data(self, tool: Tool | None, slot: int | None = None) -> None:
        self.controller.set_active_tool(tool)

    def apply_saved(self, slot: int, tool: Tool) -> None:
        self.controller.set_active_tool(tool)


class CalibrationWorkflow:
    """The calibration wizards of one pendant session (see the module docstring).

    Args:
        controller: the session's virtual controller.
        library: the server's tool library (shared by every session).
        robot: robot name for the session record ("kr6", "gp12" or a URDF stem).
        tools: physical tools by key (default: the built-in pointer, torch and gripper).
        rng: random generator of auto-touch (seed it for reproducible demos and tests).
        state: the owner of the mounted tool and the active tool data (default: a
            :class:`ControllerToolState` of ``controller``).
    """

    def __init__(self, controller: VirtualController, library: ToolLibrary, *, robot: str,
                 tools: Mapping[str, ToolModel] | None = None,
                 rng: np.random.Generator | None = None, state: ToolState | None = None) -> None:
        self.controller = controller
        self.library = library
        self.state: ToolState = ControllerToolState(controller) if state is None else state
        self.robot = robot
        self.tools: dict[str, ToolModel] = dict(builtin_tools() if tools is None else tools)
        self.rng = np.random.default_rng() if rng is None else rng
        self.training = True
        self.hide_truth = False   # an exercise (classroom): no true frame or error vs truth shown
        self.run_list = RunList()
        """The runs of this session, the one on show and the results saved."""
        self.touches = TouchMemory()
        """Joints at record, Auto-touch's steps and directions."""
        self.last_save: tuple[int, Tool] | None = None
        self.honest_records = False
        """A classroom session: the exported record carries no truth (``session_record`` honest)."""
        self.record_ids: dict[int, int] = {}
        """Run index -> gradebook calibration id (the classroom recorder fills it; exported)."""
        self.log = RunLog(controller, self.run_list, self.touches)
        """The events of the commands, the facts of each touch, the failed Finish."""
        self.auto = AutoTouchDriver(self)
        """Training mode's Auto-touch."""
        self.results = RunResult(self.run_list, self.tools, library, self.log)
        """The result of the run on show, its truth and its Save."""

    # ------------------------------------------------------------ language
    @property
    def translator(self) -> Translator:
        """The language of the texts the wizards compose (steps, warnings, refusals): the
        session's (:meth:`set_translator`), English until set."""
        return self.run_list.translator

    def set_translator(self, tr: Translator) -> None:
        """Compose every text in ``tr``'s language from now on: every run's wizard (the step on
        show reads in it at once, a result's warnings are recomposed) and the workflow's own
        refusals. The session calls it at start and on every language switch."""
        self.run_list.set_translator(tr)

    # ------------------------------------------------------------ events
    def take_events(self) -> tuple[SessionEvent, ...]:
        """The events of the commands since the last call, in order (``tcp_pendant.events``);
        the session puts them into its change signal."""
        return self.log.take()

    def note_recorded(self, step: int, *, auto: bool, had_pose: bool) -> None:
        """Keep the facts of the pose just recorded at ``step`` of the run on show (``RunLog.recorded``;
        the distance hidden when the owner's ``hide_distance`` is on)."""
        self.log.recorded(step, auto=auto, had_pose=had_pose, hide_truth=self.hide_truth,
                          hide_distance=bool(getattr(self.state, "hide_distance", False)))

    def joints_at_record(self, pose: RecordedPose) -> np.ndarray | None:
        """The joints (rad) where ``pose`` was recorded in this session (None: not known, e.g.
        a pose loaded from a record)."""
        return self.touches.joints_at_record(pose)

    # ------------------------------------------------------------ state
    @property
    def runs(self) -> list[WizardRun]:
        """The wizard runs started in this session, loaded or given back (``RunList.runs``)."""
        return self.run_list.runs

    @property
    def run(self) -> WizardRun | None:
        """The wizard run on show (open, finished or cancelled), or None."""
        return self.run_list.run

    @property
    def run_index(self) -> int | None:
        """The index in :attr:`runs` of the run on show, or None."""
        return self.run_list.current

    @property
    def wizard(self) -> Wizard | None:
        """The wizard on show (a plain getter)."""
        return self.run_list.wizard

    def note_mounted_tool(self) -> None:
        """Tell the wizard on show which physical tool is mounted now (the commands that may
        change it call this; so does the app on the session's ``tool`` change)."""
        run = self.run
        if run is not None:
            run.wizard.note_mounted_tool(self.controller.mounted_tool.key,
                                         {key: t.label for key, t in self.tools.items()})

    @property
    def is_open(self) -> bool:
        """A wizard is on show and not cancelled (the wizard panel is visible)."""
        w = self.wizard
        return w is not None and w.status != "cancelled"

    @property
    def result_saved(self) -> bool:
        """The result on show was saved to the tool library (closing it leaves nothing to resume)."""
        i = self.run_list.current
        return i is not None and self.run_list.is_saved(i)

    def resumable(self) -> list[tuple[int, str]]:
        """Cancelled runs still to be done, newest first: (index in ``runs``, label for the
        Resume list) naming the calibration, where it was left and when it started (the
        server's local time): "3: XYZ 4-point, at step 2 of 4 (1 recorded), started 14:02". A
        finished run whose result was saved is done and not listed; a finished one not saved is
        "result not saved" (it is not half-way: only its Save is missing)."""
        return self.run_list.resumable()

    # ------------------------------------------------------------ library
    def library_tools(self) -> dict[int, Tool]:
        """The shared tool library, read now: slot -> tool."""
        return self.library.tools()

    # ------------------------------------------------------------ starting wizards
    def _leave_open_wizard(self) -> None:
        """Before another run is put on show: the open one is cancelled (kept in ``runs``,
        resumable, nothing lost) and the last save message no longer applies."""
        current = self.wizard
        if current is not None and current.status != "cancelled":
            self._cancel(current)
        self.last_save = None

    def _cancel(self, wizard: Wizard) -> None:
        finished = wizard.finished_result is not None
        wizard.cancel()
        i = self.run_list.index_of(wizard)
        if i is not None:
            self.log.add(RunCancelled(i, finished))

    def _open(self, wizard: Wizard, true_tool: ToolModel | None) -> Wizard:
        self._leave_open_wizard()
        T_true = None if true_tool is None else np.array(true_tool.T_flange_tool_true, dtype=float)
        key = None if true_tool is None else true_tool.key
        index = self.run_list.add(WizardRun(wizard, key, T_true))
        self.log.add(RunStarted(index, wizard.kind, wizard.title,
                                key if key is not None else _StartContext(self).mounted_tool.key, T_true))
        self.note_mounted_tool()
        return wizard

    def start(self, kind: str, **options: Any) -> Wizard:
        """Open a wizard of the registered ``kind`` with its start options (the class's
        ``options``, and ``variant``); the open wizard is cancelled, kept. The class says which
        physical tool's truth grades it and which library tool data it makes active.

        Raises:
            WizardError: unknown kind or option, a value out of its choices, an empty slot.
            RuleRefusal: the owner's exercise holds its tool (``exercise_tool``) and the method
                would calibrate another one (the XYZ reference method's New tool).
        """
        cls = wizard_class(kind)
        if self.hide_truth and not cls.in_exercises:
            _ = self.translator.gettext
            raise WizardError(_(EXERCISE_REFUSAL).format(
                what=_("The {method} wizard").format(method=_(cls.title))))
        started = cls.start(_StartContext(self), cls.parse_options(options, tr=self.translator))
        held = getattr(self.state, "exercise_tool", None)     # the session's exercise tool, when it has one
        if held is not None:
            check_calibrated_tool(held.key, held.label, getattr(started.true_tool, "key", None), cls.title)
        self._open(started.wizard, started.true_tool)
        if started.active_data is not None:
            self.state.set_active_data(started.active_data[0], int(started.active_data[1]))
        return started.wizard

    def start_from_touches(self, touches: Sequence[Any], *, estimator: str = "lstsq") -> Xyz4Wizard:
        """Open an XYZ 4-point wizard whose first steps are ``touches`` already recorded (the
        pendant's free "Record point" list, in order): ``max(4, N)`` touch steps, the N given
        recorded, the wizard on the first step left (on the last one, Finish, when N >= 4).
        Each touch's ``distance_mm`` (if known) is kept as its distance-at-record.

        Args:
            touches: ``tcp_pendant.session.Touch`` (``T_world_flange``, metres; ``distance_mm``)
                or 4x4 flange poses in WORLD, metres.
            estimator: the 4-point estimator ("lstsq", "sphere", "pairwise").

        Raises:
            WizardError: no touches, more than the wizard's 20, a pose that is not rigid; then
                nothing is opened (the wizard on show stays as it was).
        """
        touches = list(touches)
        n_max = Xyz4Wizard.MAX_POINTS
        _ = self.translator.gettext
        if not touches:
            raise WizardStateError(_("There are no recorded points: press Record point on the Jog tab first."))
        if len(touches) > n_max:
            raise WizardStateError(_("{n} points are recorded; the XYZ 4-point wizard takes at most "
                                     "{max}: delete some in the touch list first.").format(n=len(touches), max=n_max))
        poses = [np.asarray(getattr(t, "T_world_flange", t), dtype=float) for t in touches]
        Xyz4Wizard(n_points=max(Xyz4Wizard.MIN_POINTS, len(poses))).prefill(poses)   # checked before opening
        w = self.start("xyz4", n_points=max(Xyz4Wizard.MIN_POINTS, len(poses)), estimator=estimator)
        w.prefill(poses)
        self.log.prefilled(touches, hide_truth=self.hide_truth,
                           hide_distance=bool(getattr(self.state, "hide_distance", False)))
        return cast(Xyz4Wizard, w)

    # ------------------------------------------------------------ navigation
    def require_wizard(self) -> Wizard:
        """The wizard on show.

        Raises:
            WizardStateError: none is open (says how to start one).
        """
        w = self.wizard
        if w is None:
            raise WizardStateError(self.translator.gettext("No calibration is open: choose a method and press Start."))
        return w

    def cancel(self) -> None:
        """Leave the wizard; its poses are kept and it can be resumed."""
        w = self.require_wizard()
        if w.status != "cancelled":
            self._cancel(w)

    def resume(self, index: int | None = None) -> Wizard:
        """Resume a cancelled run: ``index`` (0-based in ``runs``; any cancelled run, also a
        saved one) or, by default, the newest of :meth:`resumable`."""
        i = self.run_list.to_resume(index)
        self._leave_open_wizard()
        self.run_list.current = i
        w = self.runs[i].wizard
        self.note_mounted_tool()
        w.resume()
        self.log.add(RunResumed(i))
        return w

    def required_tool(self) -> ToolModel | None:
        """The physical tool the current step needs and that is not mounted (else None)."""
        w = self.wizard
        if w is None or w.status != "in_progress":
            return None
        key = w.step.mount_tool_key
        if key is None or key == self.controller.mounted_tool.key:
            return None
        return self.tools.get(key)

    def mount_required_tool(self) -> ToolModel:
        """The tool change of the current step: mount the tool it needs (the app swaps the model)."""
        tool = self.required_tool()
        if tool is None:
            raise WizardStateError(self.translator.gettext("This step needs no tool change."))
        self.state.mount_step_tool(tool)
        mounted = self.controller.mounted_tool          # a scenario may mount a bent version
        run = self.run
        i = self.run_index
        if run is not None and i is not None and run.true_tool_key == mounted.key:
            self.runs[i] = replace(   # grade against what is on the flange now
                run, T_flange_tool_true_m=np.array(mounted.T_flange_tool_true, dtype=float))
        self.note_mounted_tool()
        return tool

    def record(self) -> None:
        """Record the current flange pose for the current step."""
        w = self.require_wizard()
        self.note_mounted_tool()
        step = w.step_index
        had_pose = step in w.recorded_poses
        w.record(self.controller.T_world_flange())
        self.note_recorded(step, auto=False, had_pose=had_pose)

    def touches_short(self) -> str | None:
        """Why the exercise (the owner's ``rules``, when it has them) refuses Finish of the
        wizard on show: too few touches (``finish_checks.touches_short``); None: not refused."""
        return touches_short(getattr(self.state, "rules", None), self.wizard)

    def wrong_tool_touch(self) -> str | None:
        """Why the run on show cannot be filed as it is: a touch recorded with another physical
        tool than its step measures (``finish_checks.wrong_tool_touch``); None: none was."""
        return wrong_tool_touch(self.run, self.tools, tr=self.translator)

    def next(self) -> WizardResult | None:
        """Next step; on the last step compute the result (returned).

        Raises:
            RuleRefusal: Finish with fewer touches than the exercise asks for
                (:meth:`touches_short`); the wizard stays on its last step.
            WizardStateError: Finish of touches made with another tool than their step
                measures (:meth:`wrong_tool_touch`); the wizard stays on its last step.
        """
        w = self.require_wizard()
        short = self.touches_short() if w.on_last_step else None
        if short is not None:
            raise RuleRefusal(short)
        wrong = self.wrong_tool_touch() if w.on_last_step else None
        if wrong is not None:
            raise WizardStateError(wrong)
        job = self.controller_job() if w.on_last_step else None
        if job is not None:
            return self.run_controller_job(job)
        try:
            out = w.next()
        except CalibrationFailedError as exc:
            raise self.log.failed(exc) from exc
        return self.log.finished(w, out) if isinstance(out, WizardResult) else None

    @property
    def finish_failure(self) -> str | None:
        """Why the last Finish of the run on show could not compute, and what to do (plain
        text, our words and numbers), while the run is still where it failed; else None."""
        return self.log.finish_failure

    def back(self) -> None:
        """One step back (from the result: to the last step); nothing is deleted."""
        self.require_wizard().back()
        self.log.forget_failure()

    @property
    def auto_touch_allowed(self) -> bool:
        """Auto-touch may be offered: training mode, and the exercise's rules allow it."""
        return self.auto.allowed

    def auto_touch(self, request: AutoTouchRequest) -> AutoTouchOutcome:
        """:meth:`auto_touch_steps` with each pose probe run in place."""
        return run_probes(self.auto_touch_steps(request))

    def auto_touch_refusal(self) -> str | None:
        """Why Auto-touch is refused in the state as it is (training mode off, the wizard on show
        finished or cancelled), in the words :meth:`auto_touch_steps` raises; None when only
        trying tells. Reads, changes nothing: a caller refuses the click without a signal."""
        return self.auto.refusal()

    def auto_touch_steps(self, request: AutoTouchRequest) -> Generator[PoseProbe, str | None, AutoTouchOutcome]:
        """Training mode: let the controller perform the current step (mounting the tool it
        needs), record it and go on; after the last step the result is computed (unless the
        exercise asks for more touches: :meth:`touches_short`), so a whole 4-point calibration
        takes four clicks. A generator (``autotouch.auto_touch_steps``, driven by
        ``AutoTouchDriver``): it yields the probe of each pose reached for a wizard whose job
        needs the pose checked (``calibrate.jobs.POSE_CHECKS``: the app runs it in its job pool)
        and must be sent its answer; it returns the outcome.

        Raises:
            WizardStateError: training mode is off, or no wizard is in progress.
            RuleRefusal: the trainer's exercise does not allow Auto-touch (the owner's ``rules``).
            CalibrationFailedError: the touches cannot determine the result (e.g. four touches
                from the same chosen direction); the wizard stays on its last step.
        """
        return (yield from self.auto.steps(request))

    # ------------------------------------------------------------ result
    @property
    def result(self) -> WizardResult | None:
        """The result of the wizard on show (None: none yet)."""
        return self.results.result

    def truth(self) -> TruthComparison | None:
        """Training mode: the result against the hidden true TOOL frame (None otherwise)."""
        return self.results.truth(self.training)

    def T_flange_tool_true_m(self) -> np.ndarray | None:
        """Training mode, after a result: the hidden true TOOL frame (4x4, metres) to reveal."""
        return self.results.T_flange_tool_true_m(self.training)

    def preview_tool(self) -> Tool | None:
        """The tool "Save" would store (named "preview"), or None before a result."""
        return self.results.preview_tool()

    def T_flange_tool_computed_m(self) -> np.ndarray | None:
        """The computed TOOL frame of the result (4x4, metres, FLANGE -> TOOL): the TCP and, when
        orientation is not calibrated, the orientation the saved tool will have."""
        return self.results.T_flange_tool_computed_m()

    def default_save_name(self, *, tr: Translator = ENGLISH) -> str:
        """Name offered by "Save to tool library": the calibrated tool's own name or its label
        (in ``tr``'s language)."""
        return self.results.default_save_name(tr=tr)

    def save(self, name: str, slot: int | None = None) -> tuple[int, Tool]:
        """"Save to tool library": store the calibrated tool (slot None: the slot holding that name,
        else the first free one; ``RunResult.save``) and make it the session's active tool data
        (``ToolState.apply_saved``; the library's active slot is not this method's business).
        Nothing is written if anything is wrong.

        Raises:
            WizardStateError: not finished, empty name, library full.
            tcpcal.TcpcalError: the library refused (the name is used by another slot, ...).
        """
        rights = getattr(self.state, "library_rights", UNRESTRICTED)   # the session's, when it has them
        slot_tool = self.results.save(name, slot, rights)
        self.state.apply_saved(*slot_tool)
        self.last_save = slot_tool
        return slot_tool

    # ------------------------------------------------------------ controller jobs (any wizard)
    def controller_job(self) -> ControllerJob | None:
        """What the wizard on show waits for the controller to do before it can finish (None:
        nothing): the job its class names (``Wizard.controller_job``, built by
        ``calibrate.jobs.JOBS``: a TCP check's six rotations, a beam wizard's scan). Taken on
        the loop; the app runs ``job.run()`` in a worker and hands the outcome back with
        :meth:`give_controller_job`.

        Raises:
            WizardStateError: the job cannot be taken now (the message says what to do).
        """
        w = self.wizard
        name = None if w is None else type(w).controller_job
        if w is None or name is None:
            return None
        return JOBS[name](self, w)

    def give_controller_job(self, job: ControllerJob, outcome: Any) -> WizardResult | None:
        """Hand a job's outcome to its wizard and finish it (None when the wizard was left
        meanwhile: it keeps the outcome)."""
        try:
            return self.log.finished(job.wizard, job.hand_in(outcome))
        except CalibrationFailedError as exc:
            raise self.log.failed(exc) from exc

    def run_controller_job(self, job: ControllerJob | None = None) -> WizardResult | None:
        """Run the waiting controller job (``job``, default :meth:`controller_job`) here,
        synchronously (scripts and tests; the app runs it in a worker), and finish the wizard.

        Raises:
            WizardStateError: no job is waiting, or the controller could not do it (in words).
        """
        job = self.controller_job() if job is None else job
        if job is None:
            raise WizardStateError(self.translator.gettext("Nothing is waiting for the controller: record the step first."))
        try:
            outcome = job.run()
        except ControllerError as exc:
            raise WizardStateError(str(exc)) from exc
        return self.give_controller_job(job, outcome)

    def manual_comparison(self, index: int | None = None) -> ManualComparison | None:
        """The trainee's last finished manual calibration of the same physical tool as run
        ``index`` (default: the one on show) in this session, for the beam wizard's lesson: its
        method, number, wall time from start to result, and in training mode (no exercise) its
        errors against its own true tool. Manual: a method with steps done by hand (no step the
        controller runs) that calibrates a TCP. None when there is none.
        """
        return manual_comparison(self.runs, self.run_index if index is None else int(index),
                                 show_truth=self.training and not self.hide_truth,
                                 auto_touches=self.touches.auto_touches)

    # ------------------------------------------------------------ session record
    def export_record(self, touches: Any = ()) -> dict[str, Any]:
        """The session record (JSON-ready dict, ``tcp_pendant.wizards.session_record`` format):
        every wizard of the session with its poses, result and errors against truth. With the
        truth hidden (an exercise) it carries no touch's true distance either
        (:meth:`distances_shown`)."""
        return session_from_controller(self.controller, self.runs, robot=self.robot, touches=touches,
                                       honest=self.honest_records, record_ids=self.record_ids,
                                       with_distances=not self.hide_truth)

    def distances_shown(self) -> tuple[dict[int, float], set[int]]:
        """The run on show's distance-at-record of its touch steps (mm, by 0-based step) and
        the steps recorded with "Hide distance" on: the result's lesson of judging by eye.
        Empty with the truth hidden (an exercise): the true distances d_i of touches whose
        flange poses (R_i, p_i) the trainee knows give the true TCP t by trilateration,
        ``|R_i t + p_i - r| = d_i``, so neither the table nor the export may carry them."""
        return self.results.distances_shown(self.hide_truth)

    def load_record(self, source: Any) -> tuple[ReplayCheck, ...]:
        """Load a session record (its bytes, JSON text or a dict; text is never taken for a path),
        recompute every wizard with tcpcal and add them to this session's runs (the newest
        finished one is put on show). :func:`load_and_replay` then :meth:`add_loaded`.

        Raises:
            SessionRecordError: unreadable record or a limit exceeded (nothing of this session
                is changed).
        """
        return self.add_loaded(load_and_replay(source))

    def restore(self, runs: Sequence[WizardRun]) -> list[int]:
        """Give back runs this session's trainee had in progress when the server stopped (kept
        in the gradebook, ``classroom.restore``): appended to :attr:`runs` with their truth,
        joints and distances; the newest is put on show where it was, the others wait in the
        Resume list. Makes no events: they are in the gradebook already. Returns their indices.
        """
        if not runs:
            return []
        self._leave_open_wizard()
        indices = self.run_list.put_back(runs)
        self.note_mounted_tool()
        return indices

    def add_loaded(self, loaded: LoadedRecord) -> tuple[ReplayCheck, ...]:
        """Add a record read and replayed by :func:`load_and_replay` (the app does that in a
        worker thread) to this session's runs; the newest finished wizard is put on show."""
        checks = loaded.checks
        if checks:
            self._leave_open_wizard()
            self.run_list.add_loaded(loaded)
        return checks


class _StartContext:
    """What a wizard class reads when the workflow starts it (``describe.StartContext``)."""

    def __init__(self, workflow: CalibrationWorkflow) -> None:
        self._workflow = workflow

    @property
    def tools(self) -> Mapping[str, ToolModel]:
        return self._workflow.tools

    @property
    def mounted_tool(self) -> ToolModel:
        """The tool a new run starts with: the one on the flange, or the owner's exercise tool
        (``exercise_tool``), which goes back on the flange as the open run is left."""
        held = getattr(self._workflow.state, "exercise_tool", None)
        return self._workflow.controller.mounted_tool if held is None else cast(ToolModel, held)

    def library_tool(self, slot: int) -> Tool:
        tool = self._workflow.library.get(int(slot))
        if tool is None:
            raise WizardError(self._workflow.translator.gettext(
                "Slot {slot} of the tool library is empty; pick a calibrated tool.").format(slot=slot))
        return tool
