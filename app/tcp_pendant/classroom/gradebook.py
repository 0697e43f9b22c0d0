"""The class gradebook: every trainee, session, calibration, touch and crash, in one SQLite file
or, for a class served by several machines, in one PostgreSQL database.

The server writes each wizard event as it happens; ``tcp-pendant grades``
reads it back (:mod:`tcp_pendant.classroom.grades_cli`). Standard library ``sqlite3`` for a file;
a ``postgresql://`` URL runs the same SQL through psycopg 3
(:mod:`tcp_pendant.classroom.gradebook_db`: the connection seam and the one place SQL is
translated for PostgreSQL).

Durability ("a kill -9 of the server loses nothing that was acknowledged on screen"):

- Every public write is one transaction (``BEGIN IMMEDIATE`` ... ``COMMIT``) that has
  committed when the method returns, so the GUI acknowledges *after* the call.
- The file is in WAL mode with ``synchronous=FULL`` (the default here). A kill -9 alone would
  already be survived with ``NORMAL``: SQLite has ``write()``-n the transaction into the ``-wal``
  file before ``COMMIT`` returns and the kernel keeps it after the process dies. ``FULL``
  also fsyncs the WAL at every commit, so an acknowledged touch survives a power cut or a
  kernel crash of the classroom PC too; it costs one fsync per event (human-paced: a touch
  every few seconds per trainee), measured by ``tests/bench/bench_gradebook.py``.
  ``synchronous="NORMAL"`` is accepted for machines whose disk makes the fsync slow.

Safety of the file: the schema is versioned (table ``meta``: ``application`` and
``schema_version``). A version 1 file (before browser keys) is brought to version 2 when it is
opened (one transaction: the column ``trainees.key_sha256`` is added, every trainee without a
key); a TCP Pendant that reads only version 1 then refuses it as newer. Opening checks the file before writing anything to it
(``PRAGMA quick_check``, then ``meta``): a file that is not SQLite, is damaged, is another
program's database or was written by a newer TCP Pendant raises one :class:`GradebookError`
naming the file and what to do; the file is never overwritten or "repaired".

PostgreSQL: the same schema, versioned in the same ``meta`` table; every write is one
transaction committed when the method returns (the server's ``synchronous_commit``, on by
default, makes it durable). Writes that read before they write hold a named advisory lock or a
row lock, so servers on several machines can share one class; opening holds the "schema" lock,
so two servers starting on an empty database make the tables once.

Threads: one connection guarded by a lock (``check_same_thread=False``), so any thread may
call; calls run one at a time. Several processes may share the file (WAL; a writer waits up to
``busy_timeout_s`` for another), several processes and machines the PostgreSQL database.

Units: poses in metres (``T_world_flange_m``), joints and angles in degrees, distances and
errors in mm, durations in seconds; times are UTC ISO 8601 with milliseconds
(``2025-01-31T09:15:02.125+00:00``).

Schema (version 2)::

    meta(key PRIMARY KEY, value)                 application='tcp-pendant gradebook', schema_version='2',
                                                 created_at, exercise_seed (drawn when first asked for)
    trainees(id, name UNIQUE, created_at, key_sha256)
        key_sha256: hex SHA-256 of the browser key issued when a browser joined under the name
                    (NULL: no browser holds the name: never joined, released by the trainer, or
                    a trainee of a version 1 file)
    sessions(id, trainee_id, mode, started_at, ended_at)
    calibrations(id, session_id, method, tool_key, exercise_id, truth_json, status, started_at,
                 finished_at, cancelled_at, figures_json, tcp_mm_json, abc_deg_json,
                 position_error_mm, orientation_error_deg, grade)
        status: 'in_progress' | 'finished' | 'cancelled'
    touches(id, calibration_id, step_index, recorded_at, T_world_flange_m_json, joints_deg_json,
            distance_mm, auto, overwrites_touch_id, overwritten_by_touch_id)
    crashes(id, session_id, calibration_id, at, penetration_mm, note)

Added to every file when it is opened (no schema version: an older reader ignores them)::

    run_states(calibration_id PRIMARY KEY, entry_json, updated_at)     a wizard as last acknowledged
    presence(name PRIMARY KEY, holder, seen_at, status_json)           who is connected, on which
                                                                       server process (heartbeats)
    class_pushes(id PRIMARY KEY, pushed_at, push_json)                 the trainer's pushes, in order
    departures(name PRIMARY KEY, left_at, status_json)                 who left, with their last row
    class_messages(id PRIMARY KEY, name, to_all, sent_at, text)        the trainer's messages not
                                                                       dismissed yet, one row per trainee
    token_failures(id PRIMARY KEY, source, failed_at)                  wrong trainer tokens per source
                                                                       address (the last hour)
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import secrets
import sqlite3
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Literal, overload

import numpy as np
import platformdirs

from tcp_pendant.classroom.gradebook_db import (
    GradebookConnection,
    PostgresConnection,
    PostgresUnavailable,
    SqliteConnection,
    is_postgres_url,
)
from tcp_pendant.classroom.names import TraineeNameError, looks_alike, validate_trainee_name
from tcp_pendant.pendant.class_messages import MAX_WAITING_MESSAGES

__all__ = [
    "APPLICATION",
    "CSV_COLUMNS",
    "GRADES",
    "SCHEMA_VERSION",
    "BoardRun",
    "BoardTrainee",
    "ClassBoard",
    "GradeRow",
    "Gradebook",
    "GradebookError",
    "TraineeJoin",
    "default_gradebook_path",
    "to_csv",
]

APPLICATION = "tcp-pendant gradebook"
SCHEMA_VERSION = 2
GRADES = ("good", "fair", "poor")
_STATUS = ("in_progress", "finished", "cancelled")
_MAX_TEXT = 200          # method, tool key, exercise id, mode, crash note: short labels


_RUN_STATES = """CREATE TABLE IF NOT EXISTS run_states (
    calibration_id INTEGER PRIMARY KEY REFERENCES calibrations(id),
    entry_json TEXT NOT NULL,
    updated_at TEXT NOT NULL)"""
"""What a restart gives back: each calibration's wizard as it was last acknowledged (a session
record entry without truth, ``session_record.run_entry``). Added to every file when it is
opened; a TCP Pendant that does not know it ignores it, so it needs no schema version."""
_PRESENCE = """CREATE TABLE IF NOT EXISTS presence (
    name TEXT PRIMARY KEY,
    holder TEXT NOT NULL,
    seen_at REAL NOT NULL,
    status_json TEXT NOT NULL)"""
"""Which server process holds each connected trainee's name now (``holder``: the process's
own id, :attr:`tcp_pendant.classroom.class_room.ClassRoom.holder`), the holder's last
heartbeat (``seen_at``: Unix time, seconds) and the trainee's row of the trainer's live table
as that process last wrote it (``status_json``). Several server processes on one gradebook
(``tcp-pendant --workers N``) see the whole class through it. Added when the file is opened,
like ``run_states``; a row is deleted when its browser leaves, and a row whose holder stopped
beating (killed) counts as gone after ``stale_s``."""
_CLASS_PUSHES = """CREATE TABLE IF NOT EXISTS class_pushes (
    id INTEGER PRIMARY KEY,
    pushed_at TEXT NOT NULL,
    push_json TEXT NOT NULL)"""
"""Every push of the trainer's class settings, in order: the other server processes of the
class apply the ones they have not seen (``pushes_after``)."""
_DEPARTURES = """CREATE TABLE IF NOT EXISTS departures (
    name TEXT PRIMARY KEY,
    left_at REAL NOT NULL,
    status_json TEXT NOT NULL)"""
"""The trainees whose browser left the class (on any server process), with the row of the
trainer's live table as it was when they left (``status_json``, ``connected`` false) and when
(``left_at``: Unix time, seconds); a trainee connected again is listed as connected, not here
(``Gradebook.departed``)."""
_CLASS_MESSAGES = """CREATE TABLE IF NOT EXISTS class_messages (
    id INTEGER PRIMARY KEY,
    name TEXT NOT NULL,
    to_all INTEGER NOT NULL,
    sent_at TEXT NOT NULL,
    text TEXT NOT NULL)"""
"""The trainer's messages not dismissed yet: one row per trainee it was sent to (``name``; a
message to the class has a row for every trainee connected when it was sent, ``to_all`` 1), so
each trainee dismisses their own (the row goes). ``sent_at``: UTC ``2026-12-02T09:30:00Z``;
``text``: plain text as the trainer typed it (cleaned; escaped where it is shown). At most
``MAX_WAITING_MESSAGES`` per trainee (as many as a session keeps): a newer one pushes out the
oldest."""
_TOKEN_FAILURES = """CREATE TABLE IF NOT EXISTS token_failures (
    id INTEGER PRIMARY KEY,
    source TEXT NOT NULL,
    failed_at REAL NOT NULL)"""
"""Every wrong trainer token by the address it came from (``source``) and when (``failed_at``:
Unix time, seconds), for every server process of the class: the lockout
(``classroom.trainer_token``) counts them whichever process a browser reaches, and after a
restart. Rows older than the caller's ``forget_s`` are deleted at each try."""
MAX_SOURCE_CHARS = 100
"""A token try's source (an address) is cut to this many characters."""
PRESENCE_STALE_S = 10.0
"""A presence row whose holder has not beaten for this long (seconds) counts as gone."""
MAX_STATUS_BYTES = 4_000
"""A presence row's status above this is refused (a trainer's row is ~200 bytes)."""
_RUN_STATE_COLUMNS = (("method_title", "TEXT"), ("step", "TEXT"), ("step_since", "TEXT"))
"""Added to ``run_states`` when missing (additive, like the table): the wizard's title and the
step as the trainee saw it ("Step 2 of 4", "result", "cancelled") and since when (UTC), for the
trainer's dashboard after a restart (``Gradebook.board``)."""
_ADDITIVE_TABLES = {"run_states": _RUN_STATES, "presence": _PRESENCE, "class_pushes": _CLASS_PUSHES,
                    "departures": _DEPARTURES, "class_messages": _CLASS_MESSAGES,
                    "token_failures": _TOKEN_FAILURES}
