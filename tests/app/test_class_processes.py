"""Two server processes of one class on one gradebook (``tcp-pendant --workers``): each is a
``PendantApp`` with its own gradebook connection and its own ``ClassRoom.holder``, as two
processes have; the heartbeat is called by the test (``ClassRoom.beat``) instead of waiting
for its thread."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parents[1] / "calibrate"))
from guiclick import choose, click  # noqa: E402
from wsclient import DrainingClient, wait_until  # noqa: E402

from tcp_pendant.classroom.names import TraineeNameError

TOKEN = "trainer-token-for-tests-0001"


def _session(app, client_count: int = 1):
    wait_until(lambda: len(app.sessions) >= client_count
               and all("identity" in s.views for s in app.sessions.values()), what="a session with its name prompt")
    return list(app.sessions.values())[client_count - 1]


def _join(s, name: str, key: str = ""):
    prompt = s.views["identity"]
    choose(prompt.name_field, name, s.client)
    choose(prompt.key_field, key, s.client)
    click(prompt.start, s.client)
    return prompt


def _key(session) -> str:
    html = session.views["identity"].key_html.content
    return html.split('data-tcp-pendant-key="', 1)[1].split('"', 1)[0]


@pytest.fixture
def two(app_factory, tmp_path: Path):
    """Two server 'processes' of one class: (a, b), one gradebook file."""
    db = tmp_path / "class.sqlite3"
    a = app_factory(class_db=db, trainer_token=TOKEN, seed=1, presence_poll_s=3600.0)
    b = app_factory(class_db=db, trainer_token=TOKEN, seed=2, presence_poll_s=3600.0)
    assert a.classroom.holder != b.classroom.holder
    return a, b


def test_a_name_connected_on_one_process_is_refused_on_the_other_and_its_browser_moves(two) -> None:
    a, b = two
    ca, cb, cb2 = DrainingClient(a.port), None, None
    try:
        sa = _session(a)
        assert _join(sa, "Anna").name == "Anna"
        key = _key(sa)
        cb = DrainingClient(b.port)
        sb = _session(b)
        prompt = _join(sb, "Anna")                       # another browser: no key
        assert prompt.name is None
        assert "Anna is already connected in another browser" in prompt.message.content
        with pytest.raises(TraineeNameError, match="already connected in another browser"):
            b.classroom.named(sb, "Anna", None)
        # both processes list her as connected: the trainer's table on B shows A's row
        b.classroom.beat()
        assert a.classroom.connected_names() == b.classroom.connected_names() == ["Anna"]
        assert [(r.name, r.connected) for r in b.classroom.trainee_statuses()] == [("Anna", True)]
        assert b.gradebook.presence_holder("Anna") == a.classroom.holder
        # the same browser (its key) on B takes the name; A's tab returns to the welcome window
        cb2 = DrainingClient(b.port)
        sb2 = _session(b, 2)
        assert _join(sb2, "Anna", key).name == "Anna"
        assert b.gradebook.presence_holder("Anna") == b.classroom.holder
        a.classroom.beat()
        wait_until(lambda: "joined from another tab" in sa.views["identity"].message.content,
                   what="A's tab back at the welcome window")          # reopen sets the message last
        assert sa.views["identity"].name is None
        assert a.classroom.connected_names() == ["Anna"]
        assert [r.name for r in a.classroom.trainee_statuses() if r.connected] == ["Anna"]
        # the trainer releases her on A: her browser on B leaves at B's next beat
        assert "Released Anna and its browser left the class" in a.classroom.release("Anna")
        b.classroom.beat()
        wait_until(lambda: "The trainer released the name Anna" in sb2.views["identity"].message.content,
                   what="B's browser back at the welcome window on the release")
        assert sb2.views["identity"].name is None
        assert a.classroom.connected_names() == b.classroom.connected_names() == []
    finally:
        for c in (ca, cb, cb2):
            if c is not None:
                c.close()


def test_a_reconnect_landing_on_the_other_process_resumes_the_calibration(two) -> None:
    a, b = two
    ca = DrainingClient(a.port)
    try:
        sa = _session(a)
        _join(sa, "Anna")
        key = _key(sa)
        cal = sa.views["calibrate"]
        choose(cal.option_widgets["n_points"], 5, sa.client)
        click(cal.start, sa.client)
        for _ in range(3):
            click(cal.steps.auto_touch, sa.client)
        before = sa.workflow.wizard
        poses = {k: p.T_world_flange_m.copy() for k, p in before.recorded_poses.items()}
        (cid,) = [r.calibration_id for r in a.gradebook.grades(include_in_progress=True)]
    finally:
        ca.close()                                   # the browser's connection drops ...
    wait_until(lambda: a.classroom.connected_names() == [], what="A noticing the disconnect")
    cb = DrainingClient(b.port)                       # ... and its reconnect lands on B
    try:
        sb = _session(b)
        assert _join(sb, "Anna", key).name == "Anna"
        wf = sb.workflow
        w = wf.wizard
        assert wf.is_open and w.kind == "xyz4" and (w.step_index, w.n_steps) == (3, 5)
        assert sorted(w.recorded_poses) == sorted(poses)
        for k, T in poses.items():
            np.testing.assert_array_equal(w.recorded_poses[k].T_world_flange_m, T)
        for _ in range(2):                           # the touches land in the same calibration
            click(sb.views["calibrate"].steps.auto_touch, sb.client)
        assert wf.result is not None
        rows = a.gradebook.grades()                   # A's connection sees B's writes
        assert [(r.calibration_id, r.trainee, r.touches, r.status) for r in rows] == [(cid, "Anna", 5, "finished")]
    finally:
        cb.close()


def test_a_push_on_one_process_reaches_the_trainees_of_the_other(two) -> None:
    a, b = two
    cb = DrainingClient(b.port)
    try:
        sb = _session(b)
        _join(sb, "Ben")
        assert not sb.rules.distance_locked and not sb.hide_distance       # free practice
        assert a.classroom.push_settings(None, None, hide_distance="locked") == 0   # nobody on A
        b.classroom.beat()
        wait_until(lambda: sb.rules.distance_locked and sb.hide_distance, what="the push applied on B")
        assert b.classroom.distance_aids == "locked"
    finally:
        cb.close()


def test_a_message_and_a_brief_sent_on_one_process_reach_the_trainees_of_the_other(two) -> None:
    a, b = two
    cb = DrainingClient(b.port)
    try:
        sb = _session(b)
        _join(sb, "Ben")
        a.classroom.beat()                                  # A learns who is connected on B
        assert a.classroom.connected_names() == ["Ben"]
        assert a.classroom.send_message("Stop jogging, look at the projector.") == "Sent to 1 trainee."
        assert a.classroom.send_message("Ben, check your tool.", to="Ben") == "Sent to Ben."
        a.classroom.push_brief("Calibrate the TCP first.", "xyz4", 6)
        b.classroom.beat()
        wait_until(lambda: [m.text for m in sb.messages] == ["Stop jogging, look at the projector.",
                                                            "Ben, check your tool."],
                   what="both messages shown on B")
        wait_until(lambda: sb.rules.instructions == "Calibrate the TCP first.", what="the brief on B")
        assert sb.rules.allowed_methods == ("xyz4",) and sb.rules.min_touches == 6
    finally:
        cb.close()


def test_the_trainer_resets_and_pushes_to_one_trainee_on_the_other_process(two) -> None:
    a, b = two
    cb = DrainingClient(b.port)
    try:
        sb = _session(b)
        _join(sb, "Ben")
        click(sb.views["calibrate"].start, sb.client)
        assert sb.workflow.is_open
        a.classroom.beat()
        assert "on another server process" in a.classroom.reset_wizard("Ben")
        assert "on another server process" in a.classroom.push_to("Ben", hide_distance="locked")
        b.classroom.beat()
        wait_until(lambda: not sb.workflow.is_open, what="Ben's wizard reset on B")
        wait_until(lambda: sb.rules.distance_locked and sb.hide_distance, what="the push to Ben on B")
        assert a.classroom.reset_wizard("Nobody") == "Nobody is not connected: there is no running wizard to reset."
    finally:
        cb.close()
