"""A session's calibration commands (``Session.wizard_commands``): each drives the session's
:class:`~tcp_pendant.calibrate.CalibrationWorkflow` in one batch of the session that ends in one
``wizard`` change signal (``pose`` too when the robot may have moved), also when it raised.

Views never change the workflow themselves: they call these commands, and re-render from the
signal. Work whose size a browser controls (a wizard's controller job at Finish, Auto-touch's
pose probes) runs in the job pool (``SessionLoop.run_job``), off viser's event loop, between
two commands.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import ContextManager, Protocol, TypeVar

import numpy as np

from tcpcal.tool import Tool
from tcp_pendant.calibrate import ControllerJob
from tcp_pendant.calibrate.autotouch import AutoTouchOutcome, PoseProbe
from tcp_pendant.calibrate.pendant_rules import ExerciseRules, RuleRefusal
from tcp_pendant.calibrate.tcp_estimate import TcpEstimate, tcp_estimate
from tcp_pendant.calibrate.workflow import AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.controller import ToolModel
from tcp_pendant.session_loop import SessionLoop
from tcp_pendant.session_tools import SessionTools
from tcp_pendant.wizards import Wizard, WizardResult, WizardStateError, wizard_class, wizard_classes
from tcp_pendant.wizards.session_record import LoadedRecord, ReplayCheck, WizardRun

__all__ = ["WizardCommands", "WizardHost"]

T = TypeVar("T")


class WizardHost(Protocol):
    """What :class:`WizardCommands` needs of its session."""

    lock: threading.RLock
    closed: bool
    workflow: CalibrationWorkflow
    rules: ExerciseRules
    tools: SessionTools
    loop: SessionLoop

    @property
    def touches(self) -> Sequence[object]: ...

    def changed(self, *, wizard: bool = False, pose: bool = False) -> None: ...

    def batch(self) -> ContextManager[None]: ...


class WizardCommands:
    """The calibration wizards' commands of one session (module docstring)."""

    def __init__(self, host: WizardHost) -> None:
        self._host = host
        self._truth_hidden_always = False   # --hide-truth: no exercise's end shows it

    @contextmanager
    def _command(self, *, moves: bool = False) -> Iterator[None]:
        """One batch ending in one ``wizard`` signal (``pose`` too when ``moves``), also when
        the command raised; a run that ended or was left gives the exercise's tool back to the
        flange (``SessionTools.remount_exercise_tool``)."""
        host = self._host
        with host.lock, host.batch():
            try:
                yield
            finally:
                host.tools.remount_exercise_tool()
                host.changed(wizard=True, pose=moves)

    def _check_method(self, kind: str, options: Mapping[str, object] | None = None) -> None:
        """The exercise's methods (``rules.allowed_methods``) and, for a method without Add
        point whose touch count is chosen at start (``options["n_points"]``), its minimum
        number of touches.

        Raises:
            RuleRefusal: the method is not allowed, or too few touches are asked for.
            WizardError: unknown kind, or options the method refuses (``Wizard.parse_options``).
        """
        rules = self._host.rules
        cls = wizard_class(kind)
        tr = self._host.workflow.translator             # the methods named as the trainee reads them
        rules.check_method(kind, {c.kind: tr.gettext(c.title) for c in wizard_classes()})
        counted = any(o.name == "n_points" for o in cls.options)
        if counted and not cls.supports_add_point and options is not None and rules.min_touches:
            n_points = int(cls.parse_options(options, tr=self._host.workflow.translator)["n_points"])
            if rules.touches_refusal(n_points, can_add_point=False) is not None:
                _ = self._host.workflow.translator.gettext
                raise RuleRefusal(_("This exercise asks for at least {n} touches: set "
                                    "Touches to {n} or more for the {method} method.").format(
                                        n=rules.min_touches, method=_(cls.title)))

    def finish_refusal(self) -> str | None:
        """Why Finish of the wizard on show is refused by the exercise (too few touches for a
        method whose touch count the trainee chooses, ``CalibrationWorkflow.touches_short``),
        None when it is not; the step panel shows it, :meth:`next_step` and Auto-touch's last
        touch do not finish then."""
        with self._host.lock:
            return self._host.workflow.touches_short()

    def start(self, kind: str, **options: object) -> Wizard:
        """Open a wizard of the registered ``kind`` with its start options (the open one is
        cancelled and kept; ``CalibrationWorkflow.start``).

        Raises:
            RuleRefusal: the exercise does not allow the method, or (a method without Add point)
                its ``n_points`` is below the exercise's minimum; nothing is opened.
        """
        with self._command(moves=True):
            self._check_method(kind, options)
            return self._host.workflow.start(kind, **options)

    def start_from_touches(self, *, estimator: str = "lstsq") -> Wizard:
        """XYZ 4-point from the free touches recorded with Record point, in order.

        Raises:
            RuleRefusal: the exercise does not allow the XYZ 4-point method.
        """
        with self._command(moves=True):
            self._check_method("xyz4")
            return self._host.workflow.start_from_touches(list(self._host.touches), estimator=estimator)

    def record_step(self) -> None:
        """Record the current flange pose for the open wizard's step."""
        with self._command():
            self._host.workflow.record()

    def auto_touch(self, request: AutoTouchRequest) -> AutoTouchOutcome:
        """Training mode: the controller performs the current step (``CalibrationWorkflow.auto_touch``)."""
        with self._command(moves=True):
            return self._host.workflow.auto_touch(request)

    async def auto_touch_in_pool(self, request: AutoTouchRequest, *,
                                 shown: Callable[[AutoTouchOutcome], object] | None = None) -> AutoTouchOutcome:
        """:meth:`auto_touch` with the probes of the poses it reaches (a TCP check's rotations
        from there, ``calibrate.jobs.POSE_CHECKS``) run in the job pool (``SessionLoop.run_job``),
        off viser's event loop: the moves and the record are commands on the loop, each ending
        in its own signal, the probes awaited in between (no probe: one command, one signal, as
        :meth:`auto_touch`). ``shown(outcome)`` runs inside the last command (the view's words
        join its signal). A robot moved meanwhile records nothing
        (``autotouch.MOVED_DURING_PROBE``).

        Refused before anything moves while this session's job runs or its share of the job pool
        is used up (``SessionLoop.admit_job``), and without a signal when the state alone refuses
        it (training off, the wizard finished: ``CalibrationWorkflow.auto_touch_refusal``). Its
        moves are not charged to the share: a wizard has a few steps, and a trainee clicks
        Auto-touch once per step, a whole calibration in a few seconds.

        Raises:
            JobRefused: this session's previous job still runs, its share is used up, or the
                queue is full.
            WizardStateError: as :meth:`auto_touch`; the calibration on show changed meanwhile.
        """
        host = self._host
        host.loop.admit_job()
        with host.lock:                 # refused by the state alone: nothing moved, nothing to show
            why = host.workflow.auto_touch_refusal()
        if why is not None:
            raise WizardStateError(why)
        steps = host.workflow.auto_touch_steps(request)

        def advance(answer: str | None, first: bool) -> tuple[PoseProbe | None, AutoTouchOutcome | None]:
            with self._command(moves=True):
                try:
                    return (next(steps) if first else steps.send(answer)), None
                except StopIteration as stop:
                    if shown is not None:
                        shown(stop.value)
                    return None, stop.value

        probe, out = advance(None, True)
        try:
            while probe is not None:
                answer = await host.loop.run_job(probe, what=host.workflow.translator.gettext(
                    "Auto-touch's check of the pose it reached"))
                if host.closed:
                    raise WizardStateError(host.workflow.translator.gettext("The session was closed."))
                probe, out = advance(answer, False)
        finally:
            steps.close()
        assert out is not None          # the generator returned its outcome
        return out

    def back(self) -> None:
        """One step back (from the result: to the last step); nothing is deleted."""
        with self._command():
            self._host.workflow.back()

    def next_step(self) -> WizardResult | None:
        """Next step, or on the last step Finish: the result (a wizard with a controller job runs
        it here, synchronously; the views run it in the job pool instead: :meth:`next_step_in_pool`).

        Raises:
            RuleRefusal: Finish with fewer touches than the exercise asks for
                (:meth:`finish_refusal`); the wizard stays on its last step.
        """
        with self._command(moves=True):
            return self._host.workflow.next()

    def take_controller_job(self) -> ControllerJob | None:
        """The controller job the wizard on show waits for before it can finish (None: none);
        taken on the loop, run by the caller in a worker, handed back with
        :meth:`hand_in_controller_job`."""
        with self._host.lock:
            wiz = self._host.workflow.wizard
            if wiz is None or not wiz.on_last_step:
                return None
            return self._host.workflow.controller_job()

    async def next_step_in_pool(self) -> WizardResult | None:
        """Next, or Finish with the controller job the wizard on show waits for (a TCP check's
        rotations, a beam scan) taken on the loop, run in the job pool (``SessionLoop.run_job``,
        off viser's event loop) and handed in on the loop; no job: :meth:`next_step`.

        Raises:
            JobRefused: this session's previous job still runs, or the queue is full.
            WizardStateError: as :meth:`next_step` (the job cannot be taken: the words say why).
        """
        job = self.take_controller_job()
        if job is None:
            return self.next_step()
        _ = self._host.workflow.translator.gettext
        outcome = await self._host.loop.run_job(job.run, what=_("the {method} wizard's controller job").format(
            method=_(job.wizard.title)))
        if self._host.closed:
            return None
        return self.hand_in_controller_job(job, outcome)

    def hand_in_controller_job(self, job: ControllerJob, outcome: object) -> WizardResult | None:
        """The outcome of a controller job to its wizard (its result, if it finished)."""
        with self._command(moves=True):
            return self._host.workflow.give_controller_job(job, outcome)

    def cancel(self) -> bool:
        """Leave the open wizard (kept, resumable). True when it had no result yet (the caller
        may say that nothing recorded is lost)."""
        with self._command():
            unfinished = self._host.workflow.result is None
            self._host.workflow.cancel()
            return unfinished

    def resume(self, index: int | None = None) -> Wizard:
        """Resume a calibration left half-way (``index`` in the runs; default the newest)."""
        with self._command(moves=True):
            return self._host.workflow.resume(index)

    def mount_required_tool(self) -> ToolModel:
        """The tool change the current step asks for."""
        with self._command(moves=True):
            return self._host.workflow.mount_required_tool()

    def add_point(self) -> None:
        """One more touch step (the wizards that declare ``supports_add_point``)."""
        with self._command():
            self._host.workflow.require_wizard().add_point()

    def estimate_offer(self) -> TcpEstimate | None:
        """The wizard's TCP estimate from the touches so far (``calibrate.tcp_estimate``) when
        there is one and it is not the active tool data already: what "Tilt about the wizard's
        estimate" would activate (None: nothing to offer)."""
        with self._host.lock:
            wf = self._host.workflow
            est = tcp_estimate(wf.wizard) if wf.is_open else None
            active = wf.controller.active_tool
            if est is None or (active is not None and active.name == est.tool().name
                               and np.allclose(active.tcp_mm, est.tcp_mm, atol=1e-6)
                               and not np.any(active.abc_deg)):
                return None
            return est

    def pivot_on_estimate(self) -> TcpEstimate:
        """Make the wizard's TCP estimate from the touches so far the active tool data, so the
        rotation keys turn about it (a tilt then swings the tip only by the estimate's error);
        the readout names it as the estimate.

        Raises:
            WizardStateError: no XYZ 4-point open, or fewer than two touches in different
                orientations (says what to do).
        """
        with self._command(moves=True):
            wf = self._host.workflow
            est = tcp_estimate(wf.wizard) if wf.is_open else None
            if est is None:
                raise WizardStateError(wf.translator.gettext(
                    "The wizard estimates the TCP from two touches in different "
                    "orientations of an XYZ 4-point: record them first."))
            self._host.tools.set_active_data(est.tool())
            return est

    def set_variant(self, variant: int | str) -> None:
        """Switch the open wizard's variant (one of its class's ``variants`` values)."""
        with self._command():
            self._host.workflow.require_wizard().set_variant(variant)

    def set_training(self, on: bool) -> None:
        """Training mode on or off (truth after a result, Auto-touch)."""
        with self._command():
            self._host.workflow.training = bool(on)

    def save_result(self, name: str, slot: int | None = None) -> tuple[int, Tool]:
        """"Save to tool library": the result on show as tool ``name`` (slot None: the slot with
        that name, else the first free one); it becomes the active tool data."""
        with self._command(moves=True):
            return self._host.workflow.save(name, slot)

    def edit_result(self, fn: Callable[[Wizard], T]) -> T:
        """A change of the result on show that its wizard offers (the 4-point's estimator,
        outlier drop, restore): ``fn(wizard)`` inside one ``wizard`` signal."""
        with self._command():
            return fn(self._host.workflow.require_wizard())

    def set_hide_truth(self, hide: bool, *, always: bool = False) -> None:
        """A classroom exercise (True): no result shows the true TOOL frame or the error
        against it, and the methods that measure the tool by themselves are refused. ``always``
        (the server's ``--hide-truth``, a projector): from now on the truth stays hidden, whatever
        an exercise's end says."""
        with self._command():
            self._truth_hidden_always = self._truth_hidden_always or always
            self._host.workflow.hide_truth = bool(hide) or self._truth_hidden_always

    def keep_honest_records(self) -> None:
        """A classroom session: the session record this session exports carries no truth."""
        with self._host.lock:
            self._host.workflow.honest_records = True

    def add_physical_tool(self, tool: ToolModel) -> None:
        """Make ``tool`` one of the physical tools the wizards know (a classroom's mystery tool:
        its label in a step's tool-change words)."""
        with self._command():
            self._host.workflow.tools[tool.key] = tool

    def restore_runs(self, runs: Sequence[WizardRun]) -> list[int]:
        """The calibrations this trainee had in progress before a restart, back on screen
        (``CalibrationWorkflow.restore``); one ``wizard`` signal."""
        with self._command(moves=True):
            return self._host.workflow.restore(runs)

    def load_record(self, loaded: LoadedRecord) -> tuple[ReplayCheck, ...]:
        """A session record read and replayed off the loop (``session_record.load_and_replay``)
        added to the runs; returns its replay checks."""
        with self._command():
            return self._host.workflow.add_loaded(loaded)
