"""Wrong trainer tokens by the address they came from (table ``token_failures``), for every
server process of the class: the lockout (``classroom.trainer_token``) counts them whichever
process a browser reaches, and after a restart. Times: Unix seconds."""

from __future__ import annotations

from collections.abc import Callable

from tcp_pendant.classroom.gradebook_db import only_row
from tcp_pendant.classroom.gradebook_store import GradebookStore

__all__ = ["MAX_SOURCE_CHARS", "TokenFailures"]

MAX_SOURCE_CHARS = 100
"""A token try's source (an address) is cut to this many characters."""


class TokenFailures:
    """The wrong trainer tokens kept in the gradebook behind ``store`` (see the module docstring)."""

    def __init__(self, store: GradebookStore) -> None:
        self._store = store

    def try_token(self, source: str, *, now: float, forget_s: float,
                  lock_s: Callable[[int], float]) -> tuple[float, int, bool]:
        """One try of the trainer token from ``source`` (an address), counted before the token
        is compared, in one transaction (so no try slips between the processes of the class):
        failures older than ``forget_s`` are forgotten (every source's); when the source's
        ``n`` failures, the last at ``t``, lock it (``t + lock_s(n) > now``) nothing is counted;
        otherwise one failure is stored, to be forgiven (:meth:`forgive`) if the token is right.
        Times: Unix seconds.

        Returns:
            ``(wait_s, failures, counted)``: seconds still locked (0 when counted), the source's
            failures with this try, whether this try was counted (False: locked, do not compare).
        """
        src = str(source)[:MAX_SOURCE_CHARS]
        with self._store.write() as db:
            db.serialize("token failures")
            db.execute("DELETE FROM token_failures WHERE failed_at < ?", (float(now) - float(forget_s),))
            n, last = only_row(db.execute("SELECT COUNT(*), MAX(failed_at) FROM token_failures WHERE source = ?",
                                          (src,)))
            n = int(n)
            if n and float(last) + lock_s(n) > now:
                return float(last) + lock_s(n) - now, n, False
            db.execute("INSERT INTO token_failures (source, failed_at) VALUES (?, ?)", (src, float(now)))
        return 0.0, n + 1, True

    def forgive(self, source: str) -> int:
        """The right token came from ``source``: its failures are forgotten (returns how many)."""
        with self._store.write() as db:
            return db.execute("DELETE FROM token_failures WHERE source = ?",
                              (str(source)[:MAX_SOURCE_CHARS],)).rowcount
