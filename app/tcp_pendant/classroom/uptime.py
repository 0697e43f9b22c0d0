"""When the class's server was up, so that the trainer's clocks leave its downtime out (table
``server_uptime``, for every server process of the class).

Each server process keeps one row under its id (``ClassRoom.holder``): when it started and when
it last beat (``ClassRoom.beat``, at most every :data:`UPTIME_BEAT_S`; once more when it
stops). The class was down between the end of one stretch of beats and the start of the next
(:func:`downtimes`): a ``kill -9`` and a restart, or the night between two lessons. The
dashboard's "On step", "Last touch", stuck and idle clocks subtract those gaps
(``classroom.board.active_seconds``).

A killed process beat at most :data:`UPTIME_BEAT_S` before it died, so a gap may hold up to
that much time the server was still up: a clock is short by at most that per restart, never
long. Times: Unix time, seconds.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterable

from tcp_pendant.classroom.gradebook_store import GradebookStore

__all__ = ["UPTIME_BEAT_S", "UPTIME_QUERY", "ServerUptime", "downtimes"]

UPTIME_BEAT_S = 5.0
"""A process writes its ``seen_at`` at most this often (seconds): one small write, not one a second."""
UPTIME_QUERY = "SELECT started_at, seen_at FROM server_uptime"
"""The stretches of every process, for :func:`downtimes` (``BoardReader.read`` runs it in its read)."""


def downtimes(stretches: Iterable[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    """The gaps ``(from, to)`` (Unix seconds, oldest first) between the up stretches
    ``(started_at, seen_at)`` of the class's server processes: the time no process was up.
    Overlapping stretches (``--workers N``, a restart while another process ran) merge."""
    out = []
    end: float | None = None
    for start, seen in sorted((float(a), float(b)) for a, b in stretches):
        if end is not None and start > end:
            out.append((end, start))
        end = seen if end is None else max(end, seen)
    return tuple(out)


class ServerUptime:
    """The up stretches of the class's server processes in the gradebook behind ``store``
    (module docstring)."""

    def __init__(self, store: GradebookStore) -> None:
        self._store = store
        self._lock = threading.Lock()
        self._written: dict[str, float] = {}      # holder -> when its row was last written (time.time)

    def beat(self, holder: str, *, now: float | None = None, force: bool = False) -> bool:
        """``holder`` is up at ``now``: its row is made (``started_at = now``) or its
        ``seen_at`` moved to ``now``, unless it was written less than :data:`UPTIME_BEAT_S`
        ago (``force``: written anyway, as when the process stops). Returns whether it wrote."""
        t = time.time() if now is None else float(now)
        with self._lock:
            last = self._written.get(holder)
            if not force and last is not None and t - last < UPTIME_BEAT_S:
                return False
            self._written[holder] = t
        with self._store.write() as db:
            db.execute("INSERT INTO server_uptime (holder, started_at, seen_at) VALUES (?, ?, ?) ON CONFLICT(holder) "
                       "DO UPDATE SET seen_at = excluded.seen_at", (str(holder), t, t))
        return True

    def downtimes(self) -> tuple[tuple[float, float], ...]:
        """The gaps no server process of the class was up (:func:`downtimes`)."""
        with self._store.read() as db:
            rows = db.execute(UPTIME_QUERY).fetchall()
        return downtimes(rows)
