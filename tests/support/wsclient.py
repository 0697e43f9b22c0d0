"""A minimal headless viser client for tests and the benchmark: a websocket that speaks viser's
subprotocol and drains whatever the server sends (no rendering)."""

from __future__ import annotations

import asyncio
import re
import socket
import threading
import time
import typing
from collections.abc import Callable
from typing import Any

import msgspec.msgpack
import numpy as np
import viser
from viser import _messages
from websockets.sync.client import connect


def free_port() -> int:
    """A TCP port that is free right now on 127.0.0.1."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def wait_until(cond: Callable[[], bool], timeout: float = 20.0, what: str = "condition") -> None:
    """Poll ``cond`` every 10 ms until it holds; fail naming ``what`` after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if cond():
            return
        time.sleep(0.01)
    raise AssertionError(f"timed out waiting for {what}")


def loop_ran_for(loop: asyncio.AbstractEventLoop, seconds: float, timeout: float = 20.0) -> None:
    """Return once the server's event ``loop`` has run a callback scheduled ``seconds`` from now:
    asyncio runs timers in the order they fall due, so every timer due before it (e.g. a held
    key's next ticks) has run. The positive condition that lets a negative check ("nothing moved
    meanwhile") stand after real time passed."""
    done = threading.Event()
    loop.call_soon_threadsafe(lambda: loop.call_later(seconds, done.set))
    if not done.wait(seconds + timeout):
        raise AssertionError(f"timed out waiting for the server's loop to run {seconds} s on")


class _Clicks(typing.Protocol):
    def click(self, label: str) -> None: ...


def click_until_carried_out(client: _Clicks, label: str, gate: Any, done: Callable[[], bool], *,
                            what: str, clicks: int = 5, timeout: float = 20.0) -> int:
    """Click ``label`` and wait until ``done()``. A click the server's deadman dropped (``gate``:
    the session's ``PressGate``; its loop reached the click more than ``PRESS_BOUND_S`` late, e.g.
    in a full garbage collection of the test process) is clicked again, as a trainee would, up to
    ``clicks`` clicks in all. Returns how many were sent; fails naming ``what`` when ``done()``
    never held, or when it held although every click was dropped."""
    dropped0, sent = gate.dropped_total, 0

    def done_or_clicked_again() -> bool:
        nonlocal sent
        if done():
            return True
        if sent == 0 or (gate.dropped_total - dropped0 >= sent and sent < clicks):
            sent += 1
            client.click(label)
        return False

    wait_until(done_or_clicked_again, timeout=timeout, what=what)
    assert gate.dropped_total - dropped0 < sent, f"{what}: every click was dropped, yet it happened"
    return sent


class DrainingClient:
    """Connects to a viser server and reads (and discards) every message in a thread.

    ``headers``: extra request headers of the upgrade (e.g. a browser's Cookie and Origin);
    ``host_name``: the name the request is for (its ``Host``), reached at ``host`` (as a browser
    that resolved the name would).

    Attributes:
        n_messages, n_bytes: what the server sent so far.
    """

    def __init__(self, port: int, host: str = "127.0.0.1", headers: dict[str, str] | None = None,
                 host_name: str | None = None) -> None:
        sock = None if host_name is None else socket.create_connection((host, port), timeout=20)
        self.ws = connect(f"ws://{host_name or host}:{port}", subprotocols=[f"viser-v{viser.__version__}"],
                          max_size=None, open_timeout=20, additional_headers=headers, sock=sock)
        self.n_messages = 0
        self.n_bytes = 0
        self._sync_uuid: str | None = None         # the marker :meth:`sync` waits for
        self._synced = threading.Event()
        self._thread = threading.Thread(target=self._drain, daemon=True)
        self._thread.start()
        # viser counts a client as connected at its first camera message
        cam = _messages.ViewerCameraMessage(wxyz=(1.0, 0.0, 0.0, 0.0), position=(2.0, -2.0, 1.0), fov=1.0,
                                            near=0.01, far=100.0, image_height=720, image_width=1280,
                                            look_at=(0.0, 0.0, 0.5), up_direction=(0.0, 0.0, 1.0))
        self._camera = msgspec.msgpack.encode(cam.as_serializable_dict())
        self.ws.send(self._camera)

    def _drain(self) -> None:
        try:
            for msg in self.ws:
                self.n_messages += 1
                self.n_bytes += len(msg)
                if self._sync_uuid is not None and isinstance(msg, bytes):
                    if any(m.get("uuid") == self._sync_uuid for m in decode_window(msg)):
                        self._synced.set()
                self._received(msg)
        except Exception:
            pass

    def sync(self, handle: viser.ClientHandle, timeout: float = 20.0) -> None:
        """A round trip behind everything this client sent: returns once the server has handled
        every message sent on this socket before the call, and this client has received every
        message the server queued for it while handling them.

        ``handle``: the server's :class:`viser.ClientHandle` of this connection (in-process
        server). The marker is the camera message again, unchanged (it changes nothing the app
        shows; a camera callback, e.g. a wizard scene's relayout, does run): viser handles one
        socket's messages in order, so once ``handle.camera`` is the marker's, the messages
        before it have been handled (their callbacks ran up to their first real ``await``: the
        pendant's GUI callbacks are synchronous on the loop). Then the server's loop queues a
        ``GuiUpdateMessage`` for the made-up uuid ``sync-...`` (updates ``{}``) on this client's
        own buffer, behind whatever those callbacks queued for it; when it arrives, so have they.
        A subclass that records GUI updates sees that message too.
        """
        before = handle.camera._state
        self.ws.send(self._camera)
        wait_until(lambda: handle.camera._state is not before, timeout=timeout,
                   what="the server handling the marker behind this client's messages")
        uuid = f"sync-{time.monotonic_ns()}"
        self._synced.clear()
        self._sync_uuid = uuid
        conn = handle._websock_connection
        conn._state.event_loop.call_soon_threadsafe(                  # type: ignore[attr-defined]
            lambda: conn.queue_message(_messages.GuiUpdateMessage(uuid, {})))
        try:
            if not self._synced.wait(timeout):
                raise AssertionError("timed out waiting for the server's sync message")
        finally:
            self._sync_uuid = None

    def _received(self, msg: bytes | str) -> None:
        """One message as it arrives (the subclasses decode what they need)."""

    def close(self) -> None:
        """Close the websocket (the server then fires on_client_disconnect)."""
        try:
            self.ws.close()
        finally:
            self._thread.join(timeout=10)


