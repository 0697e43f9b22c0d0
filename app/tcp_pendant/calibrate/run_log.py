"""What the calibration workflow notes as its runs change (no viser).

A :class:`RunLog` belongs to one ``CalibrationWorkflow``. It keeps the events of the commands
since the session last took them (``tcp_pendant.events``: the session puts them into its
change signal, the classroom's recorder stores them), the facts of each touch taken when it is
recorded (joints, physical tool and true distance, with the robot standing at it; kept in the
run and in a :class:`~tcp_pendant.events.TouchRecorded`), and why the last Finish of a run
failed, in the trainee's words (``calibrate.finish_checks``), until the run changes.

Units: joints in degrees in the run and the event (radians in ``TouchMemory``); distances mm.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from typing import Any

from tcp_pendant.calibrate.finish_checks import failure_in_trainee_words
from tcp_pendant.calibrate.run_list import RunList
from tcp_pendant.calibrate.touch_memory import TouchMemory
from tcp_pendant.controller import VirtualController
from tcp_pendant.events import RunFinished, SessionEvent, TouchRecorded
from tcp_pendant.wizards import CalibrationFailedError, Wizard, WizardResult

__all__ = ["RunLog"]


class RunLog:
    """Events, touch facts and the failed Finish of one workflow's runs (module docstring)."""

    def __init__(self, controller: VirtualController, run_list: RunList, touches: TouchMemory) -> None:
        self._controller = controller
        self._run_list = run_list
        self._touches = touches
        self._events: list[SessionEvent] = []
        # (run, tcpcal's failure, R_world_flange then): why its Finish failed, dropped on a change
        self._failure: tuple[int, CalibrationFailedError, np.ndarray] | None = None

    def add(self, event: SessionEvent) -> None:
        """Note ``event`` (in order)."""
        self._events.append(event)

    def take(self) -> tuple[SessionEvent, ...]:
        """The events since the last call, in order."""
        events, self._events = tuple(self._events), []
        return events

    def finished(self, wizard: Wizard, result: WizardResult | None) -> WizardResult | None:
        """Note a result just computed (:class:`~tcp_pendant.events.RunFinished`); returns it."""
        i = self._run_list.index_of(wizard)
        if result is not None and i is not None:
            self._events.append(RunFinished(i, result, self._run_list.runs[i].T_flange_tool_true_m))
        return result

    def recorded(self, step: int, *, auto: bool, had_pose: bool, hide_truth: bool, hide_distance: bool) -> None:
        """Facts of the pose just recorded at ``step`` of the run on show, taken now (the robot
        stands at it): its joints, tool and distance, kept in the run and in a
        :class:`~tcp_pendant.events.TouchRecorded`. With the truth hidden (an exercise) the run
        keeps no distance (``CalibrationWorkflow.distances_shown``): the gradebook's touch rows
        keep the truth (the event), and a run recorded in an exercise shows none after it
        either; ``hide_distance``: the trainee recorded it with "Hide distance" on."""
        run, i = self._run_list.run, self._run_list.current
        if run is None or i is None:
            return
        pose = run.wizard.recorded_poses.get(step)
        if pose is None:
            return
        self._failure = None                       # a new touch: the failed Finish no longer applies
        c = self._controller
        joints = tuple(c.joint_angles_deg().values())
        run.joints_deg[step] = joints
        run.touch_tools[step] = c.mounted_tool.key
        self._touches.recorded(i, step, pose, c.q_rad, auto=auto, runs=self._run_list.runs)
        distance_mm = float(c.touch_geometry().distance_mm)
        if 0 <= step < run.wizard.n_steps and run.wizard.steps[step].role == "touch":
            run.distance_hidden.discard(step)
            if hide_truth:
                run.distance_mm.pop(step, None)
            else:
                run.distance_mm[step] = distance_mm
                if hide_distance:
                    run.distance_hidden.add(step)
        self._events.append(TouchRecorded(i, step, pose.T_world_flange_m, joints, distance_mm, auto, had_pose))

    def prefilled(self, touches: Sequence[Any], *, hide_truth: bool, hide_distance: bool) -> None:
        """The run on show was just opened with ``touches`` recorded (``Session.Touch`` or 4x4
        poses; ``CalibrationWorkflow.start_from_touches``): their distances, joints and tools
        in the run, and a :class:`~tcp_pendant.events.TouchRecorded` for each."""
        run, index = self._run_list.run, self._run_list.current
        if run is None or index is None:
            return
        recorded = run.wizard.recorded_poses
        for i, t in enumerate(touches):
            d = float(getattr(t, "distance_mm", float("nan")))
            joints = tuple(float(v) for v in getattr(t, "joints_deg", ()))
            if math.isfinite(d) and d >= 0.0 and not hide_truth:
                run.distance_mm[i] = d
                if hide_distance:
                    run.distance_hidden.add(i)
            if joints:
                run.joints_deg[i] = joints
            tool_key = getattr(t, "tool_key", None)
            if isinstance(tool_key, str):
                run.touch_tools[i] = tool_key
            if i in recorded:
                self._events.append(TouchRecorded(index, i, recorded[i].T_world_flange_m, joints, d,
                                                  auto=False, overwrite=False))

    def failed(self, exc: CalibrationFailedError) -> CalibrationFailedError:
        """tcpcal's failure of the run on show in the trainee's words
        (``finish_checks.failure_in_trainee_words``), kept as :attr:`finish_failure`."""
        R_world_flange = self._controller.T_world_flange()[:3, :3].copy()
        out = failure_in_trainee_words(exc, self._run_list.wizard, R_world_flange, tr=self._run_list.translator)
        if self._run_list.current is not None:
            self._failure = (self._run_list.current, exc, R_world_flange)
        return out

    def forget_failure(self) -> None:
        """The run on show moved (Back): its failed Finish no longer applies."""
        self._failure = None

    @property
    def finish_failure(self) -> str | None:
        """Why the last Finish of the run on show could not compute, and what to do (plain
        text in the runs' language now, the robot's orientation as it was then), while the run is
        still where it failed; else None."""
        failure, w = self._failure, self._run_list.wizard
        if failure is None or failure[0] != self._run_list.current or w is None or w.status != "in_progress":
            return None
        return str(failure_in_trainee_words(failure[1], w, failure[2], tr=self._run_list.translator))
