"""The trainer pushes "Hide distance" to every trainee, and a trainee in an
exercise sees no truth (no error against the true TOOL frame, no grade, no TRUE triad) while
the trainer's gradebook keeps it."""

from __future__ import annotations

from pathlib import Path

import pytest

from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until

from tcp_pendant.pendant.formatting import touch_indicator_markdown


def _class(app, n: int) -> tuple[list[DrainingClient], list]:
    clients = []
    for i in range(n):
        clients.append(DrainingClient(app.port))
        wait_until(lambda: len(app.sessions) == i + 1, what=f"session {i + 1}")
    wait_until(lambda: all("identity" in s.views for s in app.sessions.values()), what="name prompts")
    return clients, list(app.sessions.values())


def _name(session, name: str) -> None:
    p = session.views["identity"]
    choose(p.name_field, name, session.client)
    click(p.start, session.client)


def _trainer(session, token: str):
    q = session.views["identity"]
    choose(q.token_field, token, session.client)
    click(q.open_trainer, session.client)
    return session.views["trainer"]


def test_hide_distance_pushed_to_every_trainee_and_to_later_ones(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="trainer-token-of-16")
    clients, (anna, ben, trainer) = _class(app, 3)
    try:
        _name(anna, "Anna")
        _name(ben, "Ben")
        ben.set_hide_distance(True)                 # Ben's own choice, before the push
        view = _trainer(trainer, "trainer-token-of-16")
        choose(view.hide_distance, "on", trainer.client)
        click(view.push, trainer.client)
        assert anna.hide_distance and ben.hide_distance and not trainer.hide_distance
        assert "2 trainees" in view.push_md.content
        # the trainee's own checkbox and readout follow (the session command's change signal)
        panel = anna.views["pendant"]
        assert panel.hide_distance.value is True
        touch = anna.pose_state().touch
        assert panel.touch_md.content == touch_indicator_markdown(touch, hide_distance=True)
        assert f"{touch.distance_mm:.2f} mm" not in panel.touch_md.content
        # "(keep)" keeps it; "off" shows the distance again
        choose(view.hide_distance, "(keep)", trainer.client)
        click(view.push, trainer.client)
        assert anna.hide_distance and ben.hide_distance
        choose(view.hide_distance, "off", trainer.client)
        click(view.push, trainer.client)
        assert not anna.hide_distance and not ben.hide_distance and panel.hide_distance.value is False
        assert f"{touch.distance_mm:.2f} mm" in panel.touch_md.content
        # a trainee who names themselves after a push gets the pushed setting
        choose(view.hide_distance, "on", trainer.client)
        click(view.push, trainer.client)
        clients.append(DrainingClient(app.port))
        wait_until(lambda: len(app.sessions) == 4 and "identity" in list(app.sessions.values())[-1].views,
                   what="a late trainee")
        late = list(app.sessions.values())[-1]
        assert not late.hide_distance
        _name(late, "Cleo")
        assert late.hide_distance
    finally:
        for c in clients:
            c.close()


def _finish_xyz4(session) -> None:
    cal = session.views["calibrate"]
    click(cal.start, session.client)
    for _ in range(8):
        if cal.workflow.result is not None:
            return
        click(cal.steps.auto_touch, session.client)
    assert cal.workflow.result is not None, "the 4-point wizard did not finish"


def test_an_exercise_shows_the_trainee_no_truth_but_the_gradebook_keeps_it(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="trainer-token-of-16",
                      exercise="mystery", exercise_seed=3)
    clients, (anna, trainer) = _class(app, 2)
    try:
        _name(anna, "Anna")
        view = _trainer(trainer, "trainer-token-of-16")
        choose(view.auto_touch, "allowed", trainer.client)     # an exercise starts with Auto-touch off
        click(view.push, trainer.client)
        _finish_xyz4(anna)
        cal = anna.views["calibrate"]
        result, scene = cal.result, cal.scene
        assert cal.workflow.truth() is not None                 # the workflow knows it (training mode) ...
        assert result.folder.visible and not result.truth_md.visible       # ... the trainee does not see it
        assert not scene.true_tool.visible and not scene.true_label.visible
        assert scene.computed.visible                           # the computed triad is still shown
        row = app.gradebook.grades.rows()[0]                    # the trainer's gradebook has the error
        assert row.position_error_mm == pytest.approx(cal.workflow.truth().position_error_mm)
        assert row.grade
    finally:
        for c in clients:
            c.close()


def test_free_practice_shows_the_truth_and_a_pushed_exercise_hides_it(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="trainer-token-of-16")
    clients, (anna, trainer) = _class(app, 2)
    try:
        _name(anna, "Anna")
        _finish_xyz4(anna)
        cal = anna.views["calibrate"]
        assert cal.result.truth_md.visible and cal.scene.true_tool.visible     # training: the answer
        assert "true TOOL frame" in cal.result.truth_md.content
        view = _trainer(trainer, "trainer-token-of-16")
        choose(view.exercise, "Mystery tool", trainer.client)
        choose(view.auto_touch, "allowed", trainer.client)      # an exercise starts with Auto-touch off
        click(view.push, trainer.client)
        _finish_xyz4(anna)                                       # a new calibration in the exercise
        assert not cal.result.truth_md.visible and not cal.scene.true_tool.visible
        choose(view.exercise, "Free practice", trainer.client)
        click(view.push, trainer.client)
        assert cal.result.truth_md.visible and cal.scene.true_tool.visible
    finally:
        for c in clients:
            c.close()


