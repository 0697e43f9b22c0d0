"""The classroom recorder stores every wizard event of a session in the gradebook as it happens."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.recorder import TraineeRecorder
from tcp_pendant.wizards.session_record import load_and_replay

from support.calib_helpers import make_session


@pytest.fixture
def setup(tmp_path: Path):
    book = Gradebook(tmp_path / "class.sqlite3", synchronous="NORMAL")
    s = make_session(tmp_path / "tools.json", seed=3)
    sid = book.records.start_session(book.trainees.add("Anna"), "per-browser")
    rec = TraineeRecorder(book, sid, "Anna", s.workflow)
    s.subscribe(rec.on_change)
    yield book, s, rec
    book.close()


def test_auto_and_hand_touches_overwrite_and_finish_are_stored(setup) -> None:
    book, s, rec = setup
    c, wf = s.controller, s.workflow
    s.wizard_commands.start("xyz4")
    cal = rec._runs[0].calibration_id
    assert book.records.calibration_status(cal) == "in_progress"
    s.wizard_commands.auto_touch(AutoTouchRequest())               # step 1 by Auto-touch
    s.wizard_commands.back()                                       # Auto-touch went on to step 2: back to step 1
    s.wizard_commands.record_step()                                # step 1 again, by hand: overwrites the auto touch
    s.wizard_commands.next_step()
    touches = book.records.touches(cal)
    assert [t["auto"] for t in touches] == [True, False]
    assert touches[1]["overwrites_touch_id"] == touches[0]["id"]
    assert touches[0]["overwritten_by_touch_id"] == touches[1]["id"]
    assert len(touches[1]["joints_deg"]) == 6
    np.testing.assert_allclose(touches[1]["joints_deg"], np.degrees(c.q_rad))
    assert touches[0]["distance_mm"] is not None and touches[0]["distance_mm"] < 3.0
    for _ in range(4):
        s.wizard_commands.auto_touch(AutoTouchRequest())
        if wf.result is not None:
            break
    assert wf.result is not None
    rows = book.grades.rows()
    assert len(rows) == 1
    row = rows[0]
    assert row.trainee == "Anna" and row.method == "xyz4" and row.tool_key == "pointer"
    assert row.touches == 4 and row.overwritten == 1
    truth = wf.truth()
    assert row.position_error_mm == pytest.approx(truth.position_error_mm)
    assert row.grade == truth.grade
    assert rec.status.grade == truth.grade and rec.status.step == "result"
    assert rec.status.touches == 5


def test_a_touch_is_stored_with_the_joints_and_distance_of_its_record_not_of_the_signal(setup) -> None:
    """A Record and a jog in one signal (one batch): the gradebook keeps the joints and the
    distance the robot had at Record, not those after the jog."""
    book, s, rec = setup
    s.wizard_commands.start("xyz4")
    s.wizard_commands.auto_touch(AutoTouchRequest())                # the tool tip on the reference tip
    s.wizard_commands.back()
    q_at_record = np.degrees(s.controller.q_rad)
    d_at_record = s.controller.touch_geometry().distance_mm
    with s.batch():
        s.wizard_commands.record_step()
        s.jogger.settings = s.jogger.settings.with_(increment="10")
        s.motion.jog("Z", 1)
        s.motion.jog("Z", 1)
    assert s.controller.touch_geometry().distance_mm > d_at_record + 15.0     # the robot moved away
    touches = book.records.touches(rec._runs[0].calibration_id)
    last = touches[-1]
    assert last["auto"] is False and last["overwrites_touch_id"] == touches[0]["id"]
    np.testing.assert_allclose(last["joints_deg"], q_at_record, atol=1e-9)
    assert last["distance_mm"] == pytest.approx(d_at_record, abs=1e-9)


def test_cancel_resume_and_loaded_runs(setup, tmp_path: Path) -> None:
    book, s, rec = setup
    s.wizard_commands.start("xyz4")
    s.wizard_commands.record_step()
    cal = rec._runs[0].calibration_id
    s.wizard_commands.cancel()
    assert book.records.calibration_status(cal) == "cancelled"
    s.wizard_commands.resume(0)
    assert book.records.calibration_status(cal) == "in_progress"
    # a record loaded from a file arrives cancelled: not this session's work, not stored
    other = make_session(tmp_path / "t2.json", seed=1)
    other.wizard_commands.start("xyz4")
    other.wizard_commands.record_step()
    s.wizard_commands.load_record(load_and_replay(other.workflow.export_record()))
    assert len(s.workflow.runs) == 2 and 1 not in rec._runs
    with book.store.read() as db:
        assert db.execute("SELECT COUNT(*) FROM calibrations").fetchone()[0] == 1


def test_crash_transitions_are_counted_once(setup) -> None:
    book, s, rec = setup
    c = s.controller
    s.wizard_commands.start("xyz4")
    assert not c.touch_geometry().crashed
    # drive the true tool 5 mm through the tip along its own X (the approach direction)
    T_true = c.T_world_tool_true()
    T_true[:3, 3] = c.reference_tip_world_m + 0.005 * T_true[:3, 0]
    c.move_true_tool_to(T_true)
    assert c.touch_geometry().crashed, c.touch_geometry()
    s.moved()
    s.moved()                          # still crashed: the same crash
    with book.store.read() as db:
        assert db.execute("SELECT COUNT(*) FROM crashes").fetchone()[0] == 1
        assert db.execute("SELECT calibration_id FROM crashes").fetchone()[0] == rec._runs[0].calibration_id
    assert rec.status.crashes == 1