def decode_window(data: bytes) -> list[dict]:
    """The messages of one server window (viser's wire format: 8-byte msgpack length, 8-byte
    compressed length, zstd-compressed msgpack ``{"messages": [...], ...}``, binary buffers)."""
    import zstandard

    clen = int.from_bytes(data[8:16], "little")
    inner = zstandard.ZstdDecompressor().decompress(data[16:16 + clen])
    return list(msgspec.msgpack.decode(inner)["messages"])


def decode_window_arrays(data: bytes) -> list[dict]:
    """:func:`decode_window` with every binary placeholder (``{"__binary_index": i, "dtype": ...,
    "shape": ...}``, e.g. a mesh's vertices) replaced by its numpy array from the window's
    8-byte aligned buffers."""
    import zstandard

    clen = int.from_bytes(data[8:16], "little")
    inner = msgspec.msgpack.decode(zstandard.ZstdDecompressor().decompress(data[16:16 + clen]))
    buffers, offset = [], 16 + clen
    for n in inner.get("binaryBufferLengths", ()):
        offset += (8 - offset % 8) % 8
        buffers.append(data[offset:offset + n])
        offset += n

    def resolve(obj: Any) -> Any:
        if isinstance(obj, dict):
            if "__binary_index" in obj:
                arr = np.frombuffer(buffers[obj["__binary_index"]], dtype=np.dtype(obj["dtype"]))
                return arr.reshape(obj["shape"]) if "shape" in obj else arr
            return {k: resolve(v) for k, v in obj.items()}
        if isinstance(obj, list):
            return [resolve(v) for v in obj]
        return obj

    return [resolve(m) for m in inner["messages"]]


class ButtonClient(DrainingClient):
    """A :class:`DrainingClient` that learns the uuids of the pendant's buttons (by label, from
    the GUI messages it receives) and can press and hold them like a browser does (viser's
    ``GuiButtonHoldMessage``, which the browser repeats while a button is held).

    Args:
        labels: button labels to look for; decoding stops once all are known.
        record_updates: keep decoding and record the last value of every GUI property the
            server sends (``gui_props[uuid][prop]``), e.g. a markdown's ``_markdown``.
    """

    def __init__(self, port: int, labels: tuple[str, ...], host: str = "127.0.0.1",
                 record_updates: bool = False) -> None:
        self.labels = tuple(labels)
        self.button_uuids: dict[str, str] = {}
        self.record_updates = record_updates
        self.gui_props: dict[str, dict] = {}
        self.found = threading.Event()
        self._send_lock = threading.Lock()
        super().__init__(port, host)

    def _received(self, msg: bytes | str) -> None:
        if (self.record_updates or not self.found.is_set()) and isinstance(msg, bytes):
            for m in decode_window(msg):
                self._decoded(m)
            if len(self.button_uuids) == len(self.labels):
                self.found.set()

    def _decoded(self, m: dict) -> None:
        """One decoded message: a button's uuid, and with ``record_updates`` a GUI update."""
        kind = m.get("type")
        if kind == "GuiButtonMessage":
            label = (m.get("props") or {}).get("label")
            if label in self.labels:
                self.button_uuids.setdefault(label, m["uuid"])
        elif kind == "GuiUpdateMessage" and self.record_updates:
            self.gui_props.setdefault(m["uuid"], {}).update(m["updates"])

    def hold_tick(self, label: str, frequency: float) -> None:
        """One hold message of the button ``label`` (registered hold rate ``frequency`` Hz)."""
        msg = _messages.GuiButtonHoldMessage(self.button_uuids[label], float(frequency))
        with self._send_lock:
            self.ws.send(msgspec.msgpack.encode(msg.as_serializable_dict()))

    def click(self, label: str) -> None:
        """A click on the button ``label`` (the browser sends its value ``True``)."""
        msg = _messages.GuiUpdateMessage(self.button_uuids[label], {"value": True})
        with self._send_lock:
            self.ws.send(msgspec.msgpack.encode(msg.as_serializable_dict()))


