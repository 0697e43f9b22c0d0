"""The grade rows as CSV (``tcp-pendant grades --csv``, the trainer's download): the columns
:data:`CSV_COLUMNS` are a contract (docs/architecture.md "Classroom (gradebook)")."""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Sequence

from tcp_pendant.classroom.grade_rows import GradeRow

__all__ = ["CSV_COLUMNS", "CSV_FIGURES", "to_csv"]

CSV_FIGURES = ("mean_error_mm", "max_error_mm", "rms_error_mm", "ci95_mm", "orthogonality_defect_deg")
CSV_COLUMNS: tuple[str, ...] = (
    "calibration_id", "trainee", "session_id", "mode", "method", "tool", "exercise",
    "started_at", "finished_at", "duration_s", "touches", "hand", "auto", "overwritten", "crashes",
    "tcp_x_mm", "tcp_y_mm", "tcp_z_mm", "a_deg", "b_deg", "c_deg",
    *CSV_FIGURES, "position_error_mm", "orientation_error_deg", "grade", "figures_json", "status",
)
"""Columns of :func:`to_csv` (a contract: docs/pendant-cli.md "tcp-pendant grades")."""


def _cell(value: object) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(round(value, 6))
    return str(value)


def _csv_safe(text: str) -> str:
    # A spreadsheet runs a cell that starts with = + - @ as a formula (CSV injection): a name
    # typed by a browser is data, so such a cell gets a leading apostrophe.
    return "'" + text if text[:1] in ("=", "+", "-", "@", "\t", "\r") else text


def to_csv(rows: Sequence[GradeRow]) -> str:
    """The rows as CSV text (header :data:`CSV_COLUMNS`, ``\\r\\n`` line ends, empty cell = none).

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
            json.dumps(dict(r.figures), sort_keys=True), r.status)])
    return out.getvalue()
