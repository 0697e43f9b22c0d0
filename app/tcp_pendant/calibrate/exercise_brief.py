"""The instructions an exercise shows when the trainer typed none (no viser): what to
calibrate, how it is graded, what is hidden, said from the class's rules, so a trainee who
joins an exercise never starts blind.

The grade's thresholds are the gradebook's (``wizards.truth``: position good under 0.5 mm, fair
under 2 mm; orientation likewise in degrees); the methods are the ones the exercise allows
(``ExerciseRules.allowed_methods``, every method when None).
"""

from __future__ import annotations

from tcp_pendant.calibrate.pendant_rules import ExerciseRules
from tcp_pendant.wizards.registry import wizard_class, wizard_classes
from tcp_pendant.wizards.truth import ORIENTATION_THRESHOLDS_DEG, POSITION_THRESHOLDS_MM

__all__ = ["default_instructions_markdown"]


def _methods(rules: ExerciseRules) -> str:
    if rules.allowed_methods is None:
        titles = [c.title for c in wizard_classes() if c.in_exercises]
        return "a method of the Calibrate tab (" + ", ".join(titles) + ")" if titles else "the Calibrate tab"
    titles = []
    for kind in rules.allowed_methods:
        try:
            titles.append(wizard_class(kind).title)
        except (KeyError, ValueError):
            titles.append(kind)
    return " or ".join(titles)


def default_instructions_markdown(rules: ExerciseRules) -> str:
    """The default brief of an exercise (markdown, our words and numbers only); "" in free
    practice."""
    if rules.exercise is None:
        return ""
    p_good, p_fair = POSITION_THRESHOLDS_MM
    o_good, o_fair = ORIENTATION_THRESHOLDS_DEG
    touches = (f"at least {rules.min_touches} touches" if rules.min_touches
               else "one touch per step")
    what = ("**What to do:** calibrate the TCP of the tool mounted on the robot (a mystery tool: "
            f"its tool data is unknown) with {_methods(rules)}. Press Start on the Calibrate tab "
            f"and follow the steps on the Jog tab: {touches}, each from an orientation tilted at "
            "least 45° from the others, then Finish.")
    graded = ("**How it is graded:** by how far your TCP is from the tool's true TCP: good under "
              f"{p_good:g} mm, fair under {p_fair:g} mm, poor from {p_fair:g} mm on (a method that "
              f"also finds the orientation: good under {o_good:g}°, fair under {o_fair:g}°). Runs into "
              "the reference tip are counted as crashes.")
    hidden = ["the tool's true TCP and orientation"]
    if rules.distance_locked:
        hidden.insert(0, "the distance to the reference tip (judge each touch by eye in the two tip "
                         "views; every Record counts as a touch)")
    if not rules.auto_touch_allowed:
        hidden.append("Auto-touch (off)")
    return f"{what}\n\n{graded}\n\n**What is hidden:** " + "; ".join(hidden) + "."
