"""The pendant's deadman under overload: a jog press is carried out only if the server reaches
it within ``PRESS_BOUND_S`` of its arrival, the stale ones are dropped (not executed) and the
trainee is told, and the robot stands still within 1 s of the last press or hold message.

The logic on an injected clock (presses stamped older than the bound; hold messages the server
reaches late), then the app over a real websocket with a deliberately slowed event loop (every
jog step takes 40 ms on viser's loop while the browser presses at 100 Hz or holds at 20 Hz).
Nothing sleeps and then checks that nothing happened: the tests wait until every press is
accounted for (carried out or dropped) or the hold has stopped, then check when the robot last
moved.
"""

from __future__ import annotations

import re
import threading
import time

import pytest
from tcp_pendant.controller import JogResult, VirtualController
from tcp_pendant.pendant import Jogger, JogSettings, dropped_presses_text
from tcp_pendant.pendant.hold import DEADMAN_S, HoldDriver
from tcp_pendant.pendant.jogging import PRESS_BOUND_S

from support.jogging import FakeClock, FakeScheduler, away_from_singularity
from support.wsclient import ButtonClient, wait_until

PLUS_X = "X +"


def _x_mm(c: VirtualController) -> float:
    return float(c.T_world_tcp()[0, 3]) * 1000.0


# ------------------------------------------------------------------ logic, injected clock
def test_a_press_older_than_the_bound_is_dropped_and_counted(controller: VirtualController) -> None:
    away_from_singularity(controller)
    clock = FakeClock()
    jog = Jogger(controller, clock=clock)
    jog.settings = JogSettings(increment="1", frame="WORLD")

    def press(age_s: float) -> bool:                 # what the jog keys do: ask the gate, then jog
        if not jog.gate.admit(clock.t - age_s):
            return False
        assert jog.key("X", 1) is not None
        return True

    x0 = _x_mm(controller)
    assert press(0.9 * PRESS_BOUND_S)                                               # fresh: moves
    assert _x_mm(controller) == pytest.approx(x0 + 1.0, abs=1e-6)
    assert not any([press(age) for age in (1.1 * PRESS_BOUND_S, 3.0, 20.0)])        # a backlog
    assert _x_mm(controller) == pytest.approx(x0 + 1.0, abs=1e-6)                   # not executed
    assert jog.gate.dropped == 3 and jog.gate.take_dropped() == 3 and jog.gate.dropped == 0
    assert press(0.0)                                                               # fresh again
    assert _x_mm(controller) == pytest.approx(x0 + 2.0, abs=1e-6)
    assert jog.gate.dropped_total == 3
    assert jog.gate.admit(None) and jog.gate.dropped == 0                           # unknown: now


def test_the_trainee_is_told_how_many_presses_were_dropped() -> None:
    assert dropped_presses_text(1) == "1 jog press dropped: the server was busy"
    assert dropped_presses_text(7) == "7 jog presses dropped: the server was busy"


def test_hold_deadman_counts_from_the_arrival_not_from_when_the_server_got_to_it() -> None:
    clock = FakeClock()
    sched = FakeScheduler(clock)
    steps: list[float] = []
    driver = HoldDriver(lambda a, s: steps.append(clock.t) or JogResult(True, 1.0, None, ""), sched, clock=clock)
    t0 = clock.t
    driver.held("X", 1, arrived_s=t0)
    sched.advance(0.6)
    clock.t += 0.3                   # the server reaches a hold message late: it arrived at t0 + 0.1
    driver.held("X", 1, arrived_s=t0 + 0.1)
    sched.advance(2.0)
    assert driver.key is None                                    # stopped by the deadman
    assert steps and max(steps) <= t0 + 0.1 + DEADMAN_S          # no step after arrival + 1 s
    # a hold message that is stale when the server reaches it starts nothing and stops the key held
    driver.held("Y", 1, arrived_s=clock.t)
    assert driver.key == ("Y", 1)
    n = len(steps)
    driver.held("Z", -1, arrived_s=clock.t - 1.1 * PRESS_BOUND_S)
    assert driver.key is None and driver.dropped == 1 and len(steps) == n


