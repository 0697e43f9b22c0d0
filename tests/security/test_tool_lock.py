"""A trainee in the mystery exercise cannot swap their mystery tool for a built-in one (whose
TCP is printed in the README) and have the gradebook file that calibration for the exercise.

The attack goes over the trainee's own websocket, as a hostile browser sends it: the locked
(disabled) dropdown's update is refused and the value the server holds is sent back; and a
tool change that reaches the panel's callback all the same (a page whose lock had not arrived
yet) is refused by the session's command, in words the trainee's browser is sent."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from support.app_page import join_as_the_only_trainee
from support.guiclick import choose, click
from support.wsclient import InputsClient, wait_until

from tcp_pendant.calibrate.pendant_rules import TOOL_LOCKED_WORDS
from tcp_pendant.views.tool_panel import TOOL_LOCKED_LINE

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

TOKEN = "trainer-token-toollock-01"


def _notifications(c: InputsClient) -> list[str]:
    """The bodies of the notifications this websocket was sent."""
    out = []
    for m in list(c.messages):
        if "Notification" in str(m.get("type")):
            props = m.get("props") or m
            out.append(f"{props.get('title', '')}: {props.get('body', '')}")
    return out


def _prop(c: InputsClient, uuid: str, name: str) -> Any:
    """The last value of the prop ``name`` of the input ``uuid`` that the server sent."""
    value = c.inputs[uuid][2].get(name)
    for u, updates in list(c.updates):
        if u == uuid and name in updates:
            value = updates[name]
    return value


def _send_dropdown(c: InputsClient, label: str, value: str) -> None:
    """What a browser sends when its dropdown ``label`` is set to ``value`` (disabled or not)."""
    c.send({"type": "GuiUpdateMessage", "uuid": c.uuid_of(label), "updates": {"value": value}})


def test_the_mystery_tool_cannot_be_swapped_for_the_pointer_over_the_websocket(tmp_path: Path, app_factory) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, exercise="mystery")
    c = InputsClient(app.port)
    try:
        s = join_as_the_only_trainee(app, "Mallory")
        mystery = s.controller.mounted_tool
        assert mystery.key.startswith("mystery-")
        wait_until(lambda: "Mounted tool" in c.labels(), what="the Mounted tool dropdown")
        tools: Any = s.views["tools"]
        assert tools.mounted.disabled and mystery.label in tools.mounted.value

        uuid = c.uuid_of("Mounted tool")
        wait_until(lambda: _prop(c, uuid, "disabled") is True, what="the lock, sent to the browser")
        assert any(TOOL_LOCKED_LINE in str(m) for m in list(c.messages))   # the line that says why

        n_updates = len(c.updates)
        _send_dropdown(c, "Mounted tool", "Bent-neck welding torch")
        _send_dropdown(c, "Mounted tool", "Straight pointer")
        wait_until(lambda: [u.get("value") for v, u in c.updates[n_updates:] if v == uuid].count(mystery.label) >= 1,
                   what="the mystery tool sent back to the browser")
        assert s.controller.mounted_tool is mystery

        n_before = len(_notifications(c))
        choose(tools.mounted, "Straight pointer", s.client)            # past the lock, to the callback
        wait_until(lambda: any(TOOL_LOCKED_WORDS in n for n in _notifications(c)[n_before:]),
                   what="the refusal in words, sent to the trainee")
        assert s.controller.mounted_tool is mystery and tools.mounted.value == mystery.label

        app.classroom.push_settings("mystery", None, auto_touch=True)   # the trainer allows Auto-touch
        cal = s.views["calibrate"]
        click(cal.start, s.client)                                      # XYZ 4-point, the default
        for _ in range(6):
            if cal.workflow.result is not None:
                break
            click(cal.steps.auto_touch, s.client)
        assert cal.workflow.result is not None
        assert s.controller.mounted_tool is mystery

        (row,) = app.gradebook.grades.rows()
        assert (row.method, row.tool_key, row.exercise_id) == ("xyz4", mystery.key, "mystery")
    finally:
        c.ws.close()
