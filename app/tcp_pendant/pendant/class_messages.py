"""A trainer's message to the class or to one trainee (no viser).

The trainer types a message in the trainer view and sends it to every named trainee or to
one (``ClassRoom.send_message``); the class gradebook keeps it for each trainee until that
trainee dismisses it (``Gradebook.add_message``, table ``class_messages``), and the server
process that holds the trainee's browser now gives it to their session
(``Session.show_message``; again after a reload or a restart). The session keeps the messages
it was given until the trainee dismisses them (``Session.dismiss_message``), and the trainee's
panel shows the oldest one with a Dismiss button and how many more wait
(``views.class_notices``). The text is a stranger's (the trainer's browser): plain text here,
escaped where it is shown.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["MAX_MESSAGE_CHARS", "MAX_WAITING_MESSAGES", "ClassMessage", "clean_message_text"]

MAX_MESSAGE_CHARS = 1000
"""The longest message (characters, after trimming)."""
MAX_WAITING_MESSAGES = 10
"""Messages a session (and the gradebook, per trainee) keeps undismissed; a newer one pushes out
the oldest."""


def clean_message_text(text: object) -> str:
    """A message as kept: text, trimmed, line endings as ``\\n``, control characters other
    than line breaks and tabs dropped.

    Raises:
        ValueError: not text, empty, or longer than :data:`MAX_MESSAGE_CHARS` (says how long).
    """
    if not isinstance(text, str):
        raise ValueError(f"A message must be text, got {type(text).__name__}.")
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    text = "".join(ch for ch in text if ch in "\n\t" or ch.isprintable()).strip()
    if not text:
        raise ValueError("The message is empty: type what the trainees should read, then Send.")
    if len(text) > MAX_MESSAGE_CHARS:
        raise ValueError(f"The message is {len(text)} characters long; shorten it to at most {MAX_MESSAGE_CHARS}.")
    return text


@dataclass(frozen=True)
class ClassMessage:
    """One message as a trainee's session keeps it.

    Attributes:
        message_id: the gradebook's id of this trainee's copy, unique in the class (the
            Dismiss button names it).
        text: plain text (:func:`clean_message_text`).
        to: the trainee's name it was sent to, None for the whole class.
        sent_at_utc: when it was sent, ISO 8601 UTC (``2026-12-02T09:30:00Z``).
    """

    message_id: int
    text: str
    to: str | None
    sent_at_utc: str