# ------------------------------------------------------------------ the app, slowed event loop
STEP_S = 0.04
"""Each jog step on the server takes this long (the slowed event loop)."""


def _slow_steps(s) -> tuple[list[float], set[int]]:
    """Make every jog step of session ``s`` take ``STEP_S`` (on viser's loop: it blocks the
    loop); returns the times its steps started and the threads they ran on."""
    c = s.controller
    original = c.jog_cartesian
    loop_threads: set[int] = set()

    moves: list[float] = []

    def slow_jog(*args, **kwargs):
        moves.append(time.monotonic())
        loop_threads.add(threading.get_ident())
        time.sleep(STEP_S)
        return original(*args, **kwargs)

    c.jog_cartesian = slow_jog
    return moves, loop_threads


def _slowed_sessions(app, n: int = 1):
    clients = []
    for k in range(n):
        client = ButtonClient(app.port, (PLUS_X,))
        assert client.found.wait(30), "the client never saw the jog keys"
        wait_until(lambda k=k: len(app.sessions) == k + 1, what="session built")
        clients.append(client)
    sessions = list(app.sessions.values())
    return clients, sessions, [_slow_steps(s) for s in sessions]


def test_overloaded_server_drops_stale_presses_and_the_robot_stops_within_1s(app_factory) -> None:
    app = app_factory()
    (client,), (s,), ((moves, loop_threads),) = _slowed_sessions(app)
    try:
        with s.lock:
            s.jogger.settings = s.jogger.settings.with_(increment="0.1", frame="WORLD")
            x0 = _x_mm(s.controller)
        n_moves0 = len(moves)
        ages: list[float] = []
        jogger = s.jogger
        admit, key = jogger.gate.admit, jogger.key
        results: list[object] = []                  # per press: the jog's result, None if dropped

        def timed_admit(arrived_s):
            assert arrived_s is not None, "the press carries no arrival stamp"
            ages.append(time.monotonic() - arrived_s)
            ok = admit(arrived_s)
            if not ok:
                results.append(None)
            return ok

        def recorded_key(axis, sign, *, hold_tick=False):
            res = key(axis, sign, hold_tick=hold_tick)
            results.append(res)
            return res

        jogger.gate.admit = timed_admit
        jogger.key = recorded_key
        told: list[int] = []
        notify = s.notify

        def recording_notify(title, body, *, kind="info"):
            m = re.match(r"(\d+) jog press(es)? dropped: the server was busy", body)
            if m:
                told.append(int(m.group(1)))
            notify(title, body, kind=kind)

        s.notify = recording_notify
        n = 60                                        # 100 Hz for 0.6 s: 2.4 s of 40 ms steps
        t_start = time.monotonic()
        for i in range(n):
            client.click(PLUS_X)
            time.sleep(max(0.0, t_start + (i + 1) * 0.01 - time.monotonic()))
        t_last = time.monotonic()
        wait_until(lambda: len(results) == n, timeout=30, what="every press reached by the server")
        executed = sum(r is not None for r in results)
        dropped = jogger.gate.dropped_total
        print(f"{n} presses in 0.6 s, {STEP_S * 1e3:.0f} ms per step: {executed} carried out, {dropped} dropped; "
              f"oldest press reached {max(ages):.2f} s after arrival; last step "
              f"{(moves[-1] - t_last):+.2f} s after the last press")
        assert all(r is None or r.ok for r in results)  # every press carried out moved 0.1 mm
        assert len(ages) == n and executed + dropped == n and executed >= 1 and dropped >= 1
        assert max(ages) > PRESS_BOUND_S              # the server really was behind
        with s.lock:
            assert _x_mm(s.controller) == pytest.approx(x0 + 0.1 * executed, abs=1e-6)   # dropped: not executed
        assert len(moves) - n_moves0 == executed      # a step per press carried out, none dropped
        assert moves[-1] <= t_last + 1.0              # the last step started within 1 s of the last press
        assert len(loop_threads) == 1                 # the steps ran on the (one) event loop
        # told once per burst, every dropped press counted
        wait_until(lambda: sum(told) == dropped, what="the trainee told of every dropped press")
        assert 1 <= len(told) < dropped
    finally:
        client.close()


