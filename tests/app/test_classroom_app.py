"""The classroom wired into the app (issue 11): the "Your name" prompt, the gradebook recorder,
the trainer view behind its token, the mystery exercise and the settings the trainer pushes."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parents[1] / "calibrate"))
from guiclick import choose, click, upload  # noqa: E402
from wsclient import DrainingClient, wait_until  # noqa: E402

from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.mystery import true_frame


def _session(app, client: DrainingClient):
    wait_until(lambda: len(app.sessions) >= 1 and all("identity" in s.views for s in app.sessions.values()),
               what="a session with its name prompt")
    return next(iter(app.sessions.values()))


def _browser(session):
    return session.client


def test_name_prompt_records_the_trainee_and_escapes_the_name(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="secret-token-1")
    c = DrainingClient(app.port)
    try:
        s = _session(app, c)
        prompt = s.views["identity"]
        assert prompt.name_field.label == "Your name"
        choose(prompt.name_field, "   ", _browser(s))
        click(prompt.start, _browser(s))
        assert "empty" in prompt.message.content and prompt.name is None
        choose(prompt.name_field, "  *Anna*  <b>x</b> ", _browser(s))
        click(prompt.start, _browser(s))
        assert prompt.name == "*Anna* <b>x</b>"
        assert "\\*Anna\\*" in prompt.banner.content and "<b>" not in prompt.banner.content
        with Gradebook(tmp_path / "class.sqlite3") as book, book._read() as db:
            assert db.execute("SELECT name FROM trainees").fetchall() == [("*Anna* <b>x</b>",)]
            assert db.execute("SELECT mode, ended_at FROM sessions").fetchall() == [("per-browser", None)]
    finally:
        c.close()
    wait_until(lambda: app.classroom.trainee_statuses()[0].connected is False, what="the session closed")
    with Gradebook(tmp_path / "class.sqlite3") as book, book._read() as db:
        assert db.execute("SELECT ended_at FROM sessions").fetchone()[0] is not None


def test_wizard_events_reach_the_gradebook_through_the_gui(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="secret-token-1")
    c = DrainingClient(app.port)
    try:
        s = _session(app, c)
        prompt = s.views["identity"]
        choose(prompt.name_field, "Bo", _browser(s))
        click(prompt.start, _browser(s))
        cal = s.views["calibrate"]
        click(cal.start, _browser(s))                         # XYZ 4-point, the default
        for _ in range(4):
            click(cal.steps.auto_touch, _browser(s))
        assert cal.workflow.result is not None
        rows = app.gradebook.grades()
        assert len(rows) == 1 and rows[0].trainee == "Bo" and rows[0].auto == 4 and rows[0].hand == 0
        assert rows[0].grade == cal.workflow.truth().grade
        assert app.classroom.trainee_statuses()[0].step == "result"
    finally:
        c.close()


def test_trainer_view_needs_the_token_and_shows_the_class_escaped(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="secret-token-1")
    a = DrainingClient(app.port)
    wait_until(lambda: len(app.sessions) == 1, what="trainee session")
    t = DrainingClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 2 and all("identity" in s.views for s in app.sessions.values()),
                   what="two sessions")
        trainee, trainer = list(app.sessions.values())
        p = trainee.views["identity"]
        choose(p.name_field, "|Eve| **x**", trainee.client)
        click(p.start, trainee.client)
        q = trainer.views["identity"]
        choose(q.token_field, "secret-token-2", trainer.client)
        click(q.open_trainer, trainer.client)
        assert "trainer" not in trainer.views and "not right" in q.message.content
        choose(q.token_field, "secret-token-1", trainer.client)
        click(q.open_trainer, trainer.client)
        view = trainer.views["trainer"]
        md = view.trainees_md.content
        assert "\\|Eve\\| \\*\\*x\\*\\*" in md and "| yes |" in md
        # a touch by the trainee updates the trainer's table
        cal = trainee.views["calibrate"]
        click(cal.start, trainee.client)
        click(cal.steps.auto_touch, trainee.client)
        assert "| 1 | 0 |" in view.trainees_md.content
        # push the torch to every trainee
        choose(view.tool, "torch", trainer.client)
        click(view.push, trainer.client)
        assert trainee.controller.mounted_tool.key == "torch"
        assert "1 trainee" in view.push_md.content
        # the trainee finishes; the trainer grades the trainee's exported record by its record id
        for _ in range(6):
            if cal.workflow.result is not None:
                break
            click(cal.steps.auto_touch, trainee.client)
        import json

        record = json.dumps(cal.workflow.export_record()).encode()
        assert b"T_flange_tcp_true_m" not in record
        upload(view.grade_upload, "eve.json", record, trainer.client)
        wait_until(lambda: "Record id" in view.grade_md.content, what="the record's grades")
        grade = cal.workflow.truth().grade
        assert f"| {grade} |" in view.grade_md.content and "matches the gradebook" in view.grade_md.content
    finally:
        a.close()
        t.close()


def test_mystery_exercise_mounts_a_tool_per_trainee_and_grades_against_it(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="secret-token-1",
                      exercise="mystery", exercise_seed=7)
    a = DrainingClient(app.port)
    wait_until(lambda: len(app.sessions) == 1, what="first session")
    b = DrainingClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 2 and all("identity" in s.views for s in app.sessions.values()),
                   what="two sessions")
        s1, s2 = list(app.sessions.values())
        for s, name in ((s1, "Anna"), (s2, "Ben")):
            choose(s.views["identity"].name_field, name, s.client)
            click(s.views["identity"].start, s.client)
        k1, k2 = s1.controller.mounted_tool, s2.controller.mounted_tool
        assert k1.key.startswith("mystery-") and k2.key.startswith("mystery-") and k1.key != k2.key
        assert not np.allclose(true_frame(k1), true_frame(k2))
        cal = s1.views["calibrate"]
        click(cal.start, s1.client)
        app.classroom.push_settings("mystery", None, auto_touch=True)   # off in an exercise unless allowed
        for _ in range(4):
            click(cal.steps.auto_touch, s1.client)
        row = app.gradebook.grades()[0]
        assert row.exercise_id == "mystery" and row.tool_key == k1.key
        truth = app.gradebook.truth(row.calibration_id)
        np.testing.assert_allclose(truth["T_flange_tool_true_m"], true_frame(k1), atol=1e-12)
        assert row.position_error_mm == pytest.approx(cal.workflow.truth().position_error_mm)
    finally:
        a.close()
        b.close()


def test_without_class_db_there_is_no_prompt(app_factory) -> None:
    app = app_factory()
    c = DrainingClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 1 and "pendant" in next(iter(app.sessions.values())).views,
                   what="session")
        assert "identity" not in next(iter(app.sessions.values())).views and app.classroom is None
    finally:
        c.close()