INPUTS = {"GuiButtonMessage", "GuiUploadButtonMessage", "GuiSliderMessage", "GuiMultiSliderMessage",
          "GuiNumberMessage", "GuiRgbMessage", "GuiRgbaMessage", "GuiCheckboxMessage", "GuiVector2Message",
          "GuiVector3Message", "GuiTextMessage", "GuiDropdownMessage", "GuiButtonGroupMessage"}
"""viser's messages that create a GUI input."""

CAMERA = dict(type="ViewerCameraMessage", wxyz=[1.0, 0.0, 0.0, 0.0], position=[2.0, -2.0, 1.0], fov=1.0,
              near=0.01, far=100.0, image_height=720, image_width=1280, look_at=[0.0, 0.0, 0.5],
              up_direction=[0.0, 0.0, 1.0])
"""The camera message a browser sends first (as a msgpack mapping)."""


class InputsClient:
    """A raw viser websocket that records the GUI inputs the server creates (uuid -> kind,
    label, props), the GUI updates and every message it gets, and sends whatever it is given (a msgpack mapping, raw bytes or a text
    frame), as a hostile browser could. ``closed`` is set when the server closed it. ``headers``:
    extra request headers of the upgrade (a browser's ``Accept-Language``)."""

    def __init__(self, port: int, headers: dict[str, str] | None = None) -> None:
        self.ws = connect(f"ws://127.0.0.1:{port}", subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
                          max_size=None, open_timeout=20, additional_headers=headers)
        self.inputs: dict[str, tuple[str, str, dict[str, Any]]] = {}
        self.updates: list[tuple[str, dict[str, Any]]] = []     # (uuid, updates) the server sent
        self.messages: list[dict[str, Any]] = []                # every message the server sent, decoded
        self.closed = threading.Event()
        self._thread = threading.Thread(target=self._drain, daemon=True)
        self._thread.start()
        self.send(CAMERA)

    def _drain(self) -> None:
        try:
            for msg in self.ws:
                if isinstance(msg, bytes):
                    for m in decode_window(msg):
                        self.messages.append(m)
                        if m.get("type") in INPUTS:
                            props = m.get("props") or {}
                            self.inputs[m["uuid"]] = (m["type"], str(props.get("label")), props)
                        elif m.get("type") == "GuiUpdateMessage":
                            self.updates.append((m["uuid"], m["updates"]))
        except Exception:
            pass
        self.closed.set()

    def send(self, message: dict[str, Any] | bytes | str) -> None:
        self.ws.send(message if isinstance(message, (bytes, str)) else msgspec.msgpack.encode(message))

    def uuid_of(self, label: str) -> str:
        """The uuid of the input labelled ``label``."""
        return next(u for u, (_, lab, _) in self.inputs.items() if lab == label)

    def click(self, label: str) -> None:
        """Click the button labelled ``label`` as a browser does."""
        self.send({"type": "GuiUpdateMessage", "uuid": self.uuid_of(label), "updates": {"value": True}})

    def labels(self) -> set[str]:
        return {lab for _, lab, _ in self.inputs.values()}


class RecordingClient(DrainingClient):
    """A :class:`DrainingClient` that keeps every decoded message the server sent (binary
    arrays as numpy arrays, :func:`decode_window_arrays`)."""

    def __init__(self, port: int, host: str = "127.0.0.1") -> None:
        self.messages: list[dict] = []
        super().__init__(port, host)

    def _received(self, msg: bytes | str) -> None:
        if isinstance(msg, bytes):
            self.messages.extend(decode_window_arrays(msg))

    def of_type(self, name: str) -> list[dict]:
        return [m for m in list(self.messages) if m.get("type") == name]


class ReadoutClient(ButtonClient):
    """A :class:`ButtonClient` that notes when the TCP readout changed and the X it shows:
    ``readouts`` is a list of ``(time.monotonic() at receipt, X mm)`` (the clock is the
    machine's, so a server in another process can compare with its own stamps)."""

    X_MM = re.compile(r"\bX\s+(-?\d+\.\d\d) mm")

    def __init__(self, port: int, labels: tuple[str, ...], host: str = "127.0.0.1") -> None:
        self.readouts: list[tuple[float, float]] = []
        super().__init__(port, labels, host)

    def _received(self, msg: bytes | str) -> None:
        t = time.monotonic()                      # every message is decoded: the readout goes on
        if not isinstance(msg, bytes):
            return
        for m in decode_window(msg):
            self._decoded(m)
            if m.get("type") == "GuiUpdateMessage":
                text = (m.get("updates") or {}).get("_markdown")
                if isinstance(text, str) and text.startswith("**TCP in "):
                    x = self.X_MM.search(text)
                    if x:
                        self.readouts.append((t, float(x.group(1))))
        if len(self.button_uuids) == len(self.labels):
            self.found.set()
