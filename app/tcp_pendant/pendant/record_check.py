"""Record checks the touch (no viser): a touch farther than the touch tolerance from the
reference tip is recorded only on a second Record within ``CONFIRM_WINDOW_S`` at the same pose.

With the distance hidden ("Hide distance": the trainee judges by eye, which is the exercise)
Record records at once; the result later shows that touch's error.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tcp_pendant.controller.touch import TOUCH_TOLERANCE_MM
from tcp_pendant.translation import ENGLISH, Translator

__all__ = ["CONFIRM_WINDOW_S", "RecordCheck", "RecordDecision"]

CONFIRM_WINDOW_S = 6.0
"""Seconds within which a second Record confirms a far touch."""


@dataclass(frozen=True)
class RecordDecision:
    """What a Record click does.

    Attributes:
        record: True: record now; False: ask for confirmation (``message`` says why).
        message: the question (how far, which direction, what to do), "" when recording.
    """

    record: bool
    message: str = ""


class RecordCheck:
    """Remembers a Record that asked for confirmation.

    Args:
        clock: seconds, monotonic (injectable for tests).
    """

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self._clock = clock
        self._pending: tuple[float, tuple[float, ...]] | None = None

    def decide(self, distance_mm: float, *, hidden: bool, q_rad: np.ndarray, where: str,
               tr: Translator = ENGLISH) -> RecordDecision:
        """Record now, or ask first.

        Args:
            distance_mm: true tool tip to reference tip (mm).
            hidden: "Hide distance" is on (record without asking).
            q_rad: the joint angles now (a confirmation counts only at the same pose).
            where: the offset in words (e.g. ``"2.10 mm −X (WORLD)"``) for the question.
            tr: the question's language.
        """
        if hidden or not np.isfinite(distance_mm) or distance_mm <= TOUCH_TOLERANCE_MM:
            self._pending = None
            return RecordDecision(True)
        key = tuple(round(float(v), 9) for v in np.asarray(q_rad, dtype=float))
        now = self._clock()
        if self._pending is not None and self._pending[1] == key and now - self._pending[0] <= CONFIRM_WINDOW_S:
            self._pending = None
            return RecordDecision(True)
        self._pending = (now, key)
        return RecordDecision(False, tr.gettext(
            "⚠ The tool tip is **{distance} mm** from the reference tip (more than {tolerance} mm): the reference "
            "tip is {where} from it. Jog closer, or press **Record** again within {seconds} s to record this touch "
            "anyway.").format(distance=f"{distance_mm:.2f}", tolerance=TOUCH_TOLERANCE_MM, where=where,
                              seconds=f"{CONFIRM_WINDOW_S:.0f}"))

    def clear(self) -> None:
        """Forget a pending confirmation (the robot moved, the step changed)."""
        self._pending = None
