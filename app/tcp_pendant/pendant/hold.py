"""Hold-to-jog driven by the server's own 20 Hz clock (no viser, no asyncio).

A browser reports a held key by hold messages it means to send at 20 Hz; a busy browser (this
project's 2-core machine renders WebGL in software) sends them 0.4-0.6 s apart. Jogging once per
message then moves at a fraction of the set speed, in bursts. So the server moves on its own
clock instead: the first hold message of a key starts a tick every ``period_s`` that jogs one
tick's worth (``Jogger.key(..., hold_tick=True)``: ``speed * override * dt``, ``dt`` capped at
one tick), the browser's later hold messages only say the key is still held, and the key stops

* at the release (the click the browser sends when the key is let go): at once, so the robot
  stops within one tick of the release reaching the server;
* when its lease runs out: a held key is a lease the browser renews with every hold message
  (asked at 20 Hz, at least 10 a second: ``views.pendant_panel.HOLD_HZ``); no hold message for
  ``lease_s`` (:data:`LEASE_S`, 250 ms: the browser went away, froze or is too busy to renew,
  an enabling switch let go), counted from the messages' arrival at the server (``arrived_s``,
  stamped when viser decodes them, ``views.arrival``), not from when the busy server got round
  to them: a tick never moves later than ``lease_s`` after the last renewal arrived, at any load;
* when a jog stops short (limit, singularity, contact).

A lease that ran out stays out (the key *lapsed*, :attr:`HoldDriver.lapsed`) until the key is
released, as a real enabling switch must be let go and pressed again after a stop: a renewal
that arrives more than ``lease_s`` after the one before it (a browser that stalled and then
sends what it had queued, a late release's companions) moves nothing. Only a renewal that
arrived within ``lease_s`` of the one before it, which the busy server merely got to late,
takes the key up again (by the stamps, the lease never ran out). So a release that arrives
late moves the robot no further than the lease allowed.

A hold message that is older than ``start_bound_s`` when the server reaches it does not start a
hold (like a stale increment press, ``pendant.jogging.PressGate``; counted in ``dropped``), and
a hold of another key stops; it still keeps a running hold of the same key alive until
``deadman_s`` after its arrival.

:class:`HoldDriver` is told how to schedule (``schedule(delay_s, fn)``: the app passes viser
event loop's ``call_later`` so every tick runs on the loop, like every GUI callback).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Protocol

from tcp_pendant.controller import JogResult
from tcp_pendant.pendant.jogging import PRESS_BOUND_S

__all__ = ["DEADMAN_S", "HOLD_PERIOD_S", "LEASE_S", "HoldDriver"]

HOLD_PERIOD_S = 0.05
"""The server's jog tick while a key is held (20 Hz)."""
LEASE_S = 0.25
"""A held key stops when no hold message (its lease's renewal) arrived for this long (s)."""
DEADMAN_S = LEASE_S
"""The hold's deadman, the lease (s; the name the deadman tests use)."""

Key = tuple[str | int, int]
"""A jog key: (axis, sign), the axis a joint index or "X" .. "C"."""


class Timer(Protocol):
    """What ``schedule`` returns (an ``asyncio.TimerHandle``)."""

    def cancel(self) -> None: ...


class HoldDriver:
    """Moves a held key on the server's clock (see the module docstring).

    Args:
        step: jog one tick of ``(axis, sign)``; returns the move's result (None: no move).
        schedule: ``schedule(delay_s, fn)`` calls ``fn()`` later; returns a handle with
            ``cancel()``.
        clock: seconds, monotonic.
        period_s: the period of a tick (s; ``HOLD_PERIOD_S``).
        deadman_s: the lease, how long a hold lasts after its last hold message's arrival (s;
            :data:`LEASE_S`).
        start_bound_s: the largest age of a hold message that starts a hold (s).
        on_lapse: called (on the scheduler's thread) with the key whose lease ran out.
    """

    def __init__(self, step: Callable[[str | int, int], JogResult | None],
                 schedule: Callable[[float, Callable[[], object]], Timer], *,
                 clock: Callable[[], float] = time.monotonic, period_s: float = HOLD_PERIOD_S,
                 deadman_s: float = LEASE_S, start_bound_s: float = PRESS_BOUND_S,
                 on_lapse: Callable[[Key], object] | None = None) -> None:
        self._step = step
        self._schedule = schedule
        self._clock = clock
        self.period_s = period_s
        self.deadman_s = deadman_s
        self.start_bound_s = start_bound_s
        self.on_lapse = on_lapse
        self.dropped = 0
        self.key: Key | None = None
        self.lapsed: Key | None = None
        """The key whose lease ran out, until it is released (module docstring)."""
        self.last_renewal_s: float | None = None
        """Arrival (``clock`` s) of the last hold message of the key held or lapsed."""
        self.last_tick_s: float | None = None
        """When the last tick that moved ran (``clock`` s)."""
        self._last_message = 0.0
        self._next_at = 0.0
        self._timer: Timer | None = None

    @property
    def active(self) -> bool:
        """A key is being held (its ticks are scheduled)."""
        return self.key is not None

    def held(self, axis: str | int, sign: int, arrived_s: float | None = None) -> JogResult | None:
        """A hold message of key ``(axis, sign)`` that reached the server at ``arrived_s``
        (``clock`` seconds; None: now): start moving (first tick now) or keep going. Another
        key's message takes over from the one held before. A message older than
        ``start_bound_s`` does not start a hold (it is counted in ``dropped``) and stops the one
        held before."""
        now = self._clock()
        arrived = now if arrived_s is None else min(float(arrived_s), now)
        if self.key == (axis, sign):
            self._last_message = max(self._last_message, arrived)
            self.last_renewal_s = self._last_message
            return None
        if self.lapsed == (axis, sign):
            if arrived - self._last_message > self.deadman_s:
                self._last_message = max(self._last_message, arrived)   # a renewal after the lease ran out
                self.last_renewal_s = self._last_message
                return None
            self.lapsed = None                       # the server was late, not the browser: go on
            self._last_message = arrived
            self.last_renewal_s = arrived
            self.key = (axis, sign)
            self._next_at = now
            return self._tick()
        if now - arrived > self.start_bound_s:
            self.stop()                              # the safe side: the key held before stops too
            self.dropped += 1
            return None
        self.stop()
        self._last_message = arrived
        self.last_renewal_s = arrived
        self.key = (axis, sign)
        self._next_at = now
        return self._tick()

    def release(self) -> None:
        """The key was let go (a lapsed key may be pressed again)."""
        self.stop()

    def stop(self) -> None:
        """Stop moving (no further tick); the next hold message of any key starts afresh."""
        self.key = None
        self.lapsed = None
        self._cancel()

    def _cancel(self) -> None:
        if self._timer is not None:
            try:
                self._timer.cancel()
            except Exception:
                pass
            self._timer = None

    def _tick(self) -> JogResult | None:
        self._timer = None
        key = self.key
        if key is None:
            return None
        now = self._clock()
        if now - self._last_message > self.deadman_s:
            self.key = None                          # the lease ran out: no tick, until released
            self.lapsed = key
            self._cancel()
            if self.on_lapse is not None:
                self.on_lapse(key)
            return None
        self.last_tick_s = now
        res = self._step(*key)
        if res is not None and not res.ok:
            self.stop()
            return res
        if self.key == key:
            self._next_at = max(self._next_at + self.period_s, now + 0.2 * self.period_s)
            self._timer = self._schedule(self._next_at - now, self._tick)
        return res
