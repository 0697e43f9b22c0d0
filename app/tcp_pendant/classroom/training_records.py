"""What each trainee did, in the gradebook as it happens: sessions, calibrations, touches and
crashes (tables ``sessions``, ``calibrations``, ``touches``, ``crashes``), and each
calibration read back (its touches, its truth, its result).

The server writes each wizard event as it happens (``classroom.recorder``); each write has
committed when it returns (:class:`~tcp_pendant.classroom.gradebook_store.GradebookStore`).
The truth (the true TOOL frame) is kept on the server only, never in a trainee's export.
PostgreSQL: a touch, crash, finish, cancel or resume locks the calibration row it checks
(``FOR UPDATE``) until its transaction ends.

Units: poses in metres, joints and angles in degrees, distances and errors in mm; times UTC ISO
8601 (``gradebook_values``).
"""

from __future__ import annotations

import json
from collections.abc import Mapping

import numpy as np

from tcp_pendant.classroom.gradebook_db import GradebookConnection, only_row
from tcp_pendant.classroom.gradebook_schema import GRADES
from tcp_pendant.classroom.gradebook_store import GradebookError, GradebookStore
from tcp_pendant.classroom.gradebook_values import (
    MAX_TEXT,
    finite,
    label,
    matrix4,
    truth_json,
    utc_now,
    vector,
    whole_id,
)
from tcp_pendant.json_shapes import JsonRecord

__all__ = ["TrainingRecords", "calibration_row"]


def calibration_row(store: GradebookStore, db: GradebookConnection, calibration_id: object, *,
                    for_update: bool = False) -> tuple[int, int, str]:
    """(id, session_id, status) of a calibration; ``for_update`` (in a write): the row stays
    locked until the transaction ends, so no other server changes its status meanwhile."""
    cid = whole_id(calibration_id, "calibration_id")
    row = db.execute("SELECT id, session_id, status FROM calibrations WHERE id = ?"
                     + (" FOR UPDATE" if for_update else ""), (cid,)).fetchone()
    if row is None:
        raise GradebookError(f"No calibration {cid} in the gradebook {store.location}; start it with "
                             "start_calibration first.")
    return int(row[0]), int(row[1]), str(row[2])


