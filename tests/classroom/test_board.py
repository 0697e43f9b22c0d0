"""The trainer dashboard's data without a server: the gradebook's board (each trainee's latest
calibration, its step and since when, touches, crashes, last result), the stuck flag against
the trainer's threshold, the table's HTML (escaped, one line a trainee) and the throttled
re-render of the class room."""

from __future__ import annotations

import re
from datetime import datetime, timedelta, timezone
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.classroom.board import dashboard_rows, format_duration, is_stuck, open_runs
from tcp_pendant.classroom.class_board import BoardTrainee, ClassBoard
from tcp_pendant.classroom.class_room import ClassRoom
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.recorder import TraineeRecorder
from tcp_pendant.controller import builtin_tools
from tcp_pendant.views.dashboard_table import STUCK_BACKGROUND, trainees_html

from support.calib_helpers import make_session

T = np.eye(4)


def _iso(t: datetime) -> str:
    return t.isoformat(timespec="milliseconds")


def test_the_board_is_rebuilt_from_the_file_after_a_restart(gradebook_target: Path | str, tmp_path: Path) -> None:
    """Two trainees work through their recorders; the "server" stops (the gradebook closed);
    a new gradebook object on the same file (or database) gives back both, their steps, touches
    and results."""
    path = gradebook_target
    book = Gradebook(path)
    sessions = {}
    for name, seed in (("Anna", 3), ("Ben <b>", 4)):
        s = make_session(tmp_path / f"tools-{seed}.json", seed=seed)
        sid = book.records.start_session(book.trainees.add(name), "per-browser")
        rec = TraineeRecorder(book, sid, name, s.workflow)
        s.subscribe(rec.on_change)
        sessions[name] = s
    anna, ben = sessions["Anna"], sessions["Ben <b>"]
    anna.wizard_commands.start("xyz4")
    for _ in range(6):
        if anna.workflow.result is not None:
            break
        anna.wizard_commands.auto_touch(AutoTouchRequest())
    assert anna.workflow.result is not None
    anna.wizard_commands.start("xyz4")                       # a second one, left at step 2 after one touch
    anna.wizard_commands.auto_touch(AutoTouchRequest())
    ben.wizard_commands.start("xyz4")
    ben.wizard_commands.auto_touch(AutoTouchRequest())
    ben.wizard_commands.auto_touch(AutoTouchRequest())              # Ben at step 3, two touches
    truth = anna.workflow.runs[0].wizard.finished_result
    first = book.grades.rows()[0]
    book.close()

    book = Gradebook(path)                           # the restart: nothing in memory but the file
    board = book.board.read()
    a, b = board.trainees
    assert (a.name, a.method, a.method_title, a.status, a.step, a.touches) == \
        ("Anna", "xyz4", "XYZ 4-point", "in_progress", "Step 2 of 4", 1)
    assert a.result_calibration_id == first.calibration_id and a.grade == first.grade
    assert a.position_error_mm == pytest.approx(first.position_error_mm)
    assert a.tcp_mm == pytest.approx(tuple(truth.tcp_mm))
    assert (b.name, b.step, b.touches, b.result_calibration_id, b.in_progress) == ("Ben <b>", "Step 3 of 4", 2, None, 1)
    assert a.last_touch_at and b.last_touch_at and b.step_since >= b.last_touch_at[:19]
    assert [(r.trainee, r.step, r.touches) for r in board.in_progress] == [("Anna", "Step 2 of 4", 1),
                                                                          ("Ben <b>", "Step 3 of 4", 2)]
    now = datetime.now(timezone.utc)
    rows = dashboard_rows(board, {"Anna"}, now, stuck_after_s=300.0)  # Ben not back yet: listed, not connected
    assert [(r.number, r.name, r.connected, r.step, r.touches, r.grade) for r in rows] == \
        [(1, "Anna", True, "Step 2 of 4", 1, first.grade), (2, "Ben <b>", False, "Step 3 of 4", 2, "")]
    assert all(r.step_s is not None and 0 <= r.step_s < 120 for r in rows) and not any(r.stuck for r in rows)
    assert [(r.trainee, r.connected) for r in open_runs(board, {"Anna"}, now)] == [("Anna", True), ("Ben <b>", False)]
    html = trainees_html(rows)
    assert "Ben &lt;b&gt;" in html and "<b>" not in html                  # escaped: shown, never run
    assert html.count("<tr") == 3 and "white-space:nowrap" in html
    tcp = ", ".join(f"{v:.1f}" for v in truth.tcp_mm)
    assert f'title="TCP {tcp} mm">{first.position_error_mm:.2f}<' in html       # Anna's result in the tooltip
    book.close()


