"""What a restart gives back: each calibration's wizard as it was last acknowledged (table
``run_states``: a session record entry without truth, ``session_record.run_entry``), with the
wizard's title and step as the trainee saw it, for the trainer's dashboard.

The recorder keeps a wizard here whenever its place changes (``classroom.recorder``); a server
started again with the same gradebook rebuilds the trainee's calibrations in progress, and the
finished ones whose result is on show and not saved yet, from :meth:`RunStates.open_runs` and
the truth kept apart (``classroom.restore``). A result saved to the tool library is marked
(:meth:`RunStates.mark_saved`, column ``result_saved_at``; a new result of the run clears it);
one the trainee closed (its step "cancelled") is dismissed: neither comes back.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence

from tcp_pendant.classroom.gradebook_store import GradebookError, GradebookStore
from tcp_pendant.classroom.gradebook_values import label, utc_now
from tcp_pendant.classroom.training_records import calibration_row
from tcp_pendant.json_shapes import JsonRecord

__all__ = ["MAX_RUN_STATE_BYTES", "RunStates"]

MAX_RUN_STATE_BYTES = 200_000
"""A wizard's stored state is refused above this (20 poses with joints take ~12 kB)."""


class RunStates:
    """The kept wizards of the gradebook behind ``store`` (see the module docstring)."""

    def __init__(self, store: GradebookStore) -> None:
        self._store = store

    def save(self, calibration_id: int, entry: Mapping[str, object], *, method_title: str | None = None,
             step: str | None = None) -> None:
        """Keep the wizard of calibration ``calibration_id`` as it is now (a session record
        entry, ``session_record.run_entry``, JSON-ready, without truth); replaces the last.
        ``method_title`` / ``step``: the wizard's title and its step as the trainee sees it
        ("Step 2 of 4", "result", "cancelled"); ``step_since`` is set to now when ``step``
        differs from the one kept (the trainer's "time on the step", ``BoardReader.read``).

        Raises:
            GradebookError: no such calibration, not JSON, or above :data:`MAX_RUN_STATE_BYTES`.
        """
        try:
            text = json.dumps(entry, sort_keys=True, allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise GradebookError(f"A wizard's state must be plain JSON: {exc}.") from exc
        if len(text) > MAX_RUN_STATE_BYTES:
            raise GradebookError(f"A wizard's state of {len(text):,} bytes is above {MAX_RUN_STATE_BYTES:,}.")
        title = label(method_title, "method_title", optional=True)
        where = label(step, "step", optional=True)
        now = utc_now()
        with self._store.write() as db:
            cid = calibration_row(self._store, db, calibration_id)[0]
            db.execute("INSERT INTO run_states (calibration_id, entry_json, updated_at, method_title, step, step_since) "
                       "VALUES (?, ?, ?, ?, ?, ?) "
                       "ON CONFLICT(calibration_id) DO UPDATE SET entry_json = excluded.entry_json, "
                       "updated_at = excluded.updated_at, "
                       "method_title = COALESCE(excluded.method_title, run_states.method_title), "
                       "step_since = CASE WHEN excluded.step IS NOT NULL AND COALESCE(run_states.step, '') <> excluded.step "
                       "THEN excluded.step_since ELSE COALESCE(run_states.step_since, excluded.step_since) END, "
                       "step = COALESCE(excluded.step, run_states.step)", (cid, text, now, title, where, now))

    def mark_saved(self, calibration_id: int, saved: bool = True) -> None:
        """The result of calibration ``calibration_id`` as it is now was saved to the tool
        library (``saved``), or it has a new result not saved yet (False). Nothing happens to a
        calibration without a kept wizard."""
        when = utc_now() if saved else None
        with self._store.write() as db:
            cid = calibration_row(self._store, db, calibration_id)[0]
            db.execute("UPDATE run_states SET result_saved_at = ? WHERE calibration_id = ?", (when, cid))

    def open_runs(self, trainee: str) -> Sequence[JsonRecord]:
        """The calibrations of ``trainee`` that have a stored wizard and are still in progress,
        or finished with their result on show ("result") and not saved to the library, oldest
        first: ``{"calibration_id", "status", "method", "tool_key", "exercise_id", "truth",
        "entry", "touch_ids"}`` (``touch_ids``: step -> the id of its touch that counts, to link
        the next overwrite); for a restart to give them back."""
        with self._store.read() as db:
            rows = db.execute(
                "SELECT c.id, c.status, c.method, c.tool_key, c.exercise_id, c.truth_json, r.entry_json "
                "FROM calibrations c JOIN sessions s ON s.id = c.session_id JOIN trainees t ON t.id = s.trainee_id "
                "JOIN run_states r ON r.calibration_id = c.id "
                "WHERE t.name = ? AND (c.status = 'in_progress' OR (c.status = 'finished' AND r.step = 'result' "
                "AND r.result_saved_at IS NULL)) ORDER BY c.started_at, c.id", (str(trainee),)).fetchall()
            out = []
            for cid, status, method, tool, exercise, truth, entry in rows:
                touch_ids = {int(step): int(tid) for tid, step in db.execute(
                    "SELECT id, step_index FROM touches WHERE calibration_id = ? AND overwritten_by_touch_id IS NULL",
                    (cid,))}
                out.append({"calibration_id": cid, "status": status, "method": method, "tool_key": tool, "exercise_id": exercise,
                            "truth": json.loads(truth), "entry": json.loads(entry), "touch_ids": touch_ids})
        return out
