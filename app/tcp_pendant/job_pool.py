"""The server's one pool of browser-triggered jobs, fair per session (no viser).

Every job whose size a browser controls (a TCP check's six rotations, a beam scan, the
parsing and replay of an uploaded session record, a record's grading, the probes of
Auto-touch's pose) is taken on viser's event loop with its limits checked first, then run
here, off the loop, by :meth:`JobPool.run` (an ``async`` function a viser callback awaits:
the loop keeps serving every browser meanwhile).

The rules (what bounds the harm one browser can do to another):

* **one job per session**: a session (the pool's ``owner``) has at most one job queued or
  running; a second submit while one is pending is refused with :class:`SessionBusy`
  ("A TCP check is still running here ..."), whatever kind of job it is;
* **a share per session**: a session's jobs draw on a credit of ``burst_s`` (:data:`BURST_S`,
  0.25 s) of run time that refills at ``share`` (:data:`SHARE`, 0.1) seconds per second: on
  average a tenth of one worker, in bursts of a quarter second (a trainee's two or three TCP
  checks in a row). A job is admitted while the credit is positive and costs its whole run, so a
  job longer than the credit (a beam scan, a record's grading) leaves a debt that refills at the
  same pace: after a 1 s scan the session waits about 7.5 s. A job's work on viser's event
  loop (a TCP check's setup and the result it shows) is charged to the same credit
  (:meth:`JobPool.charge`). With no credit left a submit is refused at once with :class:`OverShare` ("The server is busy with
  this browser's jobs: try again in 3 s"), and the views ask first (:meth:`JobPool.admit`), so
  a refused click costs the loop no job setup; the session's refusal notices are coalesced
  (``refusal_notices``);
* **a bounded queue**: at most ``max_queued`` jobs of busy sessions wait (twice as many in
  all, so a resting trainee is not refused because others keep the pool busy); beyond it a
  submit is refused with :class:`PoolFull` ("The server is busy ...");
* **a rested session goes first**: a session is *busy* when it submits within ``rest_s``
  (0.5 s) of its previous job's result, as a script resubmitting at once does, and *rested*
  otherwise (its first job; a person reading a result). Jobs are served in the order of their
  key, the submit time, plus ``busy_delay_s`` (30 s) for a busy session's job: rested jobs
  first, in the order they came (first come, first served), then the busy ones, also in
  the order they came (with one job per session: round robin among the busy sessions). The
  delay bounds how long a busy session can be held back by rested ones.

The figure this guarantees: a rested session's job waits for at most the jobs already running
(one per worker) and the rested jobs submitted before it; against any number of sessions that
keep the pool busy, its latency is its own run time plus at most one job per worker (the
longest a browser can start: a beam scan, up to about a second; a TCP check 0.03-0.3 s). A
browser can defeat it only by pacing many sessions at ``rest_s`` or more apart; they then
share the pool first come, first served with the other rested sessions, and the bounded queue
refuses the excess. ``tests/security/test_job_pool.py`` proves it with 20 attacking sessions,
``tests/bench/bench_jobs.py`` prints the latencies (that rig's victim checks back to back, at a
script's pace: its pool gives every session a credit of 60 s, so it measures the order alone).

One browser flooding the pool (Check, "Check active tool" and Auto-touch clicked in
turn as fast as it can; the rig of ``tests/support/browser_flood.py``, ``bench_jobs.py
--flood``: another browser's X+ press to the readout showing the move, 40 presses alone and 40
under the flood, interleaved in blocks, 2 shared cores, one worker). Without the share, the
refusal rules and the pace, the one worker runs the attacker's checks back to back, holding the
GIL against the loop, and every refused click costs the loop a notification (a refused
Auto-touch a re-render of the Calibrate tab): measured at 128 clicks a second, the victim's p95
22 ms alone and 60 ms under the flood (2.75x); as fast as the socket allows, every press
dropped. With the share, the refusals coalesced and the
connection's messages paced (``message_rate``): at 128 clicks a second p95 25 against 26 ms and
25 against 25 ms (1.05x, 1.01x), as fast as the socket allows 23 against 31 ms and 23 against
29 ms (1.33x, 1.26x), none dropped; with a credit of 1 s instead of 0.25 s, 1.7-1.9x at 128 a
second. ``tests/security/test_browser_flood.py`` proves the behaviour (every press carried out,
the attacker refused in words, the victim's check behind no job of the attacker's but the one
running).

Threads, not processes: the jobs are numpy / pinocchio code driven from Python (per sub-step
IK, small arrays) that holds the GIL most of the time, so a second worker thread adds little
throughput and takes GIL time from viser's event loop (the jogs) and from the job running
beside it. One worker per core beyond the one the loop needs, at most two
(:func:`default_workers`; one on a 2-core machine). A process pool would take the jobs' GIL
time off the loop, but each job carries pinocchio models (its own ``RobotKinematics`` copies)
and a record's replay needs the robot models: they would be pickled per job or built per
process (measured: a TCP check's job pickles to 213 kB in 8 ms, unpickles in 3-16 ms), and a
record's grading holds the gradebook's connection, which does not cross processes. With
threads the loop measured well enough (``bench_jobs.py`` on 2 shared cores, one worker, 20
attackers: the victim's jogs p95 44-57 ms, none dropped; its check p50 1.0-2.9x its time alone;
with two workers no better: p50 0.98x, jogs p95 60 ms), and the one-job-per-session rule with
the rested-first order is what bounds the harm. The GIL's price is the loop's hops while a
worker is busy: each time the loop gives the GIL up (a select, a socket write) it waits for
the worker's next forced switch, Python's switch interval (5 ms by default), so a callback of a
few hops waits tens of ms. :func:`favour_the_event_loop` (the server calls it at start) sets
the interval to :data:`LOOP_SWITCH_INTERVAL_S`. Measured with the rig of ``test_job_pool.py``
(20 attackers, one worker, this 2-core machine), 5 ms against 1 ms: the victim's jogs p50 60
against 8 ms, p95 183 against 17 ms; its check p50 86 against 36 ms (5.3x against 2.5x its
time alone); the attackers' jobs then get about half as many runs (206 against 99 in the same
time), the loop the rest. At 0.5 ms the switches themselves cost: an attacker's check ran 36
against 25 ms. ``bench_jobs.py`` prints both intervals in one run.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import heapq
import itertools
import math
import os
import sys
import threading
import time
import weakref
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, TypeVar

__all__ = ["BUSY_DELAY_S", "MAX_QUEUED", "REST_S", "SHARE", "BURST_S", "JobPool", "JobRefused",
           "JobTiming", "OverShare", "PoolFull", "LOOP_SWITCH_INTERVAL_S", "SessionBusy", "default_pool",
           "default_workers", "favour_the_event_loop"]

T = TypeVar("T")

REST_S = 0.5
"""A session that submits within this many seconds of its previous job's result is busy."""
BUSY_DELAY_S = 30.0
"""How much later than its submit time a busy session's job is queued (seconds)."""
MAX_QUEUED = 32
"""Jobs of busy sessions that may wait; twice as many jobs in all."""
LOOP_SWITCH_INTERVAL_S = 0.001
"""Python's thread switch interval while the server runs (seconds; module docstring)."""
SHARE = 0.1
"""The part of one worker's time one session's jobs (and the loop work charged to it,
:meth:`JobPool.charge`) may use on average: its credit refills at this many seconds per second."""
BURST_S = 0.25
"""A session's credit when full (seconds of jobs it may run back to back)."""


