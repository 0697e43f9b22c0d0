"""What the trainer set for the whole class: the exercise, the distance aids, Auto-touch, the
pushed tool and the brief (instructions, allowed methods, minimum touches), and the rules every
trainee's pendant follows from them (no viser, no session).

An :class:`ExerciseSetup` is the class room's; it checks what a push asks for, keeps what was
pushed in the gradebook's class settings (:data:`PUSHED_SETTING`) and reads it back at start, so
a restart of the server with the same gradebook applies it again. Applying it to each trainee's
pendant is the class room's (``classroom.trainee_settings``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

from tcp_pendant.classroom.class_settings import ClassSettings
from tcp_pendant.classroom.exercise_rules import DistanceAids, class_rules, clean_instructions, clean_min_touches
from tcp_pendant.calibrate.pendant_rules import ExerciseRules
from tcp_pendant.wizards import WIZARD_TYPES, wizard_classes
from tcp_pendant.controller.words import Words
from tcp_pendant.translation import N_

__all__ = ["EXERCISE_IDS", "PUSHED_SETTING", "ExerciseSetup", "check_exercise", "clean_methods"]

EXERCISE_IDS = ("mystery",)
"""Exercises a trainer can start (``--exercise``; None: free practice)."""
PUSHED_SETTING = "pushed"
"""The class setting that keeps what the trainer pushed (exercise, "Hide distance", Auto-touch,
tool; the brief: instructions, allowed methods, minimum touches)."""


def check_exercise(exercise: object) -> None:
    """Raises ValueError for an exercise that is neither None nor one of :data:`EXERCISE_IDS`."""
    if exercise is not None and exercise not in EXERCISE_IDS:
        raise ValueError(f"Unknown exercise {exercise!r}; use one of {', '.join(EXERCISE_IDS)}.")


def clean_methods(methods: object) -> tuple[str, ...] | None:
    """The methods an exercise allows, as wizard kinds in menu order (None: every method).

    Args:
        methods: None, or wizard kinds (``"xyz4"``, ``"reference"``, ...) as a sequence or one
            comma-separated string (the CLI's ``--exercise-methods xyz4,reference``).

    Raises:
        ValueError: an unknown kind or no method at all (names the registered kinds).
    """
    if methods is None:
        return None
    if isinstance(methods, str):
        methods = [m for m in (part.strip() for part in methods.split(",")) if m]
    if not isinstance(methods, (list, tuple)) or not all(isinstance(m, str) for m in methods):
        raise ValueError(f"The exercise's methods must be wizard ids, got {type(methods).__name__}.")
    known = [c.kind for c in wizard_classes()]
    unknown = [m for m in methods if m not in WIZARD_TYPES]
    if unknown:
        raise ValueError(f"Unknown calibration method {unknown[0]!r:.60} for the exercise; use some of "
                         f"{', '.join(known)}.")
    if not methods:
        raise ValueError(f"An exercise needs at least one method; choose some of {', '.join(known)}.")
    return tuple(k for k in known if k in methods)


class ExerciseSetup:
    """The class's exercise, aids, Auto-touch, pushed tool and brief (module docstring).

    Args:
        settings: the gradebook's class settings (what was pushed is kept there).
        tool_keys: the physical tools a push may mount.
        exercise: None (free practice) or "mystery", given at start: it wins over a kept one.
        instructions: the exercise's instructions given at start (None: as kept); each part
            of the brief given wins over the kept one and is kept.
        allowed_methods: the methods the exercise allows, given at start (None: as kept).
        min_touches: the fewest touches a Finish takes, given at start (None: as kept).

    Raises:
        ValueError: an unknown exercise or method, instructions too long, a bad minimum.
    """

    def __init__(self, settings: ClassSettings, tool_keys: Sequence[str], exercise: str | None, *,
                 instructions: str | None = None, allowed_methods: Sequence[str] | str | None = None,
                 min_touches: int | None = None) -> None:
        check_exercise(exercise)
        given_instructions = None if instructions is None else clean_instructions(instructions)
        given_methods = clean_methods(allowed_methods)
        given_min = None if min_touches is None else clean_min_touches(min_touches)
        self._settings = settings
        self._tool_keys = tuple(tool_keys)
        self.exercise = exercise
        self.distance_aids: DistanceAids | None = None
        """The distance aids as the trainer last pushed them (None: the exercise's default -
        locked in an exercise, each trainee's own choice in free practice)."""
        self.auto_touch: bool | None = None
        """Auto-touch as the trainer last allowed it (None: the default - off in an exercise)."""
        self.pushed_tool: str | None = None
        """The tool the trainer last pushed (kept across restarts)."""
        self.instructions = ""
        """The exercise's instructions (plain text; "" none)."""
        self.allowed_methods: tuple[str, ...] | None = None
        """The wizard kinds trainees may start (None: every method)."""
        self.min_touches = 0
        """The fewest touches a Finish takes, for methods whose touch count is chosen (0: none)."""
        self._apply_kept(exercise_given=exercise is not None)   # what the trainer pushed before a restart
        if given_instructions is not None:
            self.instructions = given_instructions
        if given_methods is not None:
            self.allowed_methods = given_methods
        if given_min is not None:
            self.min_touches = given_min
        if (given_instructions, given_methods, given_min) != (None, None, None):
            self.keep(None, brief_only=True)

    @property
    def rules(self) -> ExerciseRules:
        """The rules every trainee's pendant follows now."""
        return class_rules(self.exercise, self.distance_aids, self.auto_touch, instructions=self.instructions,
                           allowed_methods=self.allowed_methods, min_touches=self.min_touches)

    def push(self, exercise: str | None, tool_key: str | None, hide_distance: bool | str | None,
             auto_touch: bool | None) -> tuple[DistanceAids | None, bool]:
        """Take a push of the class's settings (``ClassRoom.push_settings``): the aids named
        ("locked", "hidden", "shown"; True "hidden", False "shown"; None: keep) and whether the
        exercise changed (a new exercise starts from its default rules except what is pushed).

        Raises:
            ValueError: an unknown exercise, tool or aids (nothing is set).
        """
        check_exercise(exercise)
        if tool_key is not None and tool_key not in self._tool_keys:
            raise ValueError(Words(N_("Unknown tool {tool}; use one of {tools}."), tool=repr(tool_key),
                                   tools=", ".join(self._tool_keys)))
        named = {True: "hidden", False: "shown"}[hide_distance] if isinstance(hide_distance, bool) else hide_distance
        class_rules(exercise, named, auto_touch)        # type: ignore[arg-type]  # ValueError: unknown aids
        aids = cast("DistanceAids | None", named)
        new_exercise = exercise != self.exercise
        if new_exercise:
            self.distance_aids = self.auto_touch = None
        self.exercise = exercise
        if aids is not None:
            self.distance_aids = aids
        if auto_touch is not None:
            self.auto_touch = bool(auto_touch)
        return aids, new_exercise

    def set_brief(self, instructions: str, allowed_methods: Sequence[str] | str | None,
                  min_touches: int) -> None:
        """Take the exercise's brief (``ClassRoom.push_brief``).

        Raises:
            ValueError: instructions too long, an unknown method, a bad minimum (nothing is set).
        """
        text = clean_instructions(instructions)
        methods = clean_methods(allowed_methods)
        minimum = clean_min_touches(min_touches)
        self.instructions, self.allowed_methods, self.min_touches = text, methods, minimum

    def keep(self, tool_key: str | None, *, brief_only: bool = False) -> None:
        """Keep what the trainer pushed in the gradebook (:data:`PUSHED_SETTING`), so a restart
        with this gradebook applies it again; ``brief_only``: the brief's keys only (the brief
        given at start: the exercise given with it is not kept by that)."""
        kept = self._settings.get(PUSHED_SETTING)
        kept = dict(kept) if isinstance(kept, dict) else {}
        if not brief_only:
            kept.update({"exercise": self.exercise, "distance_aids": self.distance_aids,
                         "auto_touch": self.auto_touch})
        kept.update({"instructions": self.instructions, "min_touches": self.min_touches,
                     "allowed_methods": None if self.allowed_methods is None else list(self.allowed_methods)})
        if tool_key is not None:
            kept["tool_key"] = tool_key
        self._settings.set(PUSHED_SETTING, kept)

    def _apply_kept(self, exercise_given: bool) -> None:
        """At start: the settings the trainer pushed before a restart (an ``--exercise`` given
        at start wins over a kept one; a value this version does not know is ignored)."""
        kept = self._settings.get(PUSHED_SETTING)
        if not isinstance(kept, dict):
            return
        if not exercise_given and kept.get("exercise") in (None, *EXERCISE_IDS):
            self.exercise = kept.get("exercise")
        aids, auto = kept.get("distance_aids"), kept.get("auto_touch")
        try:
            class_rules(self.exercise, aids, auto if isinstance(auto, bool) else None)
        except ValueError:
            aids = None
        self.distance_aids = cast("DistanceAids | None", aids)
        self.auto_touch = auto if isinstance(auto, bool) else None
        tool = kept.get("tool_key")
        self.pushed_tool = tool if isinstance(tool, str) and tool in self._tool_keys else None
        try:                              # the brief (absent in an older gradebook: none)
            self.instructions = clean_instructions(kept.get("instructions", ""))
        except ValueError:
            self.instructions = ""
        try:
            self.allowed_methods = clean_methods(kept.get("allowed_methods"))
        except ValueError:                # a method this version does not know: every method
            self.allowed_methods = None
        try:
            self.min_touches = clean_min_touches(kept.get("min_touches", 0))
        except ValueError:
            self.min_touches = 0
