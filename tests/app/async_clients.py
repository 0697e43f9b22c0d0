"""Cheap headless pendant clients on one asyncio loop, for the class load benchmark.

Each client is one websocket speaking viser's protocol (the subprotocol ``viser-v<version>``,
the camera message a browser sends first, viser's compressed windows decoded with zstandard and
msgspec): it learns the uuids of the "X +" jog key (and, in a class, of the "Your name" field
and the "Join the class" button), joins the class under its own name when asked, and notes
every TCP readout it receives with the machine's monotonic clock (``time.monotonic``) and the
X it shows (mm). A press is viser's ``GuiUpdateMessage(uuid, {"value": True})``, what a browser
sends for a click. Hundreds of clients cost one thread: no client renders anything.

:func:`run_presses` presses "X +" ``hz`` times a second per client, spread over the period, and
:func:`latencies` turns the sends and readouts into the latency from a press to the first
readout that shows it (the m-th press is shown once the readout is ``m * step_mm`` past where
it was before the first press).
"""

from __future__ import annotations

import asyncio
import math
import re
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import msgspec.msgpack
import viser
import websockets.asyncio.client
import zstandard

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


@dataclass
class LoadClient:
    """One headless client (see the module docstring)."""

    index: int
    ws: Any = None
    uuids: dict[str, str] = field(default_factory=dict)
    readouts: list[tuple[float, float]] = field(default_factory=list)
    frames: list[tuple[float, str]] = field(default_factory=list)   # (time, frame) of each TCP readout
    notes: list[str] = field(default_factory=list)     # warnings shown ("⚠ ...") and the trainer dashboard's heading
    sends: list[float] = field(default_factory=list)
    late_s: list[float] = field(default_factory=list)   # per press of run_presses: sent this long after its plan
    ready: asyncio.Event = field(default_factory=asyncio.Event)
    task: asyncio.Task[None] | None = None
    closed_early: bool = False

    async def connect(self, host: str, port: int) -> None:
        self.ws = await websockets.asyncio.client.connect(
            f"ws://{host}:{port}", subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
            max_size=None, open_timeout=60, compression=None, ping_interval=None)
        await self.ws.send(_encoder.encode(_CAMERA))
        self.task = asyncio.get_running_loop().create_task(self._receive())

    async def _receive(self) -> None:
        dctx = zstandard.ZstdDecompressor()
        try:
            async for msg in self.ws:
                t = time.monotonic()
                if not isinstance(msg, bytes):
                    continue
                for m in _window_messages(msg, dctx):
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
                if PLUS in self.uuids and INCREMENT_LABEL in self.uuids and self.readouts:
                    self.ready.set()
        except Exception:
            pass
        self.closed_early = True

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

    async def send_update(self, label: str, updates: dict[str, Any]) -> None:
        await self.ws.send(_encoder.encode({"type": "GuiUpdateMessage", "uuid": self.uuids[label],
                                            "updates": updates}))

    async def try_token(self, token: str) -> None:
        """Type ``token`` into "Trainer token" and press "Open trainer view"."""
        await self.send_update(TOKEN_LABEL, {"value": token})
        await self.send_update(OPEN_TRAINER_LABEL, {"value": True})

    async def join(self, name: str) -> None:
        """Type ``name`` into "Your name" and press "Join the class" (as a trainee does)."""
        await self.send_update(NAME_LABEL, {"value": name})
        await self.send_update(JOIN_LABEL, {"value": True})

    async def close(self) -> None:
        if self.ws is not None:
            await self.ws.close()
        if self.task is not None:
            await asyncio.wait([self.task], timeout=5)


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
        k = 0
        while k * period <= seconds:
            delay = t0 + k * period - time.monotonic()
            if delay > 0:
                await asyncio.sleep(delay)
            now = time.monotonic()
            c.sends.append(now)
            c.late_s.append(now - (t0 + k * period))
            try:
                await c.send_update(label, {"value": True})
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
