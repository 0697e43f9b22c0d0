"""No viser: continuous jog timing and the stop at contact of the
Jogger, on a fake clock.

* every executed tick moves ``speed * override * dt`` with ``dt`` capped at one 20 Hz tick
  (a stalled or late tick never jumps farther than the speed allows at 20 Hz);
* ticks that arrive back to back (a server that fell behind works off its queue) are skipped,
  so nothing moves on after the release beyond one tick;
* an X/Y/Z step whose tool-tip path passes through the reference tip stops there, and a held
  key stays stopped until released.
"""

from __future__ import annotations

import numpy as np
import pytest
from tcp_pendant.controller import VirtualController
from tcp_pendant.pendant import Jogger, JogSettings
from tcp_pendant.pendant.guidance import contact_stop
from tcp_pendant.pendant.jogging import LINEAR_SPEED_MM_S, MAX_TICK_S

from support.jogging import FakeClock, FakeScheduler, away_from_singularity

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _x_mm(c: VirtualController) -> float:
    return float(c.T_world_tcp()[0, 3]) * 1000.0


def _cont(controller: VirtualController, override: float = 50.0) -> tuple[Jogger, FakeClock]:
    away_from_singularity(controller)
    clock = FakeClock()
    jog = Jogger(controller, clock=clock, tick_s=0.05)
    jog.settings = JogSettings(increment="Cont.", override_pct=override)
    return jog, clock


def test_a_late_tick_moves_no_more_than_one_20hz_tick(controller: VirtualController) -> None:
    jog, clock = _cont(controller)
    assert MAX_TICK_S == pytest.approx(1 / 20)
    jog.key("X", 1, hold_tick=True)
    x = _x_mm(controller)
    clock.t += 0.2                                   # the browser's tick came 4 ticks late
    jog.key("X", 1, hold_tick=True)
    assert _x_mm(controller) - x == pytest.approx(LINEAR_SPEED_MM_S * 0.5 * 0.05, abs=1e-3)   # 6.25 mm


def test_twenty_hz_ticks_move_at_the_override_speed(controller: VirtualController) -> None:
    jog, clock = _cont(controller, override=50.0)
    x0 = _x_mm(controller)
    for _ in range(20):                              # one second held
        jog.key("X", 1, hold_tick=True)
        clock.t += 0.05
    assert _x_mm(controller) - x0 == pytest.approx(125.0, abs=0.01)


def test_queued_ticks_are_skipped_so_the_key_stops_at_release(controller: VirtualController) -> None:
    jog, clock = _cont(controller)
    jog.key("X", 1, hold_tick=True)
    x = _x_mm(controller)
    for _ in range(5):                               # a backlog worked off back to back
        clock.t += 0.002
        assert jog.key("X", 1, hold_tick=True) is None
    assert _x_mm(controller) == x
    assert jog.key("X", 1, hold_tick=False) is None   # the release click
    jog.release()
    assert _x_mm(controller) == x


def test_contact_stop_geometry() -> None:
    tip, ref = np.zeros(3), np.array([0.0, 0.0, -0.004])
    stop = contact_stop(tip, np.array([0.0, 0.0, -0.010]), ref)            # 10 mm down, tip 4 mm below
    assert stop is not None and stop.fraction == pytest.approx(0.4) and stop.miss_mm == pytest.approx(0.0)
    assert contact_stop(tip, np.array([0.0, 0.0, -0.003]), ref) is None   # ends before the tip
    assert contact_stop(tip, np.array([0.0, 0.0, 0.010]), ref) is None    # away from it
    beside = np.array([0.003, 0.0, -0.004])                                # 3 mm beside the path
    assert contact_stop(tip, np.array([0.0, 0.0, -0.010]), beside) is None
    assert contact_stop(ref, np.array([0.0, 0.0, -0.010]), ref) is None   # touching: goes on


def test_a_held_key_stops_at_contact_until_released(controller: VirtualController) -> None:
    jog, clock = _cont(controller, override=100.0)
    c = controller
    tip = c.T_world_tool_true()[:3, 3]
    c.set_reference_tip(tip + np.array([0.010, 0.0, 0.0]))                  # 10 mm along +X
    for _ in range(10):                              # 12.5 mm per tick would pass it
        res = jog.key("X", 1, hold_tick=True)
        clock.t += 0.05
        if res is not None and res.stopped_by == "contact":
            break
    assert res is not None and res.stopped_by == "contact" and "Stopped at the reference tip" in res.message
    assert c.touch_geometry().distance_mm < 0.01
    assert jog.key("X", 1, hold_tick=True) is None   # still held: stays stopped
    jog.release()
    clock.t += 1.0
    assert jog.key("X", 1, hold_tick=True).ok        # a new hold goes on


def test_hold_driver_ticks_at_20hz_until_release_or_lease() -> None:
    from tcp_pendant.controller import JogResult
    from tcp_pendant.pendant.hold import LEASE_S, HoldDriver

    clock = FakeClock()
    sched = FakeScheduler(clock)
    steps: list[float] = []
    driver = HoldDriver(lambda axis, sign: steps.append(clock.t) or JogResult(True, 1.0, None, ""),
                        sched, clock=clock)
    driver.held("X", 1)                              # renewed every 50 ms for 0.5 s
    for _ in range(10):
        sched.advance(0.05)
        driver.held("X", 1)
    assert len(steps) == 11                          # now + every 50 ms
    driver.release()
    sched.advance(1.0)
    assert len(steps) == 11                          # nothing after the release
    driver.held("Y", -1)                             # one message, then the browser went quiet
    sched.advance(LEASE_S + 0.5)
    assert driver.key is None and driver.lapsed == ("Y", -1)
    assert len(steps) == 11 + int(round(LEASE_S / 0.05)) + 1


def test_hold_driver_stops_when_a_jog_stops_short() -> None:
    from tcp_pendant.controller import JogResult
    from tcp_pendant.pendant.hold import HoldDriver

    clock = FakeClock()
    sched = FakeScheduler(clock)
    results = iter([JogResult(True, 1.0, None, ""), JogResult(False, 0.3, "contact", "Stopped")])
    driver = HoldDriver(lambda a, s: next(results), sched, clock=clock)
    driver.held("Z", -1)
    sched.advance(0.2)
    assert driver.key is None


def test_a_press_after_a_stop_beside_the_tip_goes_on() -> None:
    """Stopped where the path passes closest (1.6 mm beside the reference tip, not touching),
    the next press in the same direction goes on instead of stopping again after 0 mm."""
    ref = np.array([0.5, 0.0, 0.4])
    tip = ref + np.array([-1e-9, 0.0016, 0.0])               # at the closest point (IK's last nm)
    assert contact_stop(tip, np.array([0.001, 0.0, 0.0]), ref) is None
    before = ref + np.array([-0.0008, 0.0016, 0.0])           # 0.8 mm before it: stops there
    stop = contact_stop(before, np.array([0.001, 0.0, 0.0]), ref)
    assert stop is not None and stop.fraction == pytest.approx(0.8) and stop.miss_mm == pytest.approx(1.6)
