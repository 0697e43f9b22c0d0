"""What a trainer's "Push to this trainee" changed, in the words the trainee reads (no viser).

``ClassRoom.push_to`` changes one trainee's pendant (the exercise, the mounted tool, the
distance aids, Auto-touch); :func:`push_words` says what it set, so the trainee's browser can be
told (``Session.notify``) instead of finding the pendant changed under their hands.
"""

from __future__ import annotations

__all__ = ["PUSH_TITLE", "push_words"]

PUSH_TITLE = "Your trainer changed your pendant"
"""The notification's title."""

_DISTANCE = {"locked": "the distance to the reference tip is hidden, and locked by the trainer",
             "hidden": "the distance to the reference tip is hidden (you may show it again)",
             "shown": "the distance to the reference tip is shown"}


def push_words(exercise: str | None | bool, tool_name: str | None, hide_distance: str | None,
               auto_touch: bool | None) -> str:
    """One sentence naming each setting the push set.

    Args:
        exercise: False: not changed; None: free practice; "mystery": the mystery-tool exercise.
        tool_name: the tool mounted by the push (None: not changed).
        hide_distance: "locked", "hidden" or "shown" (None: not changed).
        auto_touch: Auto-touch allowed or not (None: not changed).
    """
    parts = []
    if exercise is None:
        parts.append("free practice (no exercise: you may swap tools)")
    elif exercise == "mystery":
        parts.append("the exercise: calibrate your mystery tool (its true TCP is hidden)")
    elif exercise is not False:
        parts.append(f"the exercise: {exercise}")
    if tool_name is not None and exercise != "mystery":
        parts.append(f"the mounted tool is now {tool_name}")
    if hide_distance is not None:
        parts.append(_DISTANCE.get(hide_distance, f"distance aids: {hide_distance}"))
    if auto_touch is not None:
        parts.append("Auto-touch is allowed" if auto_touch else "Auto-touch is off: touch by jogging")
    if not parts:
        return "Your trainer pushed your settings again; nothing changed."
    text = "; ".join(parts)
    return text[0].upper() + text[1:] + "."
