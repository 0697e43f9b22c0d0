"""The class's trainer token and the check of a token a browser typed (no viser).

A :class:`TrainerLogin` holds the token's SHA-256, kept in the gradebook's class settings
(:data:`TOKEN_SETTING`) so the trainer's address keeps working after a restart without the token
being stored. :meth:`TrainerLogin.check` counts every try per source address in the gradebook
before comparing (``Gradebook.token_failures``, the rules in ``classroom.trainer_token``), so the
lockout holds on every server process of the class; the right token forgives its address's.
"""

from __future__ import annotations

import hashlib
import logging
import secrets

from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.gradebook_store import GradebookError
from tcp_pendant.classroom.trainer_token import FORGET_S, lock_s, locked, log_failure, validate_trainer_token
from tcp_pendant.controller.words import Words
from tcp_pendant.translation import N_

__all__ = ["TOKEN_SETTING", "TrainerLogin"]

log = logging.getLogger(__name__)

TOKEN_SETTING = "trainer_token_sha256"
"""The class setting that keeps the trainer token's SHA-256 (hex) in the gradebook, so the
trainer's address keeps working after a restart without the token being stored."""


def _token_digest(token: str) -> str:
    # A random token has 128 bits and a given one at least 16 characters: a plain SHA-256 is
    # enough for a file that holds the class's answers anyway.
    return hashlib.sha256(str(token).encode("utf-8")).hexdigest()


class TrainerLogin:
    """The trainer token of the class of ``gradebook`` (module docstring).

    Args:
        gradebook: the class gradebook (the token's hash and the wrong tries are kept there).
        trainer_token: the token (16 to 200 printable characters); None: the one whose hash the
            gradebook keeps, else a new random one.

    Raises:
        TrainerTokenError: a token that breaks the rules.
    """

    def __init__(self, gradebook: Gradebook, trainer_token: str | None) -> None:
        self._gradebook = gradebook
        stored = gradebook.settings.get(TOKEN_SETTING)
        if trainer_token is None and isinstance(stored, str):
            self.token: str | None = None      # the class's token, kept (hashed) in the gradebook
            self._sha256 = stored
        else:
            token = secrets.token_urlsafe(16) if trainer_token is None else trainer_token
            validate_trainer_token(token, "The trainer token")
            self.token = token
            self._sha256 = _token_digest(token)
            gradebook.settings.set(TOKEN_SETTING, self._sha256)

    def check(self, token: str, source: str, now: float, who: str) -> bool:
        """``token`` typed from the address ``source`` at Unix time ``now`` (``who``: the
        browser, for the log) is the trainer token; a wrong one is counted and logged.

        Raises:
            TrainerTokenLocked: ``source`` typed too many wrong tokens; the token was not tried.
            ValueError: the gradebook cannot count the try (the token is not tried either).
        """
        failures = self._gradebook.token_failures
        try:
            wait, count, counted = failures.try_token(source, now=now, forget_s=FORGET_S, lock_s=lock_s)
        except GradebookError as exc:
            log.error("a trainer token was not tried: %s", exc)
            raise ValueError(Words(N_("The class gradebook cannot be read now, so no trainer token is tried; "
                                      "try again in a moment."))) from None
        if not counted:
            raise locked(wait)
        if not secrets.compare_digest(_token_digest(token), self._sha256):
            log_failure(who, count, token)
            return False
        try:
            failures.forgive(source)
        except GradebookError:
            log.exception("the wrong trainer tokens of %s could not be forgiven", source)
        return True
