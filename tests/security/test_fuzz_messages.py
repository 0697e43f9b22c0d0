"""No fuzzed websocket message leaves a traceback or closes the sender's socket: a few hundred
generated messages of wrong types, ranges, shapes and kinds go to a running pendant over a raw
websocket; every one is refused (the GUI's values are unchanged), the log has no traceback and
no line longer than a cut value allows, and the same socket then still jogs the robot."""

from __future__ import annotations

import logging
import math
import random
import time
from collections.abc import Callable
from typing import Any

import msgspec.msgpack
import pytest
from tcp_pendant.serve.server import PendantApp
from tcp_pendant.views.viser_adapter import LOG_BUDGET, LOG_VALUE_CHARS, message_counts

from support.wsclient import CAMERA, InputsClient, click_until_carried_out, wait_until

HUGE = "x" * 100_000


def bad_values(kind: str, props: dict[str, Any]) -> list[Any]:
    """Values a browser's widget of ``kind`` never sends (each refused by the value check)."""
    common: list[Any] = [None, {"a": 1}, [[1, 2], [3]]]
    numbers = [-1e308, 1e308, math.nan, math.inf, -math.inf, "12", True, [1.0], HUGE]
    hi, lo = props.get("max"), props.get("min")
    if isinstance(hi, (int, float)):
        numbers.append(hi + 1)
    if isinstance(lo, (int, float)):
        numbers.append(lo - 1)
    return common + {
        "GuiButtonMessage": [False, "true", 1, HUGE],
        "GuiUploadButtonMessage": [{"name": "x.json", "content": b"{}"}, "x.json", b"{}"],
        "GuiSliderMessage": numbers,
        "GuiNumberMessage": numbers,
        "GuiMultiSliderMessage": [[math.nan, 1.0], "1,2", [1.0]],
        "GuiVector2Message": [[1.0], [1.0, "2"], [math.nan, 0.0], [1e308, 0.0]],
        "GuiVector3Message": [[1.0, 2.0], [1.0, 2.0, "3"], [math.inf, 0.0, 0.0]],
        "GuiRgbMessage": [[1, 2], [1, 2, "3"], [1e308, 0, 0]],
        "GuiRgbaMessage": [[1, 2, 3], [1, 2, 3, "4"]],
        "GuiCheckboxMessage": ["true", 1, 0.5, HUGE],
        "GuiTextMessage": [12, 1.5, True, ["a"], HUGE + "y"],
        "GuiDropdownMessage": ["not one of its options", 3, HUGE, True],
        "GuiButtonGroupMessage": ["not one of its options", 0, HUGE],
    }[kind]


def fuzz_messages(inputs: dict[str, tuple[str, str, dict[str, Any]]], seed: int) -> list[Any]:
    """Bad values for every input, bad shapes of GuiUpdateMessage, and other message kinds with
    wrong fields, undecodable frames and refused kinds; shuffled (seeded)."""
    out: list[Any] = []
    for uuid, (kind, _, props) in inputs.items():
        for v in bad_values(kind, props):
            out.append({"type": "GuiUpdateMessage", "uuid": uuid, "updates": {"value": v}})
        out += [{"type": "GuiUpdateMessage", "uuid": uuid, "updates": u}
                for u in ({"removed": True}, {"update_cb": [1]}, {"value": None, "disabled": False}, {}, "x", [1])]
        out += [{"type": "GuiButtonHoldMessage", "uuid": uuid, "frequency": f} for f in ("20", [20.0], math.nan)]
        out.append({"type": "FileTransferStartUpload", "source_component_uuid": uuid, "transfer_uuid": "t-" + uuid,
                    "filename": HUGE, "mime_type": "x", "part_count": "1", "size_bytes": -5})
        out.append({"type": "FileTransferPart", "source_component_uuid": uuid, "transfer_uuid": "t-" + uuid,
                    "part_index": "0", "content": HUGE})
    out += [{"type": "GuiUpdateMessage", "uuid": u, "updates": {"value": 1}} for u in (123, None, ["a"], HUGE)]
    out += [dict(CAMERA, **{k: v}) for k, v in (("wxyz", [1.0, 0.0]), ("fov", "wide"), ("near", math.nan),
                                                ("position", [HUGE, 0.0, 0.0]), ("image_height", [720]))]
    out += [{"type": "ShareUrlRequest"}, {"type": "ShareUrlDisconnect"}, {"type": "NoSuchMessage"},
            {"type": HUGE}, {"uuid": "no type"}, {"type": "GuiFormSubmitMessage", "uuid": [1]},
            {"type": "CommandTriggerMessage", "uuid": {"a": HUGE}}, {"type": "GuiUpdateMessage"},
            b"\xc1\xff not msgpack", b"", "a text frame " + HUGE, msgspec.msgpack.encode([1, 2, 3]),
            msgspec.msgpack.encode(HUGE)]
    random.Random(seed).shuffle(out)
    return out


@pytest.fixture
def app(app_factory: Callable[..., PendantApp]) -> PendantApp:
    return app_factory()


def _values(app: PendantApp) -> dict[str, Any]:
    """Every GUI input's value on the server (by uuid)."""
    out: dict[str, Any] = {}
    for client in app.server.get_clients().values():
        for uuid, handle in client.gui._gui_input_handle_from_uuid.items():
            out[uuid] = repr(handle.value)
    return out


