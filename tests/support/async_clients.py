"""Cheap headless pendant clients on one asyncio loop, for the class load benchmark.

Each client is one websocket speaking viser's protocol (the subprotocol ``viser-v<version>``,
the camera message a browser sends first, viser's compressed windows decoded with zstandard and
msgspec): it learns the uuids of the "X +" jog key (and, in a class, of the "Your name" field
and the "Join the class" button), joins the class under its own name when asked, and notes
every TCP readout it receives with the time it reached the client's socket (the kernel's
receive stamp, on the machine's monotonic clock ``time.monotonic``) and the X it shows (mm). A
press is viser's ``GuiUpdateMessage(uuid, {"value": True})``, what a browser sends for a click,
stamped when it is written to the socket. Hundreds of clients cost one thread: no client renders
anything, and a client that shares the server's CPUs and waits for one reads its readouts late
but stamps them when they arrived (:class:`LoadClient`).

:func:`run_presses` presses "X +" ``hz`` times a second per client, spread over the period, and
:func:`latencies` turns the sends and readouts into the latency from a press to the first
readout that shows it (the m-th press is shown once the readout is ``m * step_mm`` past where
it was before the first press).
"""

from __future__ import annotations

import asyncio
import math
import re
import socket
import struct
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import msgspec.msgpack
import viser
import zstandard
from websockets.client import ClientProtocol
from websockets.frames import Frame, Opcode
from websockets.http11 import Response
from websockets.protocol import State
from websockets.typing import Subprotocol
from websockets.uri import parse_uri

__all__ = ["LoadClient", "connect_all", "latencies", "percentile", "run_presses"]

PLUS = "X +"
NAME_LABEL = "Your name"
JOIN_LABEL = "Join the class"
INCREMENT_LABEL = "Increment"
READOUT_LABEL = "Readout"
TOKEN_LABEL = "Trainer token"
OPEN_TRAINER_LABEL = "Open trainer view"
_FRAME = re.compile(r"^\*\*TCP in (\w+)")
_X_MM = re.compile(r"\bX\s+(-?\d+\.\d\d) mm")
_CAMERA = dict(type="ViewerCameraMessage", wxyz=[1.0, 0.0, 0.0, 0.0], position=[2.0, -2.0, 1.0], fov=1.0,
               near=0.01, far=100.0, image_height=720, image_width=1280, look_at=[0.0, 0.0, 0.5],
               up_direction=[0.0, 0.0, 1.0])
_decoder = msgspec.msgpack.Decoder()
_encoder = msgspec.msgpack.Encoder()


def _window_messages(data: bytes, dctx: zstandard.ZstdDecompressor) -> list[dict[str, Any]]:
    """The messages of one viser window (8-byte msgpack length, 8-byte compressed length,
    zstd-compressed msgpack ``{"messages": [...]}``, binary buffers)."""
    clen = int.from_bytes(data[8:16], "little")
    inner = dctx.decompress(data[16:16 + clen])
    return list(_decoder.decode(inner)["messages"])


SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35)
"""Linux's ``SO_TIMESTAMPNS`` (asm-generic/socket.h; Python's socket module does not name it):
``recvmsg`` then returns, as ancillary data, the time (CLOCK_REALTIME) at which the kernel
received the last segment of what it read (socket(7))."""
READ_BYTES = 4096
"""At most this many bytes per read: the frames of one read share its arrival time (module doc)."""
_ANCILLARY = socket.CMSG_SPACE(16)      # one struct timespec (two 64-bit fields)


def _arrival_monotonic(ancillary: list[tuple[int, int, bytes]], offset_s: float) -> float:
    """The kernel's receive time of a read (``SO_TIMESTAMPNS``) on the monotonic clock
    (``offset_s`` = realtime - monotonic); the time now when the kernel gave none."""
    for level, kind, data in ancillary:
        if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS and len(data) >= 16:
            sec, nsec = struct.unpack("qq", data[:16])
            return sec + nsec * 1e-9 - offset_s
    return time.monotonic()


