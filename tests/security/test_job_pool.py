"""One browser's jobs cannot stretch another's: the server's job pool (``tcp_pendant.job_pool``)
runs one job per session at a time, refuses beyond a bounded queue in words, and serves a
session that rested since its last result before the sessions that keep the pool busy.

The attack: a pendant server in this process; 20 attacker sessions on it each run the Tool
tab's TCP check job (six rotations on the session's own robot) again the moment its result is
back; the victim, a browser over a real websocket, runs the same check from its Tool tab now
and then and jogs in between (the rig: ``job_attack.py``). The victim's check waits for no
busy session's job beyond the ones already running (one per worker), so its latency stays
within :data:`FACTOR` of its latency alone (the figure is printed; ``tests/bench/bench_jobs.py``
prints more), and its jogs are answered.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.job_pool import LOOP_SWITCH_INTERVAL_S, JobPool, PoolFull, SessionBusy, favour_the_event_loop

from support.job_attack import Classroom
from support.wsclient import wait_until

ATTACKERS = 20
FACTOR = 4.0
"""The victim's median check latency under attack over its median alone, at most. The design
lets at most one job per worker run ahead of it: ~2x with jobs of its size (measured 2.5x at
the server's 1 ms switch interval; 5-8x at Python's 5 ms, where each of the loop's hops waits
for the worker's GIL). The rest is margin for the machine: one check's run time varies 2-3x
from one second to the next on a shared 2-core machine, and "alone" is measured a few seconds
before the attack."""
JOG_P95_LIMIT_S = 0.5
RIG_BURST_S = 60.0
"""The pool's credit per session in the 20-attacker rig (``JobPool``'s ``burst_s``)."""


# ------------------------------------------------------------ the pool's rules, one by one
class Owner:
    """A session, as far as the pool is concerned (any object it can reference weakly)."""


class Gate:
    """A job that runs until the test opens its gate (no sleeps: the test decides when)."""

    def __init__(self) -> None:
        self.started = threading.Event()
        self.gate = threading.Event()

    def __call__(self) -> str:
        self.started.set()
        assert self.gate.wait(10), "the test never opened the gate"
        return "done"


def test_a_second_job_of_a_session_is_refused_in_words_while_its_first_runs() -> None:
    pool = JobPool(workers=1)
    a, b = Owner(), Owner()
    try:
        first = Gate()
        fut = pool.submit(a, first, what="a TCP check")
        assert first.started.wait(10)
        with pytest.raises(SessionBusy, match=r"^A TCP check is still running here; wait for its result, "
                                              r"then try again\.$"):
            pool.submit(a, lambda: "second", what="a beam check")
        other = pool.submit(b, lambda: "b's", what="a beam check")     # another session is not refused
        assert pool.pending(a) == "a TCP check" and pool.pending(b) == "a beam check"
        first.gate.set()
        assert fut.result(10) == "done" and other.result(10) == "b's"
        assert pool.submit(a, lambda: "again", what="a TCP check").result(10) == "again"   # once it is done
    finally:
        first.gate.set()
        pool.shutdown()


def test_a_full_queue_is_refused_in_words_and_a_rested_session_has_room_kept() -> None:
    pool = JobPool(workers=1, max_queued=2, rest_s=60.0)
    owners = [Owner() for _ in range(6)]
    blocker = Gate()
    try:
        pool.submit(owners[0], blocker, what="a TCP check")
        assert blocker.started.wait(10)
        blocker.gate.set()
        wait_until(lambda: pool.pending(owners[0]) is None, what="the first job")
        # owners 1..3 each ran a job just now: within rest_s of their result, they are busy
        for o in owners[1:4]:
            pool.submit(o, lambda: None, what="a TCP check").result(10)
        hold = Gate()
        pool.submit(owners[0], hold, what="a beam check")             # busy too; it runs, holding the worker
        assert hold.started.wait(10)
        pool.submit(owners[1], lambda: None, what="a TCP check")
        pool.submit(owners[2], lambda: None, what="a TCP check")
        with pytest.raises(PoolFull, match=r"^The server is busy: 2 jobs are waiting\. Try again in a moment\.$"):
            pool.submit(owners[3], lambda: None, what="a TCP check")
        # a session that never ran a job (rested) still gets in, up to twice the bound
        pool.submit(owners[4], lambda: None, what="a TCP check")
        pool.submit(owners[5], lambda: None, what="a TCP check")
        with pytest.raises(PoolFull, match="4 jobs are waiting"):
            pool.submit(Owner(), lambda: None, what="a TCP check")
        assert pool.queued == 4 and pool.pending(owners[3]) is None
        hold.gate.set()
    finally:
        blocker.gate.set()
        pool.shutdown()


def test_a_rested_session_goes_ahead_of_busy_ones_which_take_turns() -> None:
    pool = JobPool(workers=1, rest_s=60.0, keep_history=True)
    busy = [Owner() for _ in range(3)]
    victim = Owner()
    order: list[str] = []
    try:
        for i, o in enumerate(busy):                       # each has just had a result: busy from now
            pool.submit(o, lambda: None, what=f"job {i}").result(10)
        hold = Gate()
        pool.submit(Owner(), hold, what="the running job")
        assert hold.started.wait(10)
        futures = [pool.submit(o, lambda i=i: order.append(f"busy {i}"), what=f"job {i}")
                   for i, o in enumerate(busy)]
        futures.append(pool.submit(victim, lambda: order.append("victim"), what="the victim's job"))
        hold.gate.set()
        for f in futures:
            f.result(10)
        assert order == ["victim", "busy 0", "busy 1", "busy 2"]
        assert pool.history is not None and [h.busy for h in pool.history[-4:]] == [False, True, True, True]
    finally:
        pool.shutdown()


# ------------------------------------------------------------ 20 attackers, one victim
@pytest.fixture
def classroom(tmp_path: Path) -> Iterator[Classroom]:
    # the victim's checks come back to back here (a script's pace, not a trainee's): a credit that
    # holds them all, so this measures the order rule (the share is test_browser_flood.py's)
    c = Classroom(tmp_path, JobPool(keep_history=True, burst_s=RIG_BURST_S), attackers=ATTACKERS)
    yield c
    c.close()


def test_twenty_attackers_do_not_stretch_the_victims_check_beyond_the_factor(classroom: Classroom) -> None:
    c = classroom
    assert sys.getswitchinterval() <= LOOP_SWITCH_INTERVAL_S     # the server's start favours its loop
    m = c.measure(n_alone=5, n_under=5)
    print("\n" + m.summary())
    assert [v.busy for v in m.victim_jobs] == [False] * 5              # it rested: served first
    # no job of a session that keeps the pool busy started while the victim's waited (a rested
    # one could, by the rule: an attacker whose resubmit the loop delayed past REST_S)
    assert [[h for h in a if h.busy] for a in m.ahead] == [[]] * 5, "a busy session's job went ahead"
    assert m.attackers == ATTACKERS and len(m.attacker_jobs) >= 10    # the attack really ran
    assert c.notes == [], "a check of the victim was refused or failed"
    assert all(not a.done() for a in c.attacks), "an attacker's job was refused or failed"
    assert m.factor <= FACTOR
    assert m.unanswered == 0 and float(np.percentile(m.jogs, 95)) < JOG_P95_LIMIT_S


def test_favouring_the_loop_only_ever_shortens_the_switch_interval_and_refuses_nonsense() -> None:
    before = sys.getswitchinterval()
    try:
        sys.setswitchinterval(0.005)
        assert favour_the_event_loop() == pytest.approx(LOOP_SWITCH_INTERVAL_S)
        sys.setswitchinterval(0.0002)                            # shorter already: kept
        assert favour_the_event_loop() == pytest.approx(0.0002)
        for bad in (0.0, -1.0, float("nan"), float("inf")):
            with pytest.raises(ValueError, match="switch interval must be a positive number of seconds"):
                favour_the_event_loop(bad)
    finally:
        sys.setswitchinterval(before)


def test_a_job_given_up_before_it_started_leaves_the_queue_and_its_sessions_place() -> None:
    pool = JobPool(workers=1)
    a, b = Owner(), Owner()
    hold = Gate()
    try:
        pool.submit(a, hold, what="a beam check")
        assert hold.started.wait(10)
        waiting = pool.submit(b, lambda: "never", what="a TCP check")
        assert pool.queued == 1 and pool.pending(b) == "a TCP check"
        assert waiting.cancel()                                  # its browser's task was cancelled
        assert pool.queued == 0 and pool.pending(b) is None
        again = pool.submit(b, lambda: "b's", what="a TCP check")    # not refused as still running
        hold.gate.set()
        assert again.result(10) == "b's"
    finally:
        hold.gate.set()
        pool.shutdown()
