"""When a browser's message reached the server (monotonic s), for callbacks that must not act
on stale input (the pendant's deadman, ``pendant.jogging.PressGate``). No private API here: the
hooks that feed this module are in ``views.viser_adapter``.

viser reads each websocket connection in a task of its own and starts a task per handler
(``create_task``), which copies the reading task's context; the GUI callbacks run in those
tasks, one after the other, when the event loop reaches them. Under load that is long after the
message came in. The reading task (``viser_adapter.install``) sets the context variable behind
:func:`arrived_s` to the message's stamp before it hands the message on, so a callback reads the
arrival of the very message it handles, not the time it runs.

The stamp is the *earliest* time the message can have arrived: a press that may be stale counts
as stale, the safe side for a deadman. Two lower bounds, the smaller of which is taken:

* **The loop's polls** (:func:`earliest_from_polls`): the loop reads a socket only when it gets
  round to it, so a message may have waited there while the loop was busy. Of the loop's polls
  of its sockets (their starts and ends), a message read in the loop's iteration ``j`` came in
  poll ``j - 1``: if that poll waited (it returned when data came), the message arrived as it
  returned; if it returned at once, the data came in after the end of poll ``j - 2``.
* **The connection's backlog** (:class:`ArrivalFloor`): a connection read at a pace
  (``message_rate``) leaves its later messages in the socket, where no poll sees them. A message
  that was already received when its connection's reader asked for it arrived after the
  message before it, so it is stamped no later than that one; a message asked for while nothing
  of the connection was unread arrived after the asking. A flood's presses thus keep the stamp of
  the flood's start and are dropped by the deadman, and the first press after the backlog is
  read is fresh again.
"""

from __future__ import annotations

import contextvars
from collections.abc import Sequence

__all__ = ["WAITED_S", "ArrivalFloor", "arrived_s", "earliest_from_polls", "set_arrived"]

WAITED_S = 0.0005
"""A poll that took longer than this (s) waited for data (one that finds data ready takes microseconds)."""

_ARRIVED: contextvars.ContextVar[float | None] = contextvars.ContextVar("tcp_pendant_arrived_s", default=None)


def arrived_s() -> float | None:
    """Arrival (``time.monotonic()`` s, the earliest possible) of the browser message whose
    callback is running, or None outside such a callback (or when viser's internals differ)."""
    return _ARRIVED.get()


def set_arrived(t: float | None) -> None:
    """Stamp the messages the current task hands on from now (``viser_adapter``'s reader)."""
    _ARRIVED.set(t)


def earliest_from_polls(polls: Sequence[tuple[float, float]], now: float) -> float:
    """The earliest arrival (monotonic s) of data read from a socket now, from the loop's last
    three polls (start, end; the oldest first): ``end[j-1]`` if poll ``j - 1`` waited longer
    than :data:`WAITED_S`, else ``end[j-2]``; ``now`` with fewer than three polls known."""
    if len(polls) < 3:
        return now
    (_, end_before), (start_read, end_read) = polls[-3], polls[-2]
    return min(now, end_read if end_read - start_read > WAITED_S else end_before)


class ArrivalFloor:
    """The backlog bound of one connection's stamps (module docstring).

    Call :meth:`stamp` once per message, in the order they are read, with whether anything of
    the connection was unread when the reader asked for this message and the message's stamp
    from the polls.
    """

    def __init__(self) -> None:
        self._floor: float | None = None

    def stamp(self, backlog: bool, from_polls: float) -> float:
        """The message's stamp (monotonic s): ``from_polls`` when the reader was caught up,
        else no later than the stamp of the message before it."""
        if not backlog or self._floor is None:
            self._floor = from_polls
        else:
            self._floor = min(from_polls, self._floor)
        return self._floor
