"""When a browser's message reached the server (monotonic s), for callbacks that must not act
on stale input (the pendant's deadman, ``pendant.jogging.PressGate``).

viser reads each websocket message in a per-connection task, decodes it
(``Message.deserialize``) and starts a task per handler (``create_task``), which copies the
reading task's context; the GUI callbacks then run in those tasks, one after the other, when
the event loop reaches them. Under load that is long after the message came in. :func:`install`
wraps viser's decoder so that every decoded message sets the context variable behind
:func:`arrived_s` in the reading task; the handler tasks made for that message inherit it, so a
callback reads the arrival of the very message it handles (not the time it runs).

The decoder runs only when the event loop gets round to the socket, so a message may already
have waited there while the loop was busy. The stamp is therefore not the decoding time but the
earliest time the message can have arrived, from the loop's own polls of its sockets (its
selector, wrapped on the first message; each poll's start and end are kept): a message decoded
in the loop's iteration ``j`` was read by poll ``j - 1``. If that poll waited (it returned when
data came), everything it returned arrived as it returned; if it returned at once, the data came
in after the end of poll ``j - 2``. The stamp is that time: not later than the real arrival (but
for the microseconds of a wake-up),
the safe side for a deadman (a press that may be stale counts as stale), and on an idle loop the
arrival itself.

Falls back to "now" (no hook) if viser's internals differ; the deadman then measures the wait
on the loop only.
"""

from __future__ import annotations

import asyncio
import collections
import contextvars
import logging
import threading
import time
import weakref
from typing import Any

__all__ = ["arrived_s", "install"]

log = logging.getLogger(__name__)

_WAITED_S = 0.0005
"""A poll that took longer than this waited for data (one that finds data ready takes microseconds)."""

_ARRIVED: contextvars.ContextVar[float | None] = contextvars.ContextVar("tcp_pendant_arrived_s", default=None)
_NOT_AFTER: contextvars.ContextVar[float | None] = contextvars.ContextVar("tcp_pendant_not_after_s", default=None)
_polls: weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, collections.deque[tuple[float, float]]] = (
    weakref.WeakKeyDictionary())
_lock = threading.Lock()
_installed = False


def stamp_not_after(t: float | None) -> None:
    """The next messages this task decodes are stamped no later than ``t`` (monotonic s; None:
    from the polls alone). The reader of a connection past its pace (``views.viser_adapter``,
    ``message_rate``) reads it slowly, so its messages wait unseen in the socket: it stamps
    them long ago, and a flood's presses are stale to the deadman instead of fresh when their
    turn comes."""
    _NOT_AFTER.set(t)


def arrived_s() -> float | None:
    """Arrival (``time.monotonic()`` s, the earliest possible) of the browser message whose
    callback is running, or None outside such a callback (or without the hook)."""
    return _ARRIVED.get()


class _TimedSelector:
    """The loop's selector, keeping the start and end (monotonic s) of its last three polls."""

    def __init__(self, inner: Any, polls: collections.deque[tuple[float, float]]) -> None:
        self._inner = inner
        self._polls = polls

    def select(self, timeout: float | None = None) -> Any:
        t0 = time.monotonic()
        try:
            return self._inner.select(timeout)
        finally:
            self._polls.append((t0, time.monotonic()))

    def __getattr__(self, name: str) -> Any:
        return getattr(self._inner, name)


def _stamp() -> float:
    now = time.monotonic()
    try:
        loop = asyncio.get_running_loop()
    except RuntimeError:
        return now
    polls = _polls.get(loop)
    if polls is None:                          # first message on this loop: time its polls
        polls = collections.deque(maxlen=3)
        _polls[loop] = polls
        selector = getattr(loop, "_selector", None)
        if selector is not None and callable(getattr(selector, "select", None)):
            loop._selector = _TimedSelector(selector, polls)  # type: ignore[attr-defined]
        else:
            log.warning("event loop without a selector: jog presses are timed from their decoding")
        return now
    if len(polls) < 3:
        return now
    (_, end_before), (start_read, end_read), _ = polls   # polls j - 2, j - 1 (read it) and j
    return min(now, end_read if end_read - start_read > _WAITED_S else end_before)


def install() -> bool:
    """Wrap viser's message decoder to stamp arrivals (idempotent; any thread). Returns False
    when viser's internals are not as expected (then :func:`arrived_s` stays None)."""
    global _installed
    with _lock:
        if _installed:
            return True
        try:
            from viser.infra._messages import Message
            original: Any = Message.__dict__["deserialize"].__func__
        except (ImportError, KeyError, AttributeError):
            log.warning("viser's message decoder not found: jog presses are timed from their callback")
            return False

        def deserialize(cls: type, message: bytes) -> Any:
            decoded = original(cls, message)
            ceiling = _NOT_AFTER.get()
            _ARRIVED.set(_stamp() if ceiling is None else min(_stamp(), ceiling))
            return decoded

        Message.deserialize = classmethod(deserialize)  # type: ignore[method-assign,assignment]
        _installed = True
        return True
