"""Refusal notices of one session, coalesced (no viser).

A click refused at once ("a TCP check is still running here", "busy, try again in 2 s") is
shown as a notification; a browser that clicks faster than it reads would otherwise be sent one
notification per click (each a message encoded and written on viser's event loop, and a toast
stacked in its page). The rule: at most one refusal notice per session every ``quiet_s``
(:data:`QUIET_S`, 2 s); the clicks refused meanwhile are counted and named in the next notice
shown ("3 more clicks were refused meanwhile"). A trainee who clicks once sees every refusal.
"""

from __future__ import annotations

import time
from collections.abc import Callable

__all__ = ["QUIET_S", "RefusalNotices"]

QUIET_S = 2.0
"""At most one refusal notice per session within this many seconds."""


def _more_in_english(n: int) -> str:
    return f"({n} more {'click was' if n == 1 else 'clicks were'} refused meanwhile.)"


class RefusalNotices:
    """Decides which refusals of one session are shown (module docstring).

    Args:
        quiet_s: the least time between two notices shown.
        clock: seconds, monotonic (injectable for tests).

    Attributes:
        shown, suppressed: refusals shown, and not shown, so far.
    """

    def __init__(self, quiet_s: float = QUIET_S, clock: Callable[[], float] = time.monotonic,
                 more_words: Callable[[int], str] | None = None) -> None:
        self.quiet_s = float(quiet_s)
        self.more_words = more_words
        """How many refusals were left out, in words (the session's language); None: English."""
        self._clock = clock
        self._last_s: float | None = None
        self._pending = 0
        self.shown = 0
        self.suppressed = 0

    def body(self, body: str, more_words: Callable[[int], str] | None = None) -> str | None:
        """The body to show for a refusal with ``body`` now, or None when it is not shown;
        ``more_words(n)`` (else the notices' own :attr:`more_words`, else English) says how
        many were left out since the last one shown."""
        now = self._clock()
        if self._last_s is not None and now - self._last_s < self.quiet_s:
            self._pending += 1
            self.suppressed += 1
            return None
        self._last_s = now
        more, self._pending = self._pending, 0
        self.shown += 1
        if more:
            said = (more_words or self.more_words or _more_in_english)(more)
            body = f"{body} {said}"
        return body
