"""Store a trainee's wizard events in the gradebook as they happen (no viser).

A :class:`TraineeRecorder` belongs to one named per-browser session. The class room subscribes
:meth:`TraineeRecorder.on_change` to the session's change signal, whose ``events``
(``tcp_pendant.events``) say what happened, with the facts taken when it happened; each maps
onto one gradebook write, in order:

- :class:`~tcp_pendant.events.RunStarted` -> ``start_calibration`` (method, physical tool, its
  true TOOL frame);
- :class:`~tcp_pendant.events.TouchRecorded` -> ``record_touch`` (flange pose, joint angles and
  distance tool tip - reference tip at Record, Auto-touch or hand, and the id of the touch it
  overwrote);
- :class:`~tcp_pendant.events.Crash` -> ``record_crash`` (of the calibration open then);
- :class:`~tcp_pendant.events.RunFinished` -> ``finish_calibration`` (figures, TCP, A B C, error
  against the truth, grade; a new result of the same run replaces it);
- :class:`~tcp_pendant.events.RunCancelled` -> ``cancel_calibration`` (a finished run stays
  finished), :class:`~tcp_pendant.events.RunResumed` -> ``resume_calibration``;
- :class:`~tcp_pendant.events.ToolSaved` -> ``run_states.mark_saved`` (a restart no longer
  gives that result back; a new result of the run clears the mark).

Runs loaded from a session record file are somebody's earlier work, not this session's: the
workflow makes no events for them, so they are not stored.

What a restart gives back: after the events of a signal, each calibration they touched (and the
one on show, when its step or status changed) is kept as its wizard is now
(``Gradebook.run_states.save``, a session record entry without truth), so a server started again
with the same gradebook rebuilds it for the trainee (``classroom.restore``, :meth:`adopt`).

Acknowledgement: the change signal is emitted inside ``target.atomic()``, so the GUI messages of
the same signal are pushed after every subscriber returned; each gradebook write has committed
when it returns (``Gradebook``), so a touch is in the file before the screen shows it.
"""

from __future__ import annotations

import logging
import math
import threading
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, cast

import numpy as np

from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.events import (
    Crash, RunCancelled, RunFinished, RunResumed, RunStarted, SessionEvent, ToolSaved, TouchRecorded,
)
from tcp_pendant.wizards.session_record import run_entry
from tcp_pendant.wizards.truth import compare_with_truth

if TYPE_CHECKING:
    from tcp_pendant.calibrate import CalibrationWorkflow
    from tcp_pendant.session import SessionChange
    from tcp_pendant.wizards import Wizard, WizardResult

