"""Grades for a learning management system: one row per trainee (no viser, no SQL).

``tcp-pendant grades`` lists one row per calibration; an LMS wants one grade per learner.
:func:`per_trainee` folds the gradebook's rows (``Gradebook.grades.rows``) into one
:class:`TraineeGrade` per trainee: attempts, the best and the last grade, their position
errors. Two CSV layouts are written from it:

* :func:`per_trainee_csv`: the columns of :data:`PER_TRAINEE_COLUMNS` (a contract, documented in
  docs/pendant-cli.md "tcp-pendant grades");
* :func:`moodle_csv`: the layout Moodle's gradebook imports (Grades > Import > CSV file,
  https://docs.moodle.org/en/Grade_import): a header row, one row per learner, a column that
  identifies the learner (the teacher maps it to "username" or "useremail" in the import form;
  we write the name the trainee joined with), one numeric column per grade item and an
  optional feedback column for it. The grade is the trainee's best, as points of
  :data:`MOODLE_POINTS` (out of 100, Moodle's default maximum grade).

Every trainee who joined is listed (``Grades.attendance``), also one with no calibration at
all: a trainee with no finished calibration has an empty grade and the reason
(:data:`~tcp_pendant.classroom.grade_rows.NO_RESULT_REASON`, column ``note`` and the Moodle
feedback); in the Moodle file their grade is the trainer's choice (``--moodle-absent``:
:data:`MOODLE_ABSENT` ``"empty"``, Moodle keeps what the learner had, or ``"0"``). Numbers as
every export writes them (``classroom.export_numbers``).

Text that trainees typed (their names) starting with ``= + - @`` gets a leading ``'`` so that a
spreadsheet does not run it as a formula, as in the per-calibration CSV.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from tcp_pendant.classroom.export_numbers import export_cell
from tcp_pendant.classroom.grade_rows import NO_RESULT_REASON, Attendee, GradeRow
from tcp_pendant.classroom.gradebook_schema import GRADES

__all__ = ["MOODLE_ABSENT", "MOODLE_POINTS", "PER_TRAINEE_COLUMNS", "TraineeGrade", "moodle_csv", "per_trainee",
           "per_trainee_csv"]

MOODLE_POINTS: dict[str, int] = {"good": 100, "fair": 70, "poor": 40}
"""Points out of 100 for each grade (a finished calibration has always one)."""
PER_TRAINEE_COLUMNS: tuple[str, ...] = (
    "trainee", "attempts", "in_progress", "best_grade", "best_position_error_mm", "last_grade",
    "last_position_error_mm", "last_finished_at", "note")
"""Columns of :func:`per_trainee_csv`."""
MOODLE_ABSENT: dict[str, int | None] = {"empty": None, "0": 0}
"""The Moodle grade of a trainee with no finished calibration, by the trainer's choice
(``tcp-pendant grades --moodle --moodle-absent empty|0``): empty (Moodle keeps the learner's
grade as it is) or 0 points."""
_RANK = {g: i for i, g in enumerate(GRADES)}          # good < fair < poor


@dataclass(frozen=True)
class TraineeGrade:
    """One trainee's calibrations folded into one grade.

    Attributes:
        trainee: the name (raw text).
        attempts: finished calibrations.
        in_progress: calibrations still in progress.
        best_grade / best_position_error_mm: the best finished one (by grade, then by position
            error; None: none finished or none graded).
        last_grade / last_position_error_mm / last_finished_at: the newest finished one.
        note: why there is no grade (:data:`~tcp_pendant.classroom.grade_rows.NO_RESULT_REASON`
            when none is finished), "" otherwise.
    """

    trainee: str
    attempts: int
    in_progress: int
    best_grade: str | None
    best_position_error_mm: float | None
    last_grade: str | None
    last_position_error_mm: float | None
    last_finished_at: str | None
    note: str = ""


def _best_key(row: GradeRow) -> tuple[int, float]:
    rank = _RANK.get(row.grade or "", len(GRADES))
    err = row.position_error_mm if row.position_error_mm is not None else float("inf")
    return rank, err


def per_trainee(rows: Iterable[GradeRow], attendees: Iterable[Attendee] = ()) -> list[TraineeGrade]:
    """One :class:`TraineeGrade` per trainee of ``rows`` (any order; in-progress rows count as
    in progress) and of ``attendees`` (who joined: those without a row have no attempt),
    sorted by name."""
    by_name: dict[str, list[GradeRow]] = {a.trainee: [] for a in attendees}
    for row in rows:
        by_name.setdefault(row.trainee, []).append(row)
    out = []
    for name in sorted(by_name, key=str.casefold):
        done = [r for r in by_name[name] if r.status == "finished"]
        graded = [r for r in done if r.grade is not None]
        best = min(graded, key=_best_key) if graded else None
        last = max(done, key=lambda r: (r.finished_at, r.calibration_id)) if done else None
        out.append(TraineeGrade(
            trainee=name, attempts=len(done), in_progress=sum(1 for r in by_name[name] if r.status == "in_progress"),
            best_grade=None if best is None else best.grade,
            best_position_error_mm=None if best is None else best.position_error_mm,
            last_grade=None if last is None else last.grade,
            last_position_error_mm=None if last is None else last.position_error_mm,
            last_finished_at=None if last is None else last.finished_at, note="" if done else NO_RESULT_REASON))
    return out


def _safe(text: str) -> str:
    return "'" + text if text[:1] in ("=", "+", "-", "@") else text


def _cell(value: object) -> str:
    return export_cell(value)


def _write(header: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    out = io.StringIO()
    writer = csv.writer(out)
    writer.writerow(header)
    for row in rows:
        writer.writerow([_cell(v) for v in row])
    return out.getvalue()


def per_trainee_csv(grades: Sequence[TraineeGrade]) -> str:
    """``grades`` as CSV text with the columns of :data:`PER_TRAINEE_COLUMNS` (empty: none)."""
    return _write(PER_TRAINEE_COLUMNS, ((_safe(g.trainee), g.attempts, g.in_progress, g.best_grade,
                                         g.best_position_error_mm, g.last_grade, g.last_position_error_mm,
                                         g.last_finished_at, g.note) for g in grades))


def moodle_csv(grades: Sequence[TraineeGrade], *, item: str = "TCP calibration", absent: str = "empty") -> str:
    """``grades`` in the layout Moodle's CSV grade import reads (module docstring): columns
    ``Username``, ``<item>`` (points out of 100 of the best grade; with none finished,
    ``MOODLE_ABSENT[absent]``; finished but none graded: empty) and ``<item> feedback`` (the best and the last result in
    words, or why there is none).

    Raises:
        ValueError: ``absent`` is not one of :data:`MOODLE_ABSENT`.
    """
    if absent not in MOODLE_ABSENT:
        raise ValueError(f"The Moodle grade of a trainee without a result must be one of "
                         f"{', '.join(MOODLE_ABSENT)}, got {absent!r:.40}.")

    def feedback(g: TraineeGrade) -> str:
        if g.attempts == 0:
            return NO_RESULT_REASON + (f"; {g.in_progress} in progress" if g.in_progress else "")
        if g.best_grade is None:
            return f"no graded calibration; {g.attempts} attempt{'s' if g.attempts != 1 else ''}"
        best = (f"best: {g.best_grade}" + ("" if g.best_position_error_mm is None
                                           else f", TCP {g.best_position_error_mm:.2f} mm off"))
        return f"{best}; {g.attempts} attempt{'s' if g.attempts != 1 else ''}; last: {g.last_grade or '-'}"

    def points(g: TraineeGrade) -> int | None:
        if g.attempts == 0:
            return MOODLE_ABSENT[absent]
        return None if g.best_grade is None else MOODLE_POINTS[g.best_grade]

    return _write(("Username", item, f"{item} feedback"), ((_safe(g.trainee), points(g), feedback(g)) for g in grades))
