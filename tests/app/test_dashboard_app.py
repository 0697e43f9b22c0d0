"""The trainer's dashboard in the app: the trainer's browser loses its pendant, the table comes
back from the gradebook after a restart (trainees not yet back listed as not connected, the
calibrations in progress listed), per-trainee reset and push touch that one trainee only, and
a calibration is replayed in 3D from the gradebook."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import numpy as np

from tcp_pendant.controller.kinematics import RobotKinematics

from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

TOKEN = "trainer-token-of-16"


def _connect(app, clients: list, n_before: int):
    clients.append(DrainingClient(app.port))
    wait_until(lambda: len(app.sessions) == n_before + 1 and "identity" in list(app.sessions.values())[-1].views,
               what="a session with its name prompt")
    return list(app.sessions.values())[-1]


def _join(session, name: str, key: str = ""):
    p = session.views["identity"]
    choose(p.name_field, name, session.client)
    choose(p.key_field, key, session.client)
    click(p.start, session.client)
    assert p.name == name
    return p


def _key(prompt) -> str:
    m = re.fullmatch(r'<div hidden data-tcp-pendant-key="([A-Za-z0-9_-]+)"></div>', prompt.key_html.content)
    assert m is not None
    return m.group(1)


def _dashboard(session):
    q = session.views["identity"]
    choose(q.token_field, TOKEN, session.client)
    click(q.open_trainer, session.client)
    return session.views["trainer"]


def _touches(session, n: int) -> None:
    cal = session.views["calibrate"]
    if not cal.workflow.is_open:
        click(cal.start, session.client)                 # XYZ 4-point, the default
    for _ in range(n):
        if cal.workflow.result is not None:
            return
        click(cal.steps.auto_touch, session.client)


def test_the_dashboard_replaces_the_pendant_and_survives_a_restart(app_factory, tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    app = app_factory(class_db=db, trainer_token=TOKEN, seed=11)
    clients: list[DrainingClient] = []
    try:
        anna = _connect(app, clients, 0)
        key_anna = _key(_join(anna, "Anna"))
        ben = _connect(app, clients, 1)
        key_ben = _key(_join(ben, "Ben"))
        _touches(anna, 6)                                 # Anna finishes
        assert anna.workflow.result is not None and len(app.gradebook.grades.rows()) == 1
        _touches(ben, 2)                                  # Ben stays at step 3
        trainer = _connect(app, clients, 2)
        dash = _dashboard(trainer)
        assert set(trainer.views) == {"trainer", "tools"}          # no pendant left: the dashboard and its library
        assert trainer._subscribers == [dash.language.on_change, trainer.views["tools"].on_change, dash.on_change]
        assert [(r.name, r.connected, r.step, r.touches) for r in dash.rows] == \
            [("Anna", True, "result", 4), ("Ben", True, "Step 3 of 4", 2)]
        assert dash.rows[0].grade and dash.rows[0].position_error_mm is not None
        assert "Ben" in dash.runs_html.content
        assert dash.chart.data[0].tolist() == [1.0] and dash.chart.data[1][0] == dash.rows[0].position_error_mm
        assert dash.chart.legend == {"live": False}       # series names, no "--" values until hovered
    finally:
        for c in clients:
            c.close()
    app.stop()

    # the restart: the same gradebook, nobody connected yet
    app = app_factory(class_db=db, trainer_token=TOKEN, seed=11)
    clients = []
    try:
        trainer = _connect(app, clients, 0)
        dash = _dashboard(trainer)
        assert [(r.name, r.connected, r.method, r.step, r.touches) for r in dash.rows] == \
            [("Anna", False, "XYZ 4-point", "result", 4), ("Ben", False, "XYZ 4-point", "Step 3 of 4", 2)]
        assert dash.rows[0].grade and not any(r.stuck for r in dash.rows)
        runs = dash.runs_html.content
        assert "Ben" in runs and "3/4" in runs and "Anna" not in runs       # only Ben's is in progress
        ben = _connect(app, clients, 1)
        _join(ben, "Ben", key_ben)                        # Ben is back: his calibration with him, not 0 touches
        wait_until(lambda: dash.rows[1].connected, what="Ben connected on the dashboard")
        assert (dash.rows[1].step, dash.rows[1].touches) == ("Step 3 of 4", 2)
        assert not dash.rows[0].connected and key_anna
    finally:
        for c in clients:
            c.close()


def test_reset_and_push_act_on_the_chosen_trainee_only(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, seed=11)
    clients: list[DrainingClient] = []
    try:
        anna = _connect(app, clients, 0)
        _join(anna, "Anna")
        ben = _connect(app, clients, 1)
        _join(ben, "Ben")
        _touches(anna, 1)
        _touches(ben, 1)
        trainer = _connect(app, clients, 2)
        dash = _dashboard(trainer)
        # nobody chosen: nothing happens
        click(dash.reset, trainer.client)
        assert "Choose a trainee first" in dash.action_md.content and anna.workflow.is_open and ben.workflow.is_open
        choose(dash.trainee, "Anna", trainer.client)
        click(dash.reset, trainer.client)
        wait_until(lambda: not anna.workflow.is_open, what="Anna's wizard reset")
        assert ben.workflow.is_open and ben.workflow.wizard.step_index == 1        # Ben untouched
        statuses = {r.trainee: r.status for r in app.gradebook.grades.rows(include_in_progress=True)}
        assert statuses == {"Ben": "in_progress"}          # Anna's is cancelled in the gradebook
        with app.gradebook.store.read() as db:
            assert db.execute("SELECT status FROM calibrations ORDER BY id").fetchall() == [("cancelled",), ("in_progress",)]
        wait_until(lambda: dash.rows[0].step == "cancelled", what="the reset on the dashboard")
        # push the torch and hidden distances to Ben only
        tool_anna = anna.controller.mounted_tool.key
        choose(dash.trainee, "Ben", trainer.client)
        choose(dash.one_tool, "Bent-neck welding torch", trainer.client)
        choose(dash.one_hide_distance, "on", trainer.client)
        click(dash.push_one, trainer.client)
        wait_until(lambda: ben.controller.mounted_tool.key == "torch" and ben.hide_distance, what="Ben's push")
        assert "Pushed to Ben" in dash.action_md.content
        assert anna.controller.mounted_tool.key == tool_anna and not anna.hide_distance
        assert not trainer.hide_distance and trainer.controller.mounted_tool.key != "torch"
    finally:
        for c in clients:
            c.close()


def test_a_calibration_is_replayed_in_3d_from_the_gradebook(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, seed=11)
    clients: list[DrainingClient] = []
    try:
        anna = _connect(app, clients, 0)
        _join(anna, "Anna")
        trainer = _connect(app, clients, 1)
        dash = _dashboard(trainer)
        assert "No calibration finished yet" in dash.grades_md.content
        _touches(anna, 6)
        assert anna.workflow.result is not None
        wait_until(lambda: "| Anna |" in dash.grades_md.content, what="Anna's result in the gradebook table")
        choose(dash.trainee, "Anna", trainer.client)
        click(dash.replay_button, trainer.client)
        shown = dash.replay_scene.shown
        assert shown is not None and shown.trainee == "Anna" and len(shown.touches) == 4
        # the reference tip: where the true tip was at the touches, within Auto-touch's error of the real one
        np.testing.assert_allclose(shown.reference_world_m, app.reference_tip_m, atol=1.5e-3)
        np.testing.assert_allclose(shown.T_flange_tool_result_m[:3, 3] * 1000.0, anna.workflow.result.tcp_mm, atol=1e-6)
        handles = {h.name: h for h in dash.replay_scene.handles}
        assert {"/replay/touch_0", "/replay/touch_3", "/replay/approach", "/replay/reference", "/replay/result",
                "/replay/true"} <= set(handles)
        T0 = shown.touches[0].T_world_flange_m                 # the triad stands at the touch's flange pose
        np.testing.assert_allclose(handles["/replay/touch_0"].position, T0[:3, 3], atol=1e-9)
        np.testing.assert_allclose(handles["/replay/reference"].position, shown.reference_world_m, atol=1e-9)
        assert "4 touches" in dash.action_md.content and dash.close_replay.visible
        # the robot at each touch: posed at the joints the gradebook kept, its flange where the
        # touch's flange was (pinocchio on a model read afresh from the URDF); the reference tip's stand
        robot = dash.replay_scene.robot
        k = RobotKinematics.from_urdf(anna.controller.kinematics.urdf_path)
        assert dash.replay_touch.visible and dash.replay_touch.value.startswith("4: step 4")   # the last touch first
        assert robot is not None and robot.stand is not None
        for i, touch in enumerate(shown.touches):
            choose(dash.replay_touch, dash.replay_touch.options[i], trainer.client)
            wait_until(lambda: dash.replay_scene.touch_shown == i, what=f"the robot at touch {i + 1}")
            np.testing.assert_allclose(robot.posed_joints_deg, touch.joints_deg, atol=1e-12)
            flange = robot.link_frames[k.flange_link]
            T = k.T_world_flange(np.radians(touch.joints_deg))
            np.testing.assert_allclose(flange.position, T[:3, 3], atol=1e-9)
            np.testing.assert_allclose(flange.position, touch.T_world_flange_m[:3, 3], atol=1e-6)
        click(dash.close_replay, trainer.client)
        assert dash.replay_scene.handles == [] and not dash.close_replay.visible
        assert robot.link_frames == {} and robot.stand is None and not dash.replay_touch.visible
    finally:
        for c in clients:
            c.close()
