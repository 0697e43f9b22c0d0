"""The trainer token: its rules, where it comes from, and a brake on guessing it.

The token opens the trainer view (the whole class's grades and settings), so a trainee must not
be able to guess it: it has at least :data:`MIN_TOKEN_CHARS` characters (the random default has
22), and each source address may try :data:`FREE_TRIES` wrong tokens; after that every wrong one
locks that address out for a window that doubles each time (1 s, 2 s, 4 s, ... up to
:data:`MAX_LOCK_S`, :func:`lock_s`), during which no token is even compared. Each wrong try is
logged with at most a two-character prefix of what was typed (:func:`log_failure`).

The wrong tries are counted in the class gradebook (``Gradebook.token_failures.try_token``: table
``token_failures``), per source address and for every server process of the class, so a
reconnect that lands on another process (``--workers``, several machines) or a restart of the
server does not give new tries; a try is counted before its token is compared, and a right token
forgives its address's failures. Failures :data:`FORGET_S` old are forgotten. Times there are
Unix seconds (the machines' clocks).

It can be given on the command line (``--trainer-token``, which shows in the process list), in a
file (``--trainer-token-file PATH``: its first line) or in the environment
(:data:`TOKEN_ENV`); :func:`resolve_trainer_token` picks one.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping
from pathlib import Path

from tcp_pendant.controller.words import Words
from tcp_pendant.translation import N_

__all__ = ["FORGET_S", "FREE_TRIES", "MAX_LOCK_S", "MAX_TOKEN_CHARS", "MIN_TOKEN_CHARS", "TOKEN_ENV",
           "TrainerTokenError", "TrainerTokenLocked", "lock_s", "locked", "log_failure", "resolve_trainer_token",
           "validate_trainer_token"]

log = logging.getLogger(__name__)

MIN_TOKEN_CHARS = 16
MAX_TOKEN_CHARS = 200
TOKEN_ENV = "TCP_PENDANT_TRAINER_TOKEN"
"""Environment variable holding the trainer token (used when no option gives one)."""
FREE_TRIES = 5
"""Wrong tokens a browser may type before it is locked out."""
FIRST_LOCK_S = 1.0
MAX_LOCK_S = 300.0
FORGET_S = 3600.0
"""A wrong token this old (seconds) no longer counts."""


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


def lock_s(failures: int) -> float:
    """Seconds a source is locked after its ``failures``-th wrong token: 0 before
    :data:`FREE_TRIES`, then 1 s, 2 s, 4 s, ... at most :data:`MAX_LOCK_S`."""
    if failures < FREE_TRIES:
        return 0.0
    return min(MAX_LOCK_S, FIRST_LOCK_S * 2.0 ** (failures - FREE_TRIES))


def locked(wait_s: float) -> TrainerTokenLocked:
    """The refusal of a try ``wait_s`` seconds before the lock ends (the trainee's words)."""
    return TrainerTokenLocked(Words(N_("Too many wrong trainer tokens from this browser: try again in {seconds} s."),
                                    seconds=str(max(1, round(wait_s)))))


def log_failure(who: str, failures: int, typed: str) -> None:
    """Log a wrong token (the ``failures``-th of its source) with a two-character prefix of
    ``typed``, and the lock it starts from the :data:`FREE_TRIES`-th on."""
    prefix = typed[:2] + "..." if len(typed) > 2 else "..."
    log.warning("wrong trainer token from %s (try %d, %d characters, %r)", who, failures, len(typed), prefix)
    if failures >= FREE_TRIES:
        log.warning("trainer token: %s typed %d wrong tokens; no token is tried from it for %.0f s",
                    who, failures, lock_s(failures))