class TrainingRecords:
    """The sessions, calibrations, touches and crashes of the gradebook behind ``store`` (see
    the module docstring)."""

    def __init__(self, store: GradebookStore) -> None:
        self._store = store

    def start_session(self, trainee_id: int, mode: str) -> int:
        """A new session (one browser connection) of a trainee; ``mode`` e.g. "own" or "shared"."""
        tid = whole_id(trainee_id, "trainee_id")
        mode = label(mode, "mode")
        with self._store.write() as db:
            if db.execute("SELECT 1 FROM trainees WHERE id = ?", (tid,)).fetchone() is None:
                raise GradebookError(f"No trainee {tid} in the gradebook {self._store.location}; trainees.add first.")
            return db.insert("INSERT INTO sessions (trainee_id, mode, started_at) VALUES (?, ?, ?)",
                             (tid, mode, utc_now()))

    def end_session(self, session_id: int) -> None:
        """Mark a session ended (browser gone); its calibrations stay as they are."""
        sid = whole_id(session_id, "session_id")
        with self._store.write() as db:
            cur = db.execute("UPDATE sessions SET ended_at = ? WHERE id = ? AND ended_at IS NULL",
                             (utc_now(), sid))
            if cur.rowcount == 0 and db.execute("SELECT 1 FROM sessions WHERE id = ?", (sid,)).fetchone() is None:
                raise GradebookError(f"No session {sid} in the gradebook {self._store.location}.")

    def start_calibration(self, session_id: int, method: str, tool_key: str, truth: object,
                          exercise_id: str | None = None) -> int:
        """A calibration started in a session.

        Args:
            session_id: from :meth:`start_session`.
            method: wizard kind or method name (e.g. "xyz4", "abc-world").
            tool_key: the physical tool being calibrated (e.g. "pointer", "mystery-…").
            truth: ``T_flange_tool_true_m`` (4x4, metres) or a JSON-able dict describing the
                true TOOL frame; kept on the server only (never in a trainee's export).
            exercise_id: the exercise this belongs to, or None.
        """
        sid = whole_id(session_id, "session_id")
        method = label(method, "method")
        tool_key = label(tool_key, "tool_key")
        exercise = label(exercise_id, "exercise_id", optional=True)
        truth_text = truth_json(truth)
        with self._store.write() as db:
            if db.execute("SELECT 1 FROM sessions WHERE id = ?", (sid,)).fetchone() is None:
                raise GradebookError(f"No session {sid} in the gradebook {self._store.location}; start_session first.")
            return db.insert(
                "INSERT INTO calibrations (session_id, method, tool_key, exercise_id, truth_json, status, "
                "started_at) VALUES (?, ?, ?, ?, ?, 'in_progress', ?)",
                (sid, method, tool_key, exercise, truth_text, utc_now()))

    def record_touch(self, calibration_id: int, step_index: int, T_world_flange_m: object, joints_deg: object,
                     distance_mm: float | None, auto: bool, overwritten_touch_id: int | None = None) -> int:
        """Store one recorded touch (as it is recorded, hidden distance or not).

        Args:
            calibration_id: from :meth:`start_calibration` (not cancelled).
            step_index: 0-based wizard step.
            T_world_flange_m: (4,4) flange pose, metres.
            joints_deg: joint values, degrees.
            distance_mm: tool tip to reference tip at record, mm (stored even when the
                trainee had it hidden); None if unknown.
            auto: True for Auto-touch, False for a hand-jogged touch.
            overwritten_touch_id: the earlier touch of this calibration this one replaces.

        Returns:
            The touch id.
        """
        step = whole_id(step_index, "step_index")
        if step < 0:
            raise GradebookError(f"step_index must be >= 0, got {step}.")
        if not isinstance(auto, (bool, np.bool_)):
            raise GradebookError(f"auto must be True (Auto-touch) or False (by hand), got {auto!r:.40}.")
        T = json.dumps(matrix4(T_world_flange_m, "T_world_flange_m"))
        q = json.dumps(vector(joints_deg, "joints_deg"))
        d = finite(distance_mm, "distance_mm", optional=True)
        old = None if overwritten_touch_id is None else whole_id(overwritten_touch_id, "overwritten_touch_id")
        with self._store.write() as db:
            cid, _, status = calibration_row(self._store, db, calibration_id, for_update=True)
            if status == "cancelled":
                raise GradebookError(f"Calibration {cid} was cancelled; resume_calibration({cid}) before "
                                     "recording touches in it.")
            if old is not None:
                row = db.execute("SELECT calibration_id, overwritten_by_touch_id FROM touches WHERE id = ?",
                                 (old,)).fetchone()
                if row is None or row[0] != cid:
                    raise GradebookError(f"Touch {old} is not a touch of calibration {cid}; pass the id "
                                         "record_touch returned for the touch being replaced.")
                if row[1] is not None:
                    raise GradebookError(f"Touch {old} was already overwritten by touch {row[1]}; pass "
                                         f"{row[1]} instead.")
            new = db.insert(
                "INSERT INTO touches (calibration_id, step_index, recorded_at, T_world_flange_m_json, "
                "joints_deg_json, distance_mm, auto, overwrites_touch_id) VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
                (cid, step, utc_now(), T, q, d, int(bool(auto)), old))
            if old is not None:
                db.execute("UPDATE touches SET overwritten_by_touch_id = ? WHERE id = ?", (new, old))
            return new

    def record_crash(self, calibration_id: int | None = None, *, session_id: int | None = None,
                     penetration_mm: float | None = None, note: str = "") -> int:
        """Store a crash (the tool went through the reference tip), in a calibration or, outside
        any calibration, in a session.

        Args:
            calibration_id: the calibration running, or None.
            session_id: the session (required without ``calibration_id``; if both are given
                they must match).
            penetration_mm: how deep the tool went, mm, or None.
            note: short free text (e.g. "jog", "auto-touch").
        """
        if calibration_id is None and session_id is None:
            raise GradebookError("record_crash needs the calibration_id or the session_id it happened in.")
        depth = finite(penetration_mm, "penetration_mm", optional=True)
        if not isinstance(note, str) or len(note) > MAX_TEXT or not note.isprintable():
            raise GradebookError(f"note must be at most {MAX_TEXT} printable characters.")
        sid = None if session_id is None else whole_id(session_id, "session_id")
        with self._store.write() as db:
            cid = None
            if calibration_id is not None:
                cid, cal_session, _ = calibration_row(self._store, db, calibration_id, for_update=True)
                if sid is not None and sid != cal_session:
                    raise GradebookError(f"Calibration {cid} belongs to session {cal_session}, not {sid}.")
                sid = cal_session
            elif db.execute("SELECT 1 FROM sessions WHERE id = ?", (sid,)).fetchone() is None:
                raise GradebookError(f"No session {sid} in the gradebook {self._store.location}.")
            return db.insert("INSERT INTO crashes (session_id, calibration_id, at, penetration_mm, note) "
                             "VALUES (?, ?, ?, ?, ?)", (sid, cid, utc_now(), depth, note))

    def finish_calibration(self, calibration_id: int, figures: Mapping[str, float], *,
                           position_error_mm: float | None, orientation_error_deg: float | None,
                           grade: str | None, tcp_mm: object = None, abc_deg: object = None) -> None:
        """Store a calibration's result. Called again (the trainee went back and finished once
        more), the newest result replaces the stored one.

        Args:
            figures: quality figures by name (``WizardResult.figures``: mm, deg, counts).
            position_error_mm: position error against the truth (None: not known).
            orientation_error_deg: orientation error against the truth (None: not known).
            grade: "good" | "fair" | "poor" | None.
            tcp_mm: computed TCP (3, mm) or None; abc_deg: computed KUKA A, B, C (3, deg) or None.
        """
        if not isinstance(figures, Mapping):
            raise GradebookError(f"figures must be a mapping name -> number, got {type(figures).__name__}.")
        figs = {label(k, "figure name"): finite(v, f"figures[{k!r}]") for k, v in figures.items()}
        pos = finite(position_error_mm, "position_error_mm", optional=True)
        ori = finite(orientation_error_deg, "orientation_error_deg", optional=True)
        if grade is not None and grade not in GRADES:
            raise GradebookError(f"grade must be one of {', '.join(GRADES)} or None, got {grade!r:.40}.")
        tcp = None if tcp_mm is None else json.dumps(vector(tcp_mm, "tcp_mm", 3))
        abc = None if abc_deg is None else json.dumps(vector(abc_deg, "abc_deg", 3))
        with self._store.write() as db:
            cid, _, status = calibration_row(self._store, db, calibration_id, for_update=True)
            if status == "cancelled":
                raise GradebookError(f"Calibration {cid} was cancelled; resume_calibration({cid}) before "
                                     "finishing it.")
            db.execute("UPDATE calibrations SET status = 'finished', finished_at = ?, figures_json = ?, "
                       "tcp_mm_json = ?, abc_deg_json = ?, position_error_mm = ?, orientation_error_deg = ?, "
                       "grade = ? WHERE id = ?",
                       (utc_now(), json.dumps(figs, sort_keys=True), tcp, abc, pos, ori, grade, cid))

    def cancel_calibration(self, calibration_id: int) -> None:
        """Mark a calibration cancelled (its touches stay; a finished one stays finished)."""
        with self._store.write() as db:
            cid, _, status = calibration_row(self._store, db, calibration_id, for_update=True)
            if status == "in_progress":
                db.execute("UPDATE calibrations SET status = 'cancelled', cancelled_at = ? WHERE id = ?",
                           (utc_now(), cid))

    def resume_calibration(self, calibration_id: int) -> None:
        """Put a cancelled calibration back in progress (the wizard's Resume)."""
        with self._store.write() as db:
            cid, _, status = calibration_row(self._store, db, calibration_id, for_update=True)
            if status == "cancelled":
                db.execute("UPDATE calibrations SET status = 'in_progress', cancelled_at = NULL WHERE id = ?",
                           (cid,))

    # -- one calibration read back ------------------------------------------------------

    def calibration_status(self, calibration_id: int) -> str:
        """"in_progress" | "finished" | "cancelled"."""
        with self._store.read() as db:
            return calibration_row(self._store, db, calibration_id)[2]

    def touches(self, calibration_id: int) -> list[JsonRecord]:
        """Every touch of a calibration in recording order, overwritten ones included: dicts with
        id, step_index, recorded_at, T_world_flange_m (4x4 list), joints_deg, distance_mm, auto,
        overwrites_touch_id, overwritten_by_touch_id."""
        with self._store.read() as db:
            cid = calibration_row(self._store, db, calibration_id)[0]
            rows = db.execute("SELECT id, step_index, recorded_at, T_world_flange_m_json, joints_deg_json, "
                              "distance_mm, auto, overwrites_touch_id, overwritten_by_touch_id FROM touches "
                              "WHERE calibration_id = ? ORDER BY id", (cid,)).fetchall()
        return [{"id": r[0], "step_index": r[1], "recorded_at": r[2], "T_world_flange_m": json.loads(r[3]),
                 "joints_deg": json.loads(r[4]), "distance_mm": r[5], "auto": bool(r[6]),
                 "overwrites_touch_id": r[7], "overwritten_by_touch_id": r[8]} for r in rows]

    def truth(self, calibration_id: int) -> JsonRecord:
        """The truth stored by :meth:`start_calibration` (server side only)."""
        with self._store.read() as db:
            cid = calibration_row(self._store, db, calibration_id)[0]
            return json.loads(only_row(db.execute("SELECT truth_json FROM calibrations WHERE id = ?", (cid,)))[0])

    def calibration_result(self, calibration_id: int) -> JsonRecord:
        """A calibration's method, status and result: ``{"trainee", "method", "status",
        "tcp_mm", "abc_deg", "position_error_mm", "orientation_error_deg", "grade"}`` (None
        where there is none yet)."""
        with self._store.read() as db:
            cid = calibration_row(self._store, db, calibration_id)[0]
            row = only_row(db.execute(
                "SELECT t.name, c.method, c.status, c.tcp_mm_json, c.abc_deg_json, c.position_error_mm, "
                "c.orientation_error_deg, c.grade FROM calibrations c JOIN sessions s ON s.id = c.session_id "
                "JOIN trainees t ON t.id = s.trainee_id WHERE c.id = ?", (cid,)))
        name, method, status, tcp, abc, pos, ori, grade = row
        return {"trainee": name, "method": method, "status": status,
                "tcp_mm": json.loads(tcp) if tcp else None, "abc_deg": json.loads(abc) if abc else None,
                "position_error_mm": pos, "orientation_error_deg": ori, "grade": grade}

    def last_calibration(self, trainee: str) -> int | None:
        """The latest calibration of ``trainee`` that has a touch (any status), or None: what
        the trainer replays."""
        with self._store.read() as db:
            row = db.execute(
                "SELECT c.id FROM calibrations c JOIN sessions s ON s.id = c.session_id "
                "JOIN trainees t ON t.id = s.trainee_id WHERE t.name = ? AND EXISTS "
                "(SELECT 1 FROM touches x WHERE x.calibration_id = c.id) ORDER BY c.started_at DESC, c.id DESC LIMIT 1",
                (str(trainee),)).fetchone()
        return None if row is None else int(row[0])
