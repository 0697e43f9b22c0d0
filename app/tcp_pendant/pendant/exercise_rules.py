"""What a classroom exercise allows the trainee's pendant (no viser).

A trainer's exercise asks the trainee to find a tool's frame by touching; the pendant must not
hand them the answer. :class:`ExerciseRules` is the session's copy of the class's rules (the
classroom sets it, ``Session.set_rules``); the session's commands refuse what it forbids, in
words, whatever a browser sends (a disabled checkbox is only the polite half):

* ``distance_locked``: "Hide distance" is on and stays on - the distance, the Δ line, the text
  close-up, the stop at the tip and its message are off (the trainee judges the touch by eye);
* ``auto_touch_allowed``: Auto-touch (the robot touches for the trainee) may be used;
* ``in_exercise``: the spin-test Check shows a technician's reading only
  (:data:`CHECK_READING_MM`, ``pendant.spin_reading``).

Free practice (no exercise): nothing is locked, Auto-touch is allowed, the Check shows all it
computes. In an exercise the defaults are the strict ones (:func:`class_rules`); the trainer
view can unlock the distance aids and allow Auto-touch for the class.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from tcp_pendant.controller.errors import ControllerError

__all__ = [
    "AUTO_TOUCH_REFUSED",
    "DISTANCE_AIDS",
    "DISTANCE_LOCKED",
    "DistanceAids",
    "ExerciseRules",
    "FREE_PRACTICE",
    "RuleRefusal",
    "class_rules",
]

DistanceAids = Literal["locked", "hidden", "shown"]
"""The class's distance aids as the trainer sets them: ``locked`` (hidden, the trainee cannot
show them), ``hidden`` (hidden, the trainee may show them), ``shown``."""
DISTANCE_AIDS: tuple[str, ...] = ("locked", "hidden", "shown")

DISTANCE_LOCKED = ("The trainer has locked the distance aids for this exercise: judge the touch by eye, "
                   "as on a real robot (the distance, the Δ line and the stop at the tip stay off).")
AUTO_TOUCH_REFUSED = ("Auto-touch is off in this exercise: the robot would touch for you. Jog the tool tip "
                      "onto the reference tip and press Record (the trainer can allow Auto-touch).")


class RuleRefusal(ControllerError):
    """A command the exercise forbids (a ``ValueError``: the session shows it as a warning)."""


@dataclass(frozen=True)
class ExerciseRules:
    """The rules one trainee's pendant follows (see the module docstring).

    Attributes:
        exercise: the exercise id (e.g. "mystery"), None in free practice.
        distance_locked: "Hide distance" is on and cannot be switched off.
        auto_touch_allowed: Auto-touch may be used.
    """

    exercise: str | None = None
    distance_locked: bool = False
    auto_touch_allowed: bool = True

    @property
    def in_exercise(self) -> bool:
        return self.exercise is not None

    def check_hide_distance(self, hide: bool) -> None:
        """Refuse showing the distance while it is locked.

        Raises:
            RuleRefusal: ``hide`` is False and the distance aids are locked.
        """
        if self.distance_locked and not hide:
            raise RuleRefusal(DISTANCE_LOCKED)

    def check_auto_touch(self) -> None:
        """Refuse Auto-touch where the exercise forbids it.

        Raises:
            RuleRefusal: Auto-touch is not allowed.
        """
        if not self.auto_touch_allowed:
            raise RuleRefusal(AUTO_TOUCH_REFUSED)


FREE_PRACTICE = ExerciseRules()


def class_rules(exercise: str | None, aids: DistanceAids | None = None,
                auto_touch: bool | None = None) -> ExerciseRules:
    """The rules of a class: ``aids`` and ``auto_touch`` as the trainer set them (None: the
    default - in an exercise the aids are locked and Auto-touch is off; in free practice
    nothing is locked and Auto-touch is allowed).

    Raises:
        ValueError: an unknown ``aids`` value (names the choices).
    """
    if aids is not None and aids not in DISTANCE_AIDS:
        raise ValueError(f"Unknown distance aids setting {aids!r}; use one of {', '.join(DISTANCE_AIDS)}.")
    strict = exercise is not None
    locked = (aids == "locked") if aids is not None else strict
    allowed = bool(auto_touch) if auto_touch is not None else not strict
    return ExerciseRules(exercise=exercise, distance_locked=locked, auto_touch_allowed=allowed)
