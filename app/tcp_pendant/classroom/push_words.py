"""What a trainer's "Push to this trainee" changed, in the words the trainee reads (no viser).

``ClassRoom.push_to`` changes one trainee's pendant (the exercise, the mounted tool, the
distance aids, Auto-touch); :func:`push_words` says what it set, so the trainee's browser can be
told (``Session.notify``) instead of finding the pendant changed under their hands.
"""

from __future__ import annotations

from tcp_pendant.translation import ENGLISH, N_, Translator

__all__ = ["PUSH_TITLE", "push_words"]

PUSH_TITLE = N_("Your trainer changed your pendant")
"""The notification's title (an English msgid: shown with ``tr.gettext``)."""

_DISTANCE = {"locked": N_("the distance to the reference tip is hidden, and locked by the trainer"),
             "hidden": N_("the distance to the reference tip is hidden (you may show it again)"),
             "shown": N_("the distance to the reference tip is shown")}


def push_words(exercise: str | None | bool, tool_name: str | None, hide_distance: str | None,
               auto_touch: bool | None, *, tr: Translator = ENGLISH) -> str:
    """One sentence naming each setting the push set, in ``tr``'s language (its clauses joined
    by "; ", the first letter upper case).

    Args:
        exercise: False: not changed; None: free practice; "mystery": the mystery-tool exercise.
        tool_name: the tool mounted by the push (None: not changed).
        hide_distance: "locked", "hidden" or "shown" (None: not changed).
        auto_touch: Auto-touch allowed or not (None: not changed).
    """
    _ = tr.gettext
    parts = []
    if exercise is None:
        parts.append(_("free practice (no exercise: you may swap tools)"))
    elif exercise == "mystery":
        parts.append(_("the exercise: calibrate your mystery tool (its true TCP is hidden)"))
    elif exercise is not False:
        parts.append(_("the exercise: {exercise}").format(exercise=exercise))
    if tool_name is not None and exercise != "mystery":
        parts.append(_("the mounted tool is now {tool}").format(tool=tool_name))
    if hide_distance is not None:
        known = _DISTANCE.get(hide_distance)
        parts.append(_(known) if known else _("distance aids: {aids}").format(aids=hide_distance))
    if auto_touch is not None:
        parts.append(_("Auto-touch is allowed") if auto_touch else _("Auto-touch is off: touch by jogging"))
    if not parts:
        return _("Your trainer pushed your settings again; nothing changed.")
    text = "; ".join(parts)
    return text[0].upper() + text[1:] + "."
