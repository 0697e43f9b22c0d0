"""A session's callbacks on viser's event loop and its jobs off it (``Session.loop``).

Every GUI callback is registered through :meth:`SessionLoop.on_loop`, an ``async`` callback,
so viser runs it on its event loop, one at a time and in the order the browser's messages
arrived, and the messages it queues are pushed from the loop's own thread (viser's message
buffer is not safe to push to from other threads). :meth:`SessionLoop.guard` is the
synchronous part: it takes the session's lock (a re-entrant lock, still taken because a few
things run elsewhere: workers copy state under it (Check, record replay), tests drive sessions
from their own thread; the session itself is built on the loop, see
``PendantApp.session_steps``), ignores events after the session closed, and turns any exception
into a notification instead of a crash (a browser can send anything). Work from another thread
is handed to the loop (the server's library watcher: ``loop.call_soon_threadsafe``). Work whose
size a browser controls (a check, a scan, a record's replay, Auto-touch's pose probes) is a job
detached from the session, run in the server's job pool by :meth:`SessionLoop.run_job`
(``job_pool``: one job per session, a bounded queue), awaited without blocking the loop.
"""

from __future__ import annotations

import asyncio
import functools
import logging
import threading
import time
from collections.abc import Callable, Coroutine, Iterator
from contextlib import contextmanager
from typing import Any, ParamSpec, Protocol, TypeVar

from tcp_pendant.controller.words import error_text
from tcp_pendant.job_pool import JobPool
from tcp_pendant.translation import Translator

__all__ = ["LoopHost", "SessionLoop", "running_loop"]

log = logging.getLogger(__name__)
P = ParamSpec("P")
R = TypeVar("R")


class LoopHost(Protocol):
    """What :class:`SessionLoop` needs of its session (the job pool counts jobs per host)."""

    lock: threading.RLock
    closed: bool
    jobs: JobPool
    translator: Translator

    def notify(self, title: str, body: str, *, kind: str = "info") -> None: ...


def running_loop() -> asyncio.AbstractEventLoop | None:
    """The event loop running this thread's code (viser's, in a callback), None outside one."""
    try:
        return asyncio.get_running_loop()
    except RuntimeError:
        return None


class SessionLoop:
    """The session's side of viser's event loop (module docstring)."""

    def __init__(self, host: LoopHost) -> None:
        self._host = host

    def guard(self, fn: Callable[P, R]) -> Callable[P, R | None]:
        """Wrap a GUI callback: lock, skip after close (None), report errors as notifications."""
        host = self._host

        @functools.wraps(fn)
        def wrapper(*args: P.args, **kwargs: P.kwargs) -> R | None:
            if host.closed:
                return None
            try:
                with host.lock:
                    if host.closed:
                        return None
                    return fn(*args, **kwargs)
            except ValueError as exc:  # our packages' errors are ValueErrors with clear messages
                tr = host.translator
                host.notify(tr.gettext("Not done"), error_text(exc, tr), kind="warning")
            except Exception as exc:  # never let a browser event kill the server
                log.exception("callback %s failed", getattr(fn, "__name__", fn))
                host.notify(host.translator.gettext("Internal error"), f"{type(exc).__name__}: {exc}", kind="error")
            return None

        return wrapper

    def on_loop(self, fn: Callable[P, object]) -> Callable[P, Coroutine[Any, Any, None]]:
        """``fn`` as a GUI callback that viser runs on its event loop, under :meth:`guard`.

        viser awaits an ``async`` callback on its event loop (a plain one goes to its thread
        pool), so callbacks wrapped here run one at a time, in the order the browser sent its
        messages: a callback reads ``event.target.value`` after the previous message was
        handled, and every message it queues is pushed from the loop's thread. It must be
        short (a jog step or an IK solve takes milliseconds); it never awaits. Our own
        assignments to a handle's value fire it too, later on the loop, with
        ``event.client is None``.

        Args:
            fn: the callback, given viser's event (it may also be called with no argument).

        Returns:
            An ``async`` function to register with ``on_click`` / ``on_update`` / ``on_hold``.
        """
        guarded = self.guard(fn)

        @functools.wraps(fn)
        async def callback(*args: P.args, **kwargs: P.kwargs) -> None:
            guarded(*args, **kwargs)

        return callback

    def at_round_end(self, fn: Callable[[], None]) -> bool:
        """Run ``fn`` (under :meth:`guard`) at the end of the running loop's current round
        (``loop.call_soon``). False, and nothing scheduled, outside a running loop."""
        loop = running_loop()
        if loop is None:
            return False
        loop.call_soon(self.guard(fn))
        return True

    def admit_job(self) -> None:
        """Refuse at once a job this session may not start now (its previous job still runs, or
        its jobs used their share of the server's time: ``JobPool.admit``), before the event
        loop spends time on taking it.

        Raises:
            JobRefused: ``SessionBusy`` or ``OverShare``; the message says what to do.
        """
        self._host.jobs.admit(self._host)

    @contextmanager
    def charged(self) -> Iterator[None]:
        """Count the event loop's time spent inside against this session's share of the job
        pool (``JobPool.charge``): a job's work done on the loop (a TCP check's setup and the
        result it shows)."""
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self._host.jobs.charge(self._host, time.perf_counter() - t0)

    async def run_job(self, fn: Callable[[], R], *, what: str) -> R:
        """Run ``fn()``, a job detached from the session (its own copies of what it reads, taken
        on the loop with its limits checked), in the server's job pool, off viser's event loop,
        and return its value (or raise its exception). One job per session at a time, the
        rested sessions' jobs first (``job_pool``).

        Args:
            fn: the job; it must not touch the session, its GUI or its controller.
            what: the job in words with its article ("a TCP check"), for the refusal of
                another job of this session meanwhile.

        Raises:
            JobRefused: this session's previous job still runs (``SessionBusy``) or the
                server's queue is full (``PoolFull``); the message says what to do.
        """
        return await self._host.jobs.run(self._host, fn, what=what)
