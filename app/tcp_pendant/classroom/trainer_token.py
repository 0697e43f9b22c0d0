"""The trainer token: its rules, where it comes from, and a brake on guessing it.

The token opens the trainer view (the whole class's grades and settings), so a trainee must not
be able to guess it: it has at least :data:`MIN_TOKEN_CHARS` characters (the random default has
22), and each browser may try :data:`FREE_TRIES` wrong tokens; after that every wrong one locks
that browser out for a window that doubles each time (1 s, 2 s, 4 s, ... up to
:data:`MAX_LOCK_S`), during which no token is even compared. Each wrong try is logged with at
most a two-character prefix of what was typed.

It can be given on the command line (``--trainer-token``, which shows in the process list), in a
file (``--trainer-token-file PATH``: its first line) or in the environment
(:data:`TOKEN_ENV`); :func:`resolve_trainer_token` picks one.
"""

from __future__ import annotations

import dataclasses
import logging
import os
from collections.abc import Mapping
from pathlib import Path

__all__ = ["FREE_TRIES", "MAX_LOCK_S", "MAX_TOKEN_CHARS", "MIN_TOKEN_CHARS", "TOKEN_ENV", "TokenAttempts",
           "TrainerTokenError", "TrainerTokenLocked", "resolve_trainer_token", "validate_trainer_token"]

log = logging.getLogger(__name__)

MIN_TOKEN_CHARS = 16
MAX_TOKEN_CHARS = 200
TOKEN_ENV = "TCP_PENDANT_TRAINER_TOKEN"
"""Environment variable holding the trainer token (used when no option gives one)."""
FREE_TRIES = 5
"""Wrong tokens a browser may type before it is locked out."""
FIRST_LOCK_S = 1.0
MAX_LOCK_S = 300.0


class TrainerTokenError(ValueError):
    """A trainer token that breaks the rules, or options that give two."""


class TrainerTokenLocked(ValueError):
    """A browser typed too many wrong tokens: it must wait (the message says how long)."""


def validate_trainer_token(token: str, source: str = "--trainer-token") -> str:
    """``token`` if it has 16 to 200 printable characters.

    Raises:
        TrainerTokenError: naming ``source`` and the rule.
    """
    if not (MIN_TOKEN_CHARS <= len(token) <= MAX_TOKEN_CHARS and token.isprintable()):
        raise TrainerTokenError(f"{source} must be {MIN_TOKEN_CHARS} to {MAX_TOKEN_CHARS} printable characters "
                                f"(got {len(token)}); a random one is made when none is given")
    return token


def resolve_trainer_token(option: str | None, file: Path | None,
                          environ: Mapping[str, str] = os.environ) -> str | None:
    """The trainer token from ``--trainer-token``, else ``--trainer-token-file`` (its first
    line, without the line end), else :data:`TOKEN_ENV`; None when none gives one.

    Raises:
        TrainerTokenError: both options given, an unreadable file, or a token that breaks the
            rules (:func:`validate_trainer_token`).
    """
    if option is not None and file is not None:
        raise TrainerTokenError("give the trainer token once: --trainer-token or --trainer-token-file, not both")
    if option is not None:
        return validate_trainer_token(option)
    if file is not None:
        try:
            text = Path(file).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise TrainerTokenError(f"cannot read --trainer-token-file {file}: {exc}") from None
        lines = text.splitlines()
        return validate_trainer_token(lines[0] if lines else "", f"the first line of {file}")
    value = environ.get(TOKEN_ENV)
    if value:
        return validate_trainer_token(value, TOKEN_ENV)
    return None


@dataclasses.dataclass
class TokenAttempts:
    """The wrong tokens of one browser (times in seconds of a monotonic clock).

    Attributes:
        failures: wrong tokens so far.
        locked_until: no token is compared before this time.
    """

    failures: int = 0
    locked_until: float = 0.0

    def wait_s(self, now: float) -> float:
        """Seconds until a token may be tried again (0: now)."""
        return max(0.0, self.locked_until - now)

    def failed(self, now: float, who: str, typed: str) -> None:
        """A wrong token: count and log it; from the :data:`FREE_TRIES`-th on, lock for
        1 s, 2 s, 4 s, ... (at most :data:`MAX_LOCK_S`)."""
        self.failures += 1
        prefix = typed[:2] + "..." if len(typed) > 2 else "..."
        log.warning("wrong trainer token from %s (try %d, %d characters, %r)", who, self.failures, len(typed), prefix)
        if self.failures >= FREE_TRIES:
            lock = min(MAX_LOCK_S, FIRST_LOCK_S * 2.0 ** (self.failures - FREE_TRIES))
            self.locked_until = now + lock
            log.warning("trainer token: %s typed %d wrong tokens; no token is tried from it for %.0f s",
                        who, self.failures, lock)

    def check(self, now: float) -> None:
        """Raise :class:`TrainerTokenLocked` while this browser is locked out."""
        wait = self.wait_s(now)
        if wait > 0:
            raise TrainerTokenLocked(f"Too many wrong trainer tokens from this browser: try again in "
                                     f"{max(1, round(wait))} s.")