def test_overloaded_holds_stop_within_the_lease_of_the_last_hold_message(app_factory) -> None:
    """Four trainees hold X + at 20 Hz, each tick taking 40 ms on the one event loop (3.2 s of
    work per second): every hold message waits on the loop, yet every robot's last tick starts
    within the 250 ms lease of that browser's last hold message (the lease counts from the
    arrival, not from when the loop got to the message)."""
    from tcp_pendant.views.pendant_panel import HOLD_HZ

    app = app_factory()
    clients, sessions, watched = _slowed_sessions(app, 4)
    try:
        for s in sessions:
            with s.lock:
                s.jogger.settings = s.jogger.settings.with_(increment="Cont.", override_pct=5, frame="WORLD")
        t_start = time.monotonic()
        for i in range(30):                           # 1.5 s held, then the browsers stop reporting
            for c in clients:
                c.hold_tick(PLUS_X, HOLD_HZ)
            time.sleep(max(0.0, t_start + (i + 1) / HOLD_HZ - time.monotonic()))
        t_last = time.monotonic()
        panels = [s.views["pendant"] for s in sessions]
        wait_until(lambda: all(p._hold is not None and not p._hold.active for p in panels), timeout=30,
                   what="every hold stopped by the deadman")
        for k, (moves, _) in enumerate(watched):
            assert moves, f"hold {k} never moved"
            print(f"hold {k}: {len(moves)} ticks of {STEP_S * 1e3:.0f} ms; the last started "
                  f"{moves[-1] - t_last:+.2f} s after the last hold message")
        assert max(m[-1] for m, _ in watched) <= t_last + DEADMAN_S
    finally:
        for c in clients:
            c.close()


def test_presses_that_waited_on_a_busy_loop_signal_once_at_the_end_of_its_round(app_factory) -> None:
    """Each press moves the robot at once; presses that waited longer than COALESCE_AFTER_S
    share one change signal, sent when the loop's round ends (fresh ones signal each)."""
    import asyncio

    from tcp_pendant.session import COALESCE_AFTER_S

    app = app_factory(shared=True)
    s = app.shared_session
    with s.lock:
        s.jogger.settings = s.jogger.settings.with_(increment="0.1", frame="WORLD", mode="Cartesian")
    signals: list[tuple[float, bool]] = []
    s.subscribe(lambda change: signals.append((_x_mm(s.controller), change.pose)) if change.pose else None)

    async def presses(waited_s: float | None) -> tuple[list[float], int]:
        xs = []
        with s.lock:
            for _ in range(3):
                s.motion.jog("X", 1, waited_s=waited_s)
                xs.append(_x_mm(s.controller))
        during = len(signals)
        await asyncio.sleep(0)                  # the loop's round ends
        await asyncio.sleep(0)
        return xs, during

    def run(waited_s: float | None) -> tuple[list[float], int]:
        signals.clear()
        return asyncio.run_coroutine_threadsafe(presses(waited_s), app.server.get_event_loop()).result(30)

    xs, during = run(2 * COALESCE_AFTER_S)
    assert [round(b - a, 3) for a, b in zip(xs, xs[1:])] == [0.1, 0.1]    # every press moved at once
    assert during == 0 and len(signals) == 1 and signals[0] == (xs[-1], True)
    xs, during = run(None)                       # arrival unknown (a test's call): each signals
    assert during == 3 and [x for x, _ in signals] == xs
    xs, during = run(COALESCE_AFTER_S / 2)       # fresh presses: each signals
    assert during == 3 and [x for x, _ in signals] == xs
