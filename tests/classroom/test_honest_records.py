"""Honest records: a classroom trainee's export holds no truth and no server
path; the trainer grades it against the gradebook by the record id each wizard carries."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.grading import grade_record
from tcp_pendant.classroom.recorder import TraineeRecorder
from tcp_pendant.wizards.session_record import VERSION, load_and_replay

from tcpcal.library import ToolLibrary

from support.calib_helpers import make_controller, make_session


def _finished_class_session(tmp_path: Path, name: str = "Anna", sigma: float = 0.3):
    book = Gradebook(tmp_path / "class.sqlite3", synchronous="NORMAL")
    s = make_session(tmp_path / "tools.json", seed=5)
    s.wizard_commands.keep_honest_records()
    rec = TraineeRecorder(book, book.records.start_session(book.trainees.add(name), "per-browser"), name, s.workflow)
    s.subscribe(rec.on_change)
    s.wizard_commands.start("xyz4")
    while s.workflow.result is None:
        s.wizard_commands.auto_touch(AutoTouchRequest(sigma_mm=sigma))
    return book, s.workflow


def test_a_classroom_export_holds_no_truth_and_no_server_path(tmp_path: Path) -> None:
    book, wf = _finished_class_session(tmp_path)
    record = wf.export_record()
    text = json.dumps(record)
    assert record["version"] == VERSION == 2 and record["honest"] is True
    assert "T_flange_tcp_true_m" not in text and "T_flange_tool_true" not in text
    assert record["robot"]["urdf"] is None and "/" not in json.dumps(record["robot"])
    w = record["wizards"][0]
    assert w["truth"] is None and w["true_tool"] == {"key": "pointer"}
    assert w["record_id"] == book.grades.rows()[0].calibration_id
    # outside a class the record still carries the truth (self-study), now with record_id null
    c2 = make_controller()
    free = CalibrationWorkflow(c2, ToolLibrary(tmp_path / "t2.json"), robot="kr6")
    free.start("xyz4")
    out = free.export_record()
    assert out["honest"] is False and "T_flange_tcp_true_m" in json.dumps(out)
    assert out["wizards"][0]["record_id"] is None
    book.close()


def test_the_trainer_grades_the_record_against_the_gradebook(tmp_path: Path) -> None:
    book, wf = _finished_class_session(tmp_path)
    record = wf.export_record()
    grades = grade_record(load_and_replay(json.dumps(record)), book)
    assert len(grades) == 1
    g = grades[0]
    truth = wf.truth()
    assert g.trainee == "Anna" and g.matches_gradebook is True
    assert g.position_error_mm == pytest.approx(truth.position_error_mm, abs=1e-9)
    assert g.grade == truth.grade == book.grades.rows()[0].grade
    # edited afterwards (one touch moved 2 mm, result recomputed into the file): caught
    tampered = copy.deepcopy(record)
    pose = tampered["wizards"][0]["state"]["poses"]["0"]["T_world_flange_m"]
    pose[0][3] += 0.002
    replayed = load_and_replay(json.dumps(tampered))
    tampered["wizards"][0]["result"] = replayed.checks[0].wizard.finished_result.summary()
    g2 = grade_record(load_and_replay(json.dumps(tampered)), book)[0]
    assert g2.matches_gradebook is False and "DIFFERS" in g2.message
    # a record id this gradebook does not know, and none at all
    unknown = copy.deepcopy(record)
    unknown["wizards"][0]["record_id"] = 999
    assert "not in this gradebook" in grade_record(load_and_replay(json.dumps(unknown)), book)[0].message
    unknown["wizards"][0]["record_id"] = None
    assert grade_record(load_and_replay(json.dumps(unknown)), book)[0].grade is None
    book.close()


def test_version_1_records_are_still_read_and_bad_record_ids_refused(tmp_path: Path) -> None:
    from tcp_pendant.wizards.session_record import SessionRecordError

    c = make_controller()
    free = CalibrationWorkflow(c, ToolLibrary(tmp_path / "t.json"), robot="kr6", rng=np.random.default_rng(2))
    free.start("xyz4")
    for _ in range(4):
        free.auto_touch(AutoTouchRequest())
    v1 = free.export_record()
    v1["version"] = 1
    del v1["honest"]
    for w in v1["wizards"]:
        del w["record_id"]
    checks = load_and_replay(json.dumps(v1)).checks
    assert checks[0].matches and checks[0].truth is not None
    bad = free.export_record()
    bad["wizards"][0]["record_id"] = "1; DROP TABLE"
    with pytest.raises(SessionRecordError, match="record_id"):
        load_and_replay(json.dumps(bad))
