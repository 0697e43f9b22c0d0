"""A trainer's raw viser websocket (no browser): types its token, sets values and clicks as the
trainer view in a browser would, and keeps the texts the server sends it."""

from __future__ import annotations

import re
import threading
from typing import Any

import msgspec.msgpack
from viser import _messages

from support.wsclient import INPUTS, DrainingClient, decode_window, wait_until


class TrainerSocket(DrainingClient):
    """A trainer's raw websocket: learns the GUI inputs by label, keeps every markdown text the
    server sends (by uuid, the latest), and sets values / clicks as its browser would."""

    def __init__(self, port: int, token: str) -> None:
        self.token = token
        self.inputs: dict[str, str] = {}                 # label -> uuid (the latest of that label)
        self.texts: dict[str, str] = {}
        self._lock = threading.Lock()
        super().__init__(port)

    def _received(self, msg: bytes | str) -> None:
        if not isinstance(msg, bytes):
            return
        for m in decode_window(msg):
            kind, props = m.get("type"), m.get("props") or {}
            with self._lock:
                if kind in INPUTS and props.get("label"):
                    self.inputs[str(props["label"])] = m["uuid"]
                elif kind == "GuiMarkdownMessage":
                    self.texts[m["uuid"]] = str(props.get("_markdown", ""))
                elif kind == "GuiHtmlMessage":                  # the dashboard's tables
                    self.texts[m["uuid"]] = str(props.get("content", ""))
                elif kind == "GuiUpdateMessage":
                    updates = m.get("updates") or {}
                    for key in ("_markdown", "content"):
                        if key in updates:
                            self.texts[m["uuid"]] = str(updates[key])

    def send_value(self, label: str, value: Any) -> None:
        wait_until(lambda: label in self.inputs, what=f"the trainer's {label!r}")
        msg = _messages.GuiUpdateMessage(self.inputs[label], {"value": value})
        self.ws.send(msgspec.msgpack.encode(msg.as_serializable_dict()))

    def text_with(self, pattern: str) -> str | None:
        with self._lock:
            return next((t for t in self.texts.values() if re.search(pattern, t)), None)

    def open_trainer_view(self) -> None:
        self.send_value("Trainer token", self.token)
        self.send_value("Open trainer view", True)
        wait_until(lambda: "Push to all trainees" in self.inputs, what="the trainer view")
