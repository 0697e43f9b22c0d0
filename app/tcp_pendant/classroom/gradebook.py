"""The class gradebook: every trainee, session, calibration, touch and crash, in one SQLite file
or, for a class served by several machines, in one PostgreSQL database.

The server writes each wizard event as it happens; ``tcp-pendant grades`` reads it back
(:mod:`tcp_pendant.classroom.grades_cli`). Standard library ``sqlite3`` for a file; a
``postgresql://`` URL runs the same SQL through psycopg 3 (:mod:`tcp_pendant.classroom.gradebook_db`:
the connection seam and the one place SQL is translated for PostgreSQL).

:class:`Gradebook` opens the store and hands out its parts, each the one owner of its job;
callers use the parts directly (``book.records.record_touch(...)``):

============================  =====================================================================
``book.store``                the guarded connection: one transaction per write, durability, threads
                              (:mod:`~tcp_pendant.classroom.gradebook_store`; opening and the checks
                              before it: :mod:`~tcp_pendant.classroom.gradebook_open`; the tables:
                              :mod:`~tcp_pendant.classroom.gradebook_schema`)
``book.trainees``             names and browser keys (:mod:`~tcp_pendant.classroom.trainees`)
``book.records``              sessions, calibrations, touches, crashes; one calibration read back
                              (:mod:`~tcp_pendant.classroom.training_records`)
``book.run_states``           each wizard as last acknowledged, for a restart
                              (:mod:`~tcp_pendant.classroom.run_states`)
``book.grades``               the grade rows (:mod:`~tcp_pendant.classroom.grade_rows`; as CSV:
                              :mod:`~tcp_pendant.classroom.grades_csv`)
``book.board``                the trainer's live table (:mod:`~tcp_pendant.classroom.class_board`)
``book.settings``             the exercise seed and the class settings kept across restarts
                              (:mod:`~tcp_pendant.classroom.class_settings`)
``book.presence``             who is connected on which server process, who left
                              (:mod:`~tcp_pendant.classroom.presence`)
``book.pushes``               the trainer's pushes, in order (:mod:`~tcp_pendant.classroom.class_pushes`)
``book.messages``             the trainer's messages not dismissed yet
                              (:mod:`~tcp_pendant.classroom.waiting_messages`)
``book.token_failures``       wrong trainer tokens per source address
                              (:mod:`~tcp_pendant.classroom.token_failures`)
``book.uptime``               when each server process was up, for clocks without the downtime
                              (:mod:`~tcp_pendant.classroom.uptime`)
============================  =====================================================================
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from tcp_pendant.classroom.class_board import BoardReader
from tcp_pendant.classroom.class_pushes import ClassPushes
from tcp_pendant.classroom.class_settings import ClassSettings
from tcp_pendant.classroom.grade_rows import Grades
from tcp_pendant.classroom.gradebook_open import open_store
from tcp_pendant.classroom.presence import Presence
from tcp_pendant.classroom.run_states import RunStates
from tcp_pendant.classroom.token_failures import TokenFailures
from tcp_pendant.classroom.trainees import Trainees
from tcp_pendant.classroom.uptime import ServerUptime
from tcp_pendant.classroom.training_records import TrainingRecords
from tcp_pendant.classroom.waiting_messages import WaitingMessages

__all__ = ["Gradebook"]


class Gradebook:
    """The class gradebook in one SQLite file or one PostgreSQL database (see the module docstring).

    Args:
        path: the database file, or a ``postgresql://USER[:PASSWORD]@HOST[:PORT]/DATABASE`` URL
            (a ``str``; psycopg 3 needed); None = ``gradebook_open.default_gradebook_path()``
            (its folder is created).
        create: make a new gradebook if the file does not exist or the database has no tables
            yet (False: :class:`~tcp_pendant.classroom.gradebook_store.GradebookError`, as
            ``tcp-pendant grades`` wants).
        synchronous: SQLite: "FULL" (default: every commit fsynced, survives a power cut) or
            "NORMAL" (survives a kill -9 of the server but maybe not a power cut; no fsync per
            commit). PostgreSQL: the server's ``synchronous_commit`` decides.
        busy_timeout_s: how long a write waits for another process (or machine) holding the
            file or a row; with PostgreSQL also the connect timeout.

    Attributes:
        path: the SQLite file, or None for PostgreSQL.
        location: what messages name: the file's path, or the URL with its password masked.

    Its parts (module docstring) are the attributes ``store``, ``trainees``, ``records``,
    ``run_states``, ``grades``, ``board``, ``settings``, ``presence``, ``pushes``, ``messages``,
    ``token_failures`` and ``uptime``.

    Raises:
        GradebookError: the file is not an SQLite database, is damaged, is another program's
            database, was written by a newer TCP Pendant, or cannot be opened; the PostgreSQL
            server cannot be reached or the URL is malformed; the message names the file (the
            URL without its password) and what to do. Nothing is written to such a file.
    """

    def __init__(self, path: Path | str | None = None, *, create: bool = True,
                 synchronous: Literal["FULL", "NORMAL"] = "FULL", busy_timeout_s: float = 5.0) -> None:
        self.store = store = open_store(path, create=create, synchronous=synchronous,
                                        busy_timeout_s=busy_timeout_s)
        self.path: Path | None = store.path
        self.location = store.location
        self.trainees = Trainees(store)
        self.records = TrainingRecords(store)
        self.run_states = RunStates(store)
        self.grades = Grades(store)
        self.board = BoardReader(store)
        self.settings = ClassSettings(store)
        self.presence = Presence(store)
        self.pushes = ClassPushes(store)
        self.messages = WaitingMessages(store)
        self.token_failures = TokenFailures(store)
        self.uptime = ServerUptime(store)

    def close(self) -> None:
        """Close the connection (idempotent); later calls raise ``GradebookError``."""
        self.store.close()

    def __enter__(self) -> Gradebook:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"Gradebook({self.location!r})"
