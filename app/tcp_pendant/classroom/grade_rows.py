"""The gradebook as the trainer grades it: one :class:`GradeRow` per calibration, finished (and,
when asked, in progress), with its touches, crashes, result and errors against the truth.

``tcp-pendant grades`` prints these rows (:mod:`tcp_pendant.classroom.grades_cli`), as CSV
through :func:`tcp_pendant.classroom.grades_csv.to_csv` or folded per trainee for an LMS
(:mod:`tcp_pendant.classroom.lms`).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field

from tcp_pendant.classroom.gradebook_store import GradebookStore
from tcp_pendant.classroom.gradebook_values import duration_s, utc_now

__all__ = ["Attendee", "GradeRow", "Grades", "NO_RESULT_REASON"]

NO_RESULT_REASON = "joined, no calibration finished"
"""Why a trainee who joined has an empty grade in every export (``grades_csv``, ``lms``)."""


@dataclass(frozen=True)
class Attendee:
    """A trainee who joined the class (has a gradebook session), for the exports that list
    every trainee (:meth:`Grades.attendance`).

    Attributes:
        trainee: the name (raw text: escape before showing it as markdown).
        joined_at: their first session's start (UTC ISO 8601).
    """

    trainee: str
    joined_at: str


@dataclass(frozen=True)
class GradeRow:
    """One finished calibration as the trainer sees it (:meth:`Grades.rows`).

    Attributes:
        calibration_id: its id in the gradebook.
        trainee: the trainee's name (raw text: escape before showing it as markdown).
        session_id: the browser session it was done in.
        mode: the session's mode (as given to ``start_session``).
        method: the calibration method (e.g. "xyz4", "abc-world").
        tool_key: the physical tool calibrated.
        exercise_id: the exercise it belonged to, or None.
        started_at / finished_at: UTC ISO 8601.
        duration_s: finished_at - started_at, seconds (wall clock, a cancel/resume pause included).
        touches: touches that count (recorded and not overwritten by a later one).
        hand / auto: how many of those were jogged by hand / done by Auto-touch.
        overwritten: touches recorded and then overwritten.
        crashes: crashes during this calibration.
        figures: the result's quality figures by name (e.g. ``mean_error_mm``).
        tcp_mm / abc_deg: the computed TOOL frame (mm, KUKA A, B, C deg) or None.
        position_error_mm / orientation_error_deg: error against the true TOOL frame, or None.
        grade: "good" | "fair" | "poor" | None.
        status: "finished", or "in_progress" (``rows(include_in_progress=True)``: no result
            yet, ``finished_at`` empty, ``duration_s`` up to now).
    """

    calibration_id: int
    trainee: str
    session_id: int
    mode: str
    method: str
    tool_key: str
    exercise_id: str | None
    started_at: str
    finished_at: str
    duration_s: float
    touches: int
    hand: int
    auto: int
    overwritten: int
    crashes: int
    figures: Mapping[str, float] = field(default_factory=dict)
    tcp_mm: tuple[float, float, float] | None = None
    abc_deg: tuple[float, float, float] | None = None
    position_error_mm: float | None = None
    orientation_error_deg: float | None = None
    grade: str | None = None
    status: str = "finished"


class Grades:
    """The grade rows of the gradebook behind ``store`` (see the module docstring)."""

    def __init__(self, store: GradebookStore) -> None:
        self._store = store

    def attendance(self) -> list[Attendee]:
        """Every trainee who joined (at least one session), in the order they first joined; a
        name added but never joined under is not listed."""
        with self._store.read() as db:
            rows = db.execute("SELECT t.name, MIN(s.started_at) FROM trainees t JOIN sessions s ON s.trainee_id = t.id "
                              "GROUP BY t.id, t.name ORDER BY MIN(s.started_at), t.id").fetchall()
        return [Attendee(trainee=str(name), joined_at=str(joined)) for name, joined in rows]

    def rows(self, *, include_in_progress: bool = False) -> list[GradeRow]:
        """One row per finished calibration, oldest start first; with ``include_in_progress``
        also the calibrations still in progress (``GradeRow.status``)."""
        statuses = "('finished', 'in_progress')" if include_in_progress else "('finished')"
        query = """
            SELECT c.id, t.name, s.id, s.mode, c.method, c.tool_key, c.exercise_id, c.started_at,
                   c.finished_at, c.figures_json, c.tcp_mm_json, c.abc_deg_json, c.position_error_mm,
                   c.orientation_error_deg, c.grade, c.status,
                   (SELECT COUNT(*) FROM touches x WHERE x.calibration_id = c.id AND x.overwritten_by_touch_id IS NULL),
                   (SELECT COUNT(*) FROM touches x WHERE x.calibration_id = c.id AND x.overwritten_by_touch_id IS NULL AND x.auto = 1),
                   (SELECT COUNT(*) FROM touches x WHERE x.calibration_id = c.id AND x.overwritten_by_touch_id IS NOT NULL),
                   (SELECT COUNT(*) FROM crashes k WHERE k.calibration_id = c.id)
            FROM calibrations c JOIN sessions s ON s.id = c.session_id JOIN trainees t ON t.id = s.trainee_id
            WHERE c.status IN """ + statuses + """ ORDER BY c.started_at, c.id"""
        with self._store.read() as db:
            rows = db.execute(query).fetchall()
        out = []
        now = utc_now()
        for (cid, name, sid, mode, method, tool, exercise, started, finished, figs, tcp, abc, pos, ori, grade,
             status, n, n_auto, n_over, n_crash) in rows:
            out.append(GradeRow(
                calibration_id=cid, trainee=name, session_id=sid, mode=mode, method=method, tool_key=tool,
                exercise_id=exercise, started_at=started, finished_at=finished or "",
                duration_s=duration_s(started, finished or now), touches=n, hand=n - n_auto, auto=n_auto,
                overwritten=n_over, crashes=n_crash, figures=json.loads(figs) if figs else {},
                tcp_mm=tuple(json.loads(tcp)) if tcp else None, abc_deg=tuple(json.loads(abc)) if abc else None,
                position_error_mm=pos, orientation_error_deg=ori, grade=grade, status=status))
        return out