def test_the_step_clock_restarts_only_with_a_new_step(gradebook_target: Path | str) -> None:
    with Gradebook(gradebook_target) as book:
        sid = book.records.start_session(book.trainees.add("Anna"), "x")
        cid = book.records.start_calibration(sid, "xyz4", "pointer", T)
        book.run_states.save(cid, {"n": 1}, method_title="XYZ 4-point", step="Step 1 of 4")
        with book.store.write() as db:              # the step began long ago
            db.execute("UPDATE run_states SET step_since = '2020-01-01T00:00:00.000+00:00'")
        book.run_states.save(cid, {"n": 2}, method_title="XYZ 4-point", step="Step 1 of 4")  # same step, new pose
        (t,) = book.board.read().trainees
        assert t.step == "Step 1 of 4" and t.step_since == "2020-01-01T00:00:00.000+00:00"
        book.run_states.save(cid, {"n": 3}, method_title="XYZ 4-point", step="Step 2 of 4")
        (t,) = book.board.read().trainees
        assert t.step == "Step 2 of 4" and t.step_since > "2026"
        book.run_states.save(cid, {"n": 4})         # an older writer: no step given, the kept one stays
        (t,) = book.board.read().trainees
        assert t.step == "Step 2 of 4" and t.method_title == "XYZ 4-point"


def _board(step_min: float | None, touch_min: float | None, now: datetime, status: str = "in_progress") -> ClassBoard:
    ago = lambda m: "" if m is None else _iso(now - timedelta(minutes=m))  # noqa: E731
    return ClassBoard((BoardTrainee(1, "Anna", calibration_id=1, method="xyz4", status=status, step="Step 2 of 4",
                                    step_since=ago(step_min), last_touch_at=ago(touch_min), touches=1),), ())


@pytest.mark.parametrize("step_min, touch_min, threshold_min, connected, status, stuck", [
    (6.0, 7.0, 5.0, True, "in_progress", True),       # nothing for 6 min: stuck
    (6.0, 7.0, 10.0, True, "in_progress", False),     # the trainer allows 10 min
    (6.0, 1.0, 5.0, True, "in_progress", False),      # a touch a minute ago: working
    (1.0, 7.0, 5.0, True, "in_progress", False),      # a new step a minute ago
    (6.0, None, 5.0, True, "in_progress", True),      # no touch yet, 6 min on the first step
    (6.0, 7.0, 5.0, False, "in_progress", False),     # not connected: never flagged
    (60.0, 60.0, 5.0, True, "finished", False),       # done: never flagged
])
def test_stuck_against_the_trainers_threshold(step_min, touch_min, threshold_min, connected, status, stuck) -> None:
    now = datetime(2026, 12, 2, 9, 0, tzinfo=timezone.utc)
    (row,) = dashboard_rows(_board(step_min, touch_min, now, status), {"Anna"} if connected else set(), now,
                            stuck_after_s=threshold_min * 60.0)
    assert row.stuck is stuck
    assert row.step_s == pytest.approx(step_min * 60.0)
    html = trainees_html([row])
    assert (STUCK_BACKGROUND in html and "⚠ Anna" in html) is stuck


def test_no_threshold_flags_nobody_and_durations_read_as_clock_times() -> None:
    assert not is_stuck(True, True, 600.0, 600.0, 0.0) and not is_stuck(True, True, 600.0, 600.0, float("nan"))
    assert is_stuck(True, True, 600.0, 600.0, 600.0)
    assert [format_duration(s) for s in (None, 0.4, 65.9, 3600.0 + 62)] == ["-", "0:00", "1:05", "1:01:02"]


class _FakeView:
    def __init__(self, session) -> None:
        self.session = session
        self.renders: list[tuple[int, set[str]]] = []

    def render(self, board: ClassBoard, connected: set[str]) -> None:
        self.renders.append((len(board.trainees), connected))


def test_dashboards_render_at_most_twice_a_second_and_once_per_burst(tmp_path: Path) -> None:
    later: list[tuple[float, object]] = []
    book = Gradebook(tmp_path / "c.sqlite3", synchronous="NORMAL")
    room = ClassRoom(book, builtin_tools(), trainer_token="trainer-token-of-16",
                     call_later=lambda delay, fn: later.append((delay, fn)))
    s = make_session(tmp_path / "tools.json", seed=1)
    view = _FakeView(s)
    room.dashboards.views[id(s)] = view
    for _ in range(50):                      # a burst of changes (100 trainees touching at once)
        room.refresh_trainers()
    assert len(view.renders) == 1            # the first at once ...
    throttled = [(d, fn) for d, fn in later if getattr(fn, "__name__", "") == "_render_trainers"]
    assert len(throttled) == 1 and 0.0 < throttled[0][0] <= 0.5    # ... the rest joined into one, <= 0.5 s later
    throttled[0][1]()                        # type: ignore[operator]
    assert len(view.renders) == 2
    ticks = [d for d, fn in later if getattr(fn, "__name__", "") == "_tick"]
    assert ticks == [5.0]                    # one clock tick pending, not one per render
    book.close()


def test_the_table_fits_one_line_per_trainee_with_long_names() -> None:
    now = datetime.now(timezone.utc)
    long = "Maximiliane Gräfin von Hohenzollern-Sigmaringen"[:40]
    board = ClassBoard((BoardTrainee(1, long, calibration_id=1, method="tcp_zx", method_title="TCP & Z, X (ABB) with a long title",
                                     status="in_progress", step="Step 10 of 12", step_since=_iso(now)),), ())
    html = trainees_html(dashboard_rows(board, {long}, now, 300.0))
    assert re.search(r">10/12<", html)                 # "Step 10 of 12" shortened
    assert "text-overflow:ellipsis" in html and f'title="{long}"' in html   # cut on screen, whole in the tooltip
    assert "&amp; Z, X" in html
