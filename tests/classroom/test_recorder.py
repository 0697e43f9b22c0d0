"""The classroom recorder stores every wizard event of a session in the gradebook as it happens."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.recorder import TraineeRecorder
from tcp_pendant.controller.pose_state import pose_state, pose_state_key
from tcp_pendant.session import SessionChange

from tcpcal.library import ToolLibrary

sys.path.insert(0, str(Path(__file__).parents[1] / "calibrate"))
from calib_helpers import make_controller  # noqa: E402


@pytest.fixture
def setup(tmp_path: Path):
    book = Gradebook(tmp_path / "class.sqlite3", synchronous="NORMAL")
    c = make_controller("kr6", "pointer")
    wf = CalibrationWorkflow(c, ToolLibrary(tmp_path / "tools.json"), robot="kr6", rng=np.random.default_rng(3))
    sid = book.start_session(book.add_trainee("Anna"), "per-browser")
    rec = TraineeRecorder(book, sid, "Anna", c, wf)
    yield book, c, wf, rec
    book.close()


def signal(rec: TraineeRecorder, c, **what) -> None:
    rec.on_change(SessionChange(**what, state=pose_state(c, pose_state_key(c))))


def test_auto_and_hand_touches_overwrite_and_finish_are_stored(setup) -> None:
    book, c, wf, rec = setup
    wf.start_xyz4()
    signal(rec, c, wizard=True)
    cal = rec._runs[0].calibration_id
    assert book.calibration_status(cal) == "in_progress"
    wf.auto_touch(AutoTouchRequest())             # step 1 by Auto-touch
    signal(rec, c, wizard=True, pose=True)
    wf.back()                                      # Auto-touch went on to step 2: back to step 1
    wf.record()                                    # step 1 again, by hand: overwrites the auto touch
    wf.next()
    signal(rec, c, wizard=True)
    touches = book.touches(cal)
    assert [t["auto"] for t in touches] == [True, False]
    assert touches[1]["overwrites_touch_id"] == touches[0]["id"]
    assert touches[0]["overwritten_by_touch_id"] == touches[1]["id"]
    assert len(touches[1]["joints_deg"]) == 6
    np.testing.assert_allclose(touches[1]["joints_deg"], np.degrees(c.q_rad))
    assert touches[0]["distance_mm"] is not None and touches[0]["distance_mm"] < 3.0
    for _ in range(4):
        wf.auto_touch(AutoTouchRequest())
        signal(rec, c, wizard=True, pose=True)
        if wf.result is not None:
            break
    assert wf.result is not None
    rows = book.grades()
    assert len(rows) == 1
    row = rows[0]
    assert row.trainee == "Anna" and row.method == "xyz4" and row.tool_key == "pointer"
    assert row.touches == 4 and row.overwritten == 1
    truth = wf.truth()
    assert row.position_error_mm == pytest.approx(truth.position_error_mm)
    assert row.grade == truth.grade
    assert rec.status.grade == truth.grade and rec.status.step == "result"
    assert rec.status.touches == 5


def test_cancel_resume_and_loaded_runs(setup, tmp_path: Path) -> None:
    book, c, wf, rec = setup
    wf.start_xyz4()
    wf.record()
    signal(rec, c, wizard=True)
    cal = rec._runs[0].calibration_id
    wf.cancel()
    signal(rec, c, wizard=True)
    assert book.calibration_status(cal) == "cancelled"
    wf.resume(0)
    signal(rec, c, wizard=True)
    assert book.calibration_status(cal) == "in_progress"
    # a record loaded from a file arrives cancelled: not this session's work, not stored
    other = CalibrationWorkflow(make_controller(), ToolLibrary(tmp_path / "t2.json"), robot="kr6",
                                rng=np.random.default_rng(1))
    other.start_xyz4()
    other.record()
    wf.load_record(other.export_record())
    signal(rec, c, wizard=True)
    assert rec._runs[1].calibration_id is None
    with book._read() as db:
        assert db.execute("SELECT COUNT(*) FROM calibrations").fetchone()[0] == 1


def test_crash_transitions_are_counted_once(setup) -> None:
    book, c, wf, rec = setup
    wf.start_xyz4()
    signal(rec, c, wizard=True)
    assert not c.touch_geometry().crashed
    # drive the true tool 5 mm through the tip along its own X (the approach direction)
    T_true = c.T_world_tool_true()
    T_true[:3, 3] = c.reference_tip_world_m + 0.005 * T_true[:3, 0]
    c.move_true_tool_to(T_true)
    assert c.touch_geometry().crashed, c.touch_geometry()
    signal(rec, c, pose=True)
    signal(rec, c, pose=True)          # still crashed: the same crash
    with book._read() as db:
        assert db.execute("SELECT COUNT(*) FROM crashes").fetchone()[0] == 1
    assert rec.status.crashes == 1
