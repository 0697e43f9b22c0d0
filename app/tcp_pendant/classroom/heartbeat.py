"""This server process's part in a class that several processes serve (no viser).

Several ``tcp-pendant`` processes may serve one class on one gradebook (``--workers N``). Each
has its own sessions; what the class shares goes through the gradebook. :class:`Heartbeat` is
this process's link: its :attr:`Heartbeat.holder` id, the names it claims in the gradebook's
presence table (``Gradebook.presence``) with their live rows, the rows of the other processes'
trainees as they last beat them, and a thread that beats every ``poll_s``: renew this process's
names, notice a name it lost (taken by the same browser on another process, or released by the
trainer there), take in the others' rows and the trainer's pushes made elsewhere
(``Gradebook.pushes``), and hand this process's trainees the messages kept for them. What to do
with a lost name, a push or a message is the class room's (the callbacks).
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import os
import secrets
import socket
import threading
from collections.abc import Callable
from typing import Any

from tcp_pendant.json_shapes import JsonRecord

from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.gradebook_store import GradebookError
from tcp_pendant.classroom.recorder import TraineeStatus
from tcp_pendant.classroom.roster import Roster, Seat

__all__ = ["Heartbeat", "LostSeat"]

log = logging.getLogger(__name__)

LostSeat = tuple[Seat, bool]
"""A seat whose name this process lost, and whether the trainer released it (else the same
browser took it on another process)."""


def _status(row: JsonRecord) -> TraineeStatus | None:
    """A presence row as a :class:`TraineeStatus` (None: not one this version reads)."""
    fields = {f.name for f in dataclasses.fields(TraineeStatus)}
    try:
        return TraineeStatus(**{k: v for k, v in row.items() if k in fields})
    except TypeError:
        return None


class Heartbeat:
    """This process's presence in the class (module docstring).

    Args:
        gradebook: the class gradebook.
        roster: this process's seats.
        poll_s: the heartbeat period (seconds).
        hand_to_loop: runs a function on viser's event loop.
        on_lost: called on the loop with the seats whose names this process lost.
        on_push: called on the loop with each push the trainer made on another process.
        deliver: hands the seats given (by name) the messages kept for them.
        refresh: re-renders the dashboards (on the loop) when the other processes' rows changed.
    """

    def __init__(self, gradebook: Gradebook, roster: Roster, poll_s: float, *,
                 hand_to_loop: Callable[[Callable[[], None]], None],
                 on_lost: Callable[[list[LostSeat]], None], on_push: Callable[[dict[str, Any]], None],
                 deliver: Callable[[dict[str, Seat]], None], refresh: Callable[[], None]) -> None:
        self._gradebook = gradebook
        self._roster = roster
        self.poll_s = float(poll_s)
        self._hand_to_loop = hand_to_loop
        self._on_lost, self._on_push, self._deliver, self._refresh = on_lost, on_push, deliver, refresh
        self.holder = f"{socket.gethostname()}:{os.getpid()}:{secrets.token_hex(4)}"
        """This server process's id in the gradebook's presence table (host, pid, a nonce)."""
        self._remote: dict[str, TraineeStatus] = {}   # name -> row, connected on another process
        self._push_seen = gradebook.pushes.last_id()  # the pushes before are in the kept settings
        self._beater: threading.Thread | None = None
        self._stopping = threading.Event()

    def claim(self, name: str, status: TraineeStatus) -> None:
        """``name`` joined here: it is this process's in the presence table."""
        self._gradebook.presence.claim(name, self.holder, dataclasses.asdict(status))

    def held_elsewhere(self, name: str) -> bool:
        """Another process holds ``name`` in the presence table."""
        return self._gradebook.presence.holder(name) not in (None, self.holder)

    def on_another_process(self, name: object) -> bool:
        """``name`` is connected on another process (as it last beat)."""
        with self._roster.lock:
            return isinstance(name, str) and name in self._remote

    def depart(self, seat: Seat) -> None:
        """The trainee of ``seat`` leaves this process: kept in the gradebook with their last
        row (the trainer's table on every process lists them as not connected), unless another
        session of this process holds the name now."""
        if self._roster.by_name(seat.name, other_than=seat.session) is not None:
            return
        try:
            left = dataclasses.replace(seat.recorder.status, connected=False)
            self._gradebook.presence.depart(seat.name, dataclasses.asdict(left))
        except GradebookError:
            log.exception("the departure of %r could not be kept", seat.name)

    def drop(self, name: str) -> None:
        """The name's row goes, unless another session of this process holds the name now."""
        if name in self._roster.names():
            return
        try:
            self._gradebook.presence.drop(name, self.holder)
        except GradebookError:
            log.exception("the presence of %r could not be dropped", name)

    def start(self) -> None:
        """Start the heartbeat thread."""
        if self._beater is not None:
            return
        self._beater = threading.Thread(target=self._beat_loop, name="class-presence", daemon=True)
        self._beater.start()

    def close(self) -> None:
        """Stop the heartbeat and free every name this process holds."""
        self._stopping.set()
        if self._beater is not None:
            self._beater.join(timeout=5.0)
            self._beater = None
        try:
            self._gradebook.uptime.beat(self.holder, force=True)   # up until now: downtime starts here
            self._gradebook.presence.drop_holder(self.holder)
        except GradebookError:
            log.debug("presence not dropped: gradebook closed", exc_info=True)

    def _beat_loop(self) -> None:
        while not self._stopping.wait(self.poll_s):
            try:
                self.beat()
            except GradebookError:
                log.exception("class heartbeat failed")
            except Exception:  # the heartbeat must go on whatever one beat met
                log.exception("class heartbeat failed")

    def beat(self) -> None:
        """One heartbeat (``ClassRoom.beat``; module docstring)."""
        self._gradebook.uptime.beat(self.holder)       # this process is up (``classroom.uptime``)
        seats = {seat.name: seat for seat in self._roster.seats()}
        statuses = {name: dataclasses.asdict(seat.recorder.status) for name, seat in seats.items()}
        held = self._gradebook.presence.beat(self.holder, statuses)
        lost = [(seats[n], self._gradebook.presence.holder(n) is None) for n in sorted(set(statuses) - held)]
        if lost:
            self._hand_to_loop(functools.partial(self._on_lost, lost))
        remote = {}
        for name, holder, row in self._gradebook.presence.present():
            if holder != self.holder and isinstance(row, dict):
                status = _status(row)
                if status is not None:
                    remote[name] = status
        with self._roster.lock:
            changed = remote != self._remote
            self._remote = remote
        for push_id, push in self._gradebook.pushes.after(self._push_seen):
            self._push_seen = push_id
            if push.get("holder") != self.holder:
                self._hand_to_loop(functools.partial(self._on_push, push))
        self._deliver({name: seat for name, seat in seats.items() if name in held})
        if changed:
            self._hand_to_loop(self._refresh)

    def connected_names(self) -> list[str]:
        """Names of the trainees connected now on every process of the class: this process's in
        order of arrival, then the other processes' by name (the presence table)."""
        local = self._roster.names()
        try:
            remote = sorted({name for name, holder, _ in self._gradebook.presence.present() if holder != self.holder})
        except GradebookError:
            log.exception("the class's presence table is unreadable")
            remote = []
        return local + [name for name in remote if name not in local]

    def trainee_statuses(self) -> list[TraineeStatus]:
        """``ClassRoom.trainee_statuses``: this process's rows, the other processes' (by name),
        then those who left, the latest first. The departures are read after the connected
        trainees: a departure is kept before its trainee leaves the table, so one leaving
        meanwhile is in one list or the other."""
        with self._roster.lock:
            local = [seat.recorder.status for seat in self._roster.seats()]
            names = {row.name for row in local}
            remote = [row for name, row in sorted(self._remote.items()) if name not in names]
        names |= {row.name for row in remote}
        try:
            departed = self._gradebook.presence.departed()
        except GradebookError:
            log.exception("who left the class could not be read")
            departed = []
        left = []
        for name, row in departed:
            status = None if name in names else _status(row)
            if status is not None:
                left.append(status)
        return local + remote + left
