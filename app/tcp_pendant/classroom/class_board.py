"""The trainer's live table as the gradebook knows it (:class:`ClassBoard`): every trainee with
their latest calibration, step, touches, crashes and last result, and every calibration in
progress. The shared truth of the dashboard: a server started again with the gradebook shows
the class as it was, trainees not yet back included; who is connected only the server knows
(``classroom.board`` adds it).

Raw text (names, titles): escape before showing. Times: UTC ISO 8601, "" unknown.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

from tcp_pendant.classroom.gradebook_store import GradebookStore
from tcp_pendant.classroom.uptime import UPTIME_QUERY, downtimes

__all__ = ["BoardReader", "BoardRun", "BoardTrainee", "ClassBoard"]


@dataclass(frozen=True)
class BoardTrainee:
    """One trainee as the gradebook knows them now (:meth:`BoardReader.read`): the trainer's live
    table without "connected", which only the server knows (raw text: escape before showing).

    Attributes:
        trainee_id / name: the trainee.
        calibration_id: the trainee's latest calibration (any status), or None.
        method: its method key ("xyz4", ...), "" without one.
        method_title: its wizard's title as last kept ("XYZ 4-point"), "" unknown.
        status: its status ("in_progress" | "finished" | "cancelled"), "" without one.
        step: its step as the trainee last saw it ("Step 2 of 4", "result", "cancelled"), "" unknown.
        step_since: when that step began (UTC ISO 8601), "" unknown.
        touches: touches recorded in it (overwritten ones included: every Record counts).
        crashes: crashes during it (and, outside any calibration, in the trainee's sessions since
            it started; every crash of the trainee when there is no calibration).
        last_touch_at: the trainee's latest touch (UTC ISO 8601), "" none.
        in_progress: how many of the trainee's calibrations are in progress.
        result_calibration_id: the latest finished calibration, or None; position_error_mm,
            orientation_error_deg, grade, tcp_mm: its result (None: none, or no truth).
        joined_at: when the trainee first joined (their first session, UTC ISO 8601), "" never.
    """

    trainee_id: int
    name: str
    calibration_id: int | None = None
    method: str = ""
    method_title: str = ""
    status: str = ""
    step: str = ""
    step_since: str = ""
    touches: int = 0
    crashes: int = 0
    last_touch_at: str = ""
    in_progress: int = 0
    result_calibration_id: int | None = None
    position_error_mm: float | None = None
    orientation_error_deg: float | None = None
    grade: str | None = None
    tcp_mm: tuple[float, float, float] | None = None
    joined_at: str = ""


@dataclass(frozen=True)
class BoardRun:
    """A calibration in progress (:meth:`BoardReader.read`), for the trainer.

    Fields: calibration_id, trainee, method (key), method_title ("" unknown), step ("" unknown),
    step_since / started_at (UTC ISO 8601, "" unknown), touches (that count).
    """

    calibration_id: int
    trainee: str
    method: str
    method_title: str
    step: str
    step_since: str
    started_at: str
    touches: int


@dataclass(frozen=True)
class ClassBoard:
    """:meth:`BoardReader.read`: every trainee (in the order they first joined), every
    calibration in progress (oldest first) and the gaps no server process of the class was up
    (``(from, to)`` Unix seconds, ``classroom.uptime``), which the dashboard's clocks leave out."""

    trainees: tuple[BoardTrainee, ...]
    in_progress: tuple[BoardRun, ...]
    downtimes: tuple[tuple[float, float], ...] = ()


