"""The trainer dashboard's thresholds, kept in the gradebook so that they outlast a restart of
the server (``Gradebook.settings``, keys ``class:dashboard_stuck_after_min`` and
``class:dashboard_idle_after_min``; the same for every server process of the class, SQLite or
PostgreSQL). No viser: the dashboard (``views.dashboard``) reads them when it is built and
keeps each change.

Units: minutes, :data:`MIN_MINUTES` to :data:`MAX_MINUTES` (the dashboard's number inputs).
"""

from __future__ import annotations

import math

from tcp_pendant.classroom.board import DEFAULT_IDLE_MIN, DEFAULT_STUCK_MIN
from tcp_pendant.classroom.class_settings import ClassSettings

__all__ = ["IDLE_SETTING", "MAX_MINUTES", "MIN_MINUTES", "STUCK_SETTING", "keep_minutes", "kept_minutes"]

STUCK_SETTING = "dashboard_stuck_after_min"
"""The class setting of "Stuck after (min)"."""
IDLE_SETTING = "dashboard_idle_after_min"
"""The class setting of "Idle after (min)"."""
MIN_MINUTES = 0.5
MAX_MINUTES = 240.0
_DEFAULTS = {STUCK_SETTING: DEFAULT_STUCK_MIN, IDLE_SETTING: DEFAULT_IDLE_MIN}


def _minutes(value: object) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value) if MIN_MINUTES <= value <= MAX_MINUTES else None


def kept_minutes(settings: ClassSettings, key: str) -> float:
    """The threshold ``key`` (:data:`STUCK_SETTING` or :data:`IDLE_SETTING`) as the trainer last
    set it, minutes; its default when never set or when the kept value is not a number in range."""
    kept = _minutes(settings.get(key))
    return _DEFAULTS[key] if kept is None else kept


def keep_minutes(settings: ClassSettings, key: str, value: object) -> float:
    """Keep the threshold ``key`` at ``value`` minutes; returns what was kept.

    Raises:
        ValueError: ``key`` is not a dashboard threshold, or ``value`` is not a number of minutes
            in range (the words say which range).
    """
    if key not in _DEFAULTS:
        raise ValueError(f"Unknown dashboard setting {key!r:.60}; use one of {', '.join(_DEFAULTS)}.")
    minutes = _minutes(value)
    if minutes is None:
        raise ValueError(f"A dashboard threshold must be {MIN_MINUTES:g} to {MAX_MINUTES:g} minutes, "
                         f"got {value!r:.40}.")
    settings.set(key, minutes)
    return minutes
