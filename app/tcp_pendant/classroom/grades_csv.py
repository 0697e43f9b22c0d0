"""The grade rows as CSV (``tcp-pendant grades --csv``, the trainer's download): the columns
:data:`CSV_COLUMNS` are a contract (docs/pendant-cli.md "tcp-pendant grades").

Every trainee who joined is in it: one row per calibration (finished or in progress) and, for a
trainee with none of those, one attendance row (status ``joined``, no calibration id, an empty
grade, ``note`` :data:`~tcp_pendant.classroom.grade_rows.NO_RESULT_REASON`). ``note`` says why
a grade is empty; numbers as every export writes them (``classroom.export_numbers``)."""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Sequence

from tcp_pendant.classroom.export_numbers import export_cell
from tcp_pendant.classroom.grade_rows import NO_RESULT_REASON, Attendee, GradeRow

__all__ = ["CSV_COLUMNS", "CSV_FIGURES", "IN_PROGRESS_NOTE", "NO_TRUTH_NOTE", "grade_note", "to_csv"]

CSV_FIGURES = ("mean_error_mm", "max_error_mm", "rms_error_mm", "ci95_mm", "orthogonality_defect_deg")
CSV_COLUMNS: tuple[str, ...] = (
    "calibration_id", "trainee", "session_id", "mode", "method", "tool", "exercise",
    "started_at", "finished_at", "duration_s", "touches", "hand", "auto", "overwritten", "crashes",
    "tcp_x_mm", "tcp_y_mm", "tcp_z_mm", "a_deg", "b_deg", "c_deg",
    *CSV_FIGURES, "position_error_mm", "orientation_error_deg", "grade", "figures_json", "status", "note",
)
"""Columns of :func:`to_csv` (a contract: docs/pendant-cli.md "tcp-pendant grades")."""
IN_PROGRESS_NOTE = "in progress, no result yet"
"""``note`` of a calibration in progress."""
NO_TRUTH_NOTE = "no true TOOL frame to grade against"
"""``note`` of a finished calibration without a grade (free practice with a tool of unknown truth)."""


def grade_note(row: GradeRow) -> str:
    """Why ``row``'s grade is empty ("" when it has one)."""
    if row.grade is not None:
        return ""
    return IN_PROGRESS_NOTE if row.status == "in_progress" else NO_TRUTH_NOTE


def _cell(value: object) -> str:
    return export_cell(value)


def _csv_safe(text: str) -> str:
    # A spreadsheet runs a cell that starts with = + - @ as a formula (CSV injection): a name
    # typed by a browser is data, so such a cell gets a leading apostrophe.
    return "'" + text if text[:1] in ("=", "+", "-", "@", "\t", "\r") else text


def to_csv(rows: Sequence[GradeRow], attendees: Sequence[Attendee] = ()) -> str:
    """The rows as CSV text (header :data:`CSV_COLUMNS`, ``\\r\\n`` line ends, empty cell = none),
    then an attendance row for each of ``attendees`` who has no row (module docstring).

    Text typed by trainees (the name) starting with ``= + - @`` gets a leading ``'`` so that a
    spreadsheet does not run it as a formula.
    """
    out = io.StringIO()
    writer = csv.writer(out)
    writer.writerow(CSV_COLUMNS)
    for r in rows:
        tcp = r.tcp_mm or (None, None, None)
        abc = r.abc_deg or (None, None, None)
        writer.writerow([_cell(v) for v in (
            r.calibration_id, _csv_safe(r.trainee), r.session_id, _csv_safe(r.mode), _csv_safe(r.method),
            _csv_safe(r.tool_key), None if r.exercise_id is None else _csv_safe(r.exercise_id),
            r.started_at, r.finished_at, round(r.duration_s, 3), r.touches, r.hand, r.auto,
            r.overwritten, r.crashes, *tcp, *abc, *(r.figures.get(k) for k in CSV_FIGURES),
            r.position_error_mm, r.orientation_error_deg, r.grade,
            json.dumps(dict(r.figures), sort_keys=True), r.status, grade_note(r))])
    listed = {r.trainee for r in rows}
    blank = [None] * (len(CSV_COLUMNS) - 4)
    for a in attendees:
        if a.trainee not in listed:
            listed.add(a.trainee)
            writer.writerow([_cell(v) for v in (None, _csv_safe(a.trainee), *blank, "joined", NO_RESULT_REASON)])
    return out.getvalue()