_TRAINEES_QUERY = """
            WITH b AS MATERIALIZED (
              SELECT t.id AS tid, t.name AS name,
                (SELECT c.id FROM calibrations c JOIN sessions s ON s.id = c.session_id
                   WHERE s.trainee_id = t.id ORDER BY c.started_at DESC, c.id DESC LIMIT 1) AS cid,
                (SELECT c.id FROM calibrations c JOIN sessions s ON s.id = c.session_id
                   WHERE s.trainee_id = t.id AND c.status = 'finished'
                   ORDER BY c.finished_at DESC, c.id DESC LIMIT 1) AS fid,
                (SELECT MAX(x.recorded_at) FROM touches x JOIN calibrations c ON c.id = x.calibration_id
                   JOIN sessions s ON s.id = c.session_id WHERE s.trainee_id = t.id) AS last_touch,
                (SELECT COUNT(*) FROM calibrations c JOIN sessions s ON s.id = c.session_id
                   WHERE s.trainee_id = t.id AND c.status = 'in_progress') AS n_open,
                (SELECT MIN(s.started_at) FROM sessions s WHERE s.trainee_id = t.id) AS joined
              FROM trainees t)
            SELECT b.tid, b.name, b.cid, c.method, c.status, r.method_title, r.step, r.step_since,
                   (SELECT COUNT(*) FROM touches x WHERE x.calibration_id = b.cid),
                   (SELECT COUNT(*) FROM crashes k WHERE (b.cid IS NOT NULL AND k.calibration_id = b.cid)
                      OR (k.calibration_id IS NULL AND k.session_id IN (SELECT id FROM sessions WHERE trainee_id = b.tid)
                          AND (c.started_at IS NULL OR k.at >= c.started_at))),
                   b.last_touch, b.n_open, b.fid, f.position_error_mm, f.orientation_error_deg, f.grade, f.tcp_mm_json,
                   b.joined
            FROM b LEFT JOIN calibrations c ON c.id = b.cid LEFT JOIN run_states r ON r.calibration_id = b.cid
                   LEFT JOIN calibrations f ON f.id = b.fid
            ORDER BY b.tid"""
"""One row per trainee: the latest calibration (``cid``) and finished one (``fid``), joined once."""

_RUNS_QUERY = """
            SELECT c.id, t.name, c.method, r.method_title, r.step, r.step_since, c.started_at,
                   (SELECT COUNT(*) FROM touches x WHERE x.calibration_id = c.id AND x.overwritten_by_touch_id IS NULL)
            FROM calibrations c JOIN sessions s ON s.id = c.session_id JOIN trainees t ON t.id = s.trainee_id
                 LEFT JOIN run_states r ON r.calibration_id = c.id
            WHERE c.status = 'in_progress' ORDER BY c.started_at, c.id"""
"""One row per calibration in progress, oldest first."""


class BoardReader:
    """The trainer's live table read from the gradebook behind ``store`` (see the module
    docstring)."""

    def __init__(self, store: GradebookStore) -> None:
        self._store = store

    def read(self) -> ClassBoard:
        """The trainer's live table as the gradebook knows it now (:class:`ClassBoard`), in
        one read."""
        with self._store.read() as db:
            rows = db.execute(_TRAINEES_QUERY).fetchall()
            runs = db.execute(_RUNS_QUERY).fetchall()
            stretches = db.execute(UPTIME_QUERY).fetchall()
        trainees = tuple(BoardTrainee(
            trainee_id=tid, name=name, calibration_id=cid, method=method or "", status=status or "",
            method_title=title or "", step=step or "", step_since=since or "", touches=int(n), crashes=int(k),
            last_touch_at=last or "", in_progress=int(n_open), result_calibration_id=fid, position_error_mm=pos,
            orientation_error_deg=ori, grade=grade, tcp_mm=tuple(json.loads(tcp)) if tcp else None,
            joined_at=joined or "")
            for (tid, name, cid, method, status, title, step, since, n, k, last, n_open, fid, pos, ori, grade, tcp,
                 joined) in rows)
        open_runs = tuple(BoardRun(calibration_id=cid, trainee=name, method=method, method_title=title or "",
                                   step=step or "", step_since=since or "", started_at=started or "", touches=int(n))
                          for cid, name, method, title, step, since, started, n in runs)
        return ClassBoard(trainees, open_runs, downtimes(stretches))
