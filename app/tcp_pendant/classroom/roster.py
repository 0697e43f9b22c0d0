"""Who sits in this server process's class now (no viser, no gradebook).

A :class:`Roster` keeps, per session (by ``id(session)``): the seat of a named trainee
(:class:`Seat`: the session, its gradebook recorder and the name), the welcome window shown in
it, the name the trainer released from it, and whether the class follows its change signal. It
is the class room's table; the class room's other owners (``classroom.message_delivery``,
``classroom.heartbeat``) read it. One re-entrant lock (:attr:`Roster.lock`) guards it and the
per-session lists those owners keep beside it, so a check of a seat and a change of such a list
happen under one lock.
"""

from __future__ import annotations

import threading
from collections.abc import Collection
from typing import NamedTuple

from tcp_pendant.classroom.class_views import WelcomeWindow
from tcp_pendant.classroom.recorder import TraineeRecorder
from tcp_pendant.session import Session

__all__ = ["Roster", "Seat"]


class Seat(NamedTuple):
    """A named trainee's place in the class: their session, its recorder and their name. A seat
    is compared by identity (``is``): a name joined again gets a new one."""

    session: Session
    recorder: TraineeRecorder
    name: str


class Roster:
    """The seats, welcome windows and released names of one server process (module docstring)."""

    def __init__(self) -> None:
        self.lock = threading.RLock()
        self._seats: dict[int, Seat] = {}               # id(session) -> its trainee's seat
        self._followed: set[int] = set()                # id(session) of sessions whose changes we follow
        self._prompts: dict[int, WelcomeWindow] = {}    # id(session) -> its welcome window
        self._welcomed: dict[int, Session] = {}         # id(session) -> the session of that window
        self._released: dict[int, str] = {}             # id(session) -> the name the trainer released there

    def seat(self, session: Session) -> Seat | None:
        """The seat of ``session`` (None: not a named trainee)."""
        with self.lock:
            return self._seats.get(id(session))

    def seats(self) -> list[Seat]:
        """Every seat, in order of arrival."""
        with self.lock:
            return list(self._seats.values())

    def names(self) -> list[str]:
        """The names seated here, in order of arrival."""
        with self.lock:
            return [seat.name for seat in self._seats.values()]

    def by_name(self, name: str, *, other_than: Session | None = None) -> Seat | None:
        """The seat of ``name`` (in a session other than ``other_than``), or None."""
        with self.lock:
            return next((s for s in self._seats.values() if s.name == name and s.session is not other_than), None)

    def all_named(self, name: str) -> list[Seat]:
        """Every seat of ``name`` (one, or none)."""
        with self.lock:
            return [s for s in self._seats.values() if s.name == name]

    def by_names(self, names: Collection[str]) -> dict[str, Seat]:
        """Name -> seat of the seated names among ``names``."""
        with self.lock:
            return {s.name: s for s in self._seats.values() if s.name in names}

    def holds(self, seat: Seat) -> bool:
        """``seat`` is still its session's seat."""
        with self.lock:
            return self._seats.get(id(seat.session)) is seat

    def sit(self, seat: Seat) -> bool:
        """Seat a trainee; True when the class does not follow the session's changes yet (the
        caller subscribes once)."""
        key = id(seat.session)
        with self.lock:
            self._seats[key] = seat
            follow = key not in self._followed
            self._followed.add(key)
        return follow

    def unseat(self, seat: Seat) -> bool:
        """Take ``seat`` out when it is still its session's (True: it was)."""
        with self.lock:
            if self._seats.get(id(seat.session)) is not seat:
                return False
            del self._seats[id(seat.session)]
            return True

    def welcome(self, session: Session, prompt: WelcomeWindow) -> None:
        """Keep the welcome window shown in ``session``."""
        with self.lock:
            self._prompts[id(session)] = prompt
            self._welcomed[id(session)] = session

    def unnamed(self) -> list[Session]:
        """The sessions showing a welcome window whose browser has not joined under a name yet."""
        with self.lock:
            return [s for key, s in self._welcomed.items() if key not in self._seats]

    def prompt(self, session: Session) -> WelcomeWindow | None:
        """The welcome window of ``session`` (None: none shown)."""
        with self.lock:
            return self._prompts.get(id(session))

    def note_released(self, session: Session, name: str) -> None:
        """The trainer released ``name`` from the browser of ``session``: it may not join as it."""
        with self.lock:
            self._released[id(session)] = name

    def released(self, session: Session) -> str | None:
        """The name the trainer released from the browser of ``session`` (None: none)."""
        with self.lock:
            return self._released.get(id(session))

    def forget(self, session: Session) -> Seat | None:
        """``session`` closed: its welcome window, released name and following go; returns its
        seat, still seated (the caller ends it, then :meth:`unseat`)."""
        key = id(session)
        with self.lock:
            self._prompts.pop(key, None)
            self._welcomed.pop(key, None)
            self._released.pop(key, None)
            self._followed.discard(key)
            return self._seats.get(key)
