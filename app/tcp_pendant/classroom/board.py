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

Times are UTC ISO 8601 from the gradebook; durations seconds.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass
from datetime import datetime, timezone

from tcp_pendant.classroom.class_board import BoardRun, BoardTrainee, ClassBoard

__all__ = ["DEFAULT_STUCK_MIN", "DashboardRow", "OpenRun", "dashboard_rows", "format_duration", "is_stuck",
           "open_runs", "seconds_since"]

DEFAULT_STUCK_MIN = 5.0
"""The stuck threshold a dashboard starts with, minutes."""


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


def is_stuck(in_progress: bool, connected: bool, step_s: float | None, touch_s: float | None,
             stuck_after_s: float) -> bool:
    """Neither a touch nor a new step for ``stuck_after_s`` seconds in a calibration in progress
    of a connected trainee (a threshold that is not a positive finite number flags nobody)."""
    if not (in_progress and connected) or not math.isfinite(stuck_after_s) or stuck_after_s <= 0:
        return False
    quiet = [s for s in (step_s, touch_s) if s is not None]
    return bool(quiet) and min(quiet) >= stuck_after_s


def _method(t: BoardTrainee | BoardRun) -> str:
    return t.method_title or t.method


def dashboard_rows(board: ClassBoard, connected: Collection[str], now: datetime, stuck_after_s: float) -> list[DashboardRow]:
    """The dashboard's rows: every trainee of ``board`` in the order they first joined,
    ``connected`` (names) marked, stuck ones flagged (module docstring)."""
    rows = []
    for i, t in enumerate(board.trainees, start=1):
        on = t.name in connected
        step_s = seconds_since(t.step_since, now)
        touch_s = seconds_since(t.last_touch_at, now)
        open_ = t.status == "in_progress"
        rows.append(DashboardRow(
            number=i, name=t.name, connected=on, method=_method(t), step=t.step if t.calibration_id else "",
            step_s=step_s, touch_s=touch_s, touches=t.touches, crashes=t.crashes,
            position_error_mm=t.position_error_mm, orientation_error_deg=t.orientation_error_deg,
            grade=t.grade or "", tcp_mm=t.tcp_mm, in_progress=open_,
            stuck=is_stuck(open_, on, step_s, touch_s, stuck_after_s)))
    return rows


def open_runs(board: ClassBoard, connected: Collection[str], now: datetime) -> list[OpenRun]:
    """The calibrations in progress of ``board`` (oldest first), with their trainee's connection."""
    return [OpenRun(calibration_id=r.calibration_id, trainee=r.trainee, connected=r.trainee in connected,
                    method=_method(r), step=r.step, step_s=seconds_since(r.step_since, now),
                    started_s=seconds_since(r.started_at, now), touches=r.touches)
            for r in board.in_progress]


def format_duration(seconds: float | None) -> str:
    """``"m:ss"`` below an hour, ``"h:mm:ss"`` above, ``"-"`` for None."""
    if seconds is None or not math.isfinite(seconds):
        return "-"
    s = int(seconds)
    h, rest = divmod(s, 3600)
    m, sec = divmod(rest, 60)
    return f"{h}:{m:02d}:{sec:02d}" if h else f"{m}:{sec:02d}"
