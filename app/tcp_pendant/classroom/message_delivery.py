"""The trainer's messages on their way to this process's trainees (no viser).

A message is kept in the gradebook for each trainee it is sent to until that trainee dismisses
it (``Gradebook.messages``). :class:`MessageDelivery` hands each seated trainee's session the
kept messages it was not handed yet (``Session.show_message``, on viser's loop, that session
only): when they join, when the trainer sends one here, and at each heartbeat for one sent on
another process. It remembers, per session, the messages it handed and those last on screen; a
``notice`` signal with fewer on screen means a Dismiss, which the gradebook then forgets.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Callable
from datetime import datetime, timezone

from tcp_pendant.classroom.class_messages import clean_message_text
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.gradebook_store import GradebookError
from tcp_pendant.classroom.roster import Roster, Seat
from tcp_pendant.session import ClassMessage, Session
from tcp_pendant.controller.words import Words
from tcp_pendant.translation import ENGLISH, N_, Translator

__all__ = ["MessageDelivery"]

log = logging.getLogger(__name__)


class MessageDelivery:
    """The messages of the class's trainees seated in ``roster`` (module docstring).

    Args:
        gradebook: the class gradebook (keeps each message until it is dismissed).
        roster: this process's seats (its lock also guards the lists kept here).
        hand_to_loop: runs a function on viser's event loop.
    """

    def __init__(self, gradebook: Gradebook, roster: Roster,
                 hand_to_loop: Callable[[Callable[[], None]], None]) -> None:
        self._gradebook = gradebook
        self._roster = roster
        self._hand_to_loop = hand_to_loop
        self._on_screen: dict[int, set[int]] = {}   # id(session) -> message ids on its screen, last seen
        self._handed: dict[int, set[int]] = {}      # id(session) -> message ids handed to it (the loop shows them)

    def welcome(self, session: Session, name: str) -> None:
        """``name`` just joined in ``session`` (under its lock): show what they had not dismissed."""
        for message in self._kept_messages(name):
            session.show_message(message)
        with self._roster.lock:
            self._on_screen[id(session)] = {m.message_id for m in session.messages}
            self._handed[id(session)] = set(self._on_screen[id(session)])

    def forget(self, session: Session) -> None:
        """``session`` closed."""
        with self._roster.lock:
            self._on_screen.pop(id(session), None)
            self._handed.pop(id(session), None)

    def send(self, text: str, to: str | None, connected: list[str], *, tr: Translator = ENGLISH) -> str:
        """``ClassRoom.send_message``: ``connected`` are the names connected now on every
        process of the class. Returns what happened, in words for the trainer (plain text, in
        ``tr``'s language).

        Raises:
            ValueError: an empty or too long text; ``to`` is no trainee of this class.
        """
        clean = clean_message_text(text)
        if to is not None and not isinstance(to, str):
            raise ValueError(Words(N_("Choose whom to send the message to.")))
        if to is not None and to not in connected and to not in self._gradebook.trainees.names():
            raise ValueError(Words(N_("{name} is not in the class; choose a trainee in the list, or all trainees."),
                                   name=f"{to:.60}"))
        names = connected if to is None else [to]
        sent = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        if names:
            try:
                self._gradebook.messages.add(clean, names, to_all=to is None, sent_at=sent)
            except GradebookError as exc:
                log.error("a message was not kept: %s", exc)
                raise ValueError(Words(N_("The class gradebook cannot be written now, so the message was not sent; "
                                          "try again in a moment."))) from None
        self.deliver_kept(self._roster.by_names(names))
        if to is None:
            n = len(names)
            return (tr.ngettext("Sent to {n} trainee.", "Sent to {n} trainees.", n).format(n=n) if n
                    else tr.gettext("No trainee is connected: nobody got it."))
        if to in connected:
            return tr.gettext("Sent to {name}.").format(name=to)
        return tr.gettext("{name} is not connected: the message waits until they join again.").format(name=to)

    def _kept_messages(self, name: str) -> list[ClassMessage]:
        """The messages the gradebook keeps for ``name`` (not dismissed), oldest first."""
        try:
            kept = self._gradebook.messages.waiting([name]).get(name, [])
        except GradebookError:
            log.exception("the messages of %r could not be read", name)
            return []
        return [ClassMessage(mid, text, None if to_all else name, sent) for mid, to_all, sent, text in kept]

    def deliver_kept(self, seats: dict[str, Seat]) -> None:
        """Hand each of this process's trainees of ``seats`` (by name) the messages the
        gradebook keeps for them that their session was not handed yet (shown on viser's loop,
        on that session only)."""
        if not seats:
            return
        try:
            kept = self._gradebook.messages.waiting(list(seats))
        except GradebookError:
            log.exception("the class's messages could not be read")
            return
        for name, rows in kept.items():
            session = seats[name].session
            with self._roster.lock:
                if not self._roster.holds(seats[name]):
                    continue
                handed = self._handed.setdefault(id(session), set())
                new = [ClassMessage(mid, text, None if to_all else name, sent)
                       for mid, to_all, sent, text in rows if mid not in handed]
                handed &= {row[0] for row in rows}
                handed.update(m.message_id for m in new)
            if new:
                self._hand_to_loop(session.loop.guard(functools.partial(_show, session, new)))

    def note_dismissed(self, session: Session, name: str) -> None:
        """After a ``notice`` signal of ``name``'s session: the messages that were on its screen
        and are not any more were dismissed there (or pushed out by newer ones): the gradebook
        forgets them for ``name``."""
        now = {m.message_id for m in session.messages}
        with self._roster.lock:
            before = self._on_screen.get(id(session), set())
            self._on_screen[id(session)] = now
        gone = sorted(before - now)
        if gone:
            try:
                self._gradebook.messages.dismiss(name, gone)
            except GradebookError:
                log.exception("the dismissal of %r's messages could not be kept", name)


def _show(session: Session, messages: list[ClassMessage]) -> None:
    for message in messages:
        session.show_message(message)
