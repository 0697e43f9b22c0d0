"""A finished result outlasts a restart of the class server until it is saved or dismissed:
ana finishes, does not save, the server goes down; after the restart her result is on show
again (not only Start), she saves it to the library, and the next restart gives back nothing;
a result she closed does not come back either. The gradebook is written as each event happens
(``TraineeRecorder``), so what a ``kill -9`` leaves is what these graceful stops leave
(tests/classroom/test_sigkill_server.py kills a real server)."""

from __future__ import annotations

from pathlib import Path

import pytest

import numpy as np

from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until

from tcp_pendant.classroom.gradebook import Gradebook

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

TOKEN = "trainer-token-for-tests-0002"


def _join(app, client: DrainingClient, name: str, key: str = ""):
    wait_until(lambda: len(app.sessions) >= 1 and all("identity" in s.views for s in app.sessions.values()),
               what="a session with its name prompt")
    s = next(iter(app.sessions.values()))
    prompt = s.views["identity"]
    choose(prompt.name_field, name, s.client)
    choose(prompt.key_field, key, s.client)
    click(prompt.start, s.client)
    assert prompt.name == name, prompt.message.content
    return s


def _key(session) -> str:
    html = session.views["identity"].key_html.content
    return html.split('data-tcp-pendant-key="', 1)[1].split('"', 1)[0]


def _finish(s) -> None:
    cal = s.views["calibrate"]
    click(cal.start, s.client)                                # XYZ 4-point, the default
    for _ in range(8):
        if s.workflow.result is not None:
            return
        click(cal.steps.auto_touch, s.client)
    assert s.workflow.result is not None


def test_an_unsaved_result_comes_back_after_a_restart_until_it_is_saved(app_factory, tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    app = app_factory(class_db=db, trainer_token=TOKEN, seed=3, exercise="mystery")
    c = DrainingClient(app.port)
    try:
        app.classroom.push_settings("mystery", None, auto_touch=True)   # off in an exercise unless allowed
        s = _join(app, c, "ana")
        key = _key(s)
        _finish(s)
        tcp = np.array(s.workflow.result.tcp_mm)
        (row,) = app.gradebook.grades.rows()
        assert row.status == "finished" and not s.workflow.result_saved
    finally:
        c.close()
    app.stop()                                                # the server goes down; nothing was saved

    again = app_factory(class_db=db, trainer_token=TOKEN, seed=4, exercise="mystery")
    c2 = DrainingClient(again.port)
    try:
        s2 = _join(again, c2, "ana", key)
        wf = s2.workflow
        assert wf.is_open and wf.wizard.status == "complete" and wf.result is not None     # not only Start
        np.testing.assert_allclose(wf.result.tcp_mm, tcp, atol=1e-9)       # recomputed from the same touches
        assert wf.record_ids == {len(wf.runs) - 1: row.calibration_id}
        assert s2.views["calibrate"].result.folder.visible
        assert wf.hide_truth                                       # the exercise: the result shows no truth
        slot, tool = s2.wizard_commands.save_result("ana tool")                    # she can still save it to the library
        kept = again.library.get(slot)
        assert kept is not None and kept.name == "ana tool"
        np.testing.assert_allclose(kept.tcp_mm, tcp, atol=1e-6)
        assert [r.calibration_id for r in again.gradebook.grades.rows()] == [row.calibration_id]   # not graded twice
    finally:
        c2.close()
    again.stop()
    with Gradebook(db) as book:
        assert book.run_states.open_runs("ana") == []            # saved: nothing left to give back

    third = app_factory(class_db=db, trainer_token=TOKEN, seed=5, exercise="mystery")
    c3 = DrainingClient(third.port)
    try:
        s3 = _join(third, c3, "ana", key)
        assert not s3.workflow.runs and not s3.workflow.is_open
    finally:
        c3.close()


def test_a_result_closed_without_saving_is_dismissed(app_factory, tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    app = app_factory(class_db=db, trainer_token=TOKEN, seed=3)
    c = DrainingClient(app.port)
    try:
        s = _join(app, c, "ana")
        key = _key(s)
        _finish(s)
        with Gradebook(db) as book:
            assert [r["status"] for r in book.run_states.open_runs("ana")] == ["finished"]
        assert s.wizard_commands.cancel() is False                          # "Close (not saved)": she dismisses it
        assert not s.workflow.is_open
    finally:
        c.close()
    app.stop()
    with Gradebook(db) as book:
        assert book.run_states.open_runs("ana") == []
    again = app_factory(class_db=db, trainer_token=TOKEN, seed=4)
    c2 = DrainingClient(again.port)
    try:
        s2 = _join(again, c2, "ana", key)
        assert not s2.workflow.runs and not s2.workflow.is_open
    finally:
        c2.close()
