"""No viser: continuous jog is a lease the browser renews (``pendant.hold``), on a fake clock.

Judged by the stamps (the renewals' arrival ``arrived_s`` and the ticks' clock times), never by
wall-clock waits:

* renewals stop -> the last tick that moves runs within ``LEASE_S`` (250 ms) of the last
  renewal's arrival, at a renewal rate of 10 or 20 a second;
* a late release (and a renewal the stalled browser sends with it) moves nothing: the lapsed
  key needs a release before it moves again;
* a renewal the busy server merely reached late (it arrived within the lease) goes on;
* the renewal rate the page asks for is at least 10 a second.
"""

from __future__ import annotations

import pytest
from tcp_pendant.controller import JogResult
from tcp_pendant.pendant.hold import HOLD_PERIOD_S, LEASE_S, HoldDriver

from support.jogging import FakeClock, FakeScheduler

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _driver() -> tuple[HoldDriver, FakeClock, FakeScheduler, list[float], list[object]]:
    clock = FakeClock()
    sched = FakeScheduler(clock)
    steps: list[float] = []
    lapses: list[object] = []
    driver = HoldDriver(lambda axis, sign: steps.append(clock.t) or JogResult(True, 1.0, None, ""), sched,
                        clock=clock, on_lapse=lapses.append)
    return driver, clock, sched, steps, lapses


def test_the_lease_is_250_ms_and_the_page_renews_it_at_least_10_times_a_second() -> None:
    from tcp_pendant.views.pendant_panel import HOLD_HZ

    assert LEASE_S == pytest.approx(0.25)
    assert HOLD_HZ >= 10.0
    assert 1.0 / HOLD_HZ < LEASE_S                  # a renewal or two may be lost, not more


@pytest.mark.parametrize("rate_hz", [10.0, 20.0])
def test_renewals_stop_then_the_robot_stops_within_the_lease_of_the_last_one(rate_hz: float) -> None:
    driver, clock, sched, steps, lapses = _driver()
    t0 = clock.t
    driver.held("X", 1, arrived_s=t0)
    renewals = [t0]
    for k in range(1, 8):                             # 0.7 s (10 Hz) or 0.35 s (20 Hz) of renewals
        sched.advance(1.0 / rate_hz)
        driver.held("X", 1, arrived_s=clock.t)
        renewals.append(clock.t)
    moved_while_renewed = len(steps)
    sched.advance(3.0)                                # the browser went quiet
    last = renewals[-1]
    assert driver.key is None and driver.lapsed == ("X", 1) and lapses == [("X", 1)]
    assert driver.last_renewal_s == pytest.approx(last)
    assert max(steps) <= last + LEASE_S + 1e-9       # by the stamps: no tick after the lease
    assert max(steps) >= last + LEASE_S - HOLD_PERIOD_S - 1e-9   # and it did run until then
    assert len(steps) > moved_while_renewed


def test_a_late_release_and_its_late_renewal_move_nothing() -> None:
    driver, clock, sched, steps, _ = _driver()
    t0 = clock.t
    driver.held("X", 1, arrived_s=t0)
    for _ in range(5):
        sched.advance(0.05)
        driver.held("X", 1, arrived_s=clock.t)
    last = clock.t
    sched.advance(3.0)                                # the browser stalls 3 s with the finger up
    n = len(steps)
    driver.held("X", 1, arrived_s=clock.t)            # the renewal it had queued, then the release
    sched.advance(0.2)
    assert len(steps) == n and driver.key is None and driver.lapsed == ("X", 1)
    driver.release()
    sched.advance(1.0)
    assert len(steps) == n and max(steps) <= last + LEASE_S + 1e-9
    driver.held("X", 1, arrived_s=clock.t)            # pressed again after the release: moves
    assert len(steps) == n + 1 and driver.key == ("X", 1)


def test_a_renewal_the_server_reached_late_but_that_arrived_in_time_goes_on() -> None:
    driver, clock, sched, steps, _ = _driver()
    t0 = clock.t
    driver.held("X", 1, arrived_s=t0)
    sched.advance(0.4)                                # the loop was busy: the renewal waited
    assert driver.lapsed == ("X", 1)
    n = len(steps)
    driver.held("X", 1, arrived_s=t0 + 0.2)           # it arrived 0.2 s after the first: in time
    assert driver.key == ("X", 1) and len(steps) == n + 1
    assert steps[-1] <= t0 + 0.2 + LEASE_S            # the tick is within the lease of its arrival
    sched.advance(1.0)                                # no more renewals: out again at its lease
    assert driver.lapsed == ("X", 1) and max(steps) <= t0 + 0.2 + LEASE_S + 1e-9


def test_another_key_after_a_lapse_starts_afresh() -> None:
    driver, clock, sched, steps, _ = _driver()
    driver.held("X", 1, arrived_s=clock.t)
    sched.advance(1.0)
    n = len(steps)
    driver.held("Y", -1, arrived_s=clock.t)
    assert driver.key == ("Y", -1) and driver.lapsed is None and len(steps) == n + 1
