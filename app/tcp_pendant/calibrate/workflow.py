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

Units: the controller speaks metres (``T_world_flange``); the wizards hand millimetres to
``tcpcal``; everything shown is in mm and degrees.

Nothing already saved is lost: the library is only written by :meth:`save` (one atomic
``ToolLibrary.save``), a cancelled wizard keeps its poses and can be resumed, and starting
another wizard only cancels (never deletes) the one that was open.
"""

from __future__ import annotations

import re
from collections.abc import Generator, Mapping, Sequence
from datetime import datetime
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar, Literal, Protocol, cast

import numpy as np

from tcp_pendant.controller import T_flange_tool_m, ToolModel, VirtualController, builtin_tools
from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.calibrate.autotouch import AutoTouchOutcome, PoseProbe, auto_touch_steps, run_probes
from tcp_pendant.calibrate.jobs import EXERCISE_REFUSAL, JOBS, POSE_CHECKS, ControllerJob
from tcp_pendant.calibrate.diversity import failure_in_words
from tcp_pendant.calibrate.library_save import save_result
from tcp_pendant.calibrate.pendant_rules import UNRESTRICTED, RuleRefusal, check_calibrated_tool
from tcp_pendant.events import (
    RunCancelled,
    RunFinished,
    RunResumed,
    RunStarted,
    SessionEvent,
    ToolSaved,
    TouchRecorded,
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
    step_distances,
)
from tcp_pendant.wizards.beam import wall_time_s
from tcp_pendant.wizards.truth import TruthComparison, compare_with_truth
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

__all__ = [
    "AUTO_SIGMA_MAX_MM",
    "AutoTouchRequest",
    "CalibrationWorkflow",
    "ControllerToolState",
    "ToolState",
]

_ANGLE_APART = re.compile(r"\(([0-9.]+) deg apart\)")
"""The angle in tcpcal's "touches i and j (0-based) have the same orientation (x deg apart)"."""
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
        self.runs: list[WizardRun] = []
        self._current: int | None = None
        self.last_save: tuple[int, Tool] | None = None
        self._saved_results: dict[int, WizardResult] = {}    # run index -> the result saved from it
        self._auto_directions: dict[int, tuple[float, float, float]] = {}   # run -> last auto-touch
        self.honest_records = False
        """A classroom session: the exported record carries no truth (``session_record`` honest)."""
        self.record_ids: dict[int, int] = {}
        """Run index -> gradebook calibration id (the classroom recorder fills it; exported)."""
        self._record_q: dict[int, tuple[RecordedPose, np.ndarray]] = {}   # id(pose) -> (pose, joints rad)
        self._events: list[SessionEvent] = []
        self._failure: tuple[int, str] | None = None   # (run, why its Finish failed); dropped on a change
        self._auto_steps: dict[int, set[int]] = {}     # run -> steps whose pose Auto-touch recorded

    # ------------------------------------------------------------ events
    def take_events(self) -> tuple[SessionEvent, ...]:
        """The events of the commands since the last call, in order (``tcp_pendant.events``);
        the session puts them into its change signal."""
        events, self._events = tuple(self._events), []
        return events

    def _index_of(self, wizard: Wizard) -> int | None:
        """The run index of ``wizard`` (None: not one of this workflow's runs)."""
        return next((i for i, r in enumerate(self.runs) if r.wizard is wizard), None)

    def _finished(self, wizard: Wizard, result: WizardResult | None) -> WizardResult | None:
        """Note a result just computed (:class:`RunFinished`); returns it."""
        i = self._index_of(wizard)
        if result is not None and i is not None:
            self._events.append(RunFinished(i, result, self.runs[i].T_flange_tool_true_m))
        return result

    def _recorded(self, step: int, *, auto: bool, had_pose: bool) -> None:
        """Facts of the pose just recorded at ``step`` of the run on show, taken now (the robot
        stands at it): its joints and distance, kept in the run and in a :class:`TouchRecorded`."""
        run, i = self.run, self._current
        if run is None or i is None:
            return
        pose = run.wizard.recorded_poses.get(step)
        if pose is None:
            return
        self._failure = None                       # a new touch: the failed Finish no longer applies
        c = self.controller
        joints = tuple(c.joint_angles_deg().values())
        run.joints_deg[step] = joints
        run.touch_tools[step] = c.mounted_tool.key
        auto_steps = self._auto_steps.setdefault(i, set())
        if auto:
            auto_steps.add(step)
        else:
            auto_steps.discard(step)
        self._record_q[id(pose)] = (pose, c.q_rad.copy())
        self._forget_replaced_poses()
        self._note_distance(step)
        self._events.append(TouchRecorded(i, step, pose.T_world_flange_m, joints,
                                          float(c.touch_geometry().distance_mm), auto, had_pose))

    def _forget_replaced_poses(self) -> None:
        """Keep the joints of the poses some run still holds only: a step recorded again, or a
        run's touches dropped, leaves its old pose here, and a session that records for hours
        would otherwise keep every pose it ever recorded."""
        held = {id(p) for r in self.runs for p in r.wizard.recorded_poses.values()}
        for key in [k for k in self._record_q if k not in held]:
            del self._record_q[key]

    def joints_at_record(self, pose: RecordedPose) -> np.ndarray | None:
        """The joints (rad) where ``pose`` was recorded in this session (None: not known, e.g.
        a pose loaded from a record)."""
        known = self._record_q.get(id(pose))
        return None if known is None or known[0] is not pose else known[1].copy()

    # ------------------------------------------------------------ state
    @property
    def run(self) -> WizardRun | None:
        """The wizard run on show (open, finished or cancelled), or None."""
        return None if self._current is None else self.runs[self._current]

    @property
    def run_index(self) -> int | None:
        """The index in :attr:`runs` of the run on show, or None."""
        return self._current

    @property
    def wizard(self) -> Wizard | None:
        """The wizard on show (a plain getter)."""
        run = self.run
        return None if run is None else run.wizard

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

    def _is_saved(self, index: int) -> bool:
        """Run ``index`` is finished and its result, as it is now, was saved to the library (a
        finished check, which saves nothing, is done as it is)."""
        w = self.runs[index].wizard
        if not w.saves_to_library and w.finished_result is not None:
            return True
        saved = self._saved_results.get(index)
        return saved is not None and saved is self.runs[index].wizard.finished_result

    @property
    def result_saved(self) -> bool:
        """The result on show was saved to the tool library (closing it leaves nothing to resume)."""
        return self._current is not None and self._is_saved(self._current)

    def resumable(self) -> list[tuple[int, str]]:
        """Cancelled runs still to be done, newest first: (index in ``runs``, label for the
        Resume list) naming the calibration, where it was left and when it started (the
        server's local time): "3: XYZ 4-point, at step 2 of 4 (1 recorded), started 14:02". A
        finished run whose result was saved is done and not listed; a finished one not saved is
        "result not saved" (it is not half-way: only its Save is missing)."""
        out = []
        for i in range(len(self.runs) - 1, -1, -1):
            w = self.runs[i].wizard
            if w.status != "cancelled" or self._is_saved(i):
                continue
            started = _clock(w.started_at)
            if w.finished_result is not None:
                out.append((i, f"{i + 1}: {w.title}, result not saved, started {started}"))
            else:
                done = sum(1 for s in w.steps if s.recorded)
                out.append((i, f"{i + 1}: {w.title}, at step {w.step_index + 1} of {w.n_steps} "
                               f"({done} recorded), started {started}"))
        return out

    # ------------------------------------------------------------ library
    def library_tools(self) -> dict[int, Tool]:
        """The shared tool library, read now: slot -> tool."""
        return self.library.tools()

    def _library_tool(self, slot: int) -> Tool:
        tool = self.library.get(int(slot))
        if tool is None:
            raise WizardError(f"Slot {slot} of the tool library is empty; pick a calibrated tool.")
        return tool

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
        i = self._index_of(wizard)
        if i is not None:
            self._events.append(RunCancelled(i, finished))

    def _open(self, wizard: Wizard, true_tool: ToolModel | None) -> Wizard:
        self._leave_open_wizard()
        T_true = None if true_tool is None else np.array(true_tool.T_flange_tool_true, dtype=float)
        key = None if true_tool is None else true_tool.key
        self.runs.append(WizardRun(wizard, key, T_true))
        self._current = len(self.runs) - 1
        self._events.append(RunStarted(self._current, wizard.kind, wizard.title,
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
            raise WizardError(EXERCISE_REFUSAL.format(what=f"The {cls.title} wizard"))
        started = cls.start(_StartContext(self), cls.parse_options(options))
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
        if not touches:
            raise WizardStateError("There are no recorded points: press Record point on the Jog tab first.")
        if len(touches) > n_max:
            raise WizardStateError(f"{len(touches)} points are recorded; the XYZ 4-point wizard takes at most "
                                   f"{n_max}: delete some in the touch list first.")
        poses = [np.asarray(getattr(t, "T_world_flange", t), dtype=float) for t in touches]
        Xyz4Wizard(n_points=max(Xyz4Wizard.MIN_POINTS, len(poses))).prefill(poses)   # checked before opening
        w = self.start("xyz4", n_points=max(Xyz4Wizard.MIN_POINTS, len(poses)), estimator=estimator)
        w.prefill(poses)
        run, index = self.run, self._current
        hidden = bool(getattr(self.state, "hide_distance", False))
        recorded = w.recorded_poses
        for i, t in enumerate(touches):
            d = float(getattr(t, "distance_mm", float("nan")))
            joints = tuple(float(v) for v in getattr(t, "joints_deg", ()))
            if run is not None and np.isfinite(d) and d >= 0.0 and not self.hide_truth:
                run.distance_mm[i] = d
                if hidden:
                    run.distance_hidden.add(i)
            if run is not None and joints:
                run.joints_deg[i] = joints
            tool_key = getattr(t, "tool_key", None)
            if run is not None and isinstance(tool_key, str):
                run.touch_tools[i] = tool_key
            if index is not None and i in recorded:
                self._events.append(TouchRecorded(index, i, recorded[i].T_world_flange_m, joints, d,
                                                  auto=False, overwrite=False))
        return cast(Xyz4Wizard, w)

    # ------------------------------------------------------------ navigation
    def _note_distance(self, step: int) -> None:
        """Keep the true tool tip to reference tip distance (mm) of the touch step just recorded
        at the robot's pose (``WizardRun.distance_mm``; the session record exports it), and
        whether the distance was hidden then (``ToolState.hide_distance``, when the owner has it).
        With the truth hidden (an exercise) the run keeps none (:meth:`distances_shown`): the
        gradebook's touch rows keep the truth (``TouchRecorded``), and a run recorded in an
        exercise shows none after it either."""
        run = self.run
        if run is None or not 0 <= step < run.wizard.n_steps or run.wizard.steps[step].role != "touch":
            return
        if self.hide_truth:
            run.distance_mm.pop(step, None)
            run.distance_hidden.discard(step)
            return
        run.distance_mm[step] = float(self.controller.touch_geometry().distance_mm)
        if getattr(self.state, "hide_distance", False):
            run.distance_hidden.add(step)
        else:
            run.distance_hidden.discard(step)

    def require_wizard(self) -> Wizard:
        """The wizard on show.

        Raises:
            WizardStateError: none is open (says how to start one).
        """
        return self._require()

    def _require(self) -> Wizard:
        w = self.wizard
        if w is None:
            raise WizardStateError("No calibration is open: choose a method and press Start.")
        return w

    def cancel(self) -> None:
        """Leave the wizard; its poses are kept and it can be resumed."""
        w = self._require()
        if w.status != "cancelled":
            self._cancel(w)

    def resume(self, index: int | None = None) -> Wizard:
        """Resume a cancelled run: ``index`` (0-based in ``runs``; any cancelled run, also a
        saved one) or, by default, the newest of :meth:`resumable`."""
        if index is None:
            options = self.resumable()
            if not options:
                raise WizardStateError("There is no calibration left half-way to resume.")
            i = options[0][0]
        else:
            i = int(index)
            if not (0 <= i < len(self.runs) and self.runs[i].wizard.status == "cancelled"):
                raise WizardStateError(f"Calibration {i + 1} is not waiting to be resumed.")
        self._leave_open_wizard()
        self._current = i
        w = self.runs[i].wizard
        self.note_mounted_tool()
        w.resume()
        self._events.append(RunResumed(i))
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
            raise WizardStateError("This step needs no tool change.")
        self.state.mount_step_tool(tool)
        mounted = self.controller.mounted_tool          # a scenario may mount a bent version
        run = self.run
        if run is not None and self._current is not None and run.true_tool_key == mounted.key:
            self.runs[self._current] = replace(   # grade against what is on the flange now
                run, T_flange_tool_true_m=np.array(mounted.T_flange_tool_true, dtype=float))
        self.note_mounted_tool()
        return tool

    def record(self) -> None:
        """Record the current flange pose for the current step."""
        w = self._require()
        self.note_mounted_tool()
        step = w.step_index
        had_pose = step in w.recorded_poses
        w.record(self.controller.T_world_flange())
        self._recorded(step, auto=False, had_pose=had_pose)

    def touches_short(self) -> str | None:
        """Why the exercise refuses Finish of the wizard on show (the owner's ``rules``, when it
        has them): on the last step of a method whose touch count the trainee chooses (an
        ``n_points`` start option or Add point), fewer touch steps than ``rules.min_touches``.
        None when Finish is not refused; a method with a fixed number of poses never is."""
        rules = getattr(self.state, "rules", None)
        w = self.wizard
        if (rules is None or not getattr(rules, "min_touches", 0) or w is None or not self.is_open
                or w.is_complete or not w.on_last_step):
            return None
        cls = type(w)
        if not (cls.supports_add_point or any(o.name == "n_points" for o in cls.options)):
            return None
        refusal: str | None = rules.touches_refusal(len(w.solver_touch_steps()), can_add_point=cls.supports_add_point)
        return refusal

    def wrong_tool_touch(self) -> str | None:
        """Why the run on show cannot be filed as it is: a touch recorded with another physical
        tool than the one its step measures (the step's tool change, else the tool the run
        calibrates), in words with what to do; None when every touch whose tool is known was
        made with the right one. A calibration is graded and filed under the tool it measured,
        so touches of two tools cannot make one."""
        run = self.run
        if run is None or run.true_tool_key is None:
            return None
        w = run.wizard
        for step in sorted(w.recorded_poses):
            used = run.touch_tools.get(step)
            spec = w.steps[step] if 0 <= step < w.n_steps else None
            need = run.true_tool_key if spec is None or spec.mount_tool_key is None else spec.mount_tool_key
            if used is None or used == need:
                continue
            label = self._tool_label
            return (f"Step {step + 1} was recorded with the {label(used)}, but it measures the {label(need)}: "
                    f"a calibration is filed under the tool it measured. Mount the {label(need)} and record "
                    f"step {step + 1} again (or start a new calibration for the {label(used)}).")
        return None

    def _tool_label(self, key: str) -> str:
        tool = self.tools.get(key)
        return (key if tool is None else tool.label).lower()

    def next(self) -> WizardResult | None:
        """Next step; on the last step compute the result (returned).

        Raises:
            RuleRefusal: Finish with fewer touches than the exercise asks for
                (:meth:`touches_short`); the wizard stays on its last step.
            WizardStateError: Finish of touches made with another tool than their step
                measures (:meth:`wrong_tool_touch`); the wizard stays on its last step.
        """
        w = self._require()
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
            raise self._in_words(exc) from exc
        return self._finished(w, out) if isinstance(out, WizardResult) else None

    def _in_words(self, exc: CalibrationFailedError) -> CalibrationFailedError:
        """tcpcal's failure in the trainee's words, with what to do: the touches it is about
        as step numbers (two with the same orientation: go back to the later one), its FLANGE
        axis in words (``diversity.failure_in_words``). Kept as :attr:`finish_failure` for the
        step panels until the wizard changes."""
        w, cause = self.wizard, exc.cause
        axis = getattr(cause, "unobservable_axis", None)
        pair = tuple(getattr(cause, "indices", ()))
        steps = () if w is None else w.solver_touch_steps()
        if len(pair) == 2 and all(0 <= k < len(steps) for k in pair):
            a, b = (steps[k] + 1 for k in pair)
            angle = _ANGLE_APART.search(str(exc))
            apart = f" ({angle.group(1)}° apart)" if angle else ""
            todo = (f"record step {b} again" if w is not None and w.step_index == b - 1
                    else f"go Back to step {b} and record it again")
            text = (f"Touches {a} and {b} have the same orientation{apart}: the method needs clearly "
                    f"different orientations. Tilt the tool 30-60° about another axis and {todo}.")
            out = CalibrationFailedError(text, cause)
        elif axis is not None:
            R_world_flange = self.controller.T_world_flange()[:3, :3]
            out = CalibrationFailedError(failure_in_words(str(exc), axis, R_world_flange) +
                                         " Go Back to a step and record it tilted about that axis.", cause)
        else:
            out = exc
        if self._current is not None:
            self._failure = (self._current, str(out))
        return out

    @property
    def finish_failure(self) -> str | None:
        """Why the last Finish of the run on show could not compute, and what to do (plain
        text, our words and numbers), while the run is still where it failed; else None."""
        failure, w = self._failure, self.wizard
        if failure is None or failure[0] != self._current or w is None or w.status != "in_progress":
            return None
        return failure[1]

    def back(self) -> None:
        """One step back (from the result: to the last step); nothing is deleted."""
        self._require().back()
        self._failure = None

    @property
    def auto_touch_allowed(self) -> bool:
        """Auto-touch may be offered: training mode, and the exercise's rules allow it."""
        rules = getattr(self.state, "rules", None)
        return self.training and (rules is None or bool(rules.auto_touch_allowed))

    def auto_touch(self, request: AutoTouchRequest) -> AutoTouchOutcome:
        """:meth:`auto_touch_steps` with each pose probe run in place."""
        return run_probes(self.auto_touch_steps(request))

    def auto_touch_refusal(self) -> str | None:
        """Why Auto-touch is refused in the state as it is (training mode off, the wizard on show
        finished or cancelled), in the words :meth:`auto_touch_steps` raises; None when only
        trying tells. Reads, changes nothing: a caller refuses the click without a signal."""
        if not self.training:
            return "Auto-touch is a training-mode tool; switch training mode on."
        rules = getattr(self.state, "rules", None)
        if rules is not None:
            try:
                rules.check_auto_touch()
            except ValueError:          # the exercise's refusal comes first: trying says it
                return None
        w = self.wizard
        if w is not None and w.status != "in_progress":
            return f"Cannot auto-touch: {w.blocked_reason}"
        return None

    def auto_touch_steps(self, request: AutoTouchRequest) -> Generator[PoseProbe, str | None, AutoTouchOutcome]:
        """Training mode: let the controller perform the current step (mounting the tool it
        needs), record it and go on; after the last step the result is computed (unless the
        exercise asks for more touches: :meth:`touches_short`), so a whole 4-point calibration
        takes four clicks. A generator (``autotouch.auto_touch_steps``): it yields the probe of
        each pose reached for a wizard whose job needs the pose checked
        (``calibrate.jobs.POSE_CHECKS``: the app runs it in its job pool) and must be sent its
        answer; it returns the outcome.

        Raises:
            WizardStateError: training mode is off, or no wizard is in progress.
            RuleRefusal: the trainer's exercise does not allow Auto-touch (the owner's ``rules``).
            CalibrationFailedError: the touches cannot determine the result (e.g. four touches
                from the same chosen direction); the wizard stays on its last step.
        """
        if not self.training:
            raise WizardStateError("Auto-touch is a training-mode tool; switch training mode on.")
        rules = getattr(self.state, "rules", None)     # the session's exercise rules, when it has them
        if rules is not None:
            rules.check_auto_touch()
        w = self._require()
        if w.status == "in_progress" and w.auto_role(w.step).by_controller:
            raise WizardStateError(f"The {w.title} wizard has nothing to touch: the controller runs this "
                                   "step itself; press Finish.")
        run_index = self._current
        self.note_mounted_tool()
        had_pose = set(w.recorded_poses) if w.status == "in_progress" else set()
        job = type(w).controller_job
        pose_check = POSE_CHECKS[job](self, w) if job in POSE_CHECKS else None
        steps = auto_touch_steps(w, self.controller, direction_deg=request.direction_deg,
                                 sigma_mm=request.sigma_mm, rng=self.rng, tools=self.tools,
                                 previous_direction_deg=None if run_index is None
                                 else self._auto_directions.get(run_index),
                                 mount=self.state.mount_step_tool, pose_check=pose_check)
        try:
            probe = next(steps)
            while True:
                answer = yield probe
                if self.wizard is not w or self._current != run_index:   # left while the probe ran
                    steps.close()
                    raise WizardStateError("The calibration on show changed while Auto-touch checked the pose "
                                           "it reached; nothing was recorded.")
                probe = steps.send(answer)
        except StopIteration as stop:
            out = stop.value
        self.note_mounted_tool()
        if out.ok:                            # the robot stands at the touch it recorded
            self._recorded(out.step_index, auto=True, had_pose=out.step_index in had_pose)
        if out.direction_deg is not None and run_index is not None:
            self._auto_directions[run_index] = out.direction_deg
        if type(w).controller_job is not None:    # Finish runs the controller's job (off the loop in the app)
            return out
        if out.ok and w.on_last_step and all(s.recorded for s in w.steps) and self.touches_short() is None:
            wrong = self.wrong_tool_touch()
            if wrong is not None:
                raise WizardStateError(wrong)
            try:
                self._finished(w, w.finish())
            except CalibrationFailedError as exc:
                raise self._in_words(exc) from exc
        return out

    # ------------------------------------------------------------ result
    @property
    def result(self) -> WizardResult | None:
        w = self.wizard
        return None if w is None else w.result

    def truth(self) -> TruthComparison | None:
        """Training mode: the result against the hidden true TOOL frame (None otherwise)."""
        run, res = self.run, self.result
        if not self.training or run is None or res is None or run.T_flange_tool_true_m is None:
            return None
        return compare_with_truth(res, run.T_flange_tool_true_m)

    def T_flange_tool_true_m(self) -> np.ndarray | None:
        """Training mode, after a result: the hidden true TOOL frame (4x4, metres) to reveal."""
        run = self.run
        if not self.training or run is None or self.result is None:
            return None
        return run.T_flange_tool_true_m

    def preview_tool(self) -> Tool | None:
        """The tool "Save" would store (named "preview"), or None before a result."""
        w = self.wizard
        if w is None or w.result is None or not w.saves_to_library:
            return None
        return w.to_tool("preview")

    def T_flange_tool_computed_m(self) -> np.ndarray | None:
        """The computed TOOL frame of the result (4x4, metres, FLANGE -> TOOL): the TCP and, when
        orientation is not calibrated, the orientation the saved tool will have."""
        tool = self.preview_tool()
        if tool is None:
            return None
        return T_flange_tool_m(tool)

    def default_save_name(self) -> str:
        """Name offered by "Save to tool library": the calibrated tool's own name or its label."""
        w = self.wizard
        if w is not None and w.library_tool_name is not None:
            return w.library_tool_name
        run = self.run
        key = None if run is None else run.true_tool_key
        return self.tools[key].label if key in self.tools else "Tool"

    def save(self, name: str, slot: int | None = None) -> tuple[int, Tool]:
        """"Save to tool library": store the calibrated tool (slot None: the slot holding that name,
        else the first free one) and make it the session's active tool data
        (``ToolState.apply_saved``; the library's active slot is not this method's business).
        Nothing is written if anything is wrong.

        Raises:
            WizardStateError: not finished, empty name, library full.
            tcpcal.TcpcalError: the library refused (the name is used by another slot, ...).
        """
        w = self._require()
        if not w.saves_to_library:
            raise WizardStateError(f"The {w.title} saves nothing to the library: it only checks the tool data.")
        name = str(name).strip()
        if not name:
            raise WizardStateError("Type a name for the tool before saving.")
        rights = getattr(self.state, "library_rights", UNRESTRICTED)   # the session's, when it has them
        slot_tool = save_result(w, self.library, name, slot, rights)
        self.state.apply_saved(*slot_tool)
        self.last_save = slot_tool
        if self._current is not None and w.result is not None:
            self._saved_results[self._current] = w.result
        self._events.append(ToolSaved(self._current, slot_tool[0], slot_tool[1].name))
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
            return self._finished(job.wizard, job.hand_in(outcome))
        except CalibrationFailedError as exc:
            raise self._in_words(exc) from exc

    def run_controller_job(self, job: ControllerJob | None = None) -> WizardResult | None:
        """Run the waiting controller job (``job``, default :meth:`controller_job`) here,
        synchronously (scripts and tests; the app runs it in a worker), and finish the wizard.

        Raises:
            WizardStateError: no job is waiting, or the controller could not do it (in words).
        """
        job = self.controller_job() if job is None else job
        if job is None:
            raise WizardStateError("Nothing is waiting for the controller: record the step first.")
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
        i = self._current if index is None else int(index)
        if i is None or not 0 <= i < len(self.runs):
            return None
        key = self.runs[i].true_tool_key
        if key is None:
            return None
        for j in range(len(self.runs) - 1, -1, -1):
            run = self.runs[j]
            w, res = run.wizard, run.wizard.finished_result
            if (j == i or res is None or run.true_tool_key != key or res.tcp_result is None
                    or not w.saves_to_library or type(w).controller_job is not None):
                continue
            seconds = wall_time_s(w.started_at, res.computed_at)
            pos = ang = grade = None
            if self.training and not self.hide_truth and run.T_flange_tool_true_m is not None:
                cmp = compare_with_truth(res, run.T_flange_tool_true_m)
                pos, ang, grade = cmp.position_error_mm, cmp.x_axis_error_deg, cmp.grade
            auto = len(self._auto_steps.get(j, set()) & set(w.recorded_poses))
            return ManualComparison(w.title, w.kind, j + 1, 0.0 if seconds is None else seconds, pos, ang, grade,
                                    touches=len(w.recorded_poses), auto_touches=auto)
        return None

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
        run = self.run
        if run is None or self.hide_truth:
            return {}, set()
        return dict(run.distance_mm), set(run.distance_hidden)

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
        indices = []
        for run in runs:
            if run.wizard.status != "cancelled":
                run.wizard.cancel()
            self.runs.append(run)
            indices.append(len(self.runs) - 1)
        self._current = indices[-1]
        self.runs[self._current].wizard.resume()
        self.note_mounted_tool()
        return indices

    def add_loaded(self, loaded: LoadedRecord) -> tuple[ReplayCheck, ...]:
        """Add a record read and replayed by :func:`load_and_replay` (the app does that in a
        worker thread) to this session's runs; the newest finished wizard is put on show."""
        data, checks = loaded.record, loaded.checks
        if not checks:
            return checks
        self._leave_open_wizard()
        finished: list[int] = []
        for check, entry in zip(checks, data.get("wizards", [])):
            true_tool = entry.get("true_tool") or {}
            T_true = true_tool.get("T_flange_tcp_true_m")
            self.runs.append(WizardRun(check.wizard, true_tool.get("key"),
                                       None if T_true is None else np.array(T_true, dtype=float),
                                       distance_mm=step_distances(entry)))
            if check.wizard.finished_result is not None:
                finished.append(len(self.runs) - 1)
            if check.wizard.status != "cancelled":
                check.wizard.cancel()         # every loaded wizard waits in the Resume list
        if finished:                          # ... but the newest finished one is put on show
            self._current = finished[-1]
            self.runs[self._current].wizard.resume()
        return checks


def _clock(iso_utc: str) -> str:
    """An ISO 8601 UTC time as the server's local HH:MM ("?" when unreadable)."""
    try:
        return datetime.fromisoformat(iso_utc.replace("Z", "+00:00")).astimezone().strftime("%H:%M")
    except ValueError:
        return "?"


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
        return self._workflow._library_tool(slot)