"""Tables made (CREATE TABLE IF NOT EXISTS, by name) in every gradebook that lacks them when it
is opened, after the versioned schema; written in SQLite's words like every statement
(``gradebook_db.sql_for``). A gradebook that has them all is not asked to create anything (a
database user that may only read and write rows can open it)."""
MAX_RUN_STATE_BYTES = 200_000
"""A wizard's stored state is refused above this (20 poses with joints take ~12 kB)."""


class GradebookError(Exception):
    """The gradebook cannot be opened or a call is refused; the message names the file or the
    value and says what to do."""


def default_gradebook_path() -> Path:
    """``platformdirs.user_data_dir("tcp-pendant")/class.sqlite3`` (next to the tool library)."""
    return Path(platformdirs.user_data_dir("tcp-pendant", appauthor=False)) / "class.sqlite3"


def _now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="milliseconds")


_SCHEMA = """
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE trainees (
    id INTEGER PRIMARY KEY,
    name TEXT NOT NULL UNIQUE,
    created_at TEXT NOT NULL,
    key_sha256 TEXT);
CREATE TABLE sessions (
    id INTEGER PRIMARY KEY,
    trainee_id INTEGER NOT NULL REFERENCES trainees(id),
    mode TEXT NOT NULL,
    started_at TEXT NOT NULL,
    ended_at TEXT);
CREATE TABLE calibrations (
    id INTEGER PRIMARY KEY,
    session_id INTEGER NOT NULL REFERENCES sessions(id),
    method TEXT NOT NULL,
    tool_key TEXT NOT NULL,
    exercise_id TEXT,
    truth_json TEXT NOT NULL,
    status TEXT NOT NULL CHECK (status IN ('in_progress', 'finished', 'cancelled')),
    started_at TEXT NOT NULL,
    finished_at TEXT,
    cancelled_at TEXT,
    figures_json TEXT,
    tcp_mm_json TEXT,
    abc_deg_json TEXT,
    position_error_mm REAL,
    orientation_error_deg REAL,
    grade TEXT CHECK (grade IS NULL OR grade IN ('good', 'fair', 'poor')));
CREATE TABLE touches (
    id INTEGER PRIMARY KEY,
    calibration_id INTEGER NOT NULL REFERENCES calibrations(id),
    step_index INTEGER NOT NULL,
    recorded_at TEXT NOT NULL,
    T_world_flange_m_json TEXT NOT NULL,
    joints_deg_json TEXT NOT NULL,
    distance_mm REAL,
    auto INTEGER NOT NULL CHECK (auto IN (0, 1)),
    overwrites_touch_id INTEGER REFERENCES touches(id),
    overwritten_by_touch_id INTEGER REFERENCES touches(id));
CREATE INDEX touches_by_calibration ON touches(calibration_id);
CREATE TABLE crashes (
    id INTEGER PRIMARY KEY,
    session_id INTEGER NOT NULL REFERENCES sessions(id),
    calibration_id INTEGER REFERENCES calibrations(id),
    at TEXT NOT NULL,
    penetration_mm REAL,
    note TEXT NOT NULL DEFAULT '');
CREATE INDEX crashes_by_session ON crashes(session_id);
CREATE INDEX calibrations_by_session ON calibrations(session_id);
"""


@dataclass(frozen=True)
class GradeRow:
    """One finished calibration as the trainer sees it (``Gradebook.grades``).

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
        status: "finished", or "in_progress" (``grades(include_in_progress=True)``: no result
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


@dataclass(frozen=True)
class TraineeJoin:
    """A browser accepted under a trainee's name (``Gradebook.join_trainee``).

    Attributes:
        trainee_id: the trainee's id (the same on every return of the same browser).
        name: the name as stored.
        new_key: the browser key issued now, to be kept by that browser and shown to nobody
            else; None when the browser proved itself with the key it already had.
    """

    trainee_id: int
    name: str
    new_key: str | None


@dataclass(frozen=True)
class BoardTrainee:
    """One trainee as the gradebook knows them now (``Gradebook.board``): the trainer's live
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