def test_an_exercise_hides_and_locks_the_distance_aids_until_the_trainer_unlocks_them(
        app_factory, tmp_path: Path) -> None:
    """In an exercise the distance, the Δ line and the close-up are off from the start; a
    browser that unticks "Hide distance" anyway is refused by the server (the checkbox is
    disabled, but a browser can send anything); the trainer unlocks and locks them again."""
    from tcp_pendant.calibrate.pendant_rules import DISTANCE_LOCKED, RuleRefusal

    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="trainer-token-tok-1", exercise="mystery")
    clients, (anna, trainer) = _class(app, 2)
    try:
        _name(anna, "Anna")
        panel = anna.views["pendant"]
        touch = anna.pose_state().touch
        assert anna.hide_distance and anna.rules.distance_locked
        assert panel.hide_distance.value is True and panel.hide_distance.disabled is True
        assert "Δ" not in panel.touch_md.content and f"{touch.distance_mm:.2f}" not in panel.touch_md.content
        notes: list[str] = []
        anna.notify = lambda title, body, **kw: notes.append(body)          # type: ignore[method-assign]
        choose(panel.hide_distance, False, anna.client)                     # a hostile browser unticks it
        assert anna.hide_distance and panel.hide_distance.value is True
        assert notes == [DISTANCE_LOCKED]
        with pytest.raises(RuleRefusal, match="locked the distance aids"):
            anna.set_hide_distance(False)
        view = _trainer(trainer, "trainer-token-tok-1")
        choose(view.hide_distance, "on", trainer.client)                    # hidden, but unlocked
        click(view.push, trainer.client)
        assert "distance aids trainee's choice" in view.push_md.content
        assert anna.hide_distance and panel.hide_distance.disabled is False
        choose(panel.hide_distance, False, anna.client)                     # now the trainee may
        assert not anna.hide_distance and "Δ" in panel.touch_md.content
        choose(view.hide_distance, "on, locked", trainer.client)
        click(view.push, trainer.client)
        assert anna.hide_distance and panel.hide_distance.disabled is True
        assert "distance aids locked off" in view.push_md.content
    finally:
        for c in clients:
            c.close()


def test_auto_touch_is_refused_in_an_exercise_unless_the_trainer_allows_it(app_factory, tmp_path: Path) -> None:
    from tcp_pendant.calibrate.workflow import AutoTouchRequest
    from tcp_pendant.calibrate.pendant_rules import AUTO_TOUCH_REFUSED, RuleRefusal

    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="trainer-token-tok-1", exercise="mystery")
    clients, (anna, trainer) = _class(app, 2)
    try:
        _name(anna, "Anna")
        cal = anna.views["calibrate"]
        click(cal.start, anna.client)
        wf = cal.workflow
        assert not cal.steps.auto_folder.visible                             # not offered ...
        notes: list[str] = []
        anna.notify = lambda title, body, **kw: notes.append(body)          # type: ignore[method-assign]
        click(cal.steps.auto_touch, anna.client)                            # ... and refused when sent
        assert notes == [AUTO_TOUCH_REFUSED] and not wf.wizard.recorded_poses
        with pytest.raises(RuleRefusal, match="Auto-touch is off in this exercise"):
            wf.auto_touch(AutoTouchRequest())
        view = _trainer(trainer, "trainer-token-tok-1")
        choose(view.auto_touch, "allowed", trainer.client)
        click(view.push, trainer.client)
        assert cal.steps.auto_folder.visible
        click(cal.steps.auto_touch, anna.client)
        assert len(wf.wizard.recorded_poses) == 1
    finally:
        for c in clients:
            c.close()


def test_free_practice_keeps_auto_touch_and_the_trainees_own_distance_choice(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="trainer-token-tok-1")
    clients, (anna,) = _class(app, 1)
    try:
        _name(anna, "Anna")
        panel = anna.views["pendant"]
        assert not anna.hide_distance and panel.hide_distance.disabled is False
        choose(panel.hide_distance, True, anna.client)
        choose(panel.hide_distance, False, anna.client)
        assert not anna.hide_distance
        cal = anna.views["calibrate"]
        click(cal.start, anna.client)
        assert cal.steps.auto_folder.visible
        click(cal.steps.auto_touch, anna.client)
        assert len(cal.workflow.wizard.recorded_poses) == 1
    finally:
        for c in clients:
            c.close()


def test_the_mounted_tool_lock_follows_the_trainers_exercise(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="trainer-token-of-16",
                      exercise="mystery", exercise_seed=3)
    clients, (anna,) = _class(app, 1)
    try:
        _name(anna, "Anna")
        mystery, tools = anna.controller.mounted_tool, anna.views["tools"]
        assert anna.tools.exercise_tool is mystery and tools.mounted.disabled and tools.mounted_lock_md.visible
        app.classroom.push_settings("mystery", "torch")           # a tool pushed in the exercise: ignored
        assert anna.controller.mounted_tool is mystery
        app.classroom.push_to("Anna", tool_key="torch", hide_distance="shown")
        wait_until(lambda: not anna.hide_distance, what="the push to Anna, applied on her loop")
        assert anna.controller.mounted_tool is mystery
        app.classroom.push_settings(None, None)                   # free practice: the lock goes
        assert anna.tools.exercise_tool is None and not tools.mounted.disabled and not tools.mounted_lock_md.visible
        choose(tools.mounted, "Bent-neck welding torch", anna.client)
        assert anna.controller.mounted_tool.key == "torch"
        app.classroom.push_settings("mystery", None)              # the exercise again: its tool, locked
        assert anna.controller.mounted_tool.key == mystery.key and tools.mounted.disabled
        assert tools.mounted.value == mystery.label
    finally:
        for c in clients:
            c.close()
