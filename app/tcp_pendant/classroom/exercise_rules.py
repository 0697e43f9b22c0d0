"""The class's exercise rules: what a trainer may set and the class's defaults (no viser).

A trainer's exercise asks the trainee to find a tool's frame by touching; the pendant must not
hand them the answer. The classroom makes each trainee's
:class:`~tcp_pendant.calibrate.pendant_rules.ExerciseRules` here (:func:`class_rules`) and gives
it to the session (``Session.set_rules``), which refuses what it forbids
(``calibrate.pendant_rules`` says what each rule does).

In an exercise the defaults are the strict ones: the distance aids are locked and Auto-touch is
off; the trainer view can unlock the aids and allow Auto-touch for the class. The trainer's
instructions are plain text of at most :data:`MAX_INSTRUCTIONS_CHARS` characters
(:func:`clean_instructions`), the minimum number of touches 0..:data:`MAX_MIN_TOUCHES`
(:func:`clean_min_touches`).
"""

from __future__ import annotations

from typing import Literal

from tcp_pendant.calibrate.pendant_rules import ExerciseRules

__all__ = [
    "DISTANCE_AIDS",
    "MAX_INSTRUCTIONS_CHARS",
    "MAX_MIN_TOUCHES",
    "DistanceAids",
    "class_rules",
    "clean_instructions",
    "clean_min_touches",
]

DistanceAids = Literal["locked", "hidden", "shown"]
"""The class's distance aids as the trainer sets them: ``locked`` (hidden, the trainee cannot
show them), ``hidden`` (hidden, the trainee may show them), ``shown``."""
DISTANCE_AIDS: tuple[str, ...] = ("locked", "hidden", "shown")

MAX_INSTRUCTIONS_CHARS = 2000
"""The longest instructions an exercise carries (characters, after trimming)."""
MAX_MIN_TOUCHES = 20
"""The largest minimum number of touches (the XYZ 4-point wizard takes at most 20)."""


def clean_instructions(text: object) -> str:
    """The trainer's instructions as kept: a string, trimmed, line endings as ``\\n``, control
    characters other than line breaks and tabs dropped; plain text (escaped where shown).

    Raises:
        ValueError: not text, or longer than :data:`MAX_INSTRUCTIONS_CHARS` (says how long).
    """
    if not isinstance(text, str):
        raise ValueError(f"The exercise instructions must be text, got {type(text).__name__}.")
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    text = "".join(ch for ch in text if ch in "\n\t" or ch.isprintable()).strip()
    if len(text) > MAX_INSTRUCTIONS_CHARS:
        raise ValueError(f"The exercise instructions are {len(text)} characters long; shorten them to at most "
                         f"{MAX_INSTRUCTIONS_CHARS}.")
    return text


def clean_min_touches(value: object) -> int:
    """A minimum number of touches: a whole number 0..:data:`MAX_MIN_TOUCHES` (0: none).

    Raises:
        ValueError: not a whole number in that range (names it).
    """
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= MAX_MIN_TOUCHES:
        raise ValueError(f"The minimum number of touches must be a whole number from 0 to {MAX_MIN_TOUCHES}, "
                         f"got {value!r:.40}.")
    return value


def class_rules(exercise: str | None, aids: DistanceAids | None = None,
                auto_touch: bool | None = None, *, instructions: str = "",
                allowed_methods: tuple[str, ...] | None = None, min_touches: int = 0) -> ExerciseRules:
    """The rules of a class: ``aids`` and ``auto_touch`` as the trainer set them (None: the
    default - in an exercise the aids are locked and Auto-touch is off; in free practice
    nothing is locked and Auto-touch is allowed); the trainer's instructions, methods and
    minimum number of touches as they are (checked by the classroom).

    Raises:
        ValueError: an unknown ``aids`` value (names the choices).
    """
    if aids is not None and aids not in DISTANCE_AIDS:
        raise ValueError(f"Unknown distance aids setting {aids!r}; use one of {', '.join(DISTANCE_AIDS)}.")
    strict = exercise is not None
    locked = (aids == "locked") if aids is not None else strict
    allowed = bool(auto_touch) if auto_touch is not None else not strict
    return ExerciseRules(exercise=exercise, distance_locked=locked, auto_touch_allowed=allowed,
                         instructions=instructions, allowed_methods=allowed_methods, min_touches=min_touches)
