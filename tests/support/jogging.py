"""What the jog tests share: a clock and a ``call_later`` that the test advances by hand (the
jog loop's time without waiting), and a controller pose away from the wrist singularity."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from tcp_pendant.controller import VirtualController


def away_from_singularity(c: VirtualController) -> None:
    """KUKA HOME has A5 = 0 (wrist singular); tilt A5 so Cartesian jogs are well-conditioned."""
    c.jog_joint(4, 30.0)


class FakeClock:
    """A monotonic clock (seconds) that moves only when the test sets ``t``."""

    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


class FakeScheduler:
    """A fake ``call_later``: runs the due callbacks when the test advances the clock."""

    def __init__(self, clock: FakeClock) -> None:
        self.clock = clock
        self.pending: list[Any] = []

    def __call__(self, delay_s: float, fn: Callable[[], object]) -> Any:
        entry = [self.clock.t + delay_s, fn, False]

        class Handle:
            def cancel(self_inner) -> None:
                entry[2] = True

        self.pending.append(entry)
        return Handle()

    def advance(self, seconds: float) -> None:
        """Move the clock ``seconds`` on, running every callback due meanwhile at its time."""
        end = self.clock.t + seconds
        while True:
            due = [e for e in self.pending if e[0] <= end and not e[2]]
            if not due:
                break
            e = min(due, key=lambda e: e[0])
            self.pending.remove(e)
            self.clock.t = max(self.clock.t, e[0])
            e[1]()
        self.clock.t = end
