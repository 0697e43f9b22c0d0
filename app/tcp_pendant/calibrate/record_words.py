"""What the dock says after a step's Record (no viser): the same words for every touch an
exercise hides the distance of, near or far, so the words give nothing away.

* distance shown: "✔ Step 2 recorded, 0.31 mm from the tip."
* distance hidden, free practice: "✔ Step 2 recorded: 0.8 mm off, mostly −Z (WORLD): ..." (how
  far it really was, ``pendant.touch_feedback``: practice's teacher);
* distance hidden in an exercise: a neutral notice that it is recorded as a touch (no ✔, no
  distance, no word that depends on where the tips were).
"""

from __future__ import annotations

from tcp_pendant.translation import ENGLISH, N_, Translator

__all__ = ["EXERCISE_RECORDED", "recorded_words"]

EXERCISE_RECORDED = N_("Step {n} recorded as a touch. The distance stays hidden in this exercise, "
                     "so every Record counts as a touch wherever the tips are: your result shows "
                     "how close they were.")


def recorded_words(index: int | None, distance_mm: float, *, hidden: bool, in_exercise: bool,
                   feedback: str, tr: Translator = ENGLISH) -> str:
    """The line after Record of step ``index`` (0-based; None: unknown) at ``distance_mm`` (mm)
    from the reference tip; ``feedback`` is ``touch_feedback``'s words for the touch (in ``tr``'s
    language, as this line)."""
    _ = tr.gettext
    n = "?" if index is None else str(index + 1)
    if not hidden:
        return _("✔ Step {n} recorded, {mm} mm from the tip.").format(n=n, mm=f"{distance_mm:.2f}")
    if in_exercise:
        return _(EXERCISE_RECORDED).format(n=n)
    return _("✔ Step {n} recorded: {feedback}.").format(n=n, feedback=feedback)
