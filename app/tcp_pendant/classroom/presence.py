"""Who is connected to the class, on which server process, and who left (tables ``presence``
and ``departures``), for every server process of the class (``tcp-pendant --workers N``,
several machines on one PostgreSQL gradebook).

Each process holds the names of its connected trainees under its own id (``holder``,
``ClassRoom.holder``) and beats them every second with their row of the trainer's live table
(``status``: a JSON object); a row whose holder stopped beating for ``stale_s`` (killed) counts
as gone. A trainee whose browser left is kept with their last row until they connect again.
Times: Unix time, seconds (``now`` defaults to ``time.time()``).
"""

from __future__ import annotations

import json
import time
from collections.abc import Mapping, Sequence

from tcp_pendant.classroom.gradebook_store import GradebookError, GradebookStore
from tcp_pendant.json_shapes import JsonRecord

__all__ = ["MAX_STATUS_BYTES", "PRESENCE_STALE_S", "Presence"]

PRESENCE_STALE_S = 10.0
"""A presence row whose holder has not beaten for this long (seconds) counts as gone."""
MAX_STATUS_BYTES = 4_000
"""A presence row's status above this is refused (a trainer's row is ~200 bytes)."""


def _status_text(status: Mapping[str, object]) -> str:
    text = json.dumps(dict(status), sort_keys=True, allow_nan=False)
    if len(text) > MAX_STATUS_BYTES:
        raise GradebookError(f"A trainee's status of {len(text):,} bytes is above {MAX_STATUS_BYTES:,}.")
    return text


class Presence:
    """Who is connected, where, and who left, in the gradebook behind ``store`` (see the module
    docstring)."""

    def __init__(self, store: GradebookStore) -> None:
        self._store = store

    def holder(self, name: str, *, stale_s: float = PRESENCE_STALE_S, now: float | None = None) -> str | None:
        """The holder (a server process's id) whose browser is connected under ``name`` now,
        None when none is (no row, or its holder stopped beating ``stale_s`` ago)."""
        t = time.time() if now is None else now
        with self._store.read() as db:
            row = db.execute("SELECT holder, seen_at FROM presence WHERE name = ?", (str(name),)).fetchone()
        return None if row is None or t - float(row[1]) > stale_s else str(row[0])

    def claim(self, name: str, holder: str, status: Mapping[str, object], *, now: float | None = None) -> str | None:
        """``holder`` now holds the connected name ``name`` (the caller has checked that it may:
        a name held elsewhere is taken over only by the same browser). Returns the holder it
        took the name from (None: nobody else held it)."""
        text = _status_text(status)
        t = time.time() if now is None else now
        with self._store.write() as db:
            row = db.execute("SELECT holder FROM presence WHERE name = ?", (str(name),)).fetchone()
            if row is None:
                db.execute("INSERT INTO presence (name, holder, seen_at, status_json) VALUES (?, ?, ?, ?)",
                           (str(name), str(holder), t, text))
                return None
            db.execute("UPDATE presence SET holder = ?, seen_at = ?, status_json = ? WHERE name = ?",
                       (str(holder), t, text, str(name)))
            return None if row[0] == holder else str(row[0])

    def drop(self, name: str, holder: str | None = None) -> bool:
        """The browser connected under ``name`` left (``holder``: only if that process still
        holds it; None: whoever holds it, the trainer's release). Returns whether a row went."""
        with self._store.write() as db:
            if holder is None:
                return db.execute("DELETE FROM presence WHERE name = ?", (str(name),)).rowcount > 0
            return db.execute("DELETE FROM presence WHERE name = ? AND holder = ?",
                              (str(name), str(holder))).rowcount > 0

    def beat(self, holder: str, statuses: Mapping[str, Mapping[str, object]], *, now: float | None = None) -> set[str]:
        """The heartbeat of ``holder``: the names it holds get ``seen_at = now`` and their
        status. Returns the names of ``statuses`` it still holds (one another process took over,
        or the trainer released, is missing)."""
        if not statuses:
            return set()                          # nothing to renew: no write, no fsync
        t = time.time() if now is None else now
        rows = [(t, _status_text(st), str(name), str(holder)) for name, st in statuses.items()]
        with self._store.write() as db:
            db.executemany("UPDATE presence SET seen_at = ?, status_json = ? WHERE name = ? AND holder = ?", rows)
            held = {str(r[0]) for r in db.execute("SELECT name FROM presence WHERE holder = ?", (str(holder),))}
        return held & set(statuses)

    def present(self, *, stale_s: float = PRESENCE_STALE_S,
                now: float | None = None) -> list[tuple[str, str, JsonRecord]]:
        """``(name, holder, status)`` of every connected trainee of every server process, by
        name (rows whose holder stopped beating ``stale_s`` ago are left out)."""
        t = time.time() if now is None else now
        with self._store.read() as db:
            rows = db.execute("SELECT name, holder, status_json FROM presence WHERE seen_at >= ? ORDER BY name",
                              (t - stale_s,)).fetchall()
        return [(str(n), str(h), json.loads(st)) for n, h, st in rows]

    def drop_holder(self, holder: str) -> int:
        """A server process stops: every name it holds is free (returns how many)."""
        with self._store.write() as db:
            return db.execute("DELETE FROM presence WHERE holder = ?", (str(holder),)).rowcount

    # -- who left, for every server process of the class --------------------------------

    def depart(self, name: str, status: Mapping[str, object], *, now: float | None = None) -> None:
        """The browser of ``name`` left the class (on whichever process): keep ``status`` (the
        trainee's row as it was when they left) and when."""
        text = _status_text(status)
        t = time.time() if now is None else now
        with self._store.write() as db:
            db.execute("INSERT INTO departures (name, left_at, status_json) VALUES (?, ?, ?) ON CONFLICT(name) "
                       "DO UPDATE SET left_at = excluded.left_at, status_json = excluded.status_json",
                       (str(name), t, text))

    def departed(self, *, stale_s: float = PRESENCE_STALE_S,
                 now: float | None = None) -> Sequence[tuple[str, JsonRecord]]:
        """``(name, status)`` of every trainee who was connected and is not now, on any server
        process, the latest to leave first: those who left (:meth:`depart`) and those whose
        server process stopped beating ``stale_s`` ago (killed: their last beaten row), with
        ``status["connected"]`` false."""
        t = time.time() if now is None else now
        with self._store.read() as db:
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
