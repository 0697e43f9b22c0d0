"""A trainer's message to the class or to one trainee (no viser).

The trainer types a message in the trainer view and sends it to every named trainee or to
one (``ClassRoom.send_message``); the class gradebook keeps it for each trainee until that
trainee dismisses it (``Gradebook.add_message``, table ``class_messages``), and the server
process that holds the trainee's browser now gives it to their session
(``Session.show_message``; again after a reload or a restart). The session keeps the messages
it was given, each a ``session.ClassMessage``, at most ``session.MAX_WAITING_MESSAGES``, until
the trainee dismisses them (``Session.dismiss_message``), and the trainee's
panel shows the oldest one with a Dismiss button and how many more wait
(``views.class_notices``). The text is a stranger's (the trainer's browser): plain text here,
escaped where it is shown.
"""

from __future__ import annotations

from tcp_pendant.controller.words import Words
from tcp_pendant.translation import N_

__all__ = ["MAX_MESSAGE_CHARS", "clean_message_text"]

MAX_MESSAGE_CHARS = 1000
"""The longest message (characters, after trimming)."""


def clean_message_text(text: object) -> str:
    """A message as kept: text, trimmed, line endings as ``\\n``, control characters other
    than line breaks and tabs dropped.

    Raises:
        ValueError: not text, empty, or longer than :data:`MAX_MESSAGE_CHARS` (says how long).
    """
    if not isinstance(text, str):
        raise ValueError(Words(N_("A message must be text, got {kind}."), kind=type(text).__name__))
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    text = "".join(ch for ch in text if ch in "\n\t" or ch.isprintable()).strip()
    if not text:
        raise ValueError(Words(N_("The message is empty: type what the trainees should read, then Send.")))
    if len(text) > MAX_MESSAGE_CHARS:
        raise ValueError(Words(N_("The message is {n} characters long; shorten it to at most {most}."),
                               n=str(len(text)), most=str(MAX_MESSAGE_CHARS)))
    return text
