"""The instructions an exercise shows when the trainer typed none (no viser): what to
calibrate, how it is graded, what is hidden, said from the class's rules, so a trainee who
joins an exercise never starts blind.

The grade's thresholds are the gradebook's (``wizards.truth``: position good under 0.5 mm, fair
under 2 mm; orientation likewise in degrees); the methods are the ones the exercise allows
(``ExerciseRules.allowed_methods``, every method when None).
"""

from __future__ import annotations

from tcp_pendant.calibrate.pendant_rules import ExerciseRules
from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.wizards.registry import wizard_class, wizard_classes
from tcp_pendant.wizards.truth import ORIENTATION_THRESHOLDS_DEG, POSITION_THRESHOLDS_MM

__all__ = ["default_instructions_markdown"]


def _methods(rules: ExerciseRules, tr: Translator) -> str:
    _ = tr.gettext
    if rules.allowed_methods is None:
        titles = [_(c.title) for c in wizard_classes() if c.in_exercises]
        return (_("a method of the Calibrate tab ({methods})").format(methods=", ".join(titles)) if titles
                else _("the Calibrate tab"))
    titles = []
    for kind in rules.allowed_methods:
        try:
            titles.append(_(wizard_class(kind).title))
        except (KeyError, ValueError):
            titles.append(kind)
    return _(" or ").join(titles)


def default_instructions_markdown(rules: ExerciseRules, *, tr: Translator = ENGLISH) -> str:
    """The default brief of an exercise (markdown, our words and numbers only, in ``tr``'s
    language); "" in free practice."""
    if rules.exercise is None:
        return ""
    _ = tr.gettext
    p_good, p_fair = POSITION_THRESHOLDS_MM
    o_good, o_fair = ORIENTATION_THRESHOLDS_DEG
    touches = (tr.ngettext("at least {n} touch", "at least {n} touches", rules.min_touches).format(n=rules.min_touches)
               if rules.min_touches else _("one touch per step"))
    what = _("**What to do:** calibrate the TCP of the tool mounted on the robot (a mystery tool: "
             "its tool data is unknown) with {methods}. Press Start on the Calibrate tab "
             "and follow the steps on the Jog tab: {touches}, each from an orientation tilted at "
             "least 45° from the others, then Finish.").format(methods=_methods(rules, tr), touches=touches)
    graded = _("**How it is graded:** by how far your TCP is from the tool's true TCP: good under "
               "{p_good} mm, fair under {p_fair} mm, poor from {p_fair} mm on (a method that "
               "also finds the orientation: good under {o_good}°, fair under {o_fair}°). Runs into "
               "the reference tip are counted as crashes.").format(
                   p_good=f"{p_good:g}", p_fair=f"{p_fair:g}", o_good=f"{o_good:g}", o_fair=f"{o_fair:g}")
    hidden = [_("the tool's true TCP and orientation")]
    if rules.distance_locked:
        hidden.insert(0, _("the distance to the reference tip (judge each touch by eye in the two tip "
                           "views; every Record counts as a touch)"))
    if not rules.auto_touch_allowed:
        hidden.append(_("Auto-touch (off)"))
    return f"{what}\n\n{graded}\n\n" + _("**What is hidden:** {items}.").format(items="; ".join(hidden))
