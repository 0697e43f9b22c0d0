"""The pace of one browser's messages (no viser).

viser reads each websocket connection in a task of its own and starts a task per message; a
client that sends as fast as its socket takes the messages (a script clicking a button, tens of
thousands of messages a second) fills the event loop with its tasks, and every other browser's
message waits behind them: measured without a pace (``tests/bench/bench_jobs.py --flood``, one
such client clicking Check / Check active tool / Auto-touch, cheap refusals), another trainee's
jog press to its readout p50 21 ms alone and 490 ms under the flood, 13 of 20 presses dropped
by the deadman.

The rule (:class:`MessagePacer`, one per connection, applied where viser reads the connection:
``views.viser_adapter.install``): a connection's messages are handled at most ``rate_hz``
(:data:`RATE_HZ`, 200) a second on average, in bursts of up to ``burst`` (:data:`BURST`, 200);
beyond, its reading waits (nothing is dropped: the websocket's and the kernel's buffers fill and
the sender's socket blocks, so the sender is slowed, not the server). A browser sends far fewer:
its camera while orbiting, a held key's 20 Hz ticks, a slider's drag. Measured with
``bench_jobs.py --flood`` (2 shared cores, 40 presses alone and 40 under the flood): at 500 a
second the victim's jog p95 was 1.50-1.57x its baseline, at 200 a second 1.26-1.33x, none
dropped.
"""

from __future__ import annotations

import time
from collections.abc import Callable

__all__ = ["BURST", "RATE_HZ", "MessagePacer"]

RATE_HZ = 200.0
"""Messages of one connection handled per second, on average."""
BURST = 200
"""Messages of one connection handled back to back before its pace is enforced."""


class MessagePacer:
    """A token bucket of one connection's messages (module docstring).

    Args:
        rate_hz: messages per second on average.
        burst: messages back to back.
        clock: seconds, monotonic (injectable for tests).

    Attributes:
        paced: messages that had to wait so far.
    """

    def __init__(self, rate_hz: float = RATE_HZ, burst: int = BURST,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if not (rate_hz > 0 and burst >= 1):
            raise ValueError(f"A message pace needs a positive rate and a burst of at least 1, got {rate_hz} "
                             f"and {burst}.")
        self.rate_hz = float(rate_hz)
        self.burst = float(burst)
        self._clock = clock
        self._tokens = self.burst
        self._last = clock()
        self.paced = 0

    def delay_s(self) -> float:
        """Take one message: the seconds its handling must wait (0: none)."""
        now = self._clock()
        self._tokens = min(self.burst, self._tokens + (now - self._last) * self.rate_hz) - 1.0
        self._last = now
        if self._tokens >= 0.0:
            return 0.0
        self.paced += 1
        return -self._tokens / self.rate_hz
