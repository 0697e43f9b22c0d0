"""The classroom wired into the app: the "Your name" prompt, the gradebook recorder,
the trainer view behind its token, the mystery exercise and the settings the trainer pushes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from support.guiclick import choose, click, upload
from support.wsclient import DrainingClient, RecordingClient, wait_until

from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.mystery import true_frame
from tcp_pendant.text_escape import escape_markdown


def _session(app, client: DrainingClient):
    wait_until(lambda: len(app.sessions) >= 1 and all("identity" in s.views for s in app.sessions.values()),
               what="a session with its name prompt")
    return next(iter(app.sessions.values()))


def _browser(session):
    return session.client


def test_name_prompt_records_the_trainee_and_escapes_the_name(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="secret-token-1-of-16")
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
        with Gradebook(tmp_path / "class.sqlite3") as book, book.store.read() as db:
            assert db.execute("SELECT name FROM trainees").fetchall() == [("*Anna* <b>x</b>",)]
            assert db.execute("SELECT mode, ended_at FROM sessions").fetchall() == [("per-browser", None)]
    finally:
        c.close()
    wait_until(lambda: app.classroom.trainee_statuses()[0].connected is False, what="the session closed")
    with Gradebook(tmp_path / "class.sqlite3") as book, book.store.read() as db:
        assert db.execute("SELECT ended_at FROM sessions").fetchone()[0] is not None


def test_a_trainee_leaving_while_the_table_is_read_is_in_it_connected_or_left(app_factory, tmp_path: Path) -> None:
    """The dashboard's table reads the connected trainees and who left at two moments: a
    trainee who leaves in between (here: right after the departures were read) is in one of
    the two lists, never missing from both."""
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="secret-token-1-of-16")
    c = DrainingClient(app.port)
    try:
        s = _session(app, c)
        _join(s, "Anna")
        assert [row.name for row in app.classroom.trainee_statuses()] == ["Anna"]
        room = app.classroom
        real = room.gradebook.presence.departed

        def departed_then_anna_leaves(*args, **kwargs):
            rows = real(*args, **kwargs)
            room.gradebook.presence.departed = real
            room.detach(s)                         # Anna's browser closes just after the read
            return rows

        room.gradebook.presence.departed = departed_then_anna_leaves
        rows = room.trainee_statuses()
        assert [row.name for row in rows] == ["Anna"], rows
        assert [(row.name, row.connected) for row in room.trainee_statuses()] == [("Anna", False)]
    finally:
        c.close()


def test_wizard_events_reach_the_gradebook_through_the_gui(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="secret-token-1-of-16")
    c = DrainingClient(app.port)
    try:
        s = _session(app, c)
        _join(s, "Bo")
        cal = s.views["calibrate"]
        click(cal.start, _browser(s))                         # XYZ 4-point, the default
        for _ in range(4):
            click(cal.steps.auto_touch, _browser(s))
        assert cal.workflow.result is not None
        rows = app.gradebook.grades.rows()
        assert len(rows) == 1 and rows[0].trainee == "Bo" and rows[0].auto == 4 and rows[0].hand == 0
        assert rows[0].grade == cal.workflow.truth().grade
        assert app.classroom.trainee_statuses()[0].step == "result"
    finally:
        c.close()


def test_trainer_view_needs_the_token_and_shows_the_class_escaped(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="secret-token-1-of-16")
    a = DrainingClient(app.port)
    wait_until(lambda: len(app.sessions) == 1, what="trainee session")
    t = DrainingClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 2 and all("identity" in s.views for s in app.sessions.values()),
                   what="two sessions")
        trainee, trainer = list(app.sessions.values())
        p = trainee.views["identity"]
        choose(p.name_field, "|Eve| <i>x</i>", trainee.client)
        click(p.start, trainee.client)
        q = trainer.views["identity"]
        choose(q.token_field, "secret-token-2", trainer.client)
        click(q.open_trainer, trainer.client)
        assert "trainer" not in trainer.views and "not right" in q.message.content
        choose(q.token_field, "secret-token-1-of-16", trainer.client)
        click(q.open_trainer, trainer.client)
        view = trainer.views["trainer"]
        html = view.table_html.content
        assert "|Eve| &lt;i&gt;x&lt;/i&gt;" in html and "<i>" not in html       # escaped: shown, not run
        assert [(r.name, r.connected, r.touches) for r in view.rows] == [("|Eve| <i>x</i>", True, 0)]
        # a touch by the trainee updates the trainer's table (throttled: within half a second)
        cal = trainee.views["calibrate"]
        click(cal.start, trainee.client)
        click(cal.steps.auto_touch, trainee.client)
        wait_until(lambda: view.rows[0].touches == 1 and view.rows[0].crashes == 0
                   and view.rows[0].step == "Step 2 of 4", what="the touch in the trainer's table")
        # push the torch to every trainee
        choose(view.tool, "Bent-neck welding torch", trainer.client)
        click(view.push, trainer.client)
        assert trainee.controller.mounted_tool.key == "torch"
        assert "1 trainee" in view.push_md.content
        # the pointer's touch measured another tool: the trainee calibrates the torch anew and
        # finishes; the trainer grades the trainee's exported record by its record id
        click(cal.start, trainee.client)
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
        assert [r.tool_key for r in app.gradebook.grades.rows()] == ["torch"]
    finally:
        a.close()
        t.close()


def test_mystery_exercise_mounts_a_tool_per_trainee_and_grades_against_it(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="secret-token-1-of-16",
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
        row = app.gradebook.grades.rows()[0]
        assert row.exercise_id == "mystery" and row.tool_key == k1.key
        truth = app.gradebook.records.truth(row.calibration_id)
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


# ------------------------------------------------------------------- names and the exercise seed

def _sessions(app, n: int) -> list:
    wait_until(lambda: len(app.sessions) == n and all("identity" in s.views for s in app.sessions.values()),
               what=f"{n} sessions with their name prompts")
    return list(app.sessions.values())


def _join(session, name: str, key: str = "") -> object:
    p = session.views["identity"]
    choose(p.name_field, name, session.client)
    choose(p.key_field, key, session.client)
    click(p.start, session.client)
    return p


def _issued_key(prompt) -> str:
    import re

    assert prompt.key_html is not None, "no browser key handed to the page"
    m = re.fullmatch(r'<div hidden data-tcp-pendant-key="([A-Za-z0-9_-]+)"></div>', prompt.key_html.content)
    assert m is not None, prompt.key_html.content
    return m.group(1)


def test_a_connected_name_and_its_look_alikes_are_refused_until_the_trainer_releases_it(
        app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="trainer-token-tok-1")
    clients = [DrainingClient(app.port)]
    _sessions(app, 1)
    clients.append(DrainingClient(app.port))
    _sessions(app, 2)
    clients.append(DrainingClient(app.port))
    try:
        alice, other, trainer = _sessions(app, 3)
        pa = _join(alice, "Alice")
        assert pa.name == "Alice"
        key = _issued_key(pa)
        po = _join(other, "Alice")
        assert po.name is None
        assert ("Alice is already connected in another browser; pick another name or ask the trainer to "
                "release it") in po.message.content
        for look_alike in ("\u0410lice", "ＡＬＩＣＥ", "A\u013aice"):
            _join(other, look_alike)
            assert po.name is None and "looks like Alice, a name already in this class" in po.message.content
        for invisible in ("Alice\ufe0f", "Al\ufe00ice", "Al\U000e0100ice", "Alice\u180b", "Alice\u17b4", "Al\u17b5ice"):
            _join(other, invisible)                       # "Alice" on the screen: refused, naming the mark
            mark = next(c for c in invisible if c not in "Alice")
            assert po.name is None and escape_markdown(f"U+{ord(mark):04X}") in po.message.content
        assert [t.name for t in app.classroom.trainee_statuses()] == ["Alice"]
        # the trainer releases Alice: her browser goes back to the welcome window (its script told to forget)
        q = trainer.views["identity"]
        choose(q.token_field, "trainer-token-tok-1", trainer.client)
        click(q.open_trainer, trainer.client)
        view = trainer.views["trainer"]
        assert "Alice" in view.trainee.options
        choose(view.trainee, "Alice", trainer.client)
        click(view.release, trainer.client)
        assert "Released Alice" in view.action_md.content
        wait_until(lambda: pa.name is None and "released the name Alice" in pa.message.content,
                   what="Alice's welcome window again")
        assert pa.key_html is None and pa.marker_html.content == "<div hidden data-tcp-pendant-forget></div>"
        assert not app.gradebook.trainees.holds_key("Alice", key)
        # the released browser cannot take it straight back; another browser now can, with her records
        _join(alice, "Alice", key)
        assert pa.name is None and "released the name Alice from this browser" in pa.message.content
        _join(other, "Alice")
        assert po.name == "Alice" and _issued_key(po) != key
        with app.gradebook.store.read() as db:
            assert db.execute("SELECT COUNT(*) FROM trainees").fetchone()[0] == 1
            assert db.execute("SELECT COUNT(*), COUNT(ended_at) FROM sessions").fetchone() == (2, 1)
        # a name connected again is listed once, as connected (who left is who is not connected now)
        assert [(t.name, t.connected) for t in app.classroom.trainee_statuses()] == [("Alice", True)]
    finally:
        for c in clients:
            c.close()


def test_a_browser_that_comes_back_proves_itself_with_its_key(app_factory, tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    app = app_factory(class_db=db, trainer_token="trainer-token-tok-1", exercise="mystery")
    c = DrainingClient(app.port)
    (s,) = _sessions(app, 1)
    p = _join(s, "Anna")
    key = _issued_key(p)
    tool = s.controller.mounted_tool
    c.close()
    wait_until(lambda: not app.sessions, what="the browser gone")
    # a reload: a new connection; without the key the name is refused, with it Anna is back
    c = DrainingClient(app.port)
    try:
        (s,) = _sessions(app, 1)
        p = _join(s, "Anna")
        assert p.name is None and "joined from another browser" in p.message.content
        p = _join(s, "Anna", key)
        assert p.name == "Anna" and p.key_html is None          # no new key: the browser kept its own
        assert s.controller.mounted_tool.key == tool.key
    finally:
        c.close()
    app.stop()
    # a server restart on the same gradebook: the same key works, and Anna's mystery tool is the same
    app2 = app_factory(class_db=db, trainer_token="trainer-token-tok-1", exercise="mystery")
    c = DrainingClient(app2.port)
    try:
        (s,) = _sessions(app2, 1)
        p = _join(s, "Anna", key)
        assert p.name == "Anna"
        np.testing.assert_array_equal(true_frame(s.controller.mounted_tool), true_frame(tool))
        with app2.gradebook.store.read() as book:
            assert book.execute("SELECT COUNT(*) FROM trainees").fetchone()[0] == 1
    finally:
        c.close()


def _mystery_frame_of(app_factory, db: Path, name: str, **config) -> np.ndarray:
    app = app_factory(class_db=db, trainer_token="trainer-token-tok-1", exercise="mystery", **config)
    c = DrainingClient(app.port)
    try:
        (s,) = _sessions(app, 1)
        assert _join(s, name).name == name
        return np.array(true_frame(s.controller.mounted_tool))
    finally:
        c.close()
        app.stop()


def test_two_classes_started_alike_draw_different_tools_for_the_same_name(app_factory, tmp_path: Path) -> None:
    a = _mystery_frame_of(app_factory, tmp_path / "a.sqlite3", "Anna")
    b = _mystery_frame_of(app_factory, tmp_path / "b.sqlite3", "Anna")
    assert np.linalg.norm(a[:3, 3] - b[:3, 3]) * 1000.0 > 1.0
    # the seed that was public before (0) draws neither
    from tcp_pendant.classroom.mystery import draw_mystery_frame
    from tcp_pendant.controller import builtin_tools

    public = draw_mystery_frame(0, "Anna", builtin_tools()["pointer"]).T_flange_tool
    assert not np.allclose(public, a) and not np.allclose(public, b)


def test_an_explicit_exercise_seed_wins_for_a_demo(app_factory, tmp_path: Path) -> None:
    from tcp_pendant.classroom.mystery import draw_mystery_frame
    from tcp_pendant.controller import builtin_tools

    a = _mystery_frame_of(app_factory, tmp_path / "a.sqlite3", "Anna", exercise_seed=7)
    b = _mystery_frame_of(app_factory, tmp_path / "b.sqlite3", "Anna", exercise_seed=7)
    np.testing.assert_allclose(a, b, atol=1e-12)
    np.testing.assert_allclose(a, draw_mystery_frame(7, "Anna", builtin_tools()["pointer"]).T_flange_tool,
                               atol=1e-9)


def test_the_same_browser_in_a_second_tab_takes_the_name_and_the_first_tab_holds(app_factory, tmp_path: Path) -> None:
    """The key proves it is the same browser (a reload whose old connection is not closed yet,
    a second tab): the newer session gets the name; the older one's welcome window opens again
    with the hold marker, so its script does not join by itself and take it back."""
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="trainer-token-tok-1")
    clients = [DrainingClient(app.port)]
    _sessions(app, 1)
    clients.append(DrainingClient(app.port))
    try:
        first, second = _sessions(app, 2)
        p1 = _join(first, "Anna")
        key = _issued_key(p1)
        p2 = _join(second, "Anna", key)
        assert p2.name == "Anna"
        wait_until(lambda: p1.name is None and "joined from another tab or window of this browser"
                   in p1.message.content, what="the first tab's welcome window")
        assert p1.marker_html.content == "<div hidden data-tcp-pendant-hold></div>"
        assert app.gradebook.trainees.holds_key("Anna", key)          # the key stays the browser's
        assert [(t.name, t.connected) for t in app.classroom.trainee_statuses()] == [("Anna", True)]
        # the first tab's changes are no longer Anna's: a touch there is not recorded
        cal = first.views["calibrate"]
        click(cal.start, first.client)
        click(cal.steps.auto_touch, first.client)
        assert app.gradebook.grades.rows() == [] and app.classroom.trainee_statuses()[0].touches == 0
        with app.gradebook.store.read() as db:
            assert db.execute("SELECT COUNT(*) FROM touches").fetchone()[0] == 0
    finally:
        for c in clients:
            c.close()


def test_the_mystery_mesh_sent_to_the_browser_shows_the_tip_and_the_shaft_but_not_tool_y(
        app_factory, tmp_path: Path) -> None:
    """What the browser gets of the mystery tool (the MeshMessages under the flange, float32,
    FLANGE coordinates): the nozzle's flat tip face is centred on the TCP (as a real tool's tip
    is there to see) with no vertex at it, and no vertex of the nozzle's rings lies on tool Y or
    Z about tool X (before: one on tool Y)."""
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="trainer-token-tok-1", exercise="mystery",
                      exercise_seed=7)
    c = RecordingClient(app.port)
    try:
        (s,) = _sessions(app, 1)
        assert _join(s, "Anna").name == "Anna"
        T = np.array(true_frame(s.controller.mounted_tool))
        x, y, z, tcp = T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3]

        def sent_tool_meshes() -> list:
            return [np.asarray(m["props"]["vertices"], dtype=float).reshape(-1, 3)
                    for m in c.of_type("MeshMessage") if "/flange/tool/" in str(m.get("name"))]

        def nozzle() -> np.ndarray | None:
            with_tip = [v for v in sent_tool_meshes() if np.min(np.linalg.norm(v - tcp, axis=1)) < 3e-4]
            return with_tip[-1] if with_tip else None

        wait_until(lambda: nozzle() is not None, what="the mystery tool's nozzle sent")
        v = nozzle()
        assert v is not None
        r = v - tcp
        radial = r - np.outer(r @ x, x)
        ring = radial[np.linalg.norm(radial, axis=1) > 1e-4]
        assert len(ring) == 48 and np.min(np.linalg.norm(r, axis=1)) > 1.9e-4   # no vertex at the TCP
        angles = np.degrees(np.arctan2(ring @ z, ring @ y))
        assert np.abs((angles + 45.0) % 90.0 - 45.0).min() > 1e-3          # none on +-Y, +-Z
        axial = r @ x
        face = np.abs(axial) < 1e-6                                       # the tip face, about X
        assert face.sum() == 24 and np.allclose(v[face].mean(axis=0), tcp, atol=1e-7)
        assert np.all(axial[~face] < -0.01)                               # the rest behind the tip
    finally:
        c.close()