@dataclass(frozen=True)
class BoardRun:
    """A calibration in progress (``Gradebook.board``), for the trainer.

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
    """``Gradebook.board``: every trainee (in the order they first joined) and every
    calibration in progress (oldest first)."""

    trainees: tuple[BoardTrainee, ...]
    in_progress: tuple[BoardRun, ...]


BROWSER_KEY_BYTES = 32
"""Random bytes of a browser key (``secrets.token_urlsafe``: 43 characters)."""
MAX_BROWSER_KEY_CHARS = 200
"""A longer "key" from a browser is not looked at."""
_KEY_CHARS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_")


def _key_digest(key: str) -> str:
    # A browser key is 256 random bits, so a plain SHA-256 keeps it as safe as a slow password
    # hash would: there is no dictionary to try.
    return hashlib.sha256(key.encode("utf-8")).hexdigest()


def _clean_key(key: Any) -> str | None:
    """The browser key a browser sent, or None (none, or not the shape of a key we issue)."""
    if not isinstance(key, str):
        return None
    key = key.strip()
    if not key or len(key) > MAX_BROWSER_KEY_CHARS or not set(key) <= _KEY_CHARS:
        return None
    return key


CSV_FIGURES = ("mean_error_mm", "max_error_mm", "rms_error_mm", "ci95_mm", "orthogonality_defect_deg")
CSV_COLUMNS: tuple[str, ...] = (
    "calibration_id", "trainee", "session_id", "mode", "method", "tool", "exercise",
    "started_at", "finished_at", "duration_s", "touches", "hand", "auto", "overwritten", "crashes",
    "tcp_x_mm", "tcp_y_mm", "tcp_z_mm", "a_deg", "b_deg", "c_deg",
    *CSV_FIGURES, "position_error_mm", "orientation_error_deg", "grade", "figures_json", "status",
)
"""Columns of :func:`to_csv` (a contract: docs/pendant-cli.md "tcp-pendant grades")."""


def _cell(value: Any) -> str:
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


# --------------------------------------------------------------------------- input checks

@overload
def _label(value: Any, what: str, *, optional: Literal[False] = False) -> str: ...
@overload
def _label(value: Any, what: str, *, optional: bool) -> str | None: ...
def _label(value: Any, what: str, *, optional: bool = False) -> str | None:
    if value is None and optional:
        return None
    if not isinstance(value, str) or not value.strip():
        raise GradebookError(f"{what} must be a non-empty text, got {value!r}.")
    if len(value) > _MAX_TEXT or not value.isprintable():
        raise GradebookError(f"{what} must be at most {_MAX_TEXT} printable characters, got {value!r:.80}.")
    return value


def _finite(value: Any, what: str, *, optional: bool = False) -> float | None:
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise GradebookError(f"{what} must be a number, got {value!r:.80}.")
    out = float(value)
    if not math.isfinite(out):
        raise GradebookError(f"{what} must be finite, got {out!r}.")
    return out


def _matrix4(value: Any, what: str) -> list[list[float]]:
    try:
        T = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise GradebookError(f"{what} must be a 4x4 matrix of numbers: {exc}.") from None
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise GradebookError(f"{what} must be a finite 4x4 matrix, got shape {T.shape}.")
    return T.tolist()


def _vector(value: Any, what: str, n: int | None = None) -> list[float]:
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise GradebookError(f"{what} must be numbers: {exc}.") from None
    if v.ndim != 1 or (n is not None and v.shape[0] != n) or not np.all(np.isfinite(v)):
        want = f"{n} finite numbers" if n is not None else "a list of finite numbers"
        raise GradebookError(f"{what} must be {want}, got shape {v.shape}.")
    return v.tolist()


def _json_value(value: Any, what: str, depth: int = 0) -> Any:
    """A copy of ``value`` made of JSON types only (finite numbers, str keys), at most 8 deep."""
    if depth > 8:
        raise GradebookError(f"{what} nests more than 8 levels.")
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise GradebookError(f"{what} keys must be text, got {k!r:.40}.")
            out[k] = _json_value(v, f"{what}[{k!r}]", depth + 1)
        return out
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return [_json_value(v, f"{what}[{i}]", depth + 1) for i, v in enumerate(value)]
    if value is None or isinstance(value, (bool, str)):
        return value
    return _finite(value, what)


def _truth_json(truth: Any) -> str:
    if isinstance(truth, Mapping):
        if not truth:
            raise GradebookError("the truth must not be empty: give T_flange_tool_true_m (4x4, m) "
                                 "or a dict describing the true TOOL frame.")
        return json.dumps(_json_value(truth, "truth"), sort_keys=True)
    return json.dumps({"T_flange_tool_true_m": _matrix4(truth, "T_flange_tool_true_m")})


def _duration_s(start: str, end: str) -> float:
    return (datetime.fromisoformat(end) - datetime.fromisoformat(start)).total_seconds()


# --------------------------------------------------------------------------- the gradebook

class Gradebook:
    """The class gradebook in one SQLite file or one PostgreSQL database (see the module docstring).

    Args:
        path: the database file, or a ``postgresql://USER[:PASSWORD]@HOST[:PORT]/DATABASE`` URL
            (a ``str``; psycopg 3 needed); None = :func:`default_gradebook_path` (its folder is
            created).
        create: make a new gradebook if the file does not exist or the database has no tables
            yet (False: :class:`GradebookError`, as ``tcp-pendant grades`` wants).
        synchronous: SQLite: "FULL" (default: every commit fsynced, survives a power cut) or
            "NORMAL" (survives a kill -9 of the server but maybe not a power cut; no fsync per
            commit). PostgreSQL: the server's ``synchronous_commit`` decides.
        busy_timeout_s: how long a write waits for another process (or machine) holding the
            file or a row; with PostgreSQL also the connect timeout.

    Attributes:
        path: the SQLite file, or None for PostgreSQL.
        location: what messages name: the file's path, or the URL with its password masked.

    Raises:
        GradebookError: the file is not an SQLite database, is damaged, is another program's
            database, was written by a newer TCP Pendant, or cannot be opened; the PostgreSQL
            server cannot be reached or the URL is malformed; the message names the file (the
            URL without its password) and what to do. Nothing is written to such a file.
    """

    def __init__(self, path: Path | str | None = None, *, create: bool = True,
                 synchronous: Literal["FULL", "NORMAL"] = "FULL", busy_timeout_s: float = 5.0) -> None:
        if synchronous not in ("FULL", "NORMAL"):
            raise GradebookError(f"synchronous must be 'FULL' or 'NORMAL', got {synchronous!r}.")
        self._lock = threading.Lock()
        self._closed = False
        self._db: GradebookConnection
        self.path: Path | None
        if is_postgres_url(path):
            self.path = None
            try:
                self._db = PostgresConnection(str(path), busy_timeout_s=float(busy_timeout_s))
            except PostgresUnavailable as exc:
                raise GradebookError(str(exc)) from None
            self.location = self._db.location
        else:
            self.path = file = Path(default_gradebook_path() if path is None else path)
            self.location = str(file)
            if file.is_dir():
                raise GradebookError(f"Gradebook {file} is a folder; give a file name such as "
                                     f"{file / 'class.sqlite3'}.")
            exists = file.exists()
            if not exists and not create:
                raise GradebookError(f"No gradebook at {file}: check the path (the server writes it "
                                     "where --class-db says, by default in the user data folder).")
            if not exists and path is None:
                file.parent.mkdir(parents=True, exist_ok=True)
            try:
                self._db = SqliteConnection(file, busy_timeout_s=float(busy_timeout_s))
            except sqlite3.Error as exc:
                raise GradebookError(f"Cannot open the gradebook {file}: {exc}; check that the path and "
                                     "its folder exist and are readable and writable.") from exc
        try:
            self._open(synchronous, create)
        except BaseException:
            self._db.close()
            raise

    # -- opening ----------------------------------------------------------------------

    def _fail(self, what: str) -> GradebookError:
        noun = self._db.noun
        return GradebookError(
            f"Gradebook {self.location} {what}. Nothing was changed in it; keep it for the record, "
            + ("move it aside or give another file with --class-db." if noun == "file"
               else "or give another database with --class-db."))

    def _cannot_write(self, exc: BaseException) -> GradebookError:
        if self._db.noun == "file":
            return GradebookError(f"Cannot write the gradebook {self.location}: {exc}; check that its folder "
                                  "is writable and the disk is not full.")
        return GradebookError(f"Cannot write the gradebook {self.location}: {' '.join(str(exc).split())}; "
                              "check that the database user may create tables and write in the database.")

    def _version(self, tables: set[str], *, check_storage: bool = True) -> int:
        """The schema version of a database that has tables; refuses (nothing written) one that
        is damaged (``check_storage``: SQLite's quick_check), another program's, incomplete, or
        newer than this TCP Pendant reads."""
        db = self._db
        try:
            problems = db.integrity_problems() if check_storage else []
        except db.errors as exc:
            raise self._fail(f"is damaged ({exc})") from exc
        if problems:
            raise self._fail(f"is damaged (SQLite quick_check: {'; '.join(problems[:3])})")
        if "meta" not in tables:
            raise self._fail(f"is {db.described} of another program (no 'meta' table)")
        try:
            meta = {str(k): str(v) for k, v in db.execute("SELECT key, value FROM meta")}
        except db.errors as exc:
            raise self._fail(f"has an unreadable 'meta' table ({exc})") from exc
        if meta.get("application") != APPLICATION:
            raise self._fail(f"is {db.described} of another program (its meta table does not "
                             f"say {APPLICATION!r})")
        try:
            version = int(meta.get("schema_version", ""))
        except ValueError:
            raise self._fail(f"has no valid schema_version ({meta.get('schema_version')!r})") from None
        if version > SCHEMA_VERSION:
            raise GradebookError(
                f"Gradebook {self.location} was written by a newer TCP Pendant (schema version {version}; "
                f"this one reads up to {SCHEMA_VERSION}). Nothing was changed in it: upgrade "
                f"tcp-pendant to read it, or give another {db.noun} with --class-db.")
        if version < 1 or not {"trainees", "sessions", "calibrations", "touches", "crashes"} <= tables:
            raise self._fail(f"is incomplete (schema version {version}, tables {sorted(tables)})")
        return version

    def _open(self, synchronous: str, create: bool) -> None:
        db = self._db
        try:
            tables = db.tables()
        except db.operational_error as exc:      # cannot open / locked / I/O: not the content
            raise GradebookError(f"Cannot open the gradebook {self.location}: {exc}; check that the path and "
                                 "its folder exist and are readable and writable, and that no other "
                                 "program holds it locked.") from exc
        except db.errors as exc:
            raise self._fail(f"is not a readable {db.kind} database ({exc})") from exc
        looked = bool(tables)
        if looked:
            self._version(tables)                    # refuses before anything is written
        elif not create and db.noun == "database":
            raise GradebookError(f"No gradebook in {self.location}: the database has no gradebook tables; "
                                 "check the URL (the server makes them where --class-db says).")
        try:
            if isinstance(db, SqliteConnection):
                refused = db.configure(synchronous)
                if refused is not None:
                    raise GradebookError(
                        f"Gradebook {self.location}: SQLite refused WAL mode (got {refused!r}); put the "
                        "file on a local disk (WAL needs shared memory, network folders lack it).")
            with self._transaction():
                # Again inside the transaction, which holds the schema: another server process may
                # have made or migrated the tables since the look above.
                db.serialize("schema")
                tables = db.tables()
                if not tables:
                    for statement in _SCHEMA.split(";"):
                        if statement.strip():
                            db.execute(statement)
                    db.executemany("INSERT INTO meta (key, value) VALUES (?, ?)",
                                   [("application", APPLICATION), ("schema_version", str(SCHEMA_VERSION)),
                                    ("created_at", _now())])
                else:
                    version = self._version(tables, check_storage=not looked)
                    if version < SCHEMA_VERSION:
                        self._migrate(version)
                for name, statement in _ADDITIVE_TABLES.items():   # an older reader ignores these
                    if name not in tables:
                        db.execute(statement)
                missing = [c for c in _RUN_STATE_COLUMNS if c[0] not in db.columns("run_states")]
                for column, kind in missing:                          # additive too: only when missing
                    db.execute(f"ALTER TABLE run_states ADD COLUMN {column} {kind}")
        except db.errors as exc:
            raise self._cannot_write(exc) from exc

    def _migrate(self, version: int) -> None:
        """Bring a database of an older schema version to :data:`SCHEMA_VERSION` (inside the
        opening transaction)."""
        db = self._db
        if version < 2:       # browser keys: every trainee so far has none
            if "key_sha256" not in db.columns("trainees"):
                db.execute("ALTER TABLE trainees ADD COLUMN key_sha256 TEXT")
        db.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'", (str(SCHEMA_VERSION),))

    # -- plumbing ---------------------------------------------------------------------

    @contextmanager
    def _transaction(self) -> Iterator[GradebookConnection]:
        """One write transaction, committed (and, with FULL, fsynced) on leaving."""
        db = self._db
        db.begin()
        try:
            yield db
        except BaseException:
            db.rollback()
            raise
        db.commit()

    @contextmanager
    def _write(self) -> Iterator[GradebookConnection]:
        with self._lock:
            if self._closed:
                raise GradebookError(f"Gradebook {self.location} is closed.")
            try:
                with self._transaction() as db:
                    yield db
            except self._db.errors as exc:
                raise GradebookError(f"Cannot write the gradebook {self.location}: {' '.join(str(exc).split())}. "
                                     "Nothing of this event was stored; " + (
                                         "check the disk (full? removed?)." if self._db.noun == "file" else
                                         "check that the PostgreSQL server runs and is reachable.")) from exc

    @contextmanager
    def _read(self) -> Iterator[GradebookConnection]:
        with self._lock:
            if self._closed:
                raise GradebookError(f"Gradebook {self.location} is closed.")
            try:
                yield self._db
            except self._db.errors as exc:
                raise GradebookError(f"Cannot read the gradebook {self.location}: "
                                     f"{' '.join(str(exc).split())}.") from exc

    def close(self) -> None:
        """Close the connection (idempotent); later calls raise :class:`GradebookError`."""
        with self._lock:
            if not self._closed:
                self._closed = True
                self._db.close()

    def __enter__(self) -> Gradebook:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"Gradebook({self.location!r})"

    @staticmethod
    def _id(value: Any, what: str) -> int:
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise GradebookError(f"{what} must be a whole number (an id this gradebook returned), got {value!r:.40}.")
        return int(value)

    def _calibration(self, db: GradebookConnection, calibration_id: Any, *,
                     for_update: bool = False) -> tuple[int, int, str]:
        """(id, session_id, status) of a calibration; ``for_update`` (in a write): the row stays
        locked until the transaction ends, so no other server changes its status meanwhile."""
        cid = self._id(calibration_id, "calibration_id")
        row = db.execute("SELECT id, session_id, status FROM calibrations WHERE id = ?"
                         + (" FOR UPDATE" if for_update else ""), (cid,)).fetchone()
        if row is None:
            raise GradebookError(f"No calibration {cid} in the gradebook {self.location}; start it with "
                                 "start_calibration first.")
        return int(row[0]), int(row[1]), str(row[2])

    # -- writes -----------------------------------------------------------------------

    def add_trainee(self, name: str) -> int:
        """The id of the trainee called ``name``, added if new (a reconnect with the same name
        gets the same id).

        Raises:
            GradebookError: the name is refused (``TraineeNameError``'s words: why, what to type).
        """
        try:
            clean = validate_trainee_name(name)
        except TraineeNameError as exc:
            raise GradebookError(str(exc)) from exc
        with self._write() as db:
            db.serialize("trainee names")
            row = db.execute("SELECT id FROM trainees WHERE name = ?", (clean,)).fetchone()
            if row is not None:
                return int(row[0])
            return db.insert("INSERT INTO trainees (name, created_at) VALUES (?, ?)", (clean, _now()))

    def join_trainee(self, name: str, key: Any = None) -> TraineeJoin:
        """A browser joins the class as ``name``, showing the browser key it kept (or none).

        - A name no trainee has: refused if it looks like one (``names.looks_alike``: the words
          name the existing name); otherwise the trainee is added with a new browser key.
        - A trainee's name whose key is held by a browser: accepted only with that key (the same
          browser after a reload or a server restart); otherwise refused.
        - A trainee's name no browser holds (released by the trainer, or from a version 1
          file): accepted, with a new browser key.

        Args:
            name: what the browser typed (validated and normalised here).
            key: the browser key the browser kept, or None; anything that is not a key we issue
                counts as none.

        Returns:
            The trainee and, when one was issued, the new key (only its SHA-256 is stored).

        Raises:
            TraineeNameError: the name is refused; the message says why and what to do.
        """
        clean = validate_trainee_name(name)
        shown = _clean_key(key)
        with self._write() as db:
            db.serialize("trainee names")        # the look-alike check reads every name
            row = db.execute("SELECT id, key_sha256 FROM trainees WHERE name = ?", (clean,)).fetchone()
            if row is not None:
                tid, digest = int(row[0]), row[1]
                if digest is not None:
                    if shown is None or not secrets.compare_digest(_key_digest(shown), str(digest)):
                        raise TraineeNameError(
                            f"{clean} is already a trainee of this class, joined from another browser; "
                            "use that browser, or ask the trainer to release the name; if you are "
                            "someone else, pick another name.")
                    return TraineeJoin(tid, clean, None)
                new_key = secrets.token_urlsafe(BROWSER_KEY_BYTES)
                db.execute("UPDATE trainees SET key_sha256 = ? WHERE id = ?", (_key_digest(new_key), tid))
                return TraineeJoin(tid, clean, new_key)
            for (other,) in db.execute("SELECT name FROM trainees"):
                if looks_alike(clean, other):
                    raise TraineeNameError(
                        f"{clean} looks like {other}, a name already in this class: if you are "
                        f"{other}, type your name exactly as before; otherwise pick a name that "
                        "looks different (add an initial or your surname).")
            new_key = secrets.token_urlsafe(BROWSER_KEY_BYTES)
            tid = db.insert("INSERT INTO trainees (name, created_at, key_sha256) VALUES (?, ?, ?)",
                            (clean, _now(), _key_digest(new_key)))
            return TraineeJoin(tid, clean, new_key)

    def holds_key(self, name: str, key: Any) -> bool:
        """Whether ``key`` is the browser key of the trainee called ``name`` (False: no such
        trainee, no key held, or another key)."""
        shown = _clean_key(key)
        if shown is None or not isinstance(name, str):
            return False
        with self._read() as db:
            row = db.execute("SELECT key_sha256 FROM trainees WHERE name = ?", (name,)).fetchone()
        return row is not None and row[0] is not None and secrets.compare_digest(_key_digest(shown), str(row[0]))

    def release_trainee(self, name: str) -> bool:
        """Forget the browser key of the trainee called ``name`` (the trainer's "Release"): the
        next browser that joins under the name gets the trainee's records. Returns whether a
        key was held."""
        with self._write() as db:
            return db.execute("UPDATE trainees SET key_sha256 = NULL WHERE name = ? AND key_sha256 IS NOT NULL",
                              (name,)).rowcount > 0

    def trainee_names(self) -> list[str]:
        """Every trainee's name, in the order they first joined."""
        with self._read() as db:
            return [str(r[0]) for r in db.execute("SELECT name FROM trainees ORDER BY id")]

    def held_names(self) -> list[str]:
        """Names whose browser key a browser holds, sorted (the names a trainer can release)."""
        with self._read() as db:
            names = [str(r[0]) for r in db.execute("SELECT name FROM trainees WHERE key_sha256 IS NOT NULL")]
        return sorted(names)              # code point order on every backend (not the server's collation)

    def exercise_seed(self) -> int:
        """The class's exercise seed: drawn with ``secrets`` the first time it is asked for and
        kept in ``meta`` (so a restart with the same gradebook gives every trainee the same
        mystery tool again). A secret: whoever knows it can compute every mystery tool, so it is
        never printed, logged or sent to a browser."""
        with self._write() as db:
            db.serialize("exercise seed")
            row = db.execute("SELECT value FROM meta WHERE key = 'exercise_seed'").fetchone()
            if row is not None:
                try:
                    return int(row[0])
                except ValueError:
                    raise self._fail("has an exercise_seed that is not a whole number in its meta table") from None
            seed = secrets.randbits(63)
            db.execute("INSERT INTO meta (key, value) VALUES ('exercise_seed', ?)", (str(seed),))
            return seed

    def start_session(self, trainee_id: int, mode: str) -> int:
        """A new session (one browser connection) of a trainee; ``mode`` e.g. "own" or "shared"."""
        tid = self._id(trainee_id, "trainee_id")
        mode = _label(mode, "mode")
        with self._write() as db:
            if db.execute("SELECT 1 FROM trainees WHERE id = ?", (tid,)).fetchone() is None:
                raise GradebookError(f"No trainee {tid} in the gradebook {self.location}; add_trainee first.")
            return db.insert("INSERT INTO sessions (trainee_id, mode, started_at) VALUES (?, ?, ?)",
                             (tid, mode, _now()))

    def end_session(self, session_id: int) -> None:
        """Mark a session ended (browser gone); its calibrations stay as they are."""
        sid = self._id(session_id, "session_id")
        with self._write() as db:
            cur = db.execute("UPDATE sessions SET ended_at = ? WHERE id = ? AND ended_at IS NULL",
                             (_now(), sid))
            if cur.rowcount == 0 and db.execute("SELECT 1 FROM sessions WHERE id = ?", (sid,)).fetchone() is None:
                raise GradebookError(f"No session {sid} in the gradebook {self.location}.")

    def start_calibration(self, session_id: int, method: str, tool_key: str, truth: Any,
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
        sid = self._id(session_id, "session_id")
        method = _label(method, "method")
        tool_key = _label(tool_key, "tool_key")
        exercise = _label(exercise_id, "exercise_id", optional=True)
        truth_text = _truth_json(truth)
        with self._write() as db:
            if db.execute("SELECT 1 FROM sessions WHERE id = ?", (sid,)).fetchone() is None:
                raise GradebookError(f"No session {sid} in the gradebook {self.location}; start_session first.")
            return db.insert(
                "INSERT INTO calibrations (session_id, method, tool_key, exercise_id, truth_json, status, "
                "started_at) VALUES (?, ?, ?, ?, ?, 'in_progress', ?)",
                (sid, method, tool_key, exercise, truth_text, _now()))

    def record_touch(self, calibration_id: int, step_index: int, T_world_flange_m: Any, joints_deg: Any,
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
        step = self._id(step_index, "step_index")
        if step < 0:
            raise GradebookError(f"step_index must be >= 0, got {step}.")
        if not isinstance(auto, (bool, np.bool_)):
            raise GradebookError(f"auto must be True (Auto-touch) or False (by hand), got {auto!r:.40}.")
        T = json.dumps(_matrix4(T_world_flange_m, "T_world_flange_m"))
        q = json.dumps(_vector(joints_deg, "joints_deg"))
        d = _finite(distance_mm, "distance_mm", optional=True)
        old = None if overwritten_touch_id is None else self._id(overwritten_touch_id, "overwritten_touch_id")
        with self._write() as db:
            cid, _, status = self._calibration(db, calibration_id, for_update=True)
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
                (cid, step, _now(), T, q, d, int(bool(auto)), old))
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
        depth = _finite(penetration_mm, "penetration_mm", optional=True)
        if not isinstance(note, str) or len(note) > _MAX_TEXT or not note.isprintable():
            raise GradebookError(f"note must be at most {_MAX_TEXT} printable characters.")
        sid = None if session_id is None else self._id(session_id, "session_id")
        with self._write() as db:
            cid = None
            if calibration_id is not None:
                cid, cal_session, _ = self._calibration(db, calibration_id, for_update=True)
                if sid is not None and sid != cal_session:
                    raise GradebookError(f"Calibration {cid} belongs to session {cal_session}, not {sid}.")
                sid = cal_session
            elif db.execute("SELECT 1 FROM sessions WHERE id = ?", (sid,)).fetchone() is None:
                raise GradebookError(f"No session {sid} in the gradebook {self.location}.")
            return db.insert("INSERT INTO crashes (session_id, calibration_id, at, penetration_mm, note) "
                             "VALUES (?, ?, ?, ?, ?)", (sid, cid, _now(), depth, note))

    def finish_calibration(self, calibration_id: int, figures: Mapping[str, float], *,
                           position_error_mm: float | None, orientation_error_deg: float | None,
                           grade: str | None, tcp_mm: Any = None, abc_deg: Any = None) -> None:
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
        figs = {_label(k, "figure name"): _finite(v, f"figures[{k!r}]") for k, v in figures.items()}
        pos = _finite(position_error_mm, "position_error_mm", optional=True)
        ori = _finite(orientation_error_deg, "orientation_error_deg", optional=True)
        if grade is not None and grade not in GRADES:
            raise GradebookError(f"grade must be one of {', '.join(GRADES)} or None, got {grade!r:.40}.")
        tcp = None if tcp_mm is None else json.dumps(_vector(tcp_mm, "tcp_mm", 3))
        abc = None if abc_deg is None else json.dumps(_vector(abc_deg, "abc_deg", 3))
        with self._write() as db:
            cid, _, status = self._calibration(db, calibration_id, for_update=True)
            if status == "cancelled":
                raise GradebookError(f"Calibration {cid} was cancelled; resume_calibration({cid}) before "
                                     "finishing it.")
            db.execute("UPDATE calibrations SET status = 'finished', finished_at = ?, figures_json = ?, "
                       "tcp_mm_json = ?, abc_deg_json = ?, position_error_mm = ?, orientation_error_deg = ?, "
                       "grade = ? WHERE id = ?",
                       (_now(), json.dumps(figs, sort_keys=True), tcp, abc, pos, ori, grade, cid))

    def cancel_calibration(self, calibration_id: int) -> None:
        """Mark a calibration cancelled (its touches stay; a finished one stays finished)."""
        with self._write() as db:
            cid, _, status = self._calibration(db, calibration_id, for_update=True)
            if status == "in_progress":
                db.execute("UPDATE calibrations SET status = 'cancelled', cancelled_at = ? WHERE id = ?",
                           (_now(), cid))

    def resume_calibration(self, calibration_id: int) -> None:
        """Put a cancelled calibration back in progress (the wizard's Resume)."""
        with self._write() as db:
            cid, _, status = self._calibration(db, calibration_id, for_update=True)
            if status == "cancelled":
                db.execute("UPDATE calibrations SET status = 'in_progress', cancelled_at = NULL WHERE id = ?",
                           (cid,))

    # -- reads ------------------------------------------------------------------------

    def calibration_status(self, calibration_id: int) -> str:
        """"in_progress" | "finished" | "cancelled"."""
        with self._read() as db:
            return self._calibration(db, calibration_id)[2]

    def touches(self, calibration_id: int) -> list[dict[str, Any]]:
        """Every touch of a calibration in recording order, overwritten ones included: dicts with
        id, step_index, recorded_at, T_world_flange_m (4x4 list), joints_deg, distance_mm, auto,
        overwrites_touch_id, overwritten_by_touch_id."""
        with self._read() as db:
            cid = self._calibration(db, calibration_id)[0]
            rows = db.execute("SELECT id, step_index, recorded_at, T_world_flange_m_json, joints_deg_json, "
                              "distance_mm, auto, overwrites_touch_id, overwritten_by_touch_id FROM touches "
                              "WHERE calibration_id = ? ORDER BY id", (cid,)).fetchall()
        return [{"id": r[0], "step_index": r[1], "recorded_at": r[2], "T_world_flange_m": json.loads(r[3]),
                 "joints_deg": json.loads(r[4]), "distance_mm": r[5], "auto": bool(r[6]),
                 "overwrites_touch_id": r[7], "overwritten_by_touch_id": r[8]} for r in rows]

    def truth(self, calibration_id: int) -> dict[str, Any]:
        """The truth stored by :meth:`start_calibration` (server side only)."""
        with self._read() as db:
            cid = self._calibration(db, calibration_id)[0]
            return json.loads(db.execute("SELECT truth_json FROM calibrations WHERE id = ?", (cid,)).fetchone()[0])

    # -- what a restart gives back ------------------------------------------------------

    def save_run_state(self, calibration_id: int, entry: Mapping[str, Any], *, method_title: str | None = None,
                       step: str | None = None) -> None:
        """Keep the wizard of calibration ``calibration_id`` as it is now (a session record
        entry, ``session_record.run_entry``, JSON-ready, without truth); replaces the last.
        ``method_title`` / ``step``: the wizard's title and its step as the trainee sees it
        ("Step 2 of 4", "result", "cancelled"); ``step_since`` is set to now when ``step``
        differs from the one kept (the trainer's "time on the step", :meth:`board`).

        Raises:
            GradebookError: no such calibration, not JSON, or above :data:`MAX_RUN_STATE_BYTES`.
        """
        try:
            text = json.dumps(entry, sort_keys=True, allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise GradebookError(f"A wizard's state must be plain JSON: {exc}.") from exc
        if len(text) > MAX_RUN_STATE_BYTES:
            raise GradebookError(f"A wizard's state of {len(text):,} bytes is above {MAX_RUN_STATE_BYTES:,}.")
        title = _label(method_title, "method_title", optional=True)
        where = _label(step, "step", optional=True)
        now = _now()
        with self._write() as db:
            cid = self._calibration(db, calibration_id)[0]
            db.execute("INSERT INTO run_states (calibration_id, entry_json, updated_at, method_title, step, step_since) "
                       "VALUES (?, ?, ?, ?, ?, ?) "
                       "ON CONFLICT(calibration_id) DO UPDATE SET entry_json = excluded.entry_json, "
                       "updated_at = excluded.updated_at, "
                       "method_title = COALESCE(excluded.method_title, run_states.method_title), "
                       "step_since = CASE WHEN excluded.step IS NOT NULL AND COALESCE(run_states.step, '') <> excluded.step "
                       "THEN excluded.step_since ELSE COALESCE(run_states.step_since, excluded.step_since) END, "
                       "step = COALESCE(excluded.step, run_states.step)", (cid, text, now, title, where, now))

    def open_runs(self, trainee: str) -> list[dict[str, Any]]:
        """The calibrations of ``trainee`` still in progress that have a stored wizard, oldest
        first: ``{"calibration_id", "method", "tool_key", "exercise_id", "truth", "entry",
        "touch_ids"}`` (``touch_ids``: step -> the id of its touch that counts, to link the next
        overwrite); for a restart to give them back."""
        with self._read() as db:
            rows = db.execute(
                "SELECT c.id, c.method, c.tool_key, c.exercise_id, c.truth_json, r.entry_json FROM calibrations c "
                "JOIN sessions s ON s.id = c.session_id JOIN trainees t ON t.id = s.trainee_id "
                "JOIN run_states r ON r.calibration_id = c.id "
                "WHERE t.name = ? AND c.status = 'in_progress' ORDER BY c.started_at, c.id", (str(trainee),)).fetchall()
            out = []
            for cid, method, tool, exercise, truth, entry in rows:
                touch_ids = {int(step): int(tid) for tid, step in db.execute(
                    "SELECT id, step_index FROM touches WHERE calibration_id = ? AND overwritten_by_touch_id IS NULL",
                    (cid,))}
                out.append({"calibration_id": cid, "method": method, "tool_key": tool, "exercise_id": exercise,
                            "truth": json.loads(truth), "entry": json.loads(entry), "touch_ids": touch_ids})
        return out

    def class_setting(self, key: str) -> Any:
        """A class setting kept across restarts (``set_class_setting``), None when never set."""
        with self._read() as db:
            row = db.execute("SELECT value FROM meta WHERE key = ?", (f"class:{key}",)).fetchone()
        return None if row is None else json.loads(row[0])

    def set_class_setting(self, key: str, value: Any) -> None:
        """Keep a class setting (JSON-ready; the pushed exercise, the distance-aid lock, the
        trainer token's hash) across restarts of the server."""
        text = json.dumps(value, sort_keys=True, allow_nan=False)
        with self._write() as db:
            db.execute("INSERT INTO meta (key, value) VALUES (?, ?) ON CONFLICT(key) DO UPDATE SET value = "
                       "excluded.value", (f"class:{_label(key, 'setting name')}", text))

    # -- presence: which server process holds which connected name ---------------------

    @staticmethod
    def _status_text(status: Mapping[str, Any]) -> str:
        text = json.dumps(dict(status), sort_keys=True, allow_nan=False)
        if len(text) > MAX_STATUS_BYTES:
            raise GradebookError(f"A trainee's status of {len(text):,} bytes is above {MAX_STATUS_BYTES:,}.")
        return text

    def presence_holder(self, name: str, *, stale_s: float = PRESENCE_STALE_S,
                        now: float | None = None) -> str | None:
        """The holder (a server process's id) whose browser is connected under ``name`` now,
        None when none is (no row, or its holder stopped beating ``stale_s`` ago)."""
        t = time.time() if now is None else now
        with self._read() as db:
            row = db.execute("SELECT holder, seen_at FROM presence WHERE name = ?", (str(name),)).fetchone()
        return None if row is None or t - float(row[1]) > stale_s else str(row[0])

    def claim_presence(self, name: str, holder: str, status: Mapping[str, Any], *,
                       now: float | None = None) -> str | None:
        """``holder`` now holds the connected name ``name`` (the caller has checked that it may:
        a name held elsewhere is taken over only by the same browser). Returns the holder it
        took the name from (None: nobody else held it)."""
        text = self._status_text(status)
        t = time.time() if now is None else now
        with self._write() as db:
            row = db.execute("SELECT holder FROM presence WHERE name = ?", (str(name),)).fetchone()
            if row is None:
                db.execute("INSERT INTO presence (name, holder, seen_at, status_json) VALUES (?, ?, ?, ?)",
                           (str(name), str(holder), t, text))
                return None
            db.execute("UPDATE presence SET holder = ?, seen_at = ?, status_json = ? WHERE name = ?",
                       (str(holder), t, text, str(name)))
            return None if row[0] == holder else str(row[0])

    def drop_presence(self, name: str, holder: str | None = None) -> bool:
        """The browser connected under ``name`` left (``holder``: only if that process still
        holds it; None: whoever holds it, the trainer's release). Returns whether a row went."""
        with self._write() as db:
            if holder is None:
                return db.execute("DELETE FROM presence WHERE name = ?", (str(name),)).rowcount > 0
            return db.execute("DELETE FROM presence WHERE name = ? AND holder = ?",
                              (str(name), str(holder))).rowcount > 0

    def beat_presence(self, holder: str, statuses: Mapping[str, Mapping[str, Any]], *,
                      now: float | None = None) -> set[str]:
        """The heartbeat of ``holder``: the names it holds get ``seen_at = now`` and their
        status. Returns the names of ``statuses`` it still holds (one another process took over,
        or the trainer released, is missing)."""
        if not statuses:
            return set()                          # nothing to renew: no write, no fsync
        t = time.time() if now is None else now
        rows = [(t, self._status_text(st), str(name), str(holder)) for name, st in statuses.items()]
        with self._write() as db:
            db.executemany("UPDATE presence SET seen_at = ?, status_json = ? WHERE name = ? AND holder = ?", rows)
            held = {str(r[0]) for r in db.execute("SELECT name FROM presence WHERE holder = ?", (str(holder),))}
        return held & set(statuses)

    def present(self, *, stale_s: float = PRESENCE_STALE_S, now: float | None = None) -> list[tuple[str, str, dict[str, Any]]]:
        """``(name, holder, status)`` of every connected trainee of every server process, by
        name (rows whose holder stopped beating ``stale_s`` ago are left out)."""
        t = time.time() if now is None else now
        with self._read() as db:
            rows = db.execute("SELECT name, holder, status_json FROM presence WHERE seen_at >= ? ORDER BY name",
                              (t - stale_s,)).fetchall()
        return [(str(n), str(h), json.loads(st)) for n, h, st in rows]

    def drop_holder(self, holder: str) -> int:
        """A server process stops: every name it holds is free (returns how many)."""
        with self._write() as db:
            return db.execute("DELETE FROM presence WHERE holder = ?", (str(holder),)).rowcount

    # -- the trainer's pushes, for every server process of the class -------------------

    def add_push(self, push: Mapping[str, Any]) -> int:
        """Keep one push of the trainer's class settings (JSON-ready); returns its id (ids grow)."""
        text = json.dumps(dict(push), sort_keys=True, allow_nan=False)
        with self._write() as db:
            return db.insert("INSERT INTO class_pushes (pushed_at, push_json) VALUES (?, ?)", (_now(), text))

    def pushes_after(self, push_id: int) -> list[tuple[int, dict[str, Any]]]:
        """``(id, push)`` of the pushes kept after ``push_id``, in order (0: all)."""
        with self._read() as db:
            rows = db.execute("SELECT id, push_json FROM class_pushes WHERE id > ? ORDER BY id",
                              (int(push_id),)).fetchall()
        return [(int(i), json.loads(p)) for i, p in rows]

    def last_push_id(self) -> int:
        """The id of the last push kept (0: none)."""
        with self._read() as db:
            row = db.execute("SELECT MAX(id) FROM class_pushes").fetchone()
        return 0 if row is None or row[0] is None else int(row[0])

    # -- who left, for every server process of the class --------------------------------

    def depart(self, name: str, status: Mapping[str, Any], *, now: float | None = None) -> None:
        """The browser of ``name`` left the class (on whichever process): keep ``status`` (the
        trainee's row as it was when they left) and when."""
        text = self._status_text(status)
        t = time.time() if now is None else now
        with self._write() as db:
            db.execute("INSERT INTO departures (name, left_at, status_json) VALUES (?, ?, ?) ON CONFLICT(name) "
                       "DO UPDATE SET left_at = excluded.left_at, status_json = excluded.status_json",
                       (str(name), t, text))

    def departed(self, *, stale_s: float = PRESENCE_STALE_S,
                 now: float | None = None) -> list[tuple[str, dict[str, Any]]]:
        """``(name, status)`` of every trainee who was connected and is not now, on any server
        process, the latest to leave first: those who left (:meth:`depart`) and those whose
        server process stopped beating ``stale_s`` ago (killed: their last beaten row), with
        ``status["connected"]`` false."""
        t = time.time() if now is None else now
        with self._read() as db:
            rows = db.execute(
                "SELECT d.name, d.left_at, d.status_json FROM departures d WHERE NOT EXISTS (SELECT 1 FROM presence "
                "p WHERE p.name = d.name AND p.seen_at >= ?) UNION ALL SELECT p.name, p.seen_at, p.status_json "
                "FROM presence p WHERE p.seen_at < ? AND NOT EXISTS (SELECT 1 FROM departures d WHERE d.name = p.name)",
                (t - stale_s, t - stale_s)).fetchall()
        out = []
        for name, _at, st in sorted(rows, key=lambda r: (-float(r[1]), str(r[0]))):
            status = json.loads(st)
            if isinstance(status, dict):
                out.append((str(name), {**status, "connected": False}))
        return out

    # -- the trainer's messages, until each trainee dismisses them ---------------------

    def add_message(self, text: str, names: Sequence[str], *, to_all: bool, sent_at: str) -> dict[str, int]:
        """Keep the trainer's message ``text`` (plain text, cleaned by the caller) for each of
        ``names`` until that trainee dismisses it; beyond ``MAX_WAITING_MESSAGES`` a trainee's
        oldest go. ``to_all``: it was sent to the class. Returns each name's message id."""
        ids: dict[str, int] = {}
        with self._write() as db:
            for name in dict.fromkeys(str(n) for n in names):
                ids[name] = db.insert("INSERT INTO class_messages (name, to_all, sent_at, text) VALUES (?, ?, ?, ?)",
                                      (name, int(bool(to_all)), str(sent_at), str(text)))
                db.execute("DELETE FROM class_messages WHERE name = ? AND id NOT IN (SELECT id FROM class_messages "
                           "WHERE name = ? ORDER BY id DESC LIMIT ?)", (name, name, MAX_WAITING_MESSAGES))
        return ids

    def messages_for(self, names: Sequence[str]) -> dict[str, list[tuple[int, bool, str, str]]]:
        """The messages kept for each of ``names`` (not dismissed), oldest first:
        ``{name: [(id, to_all, sent_at, text), ...]}`` (a name without any is missing)."""
        wanted = sorted({str(n) for n in names})
        out: dict[str, list[tuple[int, bool, str, str]]] = {}
        if not wanted:
            return out
        with self._read() as db:
            rows = db.execute("SELECT id, name, to_all, sent_at, text FROM class_messages WHERE name IN ("
                              + ", ".join("?" * len(wanted)) + ") ORDER BY id", wanted).fetchall()
        for mid, name, to_all, sent, text in rows:
            out.setdefault(str(name), []).append((int(mid), bool(to_all), str(sent), str(text)))
        return out

    def dismiss_messages(self, name: str, message_ids: Sequence[int]) -> int:
        """``name`` dismissed the messages ``message_ids`` (theirs only: another trainee's id
        dismisses nothing). Returns how many went."""
        ids = [self._id(i, "message id") for i in message_ids]
        if not ids:
            return 0
        with self._write() as db:
            return sum(db.execute("DELETE FROM class_messages WHERE id = ? AND name = ?", (i, str(name))).rowcount
                       for i in ids)

    # -- wrong trainer tokens, per source address, for every server process ------------

    def try_token(self, source: str, *, now: float, forget_s: float,
                  lock_s: Callable[[int], float]) -> tuple[float, int, bool]:
        """One try of the trainer token from ``source`` (an address), counted before the token
        is compared, in one transaction (so no try slips between the processes of the class):
        failures older than ``forget_s`` are forgotten (every source's); when the source's
        ``n`` failures, the last at ``t``, lock it (``t + lock_s(n) > now``) nothing is counted;
        otherwise one failure is stored, to be forgiven (:meth:`forgive_token_failures`) if the
        token is right. Times: Unix seconds.

        Returns:
            ``(wait_s, failures, counted)``: seconds still locked (0 when counted), the source's
            failures with this try, whether this try was counted (False: locked, do not compare).
        """
        src = str(source)[:MAX_SOURCE_CHARS]
        with self._write() as db:
            db.serialize("token failures")
            db.execute("DELETE FROM token_failures WHERE failed_at < ?", (float(now) - float(forget_s),))
            n, last = db.execute("SELECT COUNT(*), MAX(failed_at) FROM token_failures WHERE source = ?",
                                 (src,)).fetchone()
            n = int(n)
            if n and float(last) + lock_s(n) > now:
                return float(last) + lock_s(n) - now, n, False
            db.execute("INSERT INTO token_failures (source, failed_at) VALUES (?, ?)", (src, float(now)))
        return 0.0, n + 1, True

    def forgive_token_failures(self, source: str) -> int:
        """The right token came from ``source``: its failures are forgotten (returns how many)."""
        with self._write() as db:
            return db.execute("DELETE FROM token_failures WHERE source = ?",
                              (str(source)[:MAX_SOURCE_CHARS],)).rowcount

    def board(self) -> ClassBoard:
        """The trainer's live table as the gradebook knows it (:class:`ClassBoard`): every
        trainee with their latest calibration, step, touches, crashes and last result, and every
        calibration in progress. The shared truth of the dashboard: a server started again with
        this gradebook shows the class as it was, trainees not yet back included."""
        query = """
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
                   WHERE s.trainee_id = t.id AND c.status = 'in_progress') AS n_open
              FROM trainees t)
            SELECT b.tid, b.name, b.cid, c.method, c.status, r.method_title, r.step, r.step_since,
                   (SELECT COUNT(*) FROM touches x WHERE x.calibration_id = b.cid),
                   (SELECT COUNT(*) FROM crashes k WHERE (b.cid IS NOT NULL AND k.calibration_id = b.cid)
                      OR (k.calibration_id IS NULL AND k.session_id IN (SELECT id FROM sessions WHERE trainee_id = b.tid)
                          AND (c.started_at IS NULL OR k.at >= c.started_at))),
                   b.last_touch, b.n_open, b.fid, f.position_error_mm, f.orientation_error_deg, f.grade, f.tcp_mm_json
            FROM b LEFT JOIN calibrations c ON c.id = b.cid LEFT JOIN run_states r ON r.calibration_id = b.cid
                   LEFT JOIN calibrations f ON f.id = b.fid
            ORDER BY b.tid"""
        runs_query = """
            SELECT c.id, t.name, c.method, r.method_title, r.step, r.step_since, c.started_at,
                   (SELECT COUNT(*) FROM touches x WHERE x.calibration_id = c.id AND x.overwritten_by_touch_id IS NULL)
            FROM calibrations c JOIN sessions s ON s.id = c.session_id JOIN trainees t ON t.id = s.trainee_id
                 LEFT JOIN run_states r ON r.calibration_id = c.id
            WHERE c.status = 'in_progress' ORDER BY c.started_at, c.id"""
        with self._read() as db:
            rows = db.execute(query).fetchall()
            runs = db.execute(runs_query).fetchall()
        trainees = tuple(BoardTrainee(
            trainee_id=tid, name=name, calibration_id=cid, method=method or "", status=status or "",
            method_title=title or "", step=step or "", step_since=since or "", touches=int(n), crashes=int(k),
            last_touch_at=last or "", in_progress=int(n_open), result_calibration_id=fid, position_error_mm=pos,
            orientation_error_deg=ori, grade=grade, tcp_mm=tuple(json.loads(tcp)) if tcp else None)
            for (tid, name, cid, method, status, title, step, since, n, k, last, n_open, fid, pos, ori, grade, tcp)
            in rows)
        open_runs = tuple(BoardRun(calibration_id=cid, trainee=name, method=method, method_title=title or "",
                                   step=step or "", step_since=since or "", started_at=started or "", touches=int(n))
                          for cid, name, method, title, step, since, started, n in runs)
        return ClassBoard(trainees, open_runs)

    def last_calibration(self, trainee: str) -> int | None:
        """The latest calibration of ``trainee`` that has a touch (any status), or None: what
        the trainer replays."""
        with self._read() as db:
            row = db.execute(
                "SELECT c.id FROM calibrations c JOIN sessions s ON s.id = c.session_id "
                "JOIN trainees t ON t.id = s.trainee_id WHERE t.name = ? AND EXISTS "
                "(SELECT 1 FROM touches x WHERE x.calibration_id = c.id) ORDER BY c.started_at DESC, c.id DESC LIMIT 1",
                (str(trainee),)).fetchone()
        return None if row is None else int(row[0])

    def calibration_result(self, calibration_id: int) -> dict[str, Any]:
        """A calibration's method, status and result: ``{"trainee", "method", "status",
        "tcp_mm", "abc_deg", "position_error_mm", "orientation_error_deg", "grade"}`` (None
        where there is none yet)."""
        with self._read() as db:
            cid = self._calibration(db, calibration_id)[0]
            row = db.execute(
                "SELECT t.name, c.method, c.status, c.tcp_mm_json, c.abc_deg_json, c.position_error_mm, "
                "c.orientation_error_deg, c.grade FROM calibrations c JOIN sessions s ON s.id = c.session_id "
                "JOIN trainees t ON t.id = s.trainee_id WHERE c.id = ?", (cid,)).fetchone()
        name, method, status, tcp, abc, pos, ori, grade = row
        return {"trainee": name, "method": method, "status": status,
                "tcp_mm": json.loads(tcp) if tcp else None, "abc_deg": json.loads(abc) if abc else None,
                "position_error_mm": pos, "orientation_error_deg": ori, "grade": grade}

    def grades(self, *, include_in_progress: bool = False) -> list[GradeRow]:
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
        with self._read() as db:
            rows = db.execute(query).fetchall()
        out = []
        now = _now()
        for (cid, name, sid, mode, method, tool, exercise, started, finished, figs, tcp, abc, pos, ori, grade,
             status, n, n_auto, n_over, n_crash) in rows:
            out.append(GradeRow(
                calibration_id=cid, trainee=name, session_id=sid, mode=mode, method=method, tool_key=tool,
                exercise_id=exercise, started_at=started, finished_at=finished or "",
                duration_s=_duration_s(started, finished or now), touches=n, hand=n - n_auto, auto=n_auto,
                overwritten=n_over, crashes=n_crash, figures=json.loads(figs) if figs else {},
                tcp_mm=tuple(json.loads(tcp)) if tcp else None, abc_deg=tuple(json.loads(abc)) if abc else None,
                position_error_mm=pos, orientation_error_deg=ori, grade=grade, status=status))
        return out

    def to_csv(self, rows: Sequence[GradeRow] | None = None) -> str:
        """:func:`to_csv` of ``rows`` (default: :meth:`grades`)."""
        return to_csv(self.grades() if rows is None else rows)