@pytest.mark.slow  # thousands of fuzzed messages
def test_fuzzed_messages_leave_no_traceback_and_the_socket_open(app: PendantApp, caplog: pytest.LogCaptureFixture,
                                                               capfd: pytest.CaptureFixture[str]) -> None:
    client = InputsClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 1, what="the session")
        wait_until(lambda: {"X +", "Load session (JSON)"} <= {lab for _, lab, _ in client.inputs.values()},
                   what="the jog keys and the upload button")
        (session,) = app.sessions.values()
        kinds = {k for k, _, _ in client.inputs.values()}
        assert {"GuiButtonMessage", "GuiSliderMessage", "GuiNumberMessage", "GuiTextMessage",
                "GuiDropdownMessage", "GuiCheckboxMessage", "GuiUploadButtonMessage"} <= kinds
        before = _values(app)
        messages = fuzz_messages(dict(client.inputs), seed=23)
        assert len(messages) >= 2000
        moves: list[int] = []
        session.add_motion_listener(lambda: moves.append(1))
        refused_before = message_counts().get("refused", 0)
        t0 = time.monotonic()
        with caplog.at_level(logging.WARNING):
            for m in messages:
                client.send(m)
            # the same socket, once every fuzzed message was handled, still jogs. (A click sent
            # right behind them would wait in the socket while the paced flood is read, and the
            # deadman drops a press that old: ``views.arrival``.)
            wait_until(lambda: message_counts().get("refused", 0) - refused_before >= len(messages) - 1,
                       timeout=60.0, what="every fuzzed message handled")
            click_until_carried_out(client, "X +", session.jogger.gate, lambda: len(moves) > 0,
                                    what="the jog behind the fuzzed messages")
        # the connection is read at its pace (``message_rate``: 200 a second), so the flood spans
        # several of the log's windows; each window logs at most its budget per sender (two here)
        windows = math.ceil((time.monotonic() - t0) / LOG_BUDGET[1]) + 1
        assert not client.closed.is_set()
        after = _values(app)
        after.pop(client.uuid_of("X +"))                     # the click's own value (True)
        before.pop(client.uuid_of("X +"))
        assert after == before                              # every fuzzed value was refused
        assert app.server._share_tunnel is None
        err = capfd.readouterr().err
        assert "Traceback" not in err and "Task exception" not in err
        assert not [r for r in caplog.records if r.exc_info], "a log record carries a traceback"
        assert "Traceback" not in caplog.text and "Task exception was never retrieved" not in caplog.text
        # each refused once, but the update of an unknown element (a long string is a uuid): viser ignores it
        assert message_counts().get("refused", 0) - refused_before == len(messages) - 1
        assert message_counts().get("failed", 0) == 0
        logged = [r.getMessage() for r in caplog.records if r.name.endswith("viser_adapter")]
        assert LOG_BUDGET[0] <= len(logged) <= 2 * LOG_BUDGET[0] * windows   # not logged line by line
        assert len(logged) < len(messages) / 5
        longest = max(len(r.getMessage()) for r in caplog.records)
        assert longest < 2 * LOG_VALUE_CHARS + 200, max((r.getMessage() for r in caplog.records), key=len)[:400]
    finally:
        client.ws.close()


def test_a_refused_value_is_sent_back_as_the_server_holds_it(app: PendantApp) -> None:
    """-1e308 typed into the override slider's field: refused, and the browser gets the value
    the server kept, so its widget does not show a number the pendant never took."""
    client = InputsClient(app.port)
    try:
        wait_until(lambda: "Override %" in client.labels(), what="the override slider")
        uuid = client.uuid_of("Override %")
        (session,) = app.sessions.values()
        kept = session.jogger.settings.override_pct
        client.send({"type": "GuiUpdateMessage", "uuid": uuid, "updates": {"value": -1e308}})
        wait_until(lambda: (uuid, {"value": kept}) in client.updates, what="the kept value sent back")
        assert session.jogger.settings.override_pct == kept
        assert not client.closed.is_set()
    finally:
        client.ws.close()


def test_a_disabled_button_takes_no_click_and_no_hold(app: PendantApp, caplog: pytest.LogCaptureFixture) -> None:
    """viser runs a button's hold callbacks even when the button is disabled; a raw client
    could hold a key the pendant has disabled. Both messages are refused."""
    client = InputsClient(app.port)
    try:
        wait_until(lambda: "X +" in client.labels(), what="the jog keys")
        (session,) = app.sessions.values()
        key = session.client.gui._gui_input_handle_from_uuid[client.uuid_of("X +")]
        key.disabled = True
        uuid = client.uuid_of("X +")
        before = message_counts().get("refused", 0)
        with caplog.at_level(logging.WARNING):
            client.send({"type": "GuiButtonHoldMessage", "uuid": uuid, "frequency": 20.0})
            client.send({"type": "GuiUpdateMessage", "uuid": uuid, "updates": {"value": True}})
            wait_until(lambda: message_counts().get("refused", 0) - before == 2, what="both refused")
        assert "'X +' is disabled: no hold" in caplog.text and "'X +' is disabled" in caplog.text
    finally:
        client.ws.close()
