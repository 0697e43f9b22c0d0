"""A restart of a class server gives back what trainees saw acknowledged: the calibration in
progress, at its step, with its touches, and written on into the same gradebook calibration;
the trainer's messages not dismissed yet, who left, and the wrong trainer tokens' lockout."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until

import pytest

from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.trainer_token import TrainerTokenLocked

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

TOKEN = "trainer-token-for-tests-0001"


def _join(app, client: DrainingClient, name: str, key: str = ""):
    """Join as ``name`` showing the browser key ``key`` (what the page script sends back after
    a restart)."""
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
    """The browser key the server handed to this session's page script."""
    html = session.views["identity"].key_html.content
    return html.split('data-tcp-pendant-key="', 1)[1].split('"', 1)[0]


def test_a_restart_gives_the_wizard_back_at_its_step_with_its_touches(app_factory, tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    app = app_factory(class_db=db, trainer_token=TOKEN, seed=3)
    c = DrainingClient(app.port)
    try:
        s = _join(app, c, "Anna")
        key = _key(s)
        cal = s.views["calibrate"]
        p_choose = cal.option_widgets["n_points"]
        choose(p_choose, 5, s.client)                        # a 5-point run: options come back too
        click(cal.start, s.client)
        for _ in range(3):
            click(cal.steps.auto_touch, s.client)
        before = s.workflow.wizard
        poses = {k: p.T_world_flange_m.copy() for k, p in before.recorded_poses.items()}
        step, n_steps = before.step_index, before.n_steps
        (cid,) = [r.calibration_id for r in app.gradebook.grades.rows(include_in_progress=True)]
        assert app.classroom.send_message("Anna: *slow down* near the tip.", to="Anna") == "Sent to Anna."
        wait_until(lambda: [m.text for m in s.messages] == ["Anna: *slow down* near the tip."], what="the message")
        now = [9000.0]
        app.classroom.clock = lambda: now[0]
        for i in range(5):                                   # five wrong tokens: locked for 1 s
            assert app.classroom.open_trainer(s, f"wrong-guess-{i:02d}-abcdef") is False
    finally:
        c.close()
    app.stop()                                               # the server goes down mid-calibration

    again = app_factory(class_db=db, trainer_token=TOKEN, seed=4)
    again.classroom.clock = lambda: now[0]
    assert [(r.name, r.connected, r.touches) for r in again.classroom.trainee_statuses()] == [("Anna", False, 3)]
    c2 = DrainingClient(again.port)
    try:
        wait_until(lambda: len(again.sessions) == 1, what="the session")
        with pytest.raises(TrainerTokenLocked, match=r"try again in 1 s\."):     # the lockout outlasts the restart
            again.classroom.open_trainer(next(iter(again.sessions.values())), TOKEN)
        s2 = _join(again, c2, "Anna", key)                 # the same browser: its key
        assert [m.text for m in s2.messages] == ["Anna: *slow down* near the tip."]   # not dismissed: back
        wf = s2.workflow
        w = wf.wizard
        assert wf.is_open and w.kind == "xyz4" and (w.step_index, w.n_steps) == (step, n_steps) == (3, 5)
        assert sorted(w.recorded_poses) == sorted(poses)
        for k, T in poses.items():
            np.testing.assert_array_equal(w.recorded_poses[k].T_world_flange_m, T)
        assert s2.views["calibrate"].steps.folder.visible and "Step 4 of 5" in s2.views["dock"].step_md.content
        assert wf.record_ids == {len(wf.runs) - 1: cid}
        # the trainee goes on: the touches land in the same calibration, which then finishes
        cal2 = s2.views["calibrate"]
        for _ in range(2):
            click(cal2.steps.auto_touch, s2.client)
        assert wf.result is not None
        rows = again.gradebook.grades.rows()
        assert [(r.calibration_id, r.trainee, r.touches, r.status) for r in rows] == [(cid, "Anna", 5, "finished")]
        assert rows[0].grade == wf.truth().grade
    finally:
        c2.close()
    with Gradebook(db) as book:
        (left,) = book.run_states.open_runs("Anna")           # finished, not saved: its result comes back
        assert (left["calibration_id"], left["status"]) == (cid, "finished")   # (tests/app/test_restart_keeps_results.py)


def test_a_trainee_without_work_in_progress_starts_clean(app_factory, tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    app = app_factory(class_db=db, trainer_token=TOKEN)
    c = DrainingClient(app.port)
    try:
        s = _join(app, c, "Ben")
        assert not s.workflow.runs and not s.workflow.is_open
    finally:
        c.close()


def test_the_trainer_token_outlives_a_restart_as_a_hash(app_factory, tmp_path: Path) -> None:
    """Started without --trainer-token again, the class keeps the token it began with: the
    trainer's page reconnects; the gradebook keeps only its SHA-256, and the address is not
    printed (it cannot be rebuilt)."""
    import hashlib

    db = tmp_path / "class.sqlite3"
    first = app_factory(class_db=db)                           # a random token, printed at start
    token = first.classroom.trainer_token
    assert token is not None and first.trainer_url.endswith(token)
    first.stop()
    with Gradebook(db) as book:
        assert book.settings.get("trainer_token_sha256") == hashlib.sha256(token.encode()).hexdigest()
        with book.store.read() as sql:
            assert token not in repr(sql.execute("SELECT * FROM meta").fetchall())
    again = app_factory(class_db=db)
    room = again.classroom
    assert room.trainer_token is None and again.trainer_url is None
    c = DrainingClient(again.port)
    try:
        wait_until(lambda: len(again.sessions) == 1 and all("identity" in s.views for s in again.sessions.values()),
                   what="a session with its name prompt")
        s = next(iter(again.sessions.values()))
        assert room.open_trainer(s, "not-the-token-at-all-0000") is False
        assert room.open_trainer(s, token) is True                # the old page's token still opens it
    finally:
        c.close()
    renewed = app_factory(class_db=db, trainer_token=TOKEN)       # a new token replaces it
    assert renewed.classroom.trainer_token == TOKEN
    with Gradebook(db) as book:
        assert book.settings.get("trainer_token_sha256") == hashlib.sha256(TOKEN.encode()).hexdigest()


def test_pushed_settings_outlive_a_restart(app_factory, tmp_path: Path) -> None:
    """A pushed exercise and 'Hide distance' were gone after a restart unless the server was
    started with --exercise again."""
    db = tmp_path / "class.sqlite3"
    first = app_factory(class_db=db, trainer_token=TOKEN)
    assert first.classroom.exercise is None
    first.classroom.push_settings("mystery", None, hide_distance="hidden", auto_touch=True)
    first.stop()
    again = app_factory(class_db=db, trainer_token=TOKEN)
    room = again.classroom
    assert room.exercise == "mystery" and room.distance_aids == "hidden" and room.auto_touch is True
    c = DrainingClient(again.port)
    try:
        s = _join(again, c, "Cleo")
        assert s.hide_distance and s.workflow.hide_truth and s.controller.mounted_tool.key.startswith("mystery")
        assert s.rules.auto_touch_allowed and not s.rules.distance_locked     # as pushed, not the defaults
    finally:
        c.close()
    room.push_settings(None, None, hide_distance=False)       # free practice again: also kept
    again.stop()
    third = app_factory(class_db=db, trainer_token=TOKEN)
    assert third.classroom.exercise is None and third.classroom.distance_aids == "shown"
