"""Store a trainee's wizard events in the gradebook as they happen (no viser).

A :class:`TraineeRecorder` belongs to one named per-browser session. The server subscribes
:meth:`TraineeRecorder.on_change` to the session's change signal; on every signal it compares
the session's calibration workflow with what it stored last and writes the difference:

- a run the workflow opened -> ``start_calibration`` (method, physical tool, its true TOOL frame);
- a pose recorded at a step (new, or replacing the step's earlier pose) -> ``record_touch``
  (flange pose, joint angles, distance tool tip - reference tip, Auto-touch or hand, and the id
  of the touch it overwrote);
- the robot driven into the reference tip (``touch_geometry().crashed`` turning true) ->
  ``record_crash``;
- a result -> ``finish_calibration`` (figures, TCP, A B C, error against the truth, grade; a
  new result of the same run replaces it), a cancel -> ``cancel_calibration`` (a finished run
  stays finished), a resume -> ``resume_calibration``.

Runs that arrive already cancelled (loaded from a session record file) are somebody's earlier
work, not this session's: they are not stored.

Acknowledgement: the change signal is emitted inside ``target.atomic()``, so the GUI messages of
the same signal are pushed after every subscriber returned; each gradebook write has committed
when it returns (``Gradebook``), so a touch is in the file before the screen shows it.

Auto-touch or hand: the workflow counts its auto-touches (``CalibrationWorkflow.auto_touches``);
poses that appear in a signal during which that count grew were recorded by Auto-touch.
"""

from __future__ import annotations

import logging
import math
import threading
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tcp_pendant.classroom.gradebook import Gradebook

__all__ = ["TraineeRecorder", "TraineeStatus"]

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
    calibration_id: int | None            # None: not stored (a loaded run)
    poses: dict[int, Any] = field(default_factory=dict)         # step -> RecordedPose object seen
    touch_ids: dict[int, int] = field(default_factory=dict)     # step -> gradebook touch id
    status: str = "in_progress"
    result: Any = None


