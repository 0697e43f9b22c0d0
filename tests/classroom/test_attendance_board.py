"""Attendance on the trainer's dashboard: an idle trainee (joined, nothing started, quiet) is
flagged like a stuck one; "Stuck after" and "Idle after" are kept in the gradebook (SQLite and
PostgreSQL) and outlast a restart; the clocks (on the step, since the last touch, stuck, idle)
leave the server's downtime out."""

from __future__ import annotations

from datetime import datetime, timedelta, timezone
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.classroom.board import active_seconds, dashboard_rows, open_runs
from tcp_pendant.classroom.class_board import BoardTrainee, ClassBoard
from tcp_pendant.classroom.class_room import ClassRoom
from tcp_pendant.classroom.dashboard_settings import (
    IDLE_SETTING, STUCK_SETTING, keep_minutes, kept_minutes,
)
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.uptime import UPTIME_BEAT_S, downtimes
from tcp_pendant.controller import builtin_tools
from tcp_pendant.views.dashboard_table import IDLE_BACKGROUND, STUCK_BACKGROUND, trainees_html

NOW = datetime(2026, 12, 2, 9, 0, tzinfo=timezone.utc)


def _ago(minutes: float | None) -> str:
    return "" if minutes is None else (NOW - timedelta(minutes=minutes)).isoformat(timespec="milliseconds")


def _chen(joined_min: float, **kw: object) -> ClassBoard:
    return ClassBoard((BoardTrainee(3, "chen", joined_at=_ago(joined_min), **kw),), ())  # type: ignore[arg-type]


@pytest.mark.parametrize("joined_min, idle_min, connected, extra, idle", [
    (6.0, 5.0, True, {}, True),                                    # joined 6 min ago, nothing since: idle
    (6.0, 10.0, True, {}, False),                                  # the trainer allows 10 min
    (6.0, 5.0, False, {}, False),                                  # not connected: never flagged
    (60.0, 5.0, True, {"calibration_id": 9, "status": "cancelled", "step": "cancelled",
                       "step_since": _ago(2.0)}, False),          # a step 2 min ago
    (60.0, 5.0, True, {"calibration_id": 9, "status": "cancelled", "step": "cancelled",
                       "step_since": _ago(20.0), "last_touch_at": _ago(30.0)}, True),   # left it 20 min ago
    (60.0, 5.0, True, {"calibration_id": 9, "status": "finished", "step": "result", "step_since": _ago(50.0),
                       "result_calibration_id": 9}, False),        # done: never idle
    (60.0, 5.0, True, {"calibration_id": 9, "status": "in_progress", "in_progress": 1, "step": "Step 2 of 4",
                       "step_since": _ago(50.0)}, False),          # in a calibration: stuck, not idle
])
def test_an_idle_trainee_is_flagged_against_the_trainers_threshold(joined_min, idle_min, connected, extra,
                                                                    idle) -> None:
    (row,) = dashboard_rows(_chen(joined_min, **extra), {"chen"} if connected else set(), NOW,
                            stuck_after_s=300.0, idle_after_s=idle_min * 60.0)
    assert row.idle is idle
    html = trainees_html([row])
    assert (IDLE_BACKGROUND in html and "◔ chen" in html and 'class="idle"' in html) is idle
    if idle and not extra:
        assert ">idle<" in html and ">6:00<" in html               # Step says idle, On step how long


def test_the_issues_class_one_finished_one_stuck_one_idle() -> None:
    board = ClassBoard((
        BoardTrainee(1, "ana", calibration_id=1, status="finished", step="result", step_since=_ago(9.0),
                     result_calibration_id=1, grade="good", joined_at=_ago(30.0)),
        BoardTrainee(2, "ben", calibration_id=2, status="in_progress", in_progress=1, step="Step 2 of 4",
                     step_since=_ago(8.0), last_touch_at=_ago(8.5), joined_at=_ago(30.0)),
        BoardTrainee(3, "chen", joined_at=_ago(30.0))), ())
    rows = dashboard_rows(board, {"ana", "ben", "chen"}, NOW, stuck_after_s=300.0, idle_after_s=300.0)
    assert [(r.name, r.stuck, r.idle) for r in rows] == [("ana", False, False), ("ben", True, False),
                                                         ("chen", False, True)]
    html = trainees_html(rows)
    assert STUCK_BACKGROUND in html and IDLE_BACKGROUND in html


def test_the_thresholds_outlast_a_restart(gradebook_target: Path | str) -> None:
    with Gradebook(gradebook_target) as book:
        assert (kept_minutes(book.settings, STUCK_SETTING), kept_minutes(book.settings, IDLE_SETTING)) == (5.0, 5.0)
        assert keep_minutes(book.settings, STUCK_SETTING, 12.5) == 12.5
        keep_minutes(book.settings, IDLE_SETTING, 3)
        with pytest.raises(ValueError, match="0.5 to 240 minutes"):
            keep_minutes(book.settings, STUCK_SETTING, 0.0)
        with pytest.raises(ValueError, match="0.5 to 240 minutes"):
            keep_minutes(book.settings, STUCK_SETTING, float("nan"))
    with Gradebook(gradebook_target) as book:                      # the restart: only the gradebook is left
        assert (kept_minutes(book.settings, STUCK_SETTING), kept_minutes(book.settings, IDLE_SETTING)) == (12.5, 3.0)
        book.settings.set(STUCK_SETTING, "ten")                   # a damaged value: the default, not a crash
        assert kept_minutes(book.settings, STUCK_SETTING) == 5.0


