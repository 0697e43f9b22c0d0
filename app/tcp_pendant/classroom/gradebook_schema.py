"""The gradebook's tables on disk: the versioned schema, the tables added to every gradebook
when it is opened, and the steps that make or bring a database to them.

Every statement is written in SQLite's words (``gradebook_db.sql_for`` translates it for
PostgreSQL). The schema is versioned (table ``meta``: ``application`` and ``schema_version``);
opening a gradebook (:mod:`tcp_pendant.classroom.gradebook_open`) checks the version before it
runs anything here.

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
    server_uptime(holder PRIMARY KEY, started_at, seen_at)             when each server process was up
                                                                       (the clocks leave downtime out)

and the column ``run_states.result_saved_at`` (with ``method_title``, ``step``, ``step_since``:
:data:`RUN_STATE_COLUMNS`).

A new table: add it to :data:`SCHEMA` (a new schema version and a :func:`migrate` step) or, if
an older reader may ignore it, to :data:`ADDITIVE_TABLES`.
"""

from __future__ import annotations

from tcp_pendant.classroom.gradebook_db import GradebookConnection
from tcp_pendant.classroom.gradebook_values import utc_now

__all__ = [
    "ADDITIVE_TABLES",
    "APPLICATION",
    "GRADES",
    "RUN_STATE_COLUMNS",
    "SCHEMA",
    "SCHEMA_VERSION",
    "add_missing_parts",
    "create_schema",
    "migrate",
]

APPLICATION = "tcp-pendant gradebook"
SCHEMA_VERSION = 2
GRADES = ("good", "fair", "poor")

SCHEMA = """
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
"""The versioned tables (:data:`SCHEMA_VERSION`), made in one transaction in an empty database."""

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
class apply the ones they have not seen (``ClassPushes.after``)."""
_DEPARTURES = """CREATE TABLE IF NOT EXISTS departures (
    name TEXT PRIMARY KEY,
    left_at REAL NOT NULL,
    status_json TEXT NOT NULL)"""
"""The trainees whose browser left the class (on any server process), with the row of the
trainer's live table as it was when they left (``status_json``, ``connected`` false) and when
(``left_at``: Unix time, seconds); a trainee connected again is listed as connected, not here
(``Presence.departed``)."""
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
_SERVER_UPTIME = """CREATE TABLE IF NOT EXISTS server_uptime (
    holder TEXT PRIMARY KEY,
    started_at REAL NOT NULL,
    seen_at REAL NOT NULL)"""
"""When each server process of the class started and last beat (Unix time, seconds;
``classroom.uptime``): the gaps between are the server's downtime, which the trainer's clocks
(time on the step, stuck, idle) leave out."""
RUN_STATE_COLUMNS = (("method_title", "TEXT"), ("step", "TEXT"), ("step_since", "TEXT"), ("result_saved_at", "TEXT"))
"""Added to ``run_states`` when missing (additive, like the table): the wizard's title and the
step as the trainee saw it ("Step 2 of 4", "result", "cancelled") and since when (UTC), for the
trainer's dashboard after a restart (``BoardReader.read``); when its result as it is now was
saved to the tool library (UTC; NULL: not saved, and a new result clears it), so that a restart
gives back a finished result until it is saved or dismissed (``classroom.restore``)."""
ADDITIVE_TABLES = {"run_states": _RUN_STATES, "presence": _PRESENCE, "class_pushes": _CLASS_PUSHES,
                   "departures": _DEPARTURES, "class_messages": _CLASS_MESSAGES,
                   "token_failures": _TOKEN_FAILURES, "server_uptime": _SERVER_UPTIME}
"""Tables made (CREATE TABLE IF NOT EXISTS, by name) in every gradebook that lacks them when it
is opened, after the versioned schema; written in SQLite's words like every statement
(``gradebook_db.sql_for``). A gradebook that has them all is not asked to create anything (a
database user that may only read and write rows can open it)."""


def create_schema(db: GradebookConnection) -> None:
    """Make the versioned tables and their ``meta`` rows in an empty database (inside the
    opening transaction)."""
    for statement in SCHEMA.split(";"):
        if statement.strip():
            db.execute(statement)
    db.executemany("INSERT INTO meta (key, value) VALUES (?, ?)",
                   [("application", APPLICATION), ("schema_version", str(SCHEMA_VERSION)),
                    ("created_at", utc_now())])


def migrate(db: GradebookConnection, version: int) -> None:
    """Bring a database of an older schema version to :data:`SCHEMA_VERSION` (inside the
    opening transaction)."""
    if version < 2:       # browser keys: every trainee so far has none
        if "key_sha256" not in db.columns("trainees"):
            db.execute("ALTER TABLE trainees ADD COLUMN key_sha256 TEXT")
    db.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'", (str(SCHEMA_VERSION),))


def add_missing_parts(db: GradebookConnection, tables: set[str]) -> None:
    """Make the :data:`ADDITIVE_TABLES` missing from ``tables`` and the
    :data:`RUN_STATE_COLUMNS` missing from ``run_states`` (inside the opening transaction)."""
    for name, statement in ADDITIVE_TABLES.items():   # an older reader ignores these
        if name not in tables:
            db.execute(statement)
    missing = [c for c in RUN_STATE_COLUMNS if c[0] not in db.columns("run_states")]
    for column, kind in missing:                          # additive too: only when missing
        db.execute(f"ALTER TABLE run_states ADD COLUMN {column} {kind}")