__all__ = ["TraineeRecorder", "TraineeStatus", "step_words"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class TraineeStatus:
    """What the trainer's live table shows of one trainee (raw text: escape before markdown).

    Attributes:
        name: the trainee's name.
        connected: the browser is connected.
        method: title of the wizard on show, or "" (none).
        step: "Step k of n", "result", "cancelled" or "".
        touches: touches stored in this session (overwritten ones included).
        crashes: crashes in this session.
        last_result: the last result's TCP, mm ("12.0, 0.1, 180.3") or "".
        grade: the last grade ("good" | "fair" | "poor") or "".
        exercise: the exercise of the session ("" none, "mystery").
    """

    name: str
    connected: bool = True
    method: str = ""
    step: str = ""
    touches: int = 0
    crashes: int = 0
    last_result: str = ""
    grade: str = ""
    exercise: str = ""


@dataclass
class _RunState:
    calibration_id: int
    touch_ids: dict[int, int] = field(default_factory=dict)     # step -> gradebook touch id
    status: str = "in_progress"
    kept: dict[str, object] | None = None                          # the wizard's entry as last kept


class TraineeRecorder:
    """Writes one session's wizard events to the gradebook (see the module docstring).

    Args:
        gradebook: the class gradebook.
        session_id: the gradebook session (``Gradebook.records.start_session``).
        name: the trainee's name (validated).
        workflow: the session's ``CalibrationWorkflow``: the run on show, for the trainer's
            table, and where the gradebook ids of the runs are noted (the exported record names
            them); None: only crashes are stored.
        exercise_id: the exercise the calibrations belong to (None: free practice).
    """

    def __init__(self, gradebook: Gradebook, session_id: int, name: str, workflow: CalibrationWorkflow | None, *,
                 exercise_id: str | None = None) -> None:
        self.gradebook = gradebook
        self.session_id = session_id
        self.workflow = workflow
        self.exercise_id = exercise_id
        self._runs: dict[int, _RunState] = {}
        self._lock = threading.Lock()
        self._status = TraineeStatus(name=name, exercise=exercise_id or "")
        self.errors = 0
        """Writes that failed (logged; the trainer's table would show a stale row)."""

    @property
    def status(self) -> TraineeStatus:
        """The trainee's row of the trainer's live table."""
        return self._status

    def disconnected(self) -> None:
        """The browser left: the gradebook session ends, the row says "not connected"."""
        with self._lock:
            self.gradebook.records.end_session(self.session_id)
            self._status = replace(self._status, connected=False)

    # ------------------------------------------------------------ the change signal
    def on_change(self, change: SessionChange) -> None:
        """Subscriber of the session's change signal: its events to the gradebook, in order
        (see the module docstring); the trainer's row after a wizard change."""
        with self._lock:
            events = tuple(getattr(change, "events", ()))
            for event in events:
                self._store(event)
            if getattr(change, "wizard", False) or events:
                self._update_status()
                touched = {i for i in (getattr(e, "run_index", None) for e in events) if i is not None}
                current = None if self.workflow is None else self.workflow.run_index
                if current is not None:
                    touched.add(current)
                for i in sorted(touched):
                    self._keep_state(i)

    def adopt(self, run_index: int, calibration_id: int, touch_ids: dict[int, int]) -> None:
        """Go on writing run ``run_index`` (restored after a restart) into its calibration;
        ``touch_ids``: step -> the touch that counts there (the next overwrite links it)."""
        with self._lock:
            runs = [] if self.workflow is None else self.workflow.runs
            done = 0 <= run_index < len(runs) and runs[run_index].wizard.finished_result is not None
            self._runs[int(run_index)] = _RunState(int(calibration_id), dict(touch_ids),
                                                   status="finished" if done else "in_progress")
            if self.workflow is not None:
                self.workflow.record_ids[int(run_index)] = int(calibration_id)
            self._status = replace(self._status, touches=self._status.touches + len(touch_ids))
            self._update_status()

    def _keep_state(self, run_index: int) -> None:
        """Keep run ``run_index``'s wizard in the gradebook when its place changed (a new pose,
        another step or status, an edited option): what a restart gives back."""
        st = self._runs.get(run_index)
        if st is None or self.workflow is None or not 0 <= run_index < len(self.workflow.runs):
            return
        try:
            wizard = self.workflow.runs[run_index].wizard
            entry = run_entry(self.workflow.runs[run_index], honest=True)
            if entry == st.kept:
                return
            self.gradebook.run_states.save(st.calibration_id, entry, method_title=str(wizard.title)[:200] or None,
                                           step=step_words(wizard)[:200] or None)
            st.kept = entry
        except Exception:            # a state that cannot be kept must not stop the lesson
            self.errors += 1
            log.exception("keeping the wizard of calibration %s failed", st.calibration_id)

    def _store(self, event: SessionEvent) -> None:
        if isinstance(event, RunStarted):
            truth: object = ({"T_flange_tool_true_m": None} if event.T_flange_tool_true_m is None
                          else np.asarray(event.T_flange_tool_true_m, dtype=float))
            cal = self.gradebook.records.start_calibration(self.session_id, event.kind, event.tool_key or "",
                                                           truth, exercise_id=self.exercise_id)
            self._runs[event.run_index] = _RunState(cal)
            if self.workflow is not None:
                self.workflow.record_ids[event.run_index] = cal    # the export names it: the trainer grades by it
            return
        if isinstance(event, Crash):
            pen = event.penetration_mm if math.isfinite(event.penetration_mm) else None
            st = None if event.run_index is None else self._runs.get(event.run_index)
            if st is None:
                self.gradebook.records.record_crash(session_id=self.session_id, penetration_mm=pen,
                                                    note="reference tip hit")
            else:
                self.gradebook.records.record_crash(st.calibration_id, penetration_mm=pen, note="reference tip hit")
            self._status = replace(self._status, crashes=self._status.crashes + 1)
            return
        run_index = getattr(event, "run_index", None)
        st = None if run_index is None else self._runs.get(run_index)
        if st is None:                      # a run of a loaded record, or started before the name
            return
        if isinstance(event, ToolSaved):
            self.gradebook.run_states.mark_saved(st.calibration_id)
        elif isinstance(event, TouchRecorded):
            dist = event.distance_mm if math.isfinite(event.distance_mm) else None
            touch_id = self.gradebook.records.record_touch(
                st.calibration_id, event.step, event.T_world_flange_m, np.asarray(event.joints_deg, dtype=float),
                dist, event.auto, overwritten_touch_id=st.touch_ids.get(event.step))
            st.touch_ids[event.step] = touch_id
            self._status = replace(self._status, touches=self._status.touches + 1)
        elif isinstance(event, RunFinished):
            self._finish(st, event)
        elif isinstance(event, RunCancelled):
            if st.status == "in_progress" and not event.finished:
                self.gradebook.records.cancel_calibration(st.calibration_id)
                st.status = "cancelled"
        elif isinstance(event, RunResumed):
            if st.status == "cancelled":
                self.gradebook.records.resume_calibration(st.calibration_id)
                st.status = "in_progress"

    def _finish(self, st: _RunState, event: RunFinished) -> None:
        result = cast("WizardResult", event.result)       # events, a utility, names no wizard type
        pos = ori = grade = None
        if event.T_flange_tool_true_m is not None:
            cmp = compare_with_truth(result, event.T_flange_tool_true_m)
            pos, ori, grade = cmp.position_error_mm, cmp.orientation_error_deg, cmp.grade
        self.gradebook.records.finish_calibration(
            st.calibration_id, result.figures, position_error_mm=pos, orientation_error_deg=ori, grade=grade,
            tcp_mm=tuple(result.tcp_mm), abc_deg=None if result.abc_deg is None else tuple(result.abc_deg))
        self.gradebook.run_states.mark_saved(st.calibration_id, False)     # a new result: not saved yet
        st.status = "finished"
        tcp = ", ".join(f"{v:.1f}" for v in result.tcp_mm)
        self._status = replace(self._status, last_result=tcp, grade=grade or "")

    def _update_status(self) -> None:
        w = None if self.workflow is None else self.workflow.wizard
        method, step = ("", "") if w is None else (w.title, step_words(w))
        self._status = replace(self._status, method=method, step=step)


def step_words(wizard: Wizard) -> str:
    """Where a wizard is, as the trainer's table says it: "Step k of n", "result" or "cancelled"."""
    if wizard.status == "complete":
        return "result"
    if wizard.status == "cancelled":
        return "cancelled"
    return str(wizard.step.heading)