class TraineeRecorder:
    """Writes one session's wizard events to the gradebook (see the module docstring).

    Args:
        gradebook: the class gradebook.
        session_id: the gradebook session (``Gradebook.start_session``).
        name: the trainee's name (validated).
        controller: the session's virtual controller (joints, distance, crash state).
        workflow: the session's ``CalibrationWorkflow`` (or None: only crashes are stored).
        exercise_id: the exercise the calibrations belong to (None: free practice).
    """

    def __init__(self, gradebook: Gradebook, session_id: int, name: str, controller: Any,
                 workflow: Any | None, *, exercise_id: str | None = None) -> None:
        self.gradebook = gradebook
        self.session_id = session_id
        self.controller = controller
        self.workflow = workflow
        self.exercise_id = exercise_id
        self._runs: dict[int, _RunState] = {}
        self._auto_seen = int(getattr(workflow, "auto_touches", 0))
        if workflow is not None:
            workflow.honest_records = True      # the trainee's export carries no answer key
        self._crashed = False
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
            self.gradebook.end_session(self.session_id)
            self._status = TraineeStatus(**{**self._status.__dict__, "connected": False})

    # ------------------------------------------------------------ the change signal
    def on_change(self, change: Any) -> None:
        """Subscriber of the session's change signal (see the module docstring)."""
        with self._lock:
            state = getattr(change, "state", None)
            if state is not None:
                self._check_crash(bool(state.touch.crashed), float(state.touch.penetration_mm))
            # a jog step (pose only) costs the crash check alone: every wizard event comes with `wizard`
            if self.workflow is not None and (getattr(change, "wizard", False) or getattr(change, "touches", False)):
                self._sync_runs()
                self._update_status()

    def _current_calibration(self) -> int | None:
        wf = self.workflow
        run = None if wf is None else wf.run
        if wf is None or run is None:
            return None
        for i, r in enumerate(wf.runs):
            if r is run:
                st = self._runs.get(i)
                return None if st is None else st.calibration_id
        return None

    def _check_crash(self, crashed: bool, penetration_mm: float) -> None:
        if crashed and not self._crashed:
            cal = self._current_calibration()
            pen = penetration_mm if math.isfinite(penetration_mm) else None
            if cal is None:
                self.gradebook.record_crash(session_id=self.session_id, penetration_mm=pen,
                                            note="reference tip hit")
            else:
                self.gradebook.record_crash(cal, penetration_mm=pen, note="reference tip hit")
            self._status = TraineeStatus(**{**self._status.__dict__, "crashes": self._status.crashes + 1})
        self._crashed = crashed

    def _sync_runs(self) -> None:
        wf = self.workflow
        if wf is None:
            return
        auto_now = int(getattr(wf, "auto_touches", 0))
        auto = auto_now != self._auto_seen
        self._auto_seen = auto_now
        for i, run in enumerate(wf.runs):
            st = self._runs.get(i)
            w = run.wizard
            if st is None:
                if w.status == "cancelled":          # loaded from a record file: not this session's work
                    st = self._runs[i] = _RunState(None, status="cancelled")
                    continue
                truth: Any = ({"T_flange_tool_true_m": None} if run.T_flange_tool_true_m is None
                              else np.asarray(run.T_flange_tool_true_m, dtype=float))
                cal = self.gradebook.start_calibration(
                    self.session_id, w.kind, run.true_tool_key or self.controller.mounted_tool.key, truth,
                    exercise_id=self.exercise_id)
                st = self._runs[i] = _RunState(cal)
                if isinstance(getattr(wf, "record_ids", None), dict):
                    wf.record_ids[i] = cal             # the export names it: the trainer grades by it
            if st.calibration_id is None:
                continue
            self._sync_poses(st, w, auto)
            self._sync_status(st, run)

    def _sync_poses(self, st: _RunState, w: Any, auto: bool) -> None:
        assert st.calibration_id is not None  # runs without a calibration are skipped
        for step, pose in sorted(w.recorded_poses.items()):
            if st.poses.get(step) is pose:
                continue
            q_deg = np.degrees(np.asarray(self.controller.q_rad, dtype=float))
            dist = float(self.controller.touch_geometry().distance_mm)
            touch_id = self.gradebook.record_touch(
                st.calibration_id, int(step), pose.T_world_flange_m, q_deg,
                dist if math.isfinite(dist) else None, auto, overwritten_touch_id=st.touch_ids.get(step))
            st.poses[step] = pose
            st.touch_ids[step] = touch_id
            self._status = TraineeStatus(**{**self._status.__dict__, "touches": self._status.touches + 1})

    def _sync_status(self, st: _RunState, run: Any) -> None:
        assert st.calibration_id is not None  # runs without a calibration are skipped
        w = run.wizard
        result = w.finished_result
        if result is not None and result is not st.result:
            self._finish(st, run, result)
        status = w.status
        if status == "cancelled" and st.status == "in_progress" and result is None:
            self.gradebook.cancel_calibration(st.calibration_id)
            st.status = "cancelled"
        elif status == "in_progress" and st.status == "cancelled":
            self.gradebook.resume_calibration(st.calibration_id)
            st.status = "in_progress"

    def _finish(self, st: _RunState, run: Any, result: Any) -> None:
        assert st.calibration_id is not None  # runs without a calibration are skipped
        from tcp_pendant.wizards.truth import compare_with_truth

        pos = ori = grade = None
        if run.T_flange_tool_true_m is not None:
            cmp = compare_with_truth(result, run.T_flange_tool_true_m)
            pos, ori, grade = cmp.position_error_mm, cmp.orientation_error_deg, cmp.grade
        self.gradebook.finish_calibration(
            st.calibration_id, result.figures, position_error_mm=pos, orientation_error_deg=ori, grade=grade,
            tcp_mm=tuple(result.tcp_mm), abc_deg=None if result.abc_deg is None else tuple(result.abc_deg))
        st.result = result
        st.status = "finished"
        tcp = ", ".join(f"{v:.1f}" for v in result.tcp_mm)
        self._status = TraineeStatus(**{**self._status.__dict__, "last_result": tcp,
                                        "grade": grade or ""})

    def _update_status(self) -> None:
        w = None if self.workflow is None else self.workflow.wizard
        if w is None:
            method, step = "", ""
        else:
            method = w.title
            step = ("result" if w.status == "complete" else "cancelled" if w.status == "cancelled"
                    else w.step.heading)
        self._status = TraineeStatus(**{**self._status.__dict__, "method": method, "step": step})
