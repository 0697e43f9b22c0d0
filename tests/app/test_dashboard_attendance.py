"""Attendance on the trainer's dashboard in the app: the issue's class (ana finishes, ben is
stuck at step 2, chen joined and never started) shows ben stuck and chen idle; the trainer's
"Stuck after" and "Idle after" typed in the dashboard outlast a restart of the server."""

from __future__ import annotations

from pathlib import Path

import pytest

from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until

from tcp_pendant.classroom.dashboard_settings import IDLE_SETTING, STUCK_SETTING, kept_minutes

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

TOKEN = "trainer-token-attendance-1"


def _connect(app, clients: list, n_before: int):
    clients.append(DrainingClient(app.port))
    wait_until(lambda: len(app.sessions) == n_before + 1 and "identity" in list(app.sessions.values())[-1].views,
               what="a session with its name prompt")
    return list(app.sessions.values())[-1]


def _join(session, name: str) -> None:
    p = session.views["identity"]
    choose(p.name_field, name, session.client)
    click(p.start, session.client)
    assert p.name == name, p.message.content


def _dashboard(session):
    q = session.views["identity"]
    choose(q.token_field, TOKEN, session.client)
    click(q.open_trainer, session.client)
    return session.views["trainer"]


def test_stuck_and_idle_and_the_thresholds_outlast_a_restart(app_factory, tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    app = app_factory(class_db=db, trainer_token=TOKEN, seed=11)
    clients: list[DrainingClient] = []
    try:
        for i, name in enumerate(("ana", "ben", "chen")):
            s = _connect(app, clients, i)
            _join(s, name)
            cal = s.views["calibrate"]
            if name != "chen":
                click(cal.start, s.client)
                for _ in range(6 if name == "ana" else 1):
                    if cal.workflow.result is not None:
                        break
                    click(cal.steps.auto_touch, s.client)
        with app.gradebook.store.write() as db_:       # 12 minutes ago: ben's step and touch, everyone's join
            db_.execute("UPDATE run_states SET step_since = strftime('%Y-%m-%dT%H:%M:%f+00:00', 'now', '-12 minutes')")
            db_.execute("UPDATE touches SET recorded_at = strftime('%Y-%m-%dT%H:%M:%f+00:00', 'now', '-12 minutes')")
            db_.execute("UPDATE sessions SET started_at = strftime('%Y-%m-%dT%H:%M:%f+00:00', 'now', '-12 minutes')")
        trainer = _connect(app, clients, 3)
        dash = _dashboard(trainer)
        assert [(r.name, r.stuck, r.idle) for r in dash.rows] == [("ana", False, False),
                                                                  ("ben", True, False), ("chen", False, True)]
        assert 'class="idle"' in dash.table_html.content and "◔ chen" in dash.table_html.content
        choose(dash.stuck_min, 15.0, trainer.client)     # the trainer allows 15 min: ben is no longer stuck
        choose(dash.idle_min, 20.0, trainer.client)      # ... and 20 min of idling
        assert [(r.stuck, r.idle) for r in dash.rows] == [(False, False)] * 3
        assert kept_minutes(app.gradebook.settings, STUCK_SETTING) == 15.0
        assert kept_minutes(app.gradebook.settings, IDLE_SETTING) == 20.0
    finally:
        for c in clients:
            c.close()
    app.stop()

    again = app_factory(class_db=db, trainer_token=TOKEN, seed=11)     # the restart
    clients = []
    try:
        dash = _dashboard(_connect(again, clients, 0))
        assert (dash.stuck_min.value, dash.idle_min.value) == (15.0, 20.0)     # not back to 5
        assert dash.stuck_after_s() == 900.0 and dash.idle_after_s() == 1200.0
    finally:
        for c in clients:
            c.close()