class JobRefused(ValueError):
    """A job not queued; the message says why and what to do (shown to the browser)."""


class SessionBusy(JobRefused):
    """The session already has a job queued or running (``what``: that job, as its caller named it)."""

    def __init__(self, message: str, what: str = "") -> None:
        super().__init__(message)
        self.what = what


class PoolFull(JobRefused):
    """The queue is full (``waiting``: the jobs waiting)."""

    def __init__(self, message: str, waiting: int = 0) -> None:
        super().__init__(message)
        self.waiting = waiting


class OverShare(JobRefused):
    """The session's jobs used their share of the server's time within the window."""

    def __init__(self, message: str, retry_in_s: float) -> None:
        super().__init__(message)
        self.retry_in_s = retry_in_s


def default_workers() -> int:
    """Worker threads: one per core beyond the one viser's event loop needs, at least one and at
    most two (the jobs hold the GIL most of the time: see the module docstring)."""
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    return max(1, min(2, cpus - 1))


@dataclass(eq=False)
class _Job:
    owner: object
    fn: Callable[[], Any]                  # its result goes to the future the caller holds (a Future[T])
    what: str
    future: concurrent.futures.Future[Any]
    submitted_s: float
    busy: bool
    started_s: float | None = None
    finished_s: float | None = None


@dataclass(frozen=True)
class JobTiming:
    """When one job was submitted, started and finished (``time.monotonic`` seconds), and
    whether its session was busy; for tests and the benchmark (:attr:`JobPool.history`)."""

    owner: object = field(repr=False)
    what: str
    submitted_s: float
    started_s: float
    finished_s: float
    busy: bool