def test_downtimes_are_the_gaps_between_the_processes_up_stretches() -> None:
    assert downtimes([]) == ()
    assert downtimes([(100.0, 200.0)]) == ()
    assert downtimes([(500.0, 900.0), (100.0, 200.0)]) == ((200.0, 500.0),)
    # two workers overlapping, then a restart: one gap only
    assert downtimes([(100.0, 300.0), (150.0, 250.0), (400.0, 450.0), (420.0, 600.0)]) == ((300.0, 400.0),)
    t = NOW.timestamp()
    since = _ago(20.0)                                            # 20 min ago; the server was down 18 of them
    assert active_seconds(since, NOW, ((t - 19 * 60, t - 60),)) == pytest.approx(120.0)
    assert active_seconds(since, NOW, ((t - 3600, t - 1500),)) == pytest.approx(1200.0)   # before: not counted
    assert active_seconds(since, NOW, ((t - 25 * 60, t - 10 * 60),)) == pytest.approx(600.0)  # overlaps the start
    assert active_seconds("", NOW, ((t - 60, t),)) is None


def test_time_on_step_leaves_the_servers_downtime_out(gradebook_target: Path | str) -> None:
    """ben is at step 2 for 20 minutes of wall clock, 18 of them with the server down (killed:
    no last beat of its own at the end): 2 minutes on the step, not stuck at 5."""
    t = NOW.timestamp()
    with Gradebook(gradebook_target) as book:
        sid = book.records.start_session(book.trainees.add("ben"), "per-browser")
        cid = book.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
        book.run_states.save(cid, {"n": 1}, method_title="XYZ 4-point", step="Step 2 of 4")
        with book.store.write() as db:
            db.execute("UPDATE run_states SET step_since = ?", (_ago(20.0),))
        assert book.uptime.beat("first:1", now=t - 30 * 60)      # up since before the step ...
        assert not book.uptime.beat("first:1", now=t - 30 * 60 + UPTIME_BEAT_S / 2)   # (at most every 5 s)
        assert book.uptime.beat("first:1", now=t - 19 * 60)      # ... its last beat, then kill -9
        assert book.uptime.beat("second:2", now=t - 60)          # the restart, 18 min later
        board = book.board.read()
    assert board.downtimes == ((t - 19 * 60, t - 60),)
    (row,) = dashboard_rows(board, {"ben"}, NOW, stuck_after_s=300.0)
    assert row.step_s == pytest.approx(120.0, abs=0.01) and not row.stuck
    (run,) = open_runs(board, {"ben"}, NOW)
    assert run.step_s == pytest.approx(120.0, abs=0.01)


def test_the_class_room_beats_its_uptime_and_writes_its_end_when_it_stops(tmp_path: Path) -> None:
    with Gradebook(tmp_path / "class.sqlite3") as book:
        room = ClassRoom(book, builtin_tools(), trainer_token="t" * 20)
        room.beat()
        with book.store.read() as db:
            ((holder, started, seen),) = db.execute("SELECT holder, started_at, seen_at FROM server_uptime").fetchall()
        assert holder == room.holder and started == seen
        room.close()
        with book.store.read() as db:
            ((seen_after,),) = db.execute("SELECT seen_at FROM server_uptime").fetchall()
        assert seen_after >= seen


def test_a_gradebook_from_before_gets_the_new_parts_without_losing_anything(gradebook_target: Path | str) -> None:
    """A gradebook written before ``server_uptime`` and ``run_states.result_saved_at`` (both
    taken out again here) opens with them added and every row kept, on SQLite and PostgreSQL."""
    with Gradebook(gradebook_target) as book:
        sid = book.records.start_session(book.trainees.add("ana"), "per-browser")
        cid = book.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
        book.run_states.save(cid, {"n": 1}, method_title="XYZ 4-point", step="result")
        book.settings.set(STUCK_SETTING, 7.0)
        with book.store.write() as db:
            db.execute("DROP TABLE server_uptime")
            db.execute("ALTER TABLE run_states DROP COLUMN result_saved_at")
    with Gradebook(gradebook_target) as book:
        with book.store.read() as db:
            assert "result_saved_at" in db.columns("run_states") and "server_uptime" in db.tables()
            assert db.execute("SELECT step, method_title, result_saved_at FROM run_states").fetchall() == [
                ("result", "XYZ 4-point", None)]
        assert kept_minutes(book.settings, STUCK_SETTING) == 7.0
        assert [a.trainee for a in book.grades.attendance()] == ["ana"]
        book.run_states.mark_saved(cid)
        assert book.uptime.beat("h:1", now=1000.0) and book.board.read().downtimes == ()
