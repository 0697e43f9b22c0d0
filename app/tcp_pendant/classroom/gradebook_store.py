"""The open gradebook's connection, guarded: one transaction per write, one call at a time,
and the refusals that name the gradebook and say what to do.

Every part of the gradebook (:mod:`tcp_pendant.classroom.gradebook`: trainees, records, the
board, presence, ...) reads and writes through one :class:`GradebookStore`, which
:func:`tcp_pendant.classroom.gradebook_open.open_store` makes.

Durability ("a kill -9 of the server loses nothing that was acknowledged on screen"):

- Every public write is one transaction (``BEGIN IMMEDIATE`` ... ``COMMIT``,
  :meth:`GradebookStore.write`) that has committed when the method returns, so the GUI
  acknowledges *after* the call.
- The file is in WAL mode with ``synchronous=FULL`` (the default here). A kill -9 alone would
  already be survived with ``NORMAL``: SQLite has ``write()``-n the transaction into the ``-wal``
  file before ``COMMIT`` returns and the kernel keeps it after the process dies. ``FULL``
  also fsyncs the WAL at every commit, so an acknowledged touch survives a power cut or a
  kernel crash of the classroom PC too; it costs one fsync per event (human-paced: a touch
  every few seconds per trainee), measured by ``tests/bench/bench_gradebook.py``.
  ``synchronous="NORMAL"`` is accepted for machines whose disk makes the fsync slow.

PostgreSQL: every write is one transaction committed when the method returns (the server's
``synchronous_commit``, on by default, makes it durable). Writes that read before they write
hold a named advisory lock (``db.serialize(NAME)``) or a row lock (``FOR UPDATE``), so servers
on several machines can share one class.

Threads: one connection guarded by a lock (``check_same_thread=False``), so any thread may
call; calls run one at a time. Several processes may share the file (WAL; a writer waits up to
``busy_timeout_s`` for another), several processes and machines the PostgreSQL database.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from tcp_pendant.classroom.gradebook_db import GradebookConnection

__all__ = ["GradebookError", "GradebookStore"]


class GradebookError(Exception):
    """The gradebook cannot be opened or a call is refused; the message names the file or the
    value and says what to do."""


class GradebookStore:
    """One open gradebook connection behind a lock (see the module docstring).

    Args:
        db: the open connection (SQLite file or PostgreSQL database).
        path: the SQLite file, or None for PostgreSQL.

    Attributes:
        path: the SQLite file, or None for PostgreSQL.
        location: what messages name: the file's path, or the URL with its password masked.
    """

    def __init__(self, db: GradebookConnection, path: Path | None) -> None:
        self._db = db
        self._lock = threading.Lock()
        self._closed = False
        self.path = path
        self.location = db.location

    def refusal(self, what: str) -> GradebookError:
        """The error for a gradebook whose content is refused (``what``: "is damaged (...)"):
        it names the gradebook, says nothing was changed and what to do."""
        noun = self._db.noun
        return GradebookError(
            f"Gradebook {self.location} {what}. Nothing was changed in it; keep it for the record, "
            + ("move it aside or give another file with --class-db." if noun == "file"
               else "or give another database with --class-db."))

    def cannot_write(self, exc: BaseException) -> GradebookError:
        """The error for a gradebook that could not be made or brought up to date while opening."""
        if self._db.noun == "file":
            return GradebookError(f"Cannot write the gradebook {self.location}: {exc}; check that its folder "
                                  "is writable and the disk is not full.")
        return GradebookError(f"Cannot write the gradebook {self.location}: {' '.join(str(exc).split())}; "
                              "check that the database user may create tables and write in the database.")

    @contextmanager
    def transaction(self) -> Iterator[GradebookConnection]:
        """One write transaction, committed (and, with FULL, fsynced) on leaving; without the
        lock and the closed check (opening, before any other caller has the store)."""
        db = self._db
        db.begin()
        try:
            yield db
        except BaseException:
            db.rollback()
            raise
        db.commit()

    @contextmanager
    def write(self) -> Iterator[GradebookConnection]:
        """One write: the lock, one transaction committed on leaving; a driver error becomes a
        :class:`GradebookError` saying nothing of the event was stored."""
        with self._lock:
            if self._closed:
                raise GradebookError(f"Gradebook {self.location} is closed.")
            try:
                with self.transaction() as db:
                    yield db
            except self._db.errors as exc:
                raise GradebookError(f"Cannot write the gradebook {self.location}: {' '.join(str(exc).split())}. "
                                     "Nothing of this event was stored; " + (
                                         "check the disk (full? removed?)." if self._db.noun == "file" else
                                         "check that the PostgreSQL server runs and is reachable.")) from exc

    @contextmanager
    def read(self) -> Iterator[GradebookConnection]:
        """One read under the lock; a driver error becomes a :class:`GradebookError`."""
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