@dataclass
class LoadClient:
    """One headless client (see the module docstring).

    Its websocket is websockets' sans-I/O ``ClientProtocol`` (the handshake, the framing, pings
    and the close) over a non-blocking socket that the loop watches (``add_reader``); what it
    reads is stamped with the kernel's receive time (:data:`SO_TIMESTAMPNS`), so a readout's time
    is when it reached this machine's socket, not when this client, sharing the server's CPUs,
    got round to it. The frames of one read share that read's stamp: the time its last segment
    arrived, never before any of them (a latency can only come out longer). The press a client
    repeats is framed once (:meth:`framed_update`).
    """

    index: int
    uuids: dict[str, str] = field(default_factory=dict)
    readouts: list[tuple[float, float]] = field(default_factory=list)
    frames: list[tuple[float, str]] = field(default_factory=list)   # (time, frame) of each TCP readout
    notes: list[str] = field(default_factory=list)     # warnings shown ("⚠ ...") and the trainer dashboard's heading
    sends: list[float] = field(default_factory=list)
    late_s: list[float] = field(default_factory=list)   # per press of run_presses: sent this long after its plan
    ready: asyncio.Event = field(default_factory=asyncio.Event)
    closed_early: bool = False
    """The connection ended (the server closed it, or :meth:`close` did)."""
    _sock: socket.socket | None = None
    _protocol: ClientProtocol | None = None
    _opened: asyncio.Event = field(default_factory=asyncio.Event)
    _ended: asyncio.Event = field(default_factory=asyncio.Event)
    _out: bytearray = field(default_factory=bytearray)
    _writing: bool = False
    _fragments: list[bytes] = field(default_factory=list)
    _dctx: zstandard.ZstdDecompressor = field(default_factory=zstandard.ZstdDecompressor)
    _offset_s: float = 0.0

    async def connect(self, host: str, port: int) -> None:
        loop = asyncio.get_running_loop()
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        sock.setblocking(False)
        try:
            await asyncio.wait_for(loop.sock_connect(sock, (host, port)), 60)
        except BaseException:
            sock.close()
            raise
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
        self._sock, self._offset_s = sock, time.time() - time.monotonic()
        self._protocol = ClientProtocol(parse_uri(f"ws://{host}:{port}"), max_size=None,
                                        subprotocols=[Subprotocol(f"viser-v{viser.__version__}")])
        self._protocol.send_request(self._protocol.connect())
        loop.add_reader(sock.fileno(), self._readable)
        self._flush_protocol()
        await asyncio.wait_for(self._opened.wait(), 60)
        if self._protocol.handshake_exc is not None:
            raise ConnectionError(f"client {self.index}: the handshake failed: {self._protocol.handshake_exc}")
        await self.send_update_payload(_encoder.encode(_CAMERA))

    # ------------------------------------------------------------ reading
    def _readable(self) -> None:
        assert self._sock is not None and self._protocol is not None
        try:
            data, ancillary, _, _ = self._sock.recvmsg(READ_BYTES, _ANCILLARY)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            self._end()
            return
        t = _arrival_monotonic(ancillary, self._offset_s)
        if data:
            self._protocol.receive_data(data)
        else:
            self._protocol.receive_eof()
        for event in self._protocol.events_received():
            if isinstance(event, Response):
                self._opened.set()
            elif isinstance(event, Frame):
                self._frame(t, event)
        self._flush_protocol()                     # pongs, the answer to a close
        if not data or self._protocol.state is State.CLOSED:
            self._end()

    def _frame(self, t: float, frame: Frame) -> None:
        if frame.opcode not in (Opcode.BINARY, Opcode.CONT):
            return                                 # pings are answered by the protocol; no text frames in viser
        self._fragments.append(bytes(frame.data))   # the very object when it is bytes already
        if not frame.fin:
            return
        data = b"".join(self._fragments)
        self._fragments.clear()
        try:
            messages = _window_messages(data, self._dctx)
        except Exception:
            return                                  # not a window of viser's: nothing a client shows
        for m in messages:
            self._message(t, m)
        if PLUS in self.uuids and INCREMENT_LABEL in self.uuids and self.readouts:
            self.ready.set()

    def _message(self, t: float, m: dict[str, Any]) -> None:
        kind = m.get("type")
        if kind == "GuiUpdateMessage":
            text = (m.get("updates") or {}).get("_markdown")
            if isinstance(text, str) and text.startswith("**TCP in "):
                self._readout(t, text)
            self._note(text)
        elif kind in ("GuiButtonMessage", "GuiTextMessage", "GuiButtonGroupMessage"):
            label = (m.get("props") or {}).get("label")
            if label in (PLUS, NAME_LABEL, JOIN_LABEL, INCREMENT_LABEL, READOUT_LABEL, TOKEN_LABEL,
                         OPEN_TRAINER_LABEL):
                self.uuids[label] = m["uuid"]
        elif kind == "GuiMarkdownMessage":
            text = (m.get("props") or {}).get("_markdown")
            if isinstance(text, str) and text.startswith("**TCP in "):
                self._readout(t, text)
            self._note(text)

    def _note(self, text: object) -> None:
        if isinstance(text, str) and text.startswith(("⚠", "### Trainer dashboard")):
            self.notes.append(text)

    def _readout(self, t: float, text: str) -> None:
        x = _X_MM.search(text)
        if x:
            self.readouts.append((t, float(x.group(1))))
        frame = _FRAME.match(text)
        if frame:
            self.frames.append((t, frame.group(1)))

    def _end(self) -> None:
        if self._sock is not None and not self._ended.is_set():
            asyncio.get_running_loop().remove_reader(self._sock.fileno())
            if self._writing:
                asyncio.get_running_loop().remove_writer(self._sock.fileno())
                self._writing = False
            self._opened.set()                      # a handshake that never finished ends too
        self.closed_early = True
        self._ended.set()

    # ------------------------------------------------------------ writing
    def _flush_protocol(self) -> None:
        assert self._protocol is not None
        for chunk in self._protocol.data_to_send():
            self._write(chunk)

    def _write(self, data: bytes) -> None:
        """Send ``data`` after what is waiting (in order; what the socket does not take now waits
        for it to be writable)."""
        if self._ended.is_set() or not data:
            return
        self._out += data
        if not self._writing:
            self._drain()

    def _drain(self) -> None:
        assert self._sock is not None
        loop = asyncio.get_running_loop()
        while self._out:
            try:
                sent = self._sock.send(self._out)
            except (BlockingIOError, InterruptedError):
                if not self._writing:
                    loop.add_writer(self._sock.fileno(), self._drain)
                    self._writing = True
                return
            except OSError:
                self._end()
                return
            del self._out[:sent]
        if self._writing:
            loop.remove_writer(self._sock.fileno())
            self._writing = False

    async def send_update_payload(self, payload: bytes) -> None:
        """Send one binary message (a msgpack-encoded viser message)."""
        if self._ended.is_set() or self._protocol is None:
            raise ConnectionError(f"client {self.index}: the connection is closed")
        self._protocol.send_binary(payload)
        self._flush_protocol()

    async def send_update(self, label: str, updates: dict[str, Any]) -> None:
        await self.send_update_payload(self._update_payload(label, updates))

    def _update_payload(self, label: str, updates: dict[str, Any]) -> bytes:
        return _encoder.encode({"type": "GuiUpdateMessage", "uuid": self.uuids[label], "updates": updates})

    def framed_update(self, label: str, updates: dict[str, Any]) -> bytes:
        """The whole websocket frame of one update (a binary frame, masked as RFC 6455 5.3 asks
        of a client; websockets' own ``Frame.serialize``), for :meth:`send_framed`."""
        return Frame(Opcode.BINARY, self._update_payload(label, updates)).serialize(mask=True)

    def send_framed(self, frame: bytes) -> None:
        """Send a frame of :meth:`framed_update` as it is.

        A press is the same bytes every time, so :func:`run_presses` frames it once: framing and
        masking it anew per press (websockets' ``send_binary``) cost a load client CPU that it
        takes from the server it measures. The server receives what ``send_binary`` would give
        it but for the mask key, which it only XORs away.

        Raises:
            ConnectionError: the connection is closed.
        """
        if self._ended.is_set():
            raise ConnectionError(f"client {self.index}: the connection is closed")
        self._write(frame)

    async def try_token(self, token: str) -> None:
        """Type ``token`` into "Trainer token" and press "Open trainer view"."""
        await self.send_update(TOKEN_LABEL, {"value": token})
        await self.send_update(OPEN_TRAINER_LABEL, {"value": True})

    async def join(self, name: str) -> None:
        """Type ``name`` into "Your name" and press "Join the class" (as a trainee does)."""
        await self.send_update(NAME_LABEL, {"value": name})
        await self.send_update(JOIN_LABEL, {"value": True})

    async def close(self) -> None:
        """Close the websocket (the closing handshake, at most 5 s), then the socket."""
        if self._sock is None:
            return
        if not self._ended.is_set() and self._protocol is not None:
            self._protocol.send_close()
            self._flush_protocol()
            try:
                await asyncio.wait_for(self._ended.wait(), 5)
            except asyncio.TimeoutError:
                self._end()
        self._end()
        self._sock.close()


