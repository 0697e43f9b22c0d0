"""The exercise's brief (instructions, allowed methods, a minimum of touches) and the trainer's
messages, on the class and its sessions without a server: ``ClassRoom`` on a real gradebook,
pendant sessions without a browser (``calib_helpers.make_session``), every command the
session's."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from support.calib_helpers import library_tool_with_true_tcp, make_session

from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.classroom.class_room import ClassRoom
from tcp_pendant.classroom.exercise_setup import PUSHED_SETTING
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.serve.cli import main
from tcp_pendant.controller import builtin_tools
from tcp_pendant.session import ClassMessage
from tcp_pendant.calibrate.pendant_rules import RuleRefusal
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.class_notices import instructions_markdown, message_markdown

TOKEN = "trainer-token-of-16"
INJECTION = "<img src=x onerror=alert(1)> [link](//evil.example) ![](//127.0.0.1:9/x) **bold** www.evil.example"


@pytest.fixture
def book(tmp_path: Path) -> Iterator[Gradebook]:
    with Gradebook(tmp_path / "class.sqlite3") as b:
        yield b


def _trainee(room: ClassRoom, tmp_path: Path, name: str, key: str | None = None):
    session = make_session(tmp_path / f"tools-{name}.json")
    join = room.named(session, name, key)
    return session, join


def live(md: str) -> list[str]:
    """Live markup in ``md``: raw HTML, links and images, autolinkable URLs."""
    return re.findall(r"<|\]\(|!\[|www\.|https?:", md)


def test_instructions_and_messages_reach_the_markdown_escaped_line_by_line() -> None:
    text = f"Step 1: {INJECTION}\n# heading\n\n| a | b |"
    banner = instructions_markdown(text)
    assert live(banner) == [] and "\n#" not in banner
    for line in ("Step 1: " + INJECTION, "# heading", "| a | b |"):
        assert escape_markdown(line) in banner            # each line shown literally, its own paragraph
    box = message_markdown(ClassMessage(3, INJECTION, "<b>Ben</b>", "2026-12-02T09:41:00Z"), waiting=2)
    assert live(box) == [] and escape_markdown(INJECTION) in box and "&lt;b&gt;Ben" in box
    assert "09:41 UTC" in box and "2 more messages" in box


def test_a_method_the_exercise_does_not_allow_is_refused_by_start_wizard(book: Gradebook, tmp_path: Path) -> None:
    room = ClassRoom(book, {}, trainer_token=TOKEN)
    anna, _ = _trainee(room, tmp_path, "Anna")
    assert room.push_brief("Find the TCP.", ["xyz4"], 0) == 1
    assert anna.rules.allowed_methods == ("xyz4",) and anna.rules.instructions == "Find the TCP."
    with pytest.raises(RuleRefusal, match=r"does not use the Three-point orientation method: choose XYZ 4-point"):
        anna.wizard_commands.start("three-point")
    assert anna.workflow.wizard is None                    # nothing was opened
    anna.record_touch()
    room.push_brief("", ["tcp-zx"], 0)
    with pytest.raises(RuleRefusal, match="does not use the XYZ 4-point method"):
        anna.wizard_commands.start_from_touches()                          # an XYZ 4-point too
    assert anna.workflow.wizard is None
    assert anna.wizard_commands.start("tcp-zx").kind == "tcp-zx"
    with pytest.raises(ValueError, match="Unknown calibration method 'nope'.*xyz4"):
        room.push_brief("", ["xyz4", "nope"], 0)
    assert anna.rules.allowed_methods == ("tcp-zx",)       # a refused push set nothing


def test_finish_with_fewer_touches_than_the_minimum_is_refused_in_words(book: Gradebook, tmp_path: Path) -> None:
    room = ClassRoom(book, {}, trainer_token=TOKEN)
    bo, _ = _trainee(room, tmp_path, "Bo")
    room.push_brief("", None, 6)
    wiz = bo.wizard_commands.start("xyz4", n_points=4)
    for _ in range(4):
        assert bo.wizard_commands.auto_touch(AutoTouchRequest()).ok
    words = "This exercise asks for at least 6 touches: record 2 more (press Add point for another touch step)."
    assert bo.workflow.result is None and wiz.on_last_step        # Auto-touch's last touch did not finish
    assert bo.wizard_commands.finish_refusal() == words
    with pytest.raises(RuleRefusal) as refused:
        bo.wizard_commands.next_step()
    assert str(refused.value) == words and not wiz.is_complete
    bo.wizard_commands.add_point()
    assert "record 1 more" in (bo.wizard_commands.finish_refusal() or "")
    bo.wizard_commands.add_point()
    bo.wizard_commands.auto_touch(AutoTouchRequest())
    bo.wizard_commands.auto_touch(AutoTouchRequest())
    assert bo.wizard_commands.finish_refusal() is None and bo.workflow.result is not None and len(wiz.solver_touch_steps()) == 6
    # TCP & Z, X chooses its touches at start and has no Add point: refused there
    with pytest.raises(RuleRefusal, match="set Touches to 6 or more for the TCP & Z, X"):
        bo.wizard_commands.start("tcp-zx", n_points=4)
    assert bo.wizard_commands.start("tcp-zx", n_points=6).kind == "tcp-zx"
    # a method with a fixed number of poses keeps its own count
    bo.tools.store_tool(1, library_tool_with_true_tcp("pointer", "Pointer"))
    three = bo.wizard_commands.start("three-point", slot=1)
    for _ in range(three.n_steps):
        bo.wizard_commands.auto_touch(AutoTouchRequest())
    assert bo.workflow.result is not None and bo.wizard_commands.finish_refusal() is None


def test_a_message_to_one_trainee_reaches_only_that_trainee_and_dismissed_stays_dismissed(
        book: Gradebook, tmp_path: Path) -> None:
    room = ClassRoom(book, {}, trainer_token=TOKEN)
    anna, _ = _trainee(room, tmp_path, "Anna")
    ben, ben_join = _trainee(room, tmp_path, "Ben")
    assert room.send_message("  Ben: check your B angle  ", "Ben") == "Sent to Ben."
    assert anna.messages == () and [m.text for m in ben.messages] == ["Ben: check your B angle"]
    assert room.send_message("Break in 5 minutes", None) == "Sent to 2 trainees."
    to_all = anna.messages[0]
    assert to_all.to is None and [m.text for m in ben.messages] == ["Ben: check your B angle", "Break in 5 minutes"]
    assert anna.dismiss_message(to_all.message_id) and anna.messages == ()
    assert len(ben.messages) == 2                          # Anna's dismissal is hers alone
    first = ben.messages[0]
    assert ben.dismiss_message(first.message_id) and not ben.dismiss_message(first.message_id)
    assert [m.text for m in ben.messages] == ["Break in 5 minutes"]
    with pytest.raises(ValueError, match="empty"):
        room.send_message("   ", None)
    with pytest.raises(ValueError, match="Cleo is not in the class"):
        room.send_message("hello", "Cleo")
    # Ben reloads: what he dismissed stays dismissed, what he did not comes back
    room.detach(ben)
    ben.close()
    assert room.send_message("Only for Ben", "Ben") == "Ben is not connected: the message waits until they join again."
    again, _ = _trainee(room, tmp_path, "Ben", ben_join.new_key)
    assert [m.text for m in again.messages] == ["Break in 5 minutes", "Only for Ben"]
    assert anna.messages == ()


def test_the_brief_outlives_a_restart_and_an_older_gradebook_still_opens(tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    with Gradebook(db) as book:
        room = ClassRoom(book, {}, trainer_token=TOKEN, exercise="mystery")
        room.push_settings("mystery", None, hide_distance="hidden")
        room.push_brief("Touch from 6 directions.\nNo Auto-touch.", ["xyz4", "tcp-zx"], 6)
    with Gradebook(db) as book:                             # a new server on the same gradebook
        room = ClassRoom(book, builtin_tools(), trainer_token=None)
        rules = room.rules
        assert (rules.exercise, rules.instructions, rules.allowed_methods, rules.min_touches) == (
            "mystery", "Touch from 6 directions.\nNo Auto-touch.", ("xyz4", "tcp-zx"), 6)
        assert room.distance_aids == "hidden"
        cleo, _ = _trainee(room, tmp_path, "Cleo")
        assert cleo.rules == room.rules
        with pytest.raises(RuleRefusal):
            cleo.wizard_commands.start("abc-world")
        # options given at start win over the kept brief, and are kept
        assert ClassRoom(book, {}, trainer_token=None, min_touches=3, allowed_methods="reference").rules.min_touches == 3
        assert ClassRoom(book, {}, trainer_token=None).rules.allowed_methods == ("reference",)
        # a gradebook kept by an older version: no brief keys at all
        book.settings.set(PUSHED_SETTING, {"exercise": None, "distance_aids": None, "auto_touch": None})
        old = ClassRoom(book, {}, trainer_token=None).rules
        assert (old.instructions, old.allowed_methods, old.min_touches) == ("", None, 0)


def test_the_brief_options_of_the_command_line(book: Gradebook, tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """The three options reach the server's config (and imply a class); the class checks them."""
    import tcp_pendant.classroom.gradebook_open as gb
    import tcp_pendant.serve.server as server

    seen: list[object] = []

    class Stop(Exception):
        pass

    class FakeApp:
        def __init__(self, config: object) -> None:
            seen.append(config)
            raise Stop

    monkeypatch.setattr(server, "PendantApp", FakeApp)
    monkeypatch.setattr(gb, "default_gradebook_path", lambda: tmp_path / "data" / "class.sqlite3")
    with pytest.raises(Stop):
        main(["--port", "0", "--exercise-instructions", "Find the TCP", "--exercise-methods", "xyz4, reference",
              "--exercise-min-touches", "6"])
    config = seen[0]
    assert (config.exercise_instructions, config.exercise_methods, config.exercise_min_touches) == (  # type: ignore[attr-defined]
        "Find the TCP", ("xyz4", "reference"), 6)
    assert config.class_db == tmp_path / "data" / "class.sqlite3"   # type: ignore[attr-defined]
    assert main(["--shared", "--exercise-methods", "xyz4"]) == 2
    with pytest.raises(ValueError, match="at most 2000"):
        ClassRoom(book, {}, trainer_token=TOKEN, instructions="x" * 2001)
    with pytest.raises(ValueError, match="from 0 to 20"):
        ClassRoom(book, {}, trainer_token=TOKEN, min_touches=21)
    with pytest.raises(ValueError, match="Unknown calibration method 'xyz5'"):
        ClassRoom(book, {}, trainer_token=TOKEN, allowed_methods="xyz5")
