"""The rows of the trainer's dashboard, from the gradebook and who is connected (no viser).

The gradebook is the shared truth (``Gradebook.board.read``): every trainee with their latest
calibration, its step as they last saw it and since when, its touches and crashes, and their
last result. The server adds only who is connected now (``ClassRoom.connected_names``), so a
server started again with the same gradebook shows the class as it was, the trainees not yet
back listed as not connected with their last state.

Stuck: a trainee is flagged when a calibration of theirs is on show in progress and neither a
touch nor a new step came for ``stuck_after_s`` seconds (the trainer's threshold, minutes in
the dashboard): ``min(time on the step, time since the last touch) >= stuck_after_s``. A trainee
not connected is never flagged (the row says "not connected" instead).

Idle: a connected trainee who joined and has no calibration in progress and none finished is
flagged when neither a join, a step nor a touch came for ``idle_after_s`` seconds (the
trainer's "Idle after", minutes): ``min(time since they first joined, time on the latest
calibration's step, time since the last touch) >= idle_after_s``.

Every clock (on the step, since the last touch, stuck, idle) counts the server's time up only:
the gaps no server process of the class was up (``ClassBoard.downtimes``, ``classroom.uptime``)
are left out (:func:`active_seconds`).

Times are UTC ISO 8601 from the gradebook; durations seconds.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from datetime import datetime, timezone

from tcp_pendant.classroom.class_board import BoardRun, BoardTrainee, ClassBoard

__all__ = ["DEFAULT_IDLE_MIN", "DEFAULT_STUCK_MIN", "DashboardRow", "OpenRun", "active_seconds", "dashboard_rows",
           "format_duration", "is_idle", "is_stuck", "open_runs", "seconds_since"]

DEFAULT_STUCK_MIN = 5.0
"""The stuck threshold a dashboard starts with, minutes."""
DEFAULT_IDLE_MIN = 5.0
"""The idle threshold a dashboard starts with, minutes."""


@dataclass(frozen=True)
class DashboardRow:
    """One trainee's row of the dashboard (raw text: escape before showing it).

    Attributes:
        number: 1-based, the trainee's mark on the position-error chart.
        name: the trainee.
        connected: the trainee's browser is connected now.
        method: the latest calibration's wizard title (its method key when the title is unknown), "".
        step: where it is ("Step 2 of 4", "result", "cancelled"), "" none.
        step_s: seconds on that step (None: unknown).
        touch_s: seconds since the trainee's last touch (None: no touch yet).
        touches / crashes: of the latest calibration (``BoardTrainee``).
        position_error_mm / orientation_error_deg / grade: the last finished calibration's (None: none).
        tcp_mm: its TCP, mm (None: none).
        in_progress: the latest calibration is in progress.
        stuck: flagged (module docstring).
        idle: flagged idle (module docstring).
        quiet_s: seconds since the trainee's last join, step or touch (None: unknown).
    """

    number: int
    name: str
    connected: bool
    method: str
    step: str
    step_s: float | None
    touch_s: float | None
    touches: int
    crashes: int
    position_error_mm: float | None
    orientation_error_deg: float | None
    grade: str
    tcp_mm: tuple[float, float, float] | None
    in_progress: bool
    stuck: bool
    idle: bool = False
    quiet_s: float | None = None


@dataclass(frozen=True)
class OpenRun:
    """A calibration in progress, for the dashboard's "in progress" list (raw text)."""

    calibration_id: int
    trainee: str
    connected: bool
    method: str
    step: str
    step_s: float | None
    started_s: float | None
    touches: int


def seconds_since(when: str, now: datetime) -> float | None:
    """Seconds from the UTC ISO 8601 time ``when`` to ``now`` (None: ``when`` is "" or not a
    time; never negative)."""
    if not when:
        return None
    try:
        t = datetime.fromisoformat(when)
    except ValueError:
        return None
    if t.tzinfo is None:
        t = t.replace(tzinfo=timezone.utc)
    return max(0.0, (now - t).total_seconds())


