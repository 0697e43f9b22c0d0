"""Two server processes of one class on one gradebook (``tcp-pendant --workers``): each is a
``PendantApp`` with its own gradebook connection and its own ``ClassRoom.holder``, as two
processes have; the heartbeat is called by the test (``ClassRoom.beat``) instead of waiting
for its thread. Each browser is a real websocket client from 127.0.0.1 (one source address for
the trainer token's lockout)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until

from tcp_pendant.classroom.names import TraineeNameError
from tcp_pendant.classroom.trainer_token import TrainerTokenLocked
from tcp_pendant.text_escape import escape_markdown, escape_markdown_lines

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

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
        assert b.gradebook.presence.holder("Anna") == a.classroom.holder
        # the same browser (its key) on B takes the name; A's tab returns to the welcome window
        cb2 = DrainingClient(b.port)
        sb2 = _session(b, 2)
        assert _join(sb2, "Anna", key).name == "Anna"
        assert b.gradebook.presence.holder("Anna") == b.classroom.holder
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


def test_a_name_with_invisible_marks_is_refused_on_the_other_process(two) -> None:
    """Issue 42: "Alice" with a default-ignorable mark is refused while Alice is connected on
    the other process, and a Persian name with and without its zero-width non-joiner (kept in
    the name, dropped when names are compared) is one trainee on both processes."""
    a, b = two
    ca, cb = DrainingClient(a.port), None
    try:
        sa = _session(a)
        assert _join(sa, "Alice").name == "Alice"
        cb = DrainingClient(b.port)
        sb = _session(b)
        for invisible in ("Alice\ufe0f", "Al\ufe00ice", "Al\U000e0100ice", "Alice\u180b", "Alice\u17b4",
                          "Al\u17b5ice"):
            prompt = _join(sb, invisible)
            mark = next(c for c in invisible if c not in "Alice")
            assert prompt.name is None and escape_markdown(f"U+{ord(mark):04X}") in prompt.message.content
            with pytest.raises(TraineeNameError, match=f"U\\+{ord(mark):04X}"):
                b.classroom.named(sb, invisible, None)
        joined, bare = "\u0639\u0644\u06cc\u200c\u0627\u06a9\u0628\u0631", "\u0639\u0644\u06cc\u0627\u06a9\u0628\u0631"
        assert _join(sb, joined).name == joined
        with pytest.raises(TraineeNameError, match=f"^{bare} looks like {joined}, a name already in this class"):
            a.classroom.named(sa, bare, None)
        assert a.gradebook.trainees.names() == ["Alice", joined]
        b.classroom.beat()
        assert sorted(a.classroom.connected_names()) == sorted(b.classroom.connected_names()) == ["Alice", joined]
    finally:
        for c in (ca, cb):
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
        (cid,) = [r.calibration_id for r in a.gradebook.grades.rows(include_in_progress=True)]
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
        rows = a.gradebook.grades.rows()              # A's connection sees B's writes
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


def test_the_token_lockout_holds_on_the_other_process(two) -> None:
    """Five wrong tokens on A lock the address out on B too (a reconnect gains no tries); the
    right token on B after the window opens the trainer view and forgives the address."""
    a, b = two
    now = [5000.0]
    a.classroom.clock = b.classroom.clock = lambda: now[0]
    ca, cb = DrainingClient(a.port), None
    try:
        sa = _session(a)
        for i in range(5):
            assert a.classroom.open_trainer(sa, f"wrong-guess-{i:02d}-abcdef") is False
        with pytest.raises(TrainerTokenLocked, match=r"try again in 1 s\."):
            a.classroom.open_trainer(sa, TOKEN)
        cb = DrainingClient(b.port)                  # the same address, on the other process
        sb = _session(b)
        prompt = sb.views["identity"]
        choose(prompt.token_field, TOKEN, sb.client)
        click(prompt.open_trainer, sb.client)
        assert prompt.message.content.startswith(escape_markdown(
            "⚠ Too many wrong trainer tokens from this browser: try again in 1 s."))
        assert b.classroom.dashboards.views == {}
        now[0] += 1.5
        assert b.classroom.open_trainer(sb, "wrong-guess-05-abcdef") is False    # the 6th: 2 s
        with pytest.raises(TrainerTokenLocked, match=r"try again in 2 s\."):
            b.classroom.open_trainer(sb, TOKEN)
        with pytest.raises(TrainerTokenLocked, match=r"try again in 2 s\."):
            a.classroom.open_trainer(sa, TOKEN)
        now[0] += 2.5
        assert b.classroom.open_trainer(sb, TOKEN) is True
        assert "trainer" in sb.views
        assert a.classroom.open_trainer(sa, "wrong-guess-06-abcdef") is False    # forgiven: try 1, no lock
        assert a.classroom.open_trainer(sa, TOKEN) is True
    finally:
        for c in (ca, cb):
            if c is not None:
                c.close()


def test_a_message_follows_its_trainee_to_the_other_process_until_dismissed(two) -> None:
    a, b = two
    ca, cb = DrainingClient(a.port), None
    try:
        sa = _session(a)
        _join(sa, "Anna")
        key = _key(sa)
        text = "Anna: *check* <b>the tool</b>"
        assert a.classroom.send_message("Everyone: look at the projector.") == "Sent to 1 trainee."
        assert a.classroom.send_message(text, to="Anna") == "Sent to Anna."
        wait_until(lambda: len(sa.messages) == 2, what="both messages on A")
        box = sa.views["notices"]
        wait_until(lambda: box.dismiss.visible, what="A's message box")
        click(box.dismiss, sa.client)                 # the message to the class, dismissed on A
        wait_until(lambda: [m.text for m in sa.messages] == [text], what="the dismissal on A")
    finally:
        ca.close()                                    # the browser's connection drops ...
    wait_until(lambda: a.classroom.connected_names() == [], what="A noticing the disconnect")
    try:
        cb = DrainingClient(b.port)                   # ... and its reconnect lands on B
        sb = _session(b)
        assert _join(sb, "Anna", key).name == "Anna"
        assert [(m.text, m.to) for m in sb.messages] == [(text, "Anna")]     # undismissed: shown again
        box = sb.views["notices"]
        wait_until(lambda: box.message_md.visible, what="B's message box")
        assert escape_markdown_lines(text) in box.message_md.content and "<b>" not in box.message_md.content
        a.classroom.beat()                            # the trainer, on A, sends her another
        assert a.classroom.send_message("Anna, come to the front.", to="Anna") == "Sent to Anna."
        b.classroom.beat()                            # B's heartbeat delivers it
        wait_until(lambda: [m.text for m in sb.messages] == [text, "Anna, come to the front."],
                   what="the new message on B")
        click(box.dismiss, sb.client)
        wait_until(lambda: [m.text for m in sb.messages] == ["Anna, come to the front."], what="the dismissal on B")
        assert [row[3] for row in a.gradebook.messages.waiting(["Anna"])["Anna"]] == ["Anna, come to the front."]
    finally:
        if cb is not None:
            cb.close()


def test_who_left_on_one_process_is_listed_the_same_on_the_other(two) -> None:
    a, b = two
    cb = DrainingClient(b.port)
    try:
        sb = _session(b)
        _join(sb, "Ben")
        cal = sb.views["calibrate"]
        click(cal.start, sb.client)
        click(cal.steps.auto_touch, sb.client)
        b.classroom.beat()                            # B writes Ben's row, A reads it
        a.classroom.beat()
        assert [(r.name, r.connected, r.touches) for r in a.classroom.trainee_statuses()] == [("Ben", True, 1)]
    finally:
        cb.close()
    wait_until(lambda: b.classroom.connected_names() == [], what="B noticing the disconnect")
    a.classroom.beat()
    left = b.classroom.trainee_statuses()
    assert [(r.name, r.connected, r.touches, r.step) for r in left] == [("Ben", False, 1, "Step 2 of 4")]
    assert a.classroom.trainee_statuses() == left
    assert a.classroom.connected_names() == []
    # the trainer on A may write to him: it waits until he joins again
    assert a.classroom.send_message("Ben, finish your XYZ.", to="Ben") == \
        "Ben is not connected: the message waits until they join again."
