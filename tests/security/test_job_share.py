"""The rules that keep one browser's clicks from slowing another's, one by one (no server):
a session's share of the job pool (``JobPool``: a credit of 0.25 s refilling at a tenth of a
second per second, refused at once beyond it), its refusal notices coalesced
(``refusal_notices``) and each connection's messages paced (``message_rate``)."""

from __future__ import annotations

import collections
import time

import pytest
from tcp_pendant.job_pool import BURST_S, SHARE, JobPool, OverShare, SessionBusy
from tcp_pendant.message_rate import MessagePacer
from tcp_pendant.refusal_notices import RefusalNotices
from tcp_pendant.views.arrival import ArrivalFloor, earliest_from_polls


class Owner:
    """A session, as far as the pool is concerned."""


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def test_the_servers_share_is_a_tenth_of_a_worker_in_bursts_of_a_second() -> None:
    assert (SHARE, BURST_S) == (0.1, 0.25)
    pool = JobPool(workers=1)
    assert (pool.share, pool.burst_s) == (SHARE, BURST_S)


def test_a_session_past_its_share_is_refused_at_once_in_words_and_another_is_not() -> None:
    pool = JobPool(workers=1, share=0.01, burst_s=0.02)
    a, b = Owner(), Owner()
    try:
        assert pool.credit_s(a) == pytest.approx(0.02)                  # a new session: full credit
        assert pool.submit(a, lambda: time.sleep(0.1) or "done", what="a TCP check").result(10) == "done"
        assert pool.credit_s(a) < 0                                    # it ran longer than its credit
        with pytest.raises(OverShare, match=r"^The server is busy with this browser's jobs: try again in "
                                            r"\d+ s\.$") as refused:
            pool.admit(a)
        assert refused.value.retry_in_s > 0
        with pytest.raises(OverShare):                                 # submit applies the same rule
            pool.submit(a, lambda: "never", what="a TCP check")
        assert pool.submit(b, lambda: "b's", what="a TCP check").result(10) == "b's"    # b is not refused
        pool.charge(b, 1.0)                                            # loop work counts as a job's run
        with pytest.raises(OverShare):
            pool.admit(b)
    finally:
        pool.shutdown()


def test_a_pending_job_is_refused_before_the_share_is_looked_at() -> None:
    pool = JobPool(workers=1, share=0.01, burst_s=0.02)
    a = Owner()
    try:
        import threading
        gate = threading.Event()
        fut = pool.submit(a, gate.wait, what="a beam check")
        with pytest.raises(SessionBusy, match="^A beam check is still running here"):
            pool.admit(a)
        gate.set()
        fut.result(10)
    finally:
        pool.shutdown()


def test_refusal_notices_of_a_session_are_coalesced_and_the_left_out_ones_counted() -> None:
    clock = Clock()
    notices = RefusalNotices(quiet_s=2.0, clock=clock)
    assert notices.body("Busy.") == "Busy."                            # the first is shown
    assert [notices.body("Busy.") for _ in range(3)] == [None] * 3      # within 2 s: left out
    clock.t += 2.0
    assert notices.body("Busy.") == "Busy. (3 more clicks were refused meanwhile.)"
    clock.t += 1.0
    assert notices.body("Busy.") is None
    clock.t += 1.0
    assert notices.body("Busy.") == "Busy. (1 more click was refused meanwhile.)"
    clock.t += 10.0
    assert notices.body("Busy.") == "Busy."                            # a trainee clicking once sees each
    assert (notices.shown, notices.suppressed) == (4, 4)


def test_a_connections_messages_wait_beyond_its_burst_at_its_pace() -> None:
    clock = Clock()
    pacer = MessagePacer(rate_hz=500.0, burst=1000, clock=clock)
    assert [pacer.delay_s() for _ in range(1000)] == [0.0] * 1000       # a burst goes through at once
    assert pacer.delay_s() == pytest.approx(1 / 500)                    # then one every 2 ms
    assert pacer.delay_s() == pytest.approx(2 / 500)
    clock.t += 10.0                                                     # a quiet browser: full again
    assert pacer.delay_s() == 0.0 and pacer.paced == 2
    with pytest.raises(ValueError, match="positive rate"):
        MessagePacer(rate_hz=0.0)


def test_a_backlogged_connections_messages_keep_the_stamp_of_the_first_one_read_caught_up() -> None:
    floor = ArrivalFloor()
    assert floor.stamp(False, 10.0) == 10.0                             # asked while caught up: its own
    assert floor.stamp(True, 12.0) == 10.0                              # already waiting: no later than
    assert floor.stamp(True, 30.0) == 10.0                              # the one before it, however late
    assert floor.stamp(True, 9.5) == 9.5                                # a lower bound from the polls wins
    assert floor.stamp(False, 31.0) == 31.0                             # caught up again: fresh
    assert ArrivalFloor().stamp(True, 5.0) == 5.0                       # a first message in a backlog


def test_the_polls_bound_a_messages_arrival_by_the_poll_that_read_it() -> None:
    assert earliest_from_polls([(0.0, 0.1)], 5.0) == 5.0                # too few polls known: now
    waited = collections.deque([(0.0, 1.0), (1.0, 2.0), (2.0, 2.0001)], maxlen=3)   # as the adapter keeps
    assert earliest_from_polls(waited, 5.0) == 2.0                      # them; poll j-1 waited: its end
    at_once = [(0.0, 1.0), (3.0, 3.0001), (4.0, 4.0001)]                # j-1 returned at once: j-2's end
    assert earliest_from_polls(at_once, 5.0) == 1.0
    assert earliest_from_polls(at_once, 0.5) == 0.5                     # never later than now