class JobPool:
    """A bounded pool of worker threads, fair per session (see the module docstring).

    Args:
        workers: worker threads (default :func:`default_workers`).
        max_queued: jobs of busy sessions that may wait (twice as many in all).
        rest_s: a session that submits within this many seconds of its previous result is busy.
        busy_delay_s: how much later than its submit time a busy session's job is queued.
        share: the part of one worker's time one session's jobs (and the loop work charged to
            it) may use on average: its credit refills at ``share`` seconds per second.
        burst_s: a session's credit when full; at no credit left a submit is refused
            (:class:`OverShare`).
        name: the threads' name prefix.
        keep_history: keep a :class:`JobTiming` of each finished job in :attr:`history`
            (tests and benchmarks; off in the server).
    """

    def __init__(self, workers: int | None = None, *, max_queued: int = MAX_QUEUED, rest_s: float = REST_S,
                 busy_delay_s: float = BUSY_DELAY_S, share: float = SHARE, burst_s: float = BURST_S,
                 name: str = "tcp-pendant-job", keep_history: bool = False) -> None:
        self.workers = default_workers() if workers is None else int(workers)
        if self.workers < 1 or max_queued < 1:
            raise ValueError(f"A job pool needs at least one worker and one queue place, got {workers} "
                             f"and {max_queued}.")
        self.max_queued = int(max_queued)
        self.rest_s = float(rest_s)
        self.busy_delay_s = float(busy_delay_s)
        if not (share > 0.0 and burst_s > 0.0):
            raise ValueError(f"A session's share and burst must be positive, got {share} and {burst_s} s.")
        self.share = float(share)
        self.burst_s = float(burst_s)
        self.name = name
        self.history: list[JobTiming] | None = [] if keep_history else None
        self._cond = threading.Condition()
        self._queue: list[tuple[float, int, _Job]] = []          # heap of (key, order, job)
        self._order = itertools.count()
        self._pending: dict[int, _Job] = {}                     # id(owner) -> its job, queued or running
        self._last_result: weakref.WeakKeyDictionary[object, float] = weakref.WeakKeyDictionary()
        # owner -> its credit (seconds; below 0 after a job longer than the credit) and when it was counted
        self._credit: weakref.WeakKeyDictionary[object, tuple[float, float]] = weakref.WeakKeyDictionary()
        self._threads: list[threading.Thread] = []
        self._closed = False

    # ------------------------------------------------------------ submitting
    async def run(self, owner: object, fn: Callable[[], T], *, what: str) -> T:
        """Run ``fn()`` in the pool for ``owner`` (a session) and return its value (or raise
        its exception), awaiting it without blocking the event loop.

        Args:
            owner: whose job it is (one job per owner at a time; held weakly once finished, so
                an owner that cannot be referenced weakly always counts as rested).
            fn: the job, detached from the session (its own copies of what it reads).
            what: the job in words, lower case with its article ("a TCP check"), for the
                refusal another submit of the same owner gets meanwhile.

        Raises:
            SessionBusy: ``owner`` has a job queued or running.
            PoolFull: the queue is full.
        """
        return await asyncio.wrap_future(self.submit(owner, fn, what=what))

    def submit(self, owner: object, fn: Callable[[], T], *, what: str) -> concurrent.futures.Future[T]:
        """:meth:`run` without awaiting: the job's future (any thread may call it)."""
        future: concurrent.futures.Future[T] = concurrent.futures.Future()
        with self._cond:
            if self._closed:
                raise JobRefused("The server is shutting down; the job was not started.")
            now = time.monotonic()
            self._admit(owner, now)
            try:
                last = self._last_result.get(owner)
            except TypeError:           # an owner that cannot be referenced weakly: always rested
                last = None
            busy = last is not None and now - last < self.rest_s
            waiting = len(self._queue)
            if waiting >= (self.max_queued if busy else 2 * self.max_queued):
                raise PoolFull(f"The server is busy: {waiting} jobs are waiting. Try again in a moment.", waiting)
            job = _Job(owner, fn, what, future, now, busy)
            self._pending[id(owner)] = job
            heapq.heappush(self._queue, (now + (self.busy_delay_s if busy else 0.0), next(self._order), job))
            self._start_threads()
            self._cond.notify()
        future.add_done_callback(lambda f: self._drop_cancelled(job) if f.cancelled() else None)
        return future

    def admit(self, owner: object) -> None:
        """Refuse at once what :meth:`submit` would refuse for ``owner`` itself (its pending job,
        its share used up), before a caller spends the event loop's time on taking a job.

        Raises:
            SessionBusy: ``owner`` has a job queued or running.
            OverShare: ``owner``'s jobs used their share within the window; its message says
                in how many seconds to try again.
        """
        with self._cond:
            self._admit(owner, time.monotonic())

    def _admit(self, owner: object, now: float) -> None:
        running = self._pending.get(id(owner))
        if running is not None:
            raise SessionBusy(f"{running.what[:1].upper()}{running.what[1:]} is still running here; "
                              "wait for its result, then try again.", running.what)
        retry_in_s = self._retry_in_s(owner, now)
        if retry_in_s > 0.0:
            wait = max(1, math.ceil(retry_in_s))
            raise OverShare(f"The server is busy with this browser's jobs: try again in {wait} s.", retry_in_s)

    def _retry_in_s(self, owner: object, now: float) -> float:
        """Seconds until ``owner`` has credit again (0: it has)."""
        credit = self._credit_at(owner, now)
        return 0.0 if credit > 0.0 else -credit / self.share + 1e-3

    def _credit_at(self, owner: object, now: float) -> float:
        """``owner``'s credit at ``now`` (full for an owner never counted or not weakly
        referable)."""
        try:
            held = self._credit.get(owner)
        except TypeError:
            return self.burst_s
        if held is None:
            return self.burst_s
        credit, when = held
        return min(self.burst_s, credit + (now - when) * self.share)

    def charge(self, owner: object, seconds: float) -> None:
        """Count ``seconds`` of the event loop's time spent on ``owner``'s job-like work (e.g.
        a TCP check's setup and the result it shows) against its credit, as a job's run."""
        if seconds > 0.0:
            with self._cond:
                self._spend(owner, time.monotonic(), float(seconds))

    def credit_s(self, owner: object) -> float:
        """``owner``'s credit now (seconds; negative: refused for ``-credit / share`` s)."""
        with self._cond:
            return self._credit_at(owner, time.monotonic())

    def _spend(self, owner: object, now: float, seconds: float) -> None:
        try:
            self._credit[owner] = (self._credit_at(owner, now) - seconds, now)
        except TypeError:           # an owner that cannot be referenced weakly: not counted
            pass

    def _drop_cancelled(self, job: _Job) -> None:
        """A job whose caller gave up before it started (its awaiting task was cancelled) leaves
        the queue and its owner's place at once."""
        with self._cond:
            if self._pending.get(id(job.owner)) is job:
                del self._pending[id(job.owner)]
            kept = [entry for entry in self._queue if entry[2] is not job]
            if len(kept) != len(self._queue):
                heapq.heapify(kept)
                self._queue = kept

    def pending(self, owner: object) -> str | None:
        """What ``owner``'s queued or running job is (its ``what``), or None."""
        with self._cond:
            job = self._pending.get(id(owner))
            return None if job is None else job.what

    @property
    def queued(self) -> int:
        """Jobs waiting for a worker (not counting the running ones)."""
        with self._cond:
            return len(self._queue)

    # ------------------------------------------------------------ workers
    def _start_threads(self) -> None:
        """Start the worker threads at the first job (a pool nobody uses costs no thread)."""
        while len(self._threads) < self.workers:
            t = threading.Thread(target=self._work, name=f"{self.name}-{len(self._threads) + 1}", daemon=True)
            self._threads.append(t)
            t.start()

    def _work(self) -> None:
        while True:
            with self._cond:
                while not self._queue and not self._closed:
                    self._cond.wait()
                if not self._queue:
                    return
                _, _, job = heapq.heappop(self._queue)
            job.started_s = time.monotonic()
            if not job.future.set_running_or_notify_cancel():      # its caller gave up waiting
                self._finished(job)
                continue
            try:
                value = job.fn()
            except BaseException as exc:  # the awaiting callback shows it; the worker lives on
                self._finished(job)
                job.future.set_exception(exc)
            else:
                self._finished(job)
                job.future.set_result(value)

    def _finished(self, job: _Job) -> None:
        """The job is no longer its owner's pending one: done before its future is resolved,
        so the owner's next submit, made as soon as it has the result, is not refused."""
        job.finished_s = time.monotonic()
        with self._cond:
            self._pending.pop(id(job.owner), None)
            try:
                self._last_result[job.owner] = job.finished_s
                if job.started_s is not None:
                    self._spend(job.owner, job.finished_s, job.finished_s - job.started_s)
            except TypeError:           # an owner that cannot be referenced weakly: no history
                pass
            if self.history is not None and job.started_s is not None:
                self.history.append(JobTiming(job.owner, job.what, job.submitted_s, job.started_s,
                                              job.finished_s, job.busy))

    def shutdown(self, *, wait: bool = True) -> None:
        """Refuse new jobs, cancel the queued ones, let the running ones finish (and wait for
        them when ``wait``)."""
        with self._cond:
            self._closed = True
            queued, self._queue = self._queue, []
            for _, _, job in queued:
                self._pending.pop(id(job.owner), None)
                job.future.cancel()
            self._cond.notify_all()
            threads = list(self._threads)
        if wait:
            for t in threads:
                if t is not threading.current_thread():
                    t.join()


def favour_the_event_loop(interval_s: float = LOOP_SWITCH_INTERVAL_S) -> float:
    """Let viser's event loop take the GIL back from a busy worker within ``interval_s``
    (Python's switch interval, ``sys.setswitchinterval``; never raised above what it is).
    Process-wide, as the GIL is. Returns the interval now in force (seconds)."""
    if not (math.isfinite(interval_s) and interval_s > 0):
        raise ValueError(f"The switch interval must be a positive number of seconds, got {interval_s!r}.")
    if sys.getswitchinterval() > interval_s:
        sys.setswitchinterval(interval_s)
    return sys.getswitchinterval()


_DEFAULT: JobPool | None = None
_DEFAULT_LOCK = threading.Lock()


def default_pool() -> JobPool:
    """The process's pool for sessions built without one (``Session.jobs``; the server passes
    its own, :attr:`PendantApp.jobs`)."""
    global _DEFAULT
    with _DEFAULT_LOCK:
        if _DEFAULT is None:
            _DEFAULT = JobPool()
        return _DEFAULT
