"""The brief and the messages through the GUI of a running server: the trainer's controls
push them, the trainee's banner and message box show them escaped (the markdown viser is given),
the Calibrate menu offers the allowed methods only, the step panel says why Finish is refused,
and Dismiss dismisses on the trainee's own screen only."""

from __future__ import annotations

import re
from pathlib import Path


from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until

from tcp_pendant.text_escape import escape_markdown

TOKEN = "trainer-token-of-16"
INJECTION = "<style>*{opacity:0}</style> [x](//evil.example) ![](//127.0.0.1:9/x) www.evil.example"


def live(md: str) -> list[str]:
    return re.findall(r"<|\]\(|!\[|www\.|https?:", md)


def test_the_trainers_brief_and_message_reach_the_right_screens_escaped(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, seed=11)
    clients = []
    for i in range(3):
        clients.append(DrainingClient(app.port))
        wait_until(lambda: len(app.sessions) == i + 1, what=f"session {i + 1}")
    wait_until(lambda: all("identity" in s.views for s in app.sessions.values()), what="name prompts")
    anna, ben, trainer = list(app.sessions.values())
    try:
        for session, name in ((anna, "Anna"), (ben, "Ben")):
            choose(session.views["identity"].name_field, name, session.client)
            click(session.views["identity"].start, session.client)
        q = trainer.views["identity"]
        choose(q.token_field, TOKEN, trainer.client)
        click(q.open_trainer, trainer.client)
        view = trainer.views["trainer"]
        brief, box = view.class_extras
        assert not anna.views["notices"].banner.visible            # no instructions yet
        # the brief: instructions with markup, two methods, at least 6 touches
        choose(brief.instructions, f"Calibrate the pointer.\n{INJECTION}", trainer.client)
        for kind, checkbox in brief.methods.items():
            choose(checkbox, kind in ("xyz4", "tcp-zx"), trainer.client)
        choose(brief.min_touches, 6, trainer.client)
        click(brief.push, trainer.client)
        assert "Pushed to 2 trainees" in brief.status.content
        banner = anna.views["notices"].banner
        assert banner.visible and escape_markdown(INJECTION) in banner.content and live(banner.content) == []
        cal = anna.views["calibrate"]
        assert tuple(cal.method.options) == ("XYZ 4-point", "TCP & Z, X (ABB)")   # the others are not offered
        # a browser that sends a method not offered anyway is refused in words
        notes: list[str] = []
        anna.notify = lambda title, body, kind="info": notes.append(body)   # type: ignore[method-assign]
        cal.method._impl.value = "Automatic (beam)"
        click(cal.start, anna.client)
        assert anna.workflow.wizard is None
        assert notes == ["This exercise does not use the Automatic (beam) method: choose XYZ 4-point or "
                         "TCP & Z, X (ABB) (the trainer chose the methods)."]
        # Finish with 4 touches: the step panel says why not
        choose(cal.method, "XYZ 4-point", anna.client)
        click(cal.start, anna.client)
        for _ in range(4):
            click(cal.steps.auto_touch, anna.client)
        assert anna.workflow.result is None
        assert cal.steps.blocked_md.visible and "record 2 more" in cal.steps.blocked_md.content
        # a message to Ben only, with markup
        wait_until(lambda: tuple(box.to.options)[1:] == ("Anna", "Ben"), what="the trainees in To")
        choose(box.to, "Ben", trainer.client)
        choose(box.text, f"Ben, look here: {INJECTION}", trainer.client)
        click(box.send, trainer.client)
        assert box.status.content == escape_markdown("Sent to Ben.") and box.text.value == ""
        ben_box = ben.views["notices"]
        wait_until(lambda: ben_box.message_md.visible, what="Ben's message box")
        assert escape_markdown(f"Ben, look here: {INJECTION}") in ben_box.message_md.content
        assert live(ben_box.message_md.content) == [] and ben_box.dismiss.visible
        assert not anna.views["notices"].message_md.visible and anna.messages == ()
        click(ben_box.dismiss, ben.client)
        assert not ben_box.message_md.visible and ben.messages == ()
    finally:
        for c in clients:
            c.close()