PRESS_LEAD_S = 0.2
""":func:`run_presses` starts its first press this long (seconds) after it was called."""

ARRIVAL_GAP_S = 0.02
"""The clients of :func:`connect_all` arrive at least this far apart (seconds): as a class
does, one browser after another, not all in the same millisecond (100 in 2 s or more)."""


async def connect_all(host: str, port: int, n: int, *, names: str | None = None, increment: str = "0.1",
                      first: int = 0, timeout_s: float = 120.0) -> list[LoadClient]:
    """Connect ``n`` clients (a few at a time, :data:`ARRIVAL_GAP_S` apart, as a class
    arrives), wait until each sees its jog key and a readout, pick the jog ``increment`` (mm)
    and with ``names`` (a prefix) join each as ``"<names> 001"``... (numbered from
    ``first + 1``)."""
    clients = [LoadClient(i) for i in range(n)]
    sem = asyncio.Semaphore(8)
    arrival = asyncio.Lock()

    async def one(c: LoadClient) -> None:
        async with sem:
            async with arrival:                   # the next one arrives a gap later
                await c.connect(host, port)
                await asyncio.sleep(ARRIVAL_GAP_S)
            await asyncio.wait_for(c.ready.wait(), timeout_s)
            await c.send_update(INCREMENT_LABEL, {"value": increment})
            if names is not None:
                deadline = time.monotonic() + timeout_s
                while NAME_LABEL not in c.uuids or JOIN_LABEL not in c.uuids:
                    if time.monotonic() > deadline:
                        raise RuntimeError(f"client {c.index} never saw the name prompt")
                    await asyncio.sleep(0.05)
                await c.join(f"{names} {first + c.index + 1:03d}")

    await asyncio.gather(*(one(c) for c in clients))
    return clients


