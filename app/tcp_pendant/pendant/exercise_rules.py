"""What a classroom exercise allows the trainee's pendant (no viser).

A trainer's exercise asks the trainee to find a tool's frame by touching; the pendant must not
hand them the answer. :class:`ExerciseRules` is the session's copy of the class's rules (the
classroom sets it, ``Session.set_rules``); the session's commands refuse what it forbids, in
words, whatever a browser sends (a disabled checkbox is only the polite half):

* ``distance_locked``: "Hide distance" is on and stays on - the distance, the Δ line, the text
  close-up, the stop at the tip and its message are off (the trainee judges the touch by eye);
* ``auto_touch_allowed``: Auto-touch (the robot touches for the trainee) may be used;
* ``in_exercise``: the spin-test Check shows a technician's reading only
  (:data:`CHECK_READING_MM`, ``pendant.spin_reading``);
* ``instructions``: the trainer's words for the exercise (plain text, at most
  :data:`MAX_INSTRUCTIONS_CHARS` characters; a banner on the trainee's panel shows them, escaped);
* ``allowed_methods``: the calibration methods (wizard kinds) the trainee may start (None: all);
  the Calibrate menu offers only those and ``Session.start_wizard`` refuses the others in words;
* ``min_touches``: the fewest touches a Finish takes (0: the method's own minimum). It applies
  to the methods whose touch count the trainee chooses (an ``n_points`` start option or Add
  point: XYZ 4-point, TCP & Z, X); a method with a fixed number of poses (three-point, ABC
  world, XYZ reference, the checks) keeps its own count.

The exercise's tool (``Session.set_exercise_tool``, the classroom's mystery tool of each trainee)
is not a class-wide rule: each trainee has their own. While one is held, "Mounted tool" is locked
to it (:func:`check_tool_change` refuses another in words), a calibration may only measure it
(:func:`check_calibrated_tool`), and the one exception is a wizard step's own tool change: the XYZ
reference method touches first with its known reference tool (``Session.mount_required_tool``),
and the exercise's tool is mounted again when that run ends or is cancelled.

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
    "MAX_INSTRUCTIONS_CHARS",
    "MAX_MIN_TOUCHES",
    "DISTANCE_AIDS",
    "DISTANCE_LOCKED",
    "DistanceAids",
    "ExerciseRules",
    "FREE_PRACTICE",
    "RuleRefusal",
    "TOOL_LOCKED_WORDS",
    "check_calibrated_tool",
    "check_tool_change",
    "class_rules",
    "clean_instructions",
    "clean_min_touches",
]

DistanceAids = Literal["locked", "hidden", "shown"]
"""The class's distance aids as the trainer sets them: ``locked`` (hidden, the trainee cannot
show them), ``hidden`` (hidden, the trainee may show them), ``shown``."""
DISTANCE_AIDS: tuple[str, ...] = ("locked", "hidden", "shown")

DISTANCE_LOCKED = ("The trainer has locked the distance aids for this exercise: judge the touch by eye, "
                   "as on a real robot (the distance, the Δ line and the stop at the tip stay off).")
AUTO_TOUCH_REFUSED = ("Auto-touch is off in this exercise: the robot would touch for you. Jog the tool tip "
                      "onto the reference tip and press Record (the trainer can allow Auto-touch).")
TOOL_LOCKED_WORDS = "This exercise keeps your own tool mounted"
"""The start of the refusal of a tool change in an exercise (:func:`check_tool_change`)."""


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


class RuleRefusal(ControllerError):
    """A command the exercise forbids (a ``ValueError``: the session shows it as a warning)."""


def check_tool_change(held_key: str, held_label: str, wanted_key: str, wanted_label: str) -> None:
    """Refuse mounting the tool ``wanted_key`` while the exercise holds the tool ``held_key``
    mounted (the same tool is no change and passes).

    Raises:
        RuleRefusal: ``wanted_key`` is another tool; the words say what stays mounted and why.
    """
    if wanted_key == held_key:
        return
    raise RuleRefusal(f"{TOOL_LOCKED_WORDS} (the {held_label.lower()}): the trainer gave it to you to "
                      f"calibrate, so the {wanted_label.lower()} cannot be mounted. (The XYZ reference method "
                      "mounts its reference tool for its first touch by itself, with its Mount the tool button.)")


def check_calibrated_tool(held_key: str, held_label: str, calibrated_key: str | None, method_title: str) -> None:
    """Refuse a calibration that would measure another tool than the exercise's ``held_key``
    (``calibrated_key``: the physical tool whose truth grades it; None: none, e.g. a check).

    Raises:
        RuleRefusal: it measures another tool; the words name the one to choose.
    """
    if calibrated_key is None or calibrated_key == held_key:
        return
    raise RuleRefusal(f"This exercise calibrates your own tool (the {held_label.lower()}): the {method_title} "
                      f"method can only measure it. Choose the {held_label.lower()} as the tool to calibrate "
                      "(the XYZ reference method: as its New tool).")


@dataclass(frozen=True)
class ExerciseRules:
    """The rules one trainee's pendant follows (see the module docstring).

    Attributes:
        exercise: the exercise id (e.g. "mystery"), None in free practice.
        distance_locked: "Hide distance" is on and cannot be switched off.
        auto_touch_allowed: Auto-touch may be used.
        instructions: the trainer's words (plain text; "" none).
        allowed_methods: the wizard kinds the trainee may start (None: every method).
        min_touches: the fewest touches a Finish of a method with a chosen touch count takes
            (0: none).
    """

    exercise: str | None = None
    distance_locked: bool = False
    auto_touch_allowed: bool = True
    instructions: str = ""
    allowed_methods: tuple[str, ...] | None = None
    min_touches: int = 0

    def allows_method(self, kind: str) -> bool:
        """The method ``kind`` may be started."""
        return self.allowed_methods is None or kind in self.allowed_methods

    def check_method(self, kind: str, titles: dict[str, str]) -> None:
        """Refuse starting a method the exercise does not allow.

        Args:
            kind: the wizard kind asked for.
            titles: wizard kind -> its title (the words name the allowed methods).

        Raises:
            RuleRefusal: ``kind`` is not one of :attr:`allowed_methods`.
        """
        if self.allows_method(kind):
            return
        allowed = [titles.get(k, k) for k in self.allowed_methods or ()]
        raise RuleRefusal(f"This exercise does not use the {titles.get(kind, kind)} method: choose "
                          f"{' or '.join(allowed)} (the trainer chose the methods).")

    def touches_refusal(self, n_touches: int, *, can_add_point: bool) -> str | None:
        """Why a Finish with ``n_touches`` touches is refused (None: it is not), for a method
        whose touch count the trainee chooses."""
        missing = self.min_touches - int(n_touches)
        if missing <= 0:
            return None
        how = ("press Add point for another touch step" if can_add_point else
               f"start it again with {self.min_touches} touches or more")
        return (f"This exercise asks for at least {self.min_touches} touches: record {missing} more "
                f"({how}).")

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
