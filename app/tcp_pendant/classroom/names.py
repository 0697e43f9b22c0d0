"""The trainee's name ("Your name"): what the pendant accepts and how it is normalised.

A name is what the trainer reads in the gradebook, so it must be visible text: after
:func:`validate_trainee_name` it is NFC-normalised (the same letters typed on two keyboards give
the same name), stripped, runs of spaces are one space, it has 1..40 characters and no control,
format or other invisible character.

Why not ``tcpcal.tool``'s tool-name check: that check is private (``_check_name``) and carries
a controller's rules that do not apply to people (at most 24 characters, no double quote, no
surrounding spaces instead of stripping them). The rule both share is Python's
``str.isprintable`` (no Unicode category C*, no separator but the space), used here as there;
on top of it this module refuses the few *letters* that draw nothing (Hangul fillers, the
braille blank), which ``isprintable`` lets through.

Names are data: the views must still show them through ``escape_markdown``.
"""

from __future__ import annotations

import re
import unicodedata
from typing import Any

__all__ = ["MAX_TRAINEE_NAME_LENGTH", "TraineeNameError", "validate_trainee_name"]

MAX_TRAINEE_NAME_LENGTH: int = 40
"""Longest trainee name, in characters (after normalisation)."""

#: Printable by ``str.isprintable`` but drawn as nothing: a name made of them looks empty.
_BLANK_LETTERS = frozenset("\u115f\u1160\u3164\uffa0\u2800")
_SPACES = re.compile(" {2,}")


class TraineeNameError(ValueError):
    """A name the pendant does not accept; the message says why and what to type instead."""


def validate_trainee_name(text: Any) -> str:
    """Check and normalise a trainee's name.

    Args:
        text: what the browser sent (anything; only a str can pass).

    Returns:
        The name as stored and shown: NFC, stripped, single spaces, 1..40 characters.

    Raises:
        TraineeNameError: not a string, empty, longer than 40 characters, or holding a control
            or invisible character (the message names it by its code point and Unicode name).
    """
    if not isinstance(text, str):
        raise TraineeNameError(f"a name must be text, got {type(text).__name__}; type your name.")
    name = _SPACES.sub(" ", unicodedata.normalize("NFC", text).strip())
    for ch in name:
        if not ch.isprintable() or ch in _BLANK_LETTERS:
            what = unicodedata.name(ch, unicodedata.category(ch))
            raise TraineeNameError(
                f"your name contains an invisible or control character, U+{ord(ch):04X} ({what}); "
                "type it again with visible letters only.")
    if not name:
        raise TraineeNameError("your name is empty; type the name your trainer should see "
                               f"(1 to {MAX_TRAINEE_NAME_LENGTH} characters).")
    if len(name) > MAX_TRAINEE_NAME_LENGTH:
        raise TraineeNameError(f"your name has {len(name)} characters; shorten it to at most "
                               f"{MAX_TRAINEE_NAME_LENGTH}.")
    return name