async def run_presses(clients: list[LoadClient], label: str, hz: float, seconds: float,
                      wait_s: float) -> list[float | None]:
    """Every client presses ``label`` ``hz`` times a second for ``seconds`` (spread over the
    period), then ``wait_s`` for the last answers. Returns each client's X before the first
    press (None: no readout seen)."""
    x0 = [c.readouts[-1][1] if c.readouts else None for c in clients]
    for c in clients:
        c.sends = []
        c.late_s = []
    period = 1.0 / hz
    n = len(clients)
    start = time.monotonic() + PRESS_LEAD_S

    async def press(c: LoadClient) -> None:
        t0 = start + period * c.index / n
        frame = c.framed_update(label, {"value": True})
        k = 0
        while k * period <= seconds:
            delay = t0 + k * period - time.monotonic()
            if delay > 0:
                await asyncio.sleep(delay)
            now = time.monotonic()
            c.sends.append(now)
            c.late_s.append(now - (t0 + k * period))
            try:
                c.send_framed(frame)
            except Exception:
                return
            k += 1

    marks = [len(c.readouts) for c in clients]
    await asyncio.gather(*(press(c) for c in clients))
    await asyncio.sleep(wait_s)
    for c, m in zip(clients, marks):
        c.readouts = c.readouts[m:]
    return x0


@dataclass(frozen=True)
class PressFigures:
    """Latency (ms) from a press to the readout that shows it, and the counts."""

    latencies_ms: tuple[float, ...]
    asked: int
    answered: int

    @property
    def unanswered(self) -> int:
        return self.asked - self.answered

    def percentile(self, q: float) -> float:
        return percentile(self.latencies_ms, q)


def percentile(values: Sequence[float], q: float) -> float:
    """The ``q``-th percentile of ``values`` (linear between ranks; nan when empty)."""
    if not values:
        return math.nan
    v = sorted(values)
    k = (len(v) - 1) * q / 100.0
    lo, hi = math.floor(k), math.ceil(k)
    return v[lo] + (v[hi] - v[lo]) * (k - lo)


def latencies(clients: list[LoadClient], x0: list[float | None], step_mm: float) -> PressFigures:
    """The m-th press of a client is answered by the first readout at least ``m * step_mm``
    past ``x0``; its latency runs from its send. A press the server's deadman dropped makes the
    later presses look answered by the readouts of earlier ones (their latencies then count from
    earlier sends: longer, never shorter); the presses never shown are unanswered."""
    out: list[float] = []
    asked = answered = 0
    for c, x in zip(clients, x0):
        asked += len(c.sends)
        if x is None:
            continue
        j = 0
        shown = [(t, round((v - x) / step_mm)) for t, v in c.readouts]
        for m, sent in enumerate(c.sends, start=1):
            while j < len(shown) and shown[j][1] < m:
                j += 1
            if j == len(shown):
                break
            out.append((shown[j][0] - sent) * 1e3)
            answered += 1
    return PressFigures(tuple(out), asked, answered)