def active_seconds(when: str, now: datetime, downtimes: Sequence[tuple[float, float]] = ()) -> float | None:
    """:func:`seconds_since` without the server's downtime: the parts of the gaps
    ``downtimes`` (``(from, to)``, Unix seconds) between ``when`` and ``now`` are left out."""
    total = seconds_since(when, now)
    if total is None or not downtimes:
        return total
    end = now.timestamp()
    start = end - total
    down = sum(max(0.0, min(b, end) - max(a, start)) for a, b in downtimes)
    return max(0.0, total - down)


def is_stuck(in_progress: bool, connected: bool, step_s: float | None, touch_s: float | None,
             stuck_after_s: float) -> bool:
    """Neither a touch nor a new step for ``stuck_after_s`` seconds in a calibration in progress
    of a connected trainee (a threshold that is not a positive finite number flags nobody)."""
    if not (in_progress and connected) or not math.isfinite(stuck_after_s) or stuck_after_s <= 0:
        return False
    quiet = [s for s in (step_s, touch_s) if s is not None]
    return bool(quiet) and min(quiet) >= stuck_after_s


def is_idle(trainee: BoardTrainee, connected: bool, quiet_s: float | None, idle_after_s: float) -> bool:
    """A connected trainee with no calibration in progress and none finished, quiet (no join,
    step or touch) for ``idle_after_s`` seconds (a threshold that is not a positive finite
    number flags nobody)."""
    if not connected or not math.isfinite(idle_after_s) or idle_after_s <= 0 or quiet_s is None:
        return False
    busy = trainee.in_progress > 0 or trainee.result_calibration_id is not None
    return not busy and quiet_s >= idle_after_s


def _method(t: BoardTrainee | BoardRun) -> str:
    return t.method_title or t.method


def dashboard_rows(board: ClassBoard, connected: Collection[str], now: datetime, stuck_after_s: float,
                   idle_after_s: float = DEFAULT_IDLE_MIN * 60.0) -> list[DashboardRow]:
    """The dashboard's rows: every trainee of ``board`` in the order they first joined,
    ``connected`` (names) marked, stuck and idle ones flagged (module docstring)."""
    rows = []
    down = board.downtimes
    for i, t in enumerate(board.trainees, start=1):
        on = t.name in connected
        step_s = active_seconds(t.step_since, now, down)
        touch_s = active_seconds(t.last_touch_at, now, down)
        clocks = [s for s in (active_seconds(t.joined_at, now, down), step_s, touch_s) if s is not None]
        quiet_s = min(clocks) if clocks else None
        open_ = t.status == "in_progress"
        rows.append(DashboardRow(
            number=i, name=t.name, connected=on, method=_method(t), step=t.step if t.calibration_id else "",
            step_s=step_s, touch_s=touch_s, touches=t.touches, crashes=t.crashes,
            position_error_mm=t.position_error_mm, orientation_error_deg=t.orientation_error_deg,
            grade=t.grade or "", tcp_mm=t.tcp_mm, in_progress=open_,
            stuck=is_stuck(open_, on, step_s, touch_s, stuck_after_s),
            idle=is_idle(t, on, quiet_s, idle_after_s), quiet_s=quiet_s))
    return rows


def open_runs(board: ClassBoard, connected: Collection[str], now: datetime) -> list[OpenRun]:
    """The calibrations in progress of ``board`` (oldest first), with their trainee's connection
    (clocks without the server's downtime)."""
    down = board.downtimes
    return [OpenRun(calibration_id=r.calibration_id, trainee=r.trainee, connected=r.trainee in connected,
                    method=_method(r), step=r.step, step_s=active_seconds(r.step_since, now, down),
                    started_s=active_seconds(r.started_at, now, down), touches=r.touches)
            for r in board.in_progress]


def format_duration(seconds: float | None) -> str:
    """``"m:ss"`` below an hour, ``"h:mm:ss"`` above, ``"-"`` for None."""
    if seconds is None or not math.isfinite(seconds):
        return "-"
    s = int(seconds)
    h, rest = divmod(s, 3600)
    m, sec = divmod(rest, 60)
    return f"{h}:{m:02d}:{sec:02d}" if h else f"{m}:{sec:02d}"
