"""The rig of the browser job flood (issue 42, item 5; ``test_browser_flood.py``,
``tests/bench/bench_jobs.py --flood``): a pendant server in this process, the victim's browser
over a real websocket (a ``ButtonClient`` in this process: it jogs X+ by 0.1 mm, press after
press) and one attacker browser in a process of its own (a real websocket client, as a browser
in another tab or machine is) clicking the Tool tab's Check and "Check active tool" and the
Calibrate tab's Auto-touch, in turn, as fast as its socket takes the clicks.

The attacker's session has a library tool selected (slot 1, the pointer's true data), the same
data active, training mode on and an XYZ 4-point wizard open, so every one of its clicks can
start something: a TCP check (six rotations) or an Auto-touch (a pose reached, a step recorded;
on the fourth the result). The victim's latency is the time from its press to its robot having
moved (polled on the server's controller); a press the server's deadman dropped (it reached the
loop more than ``PRESS_BOUND_S`` after its arrival) is counted from the session's
``PressGate.dropped_total``.

The attack runs in bursts (:meth:`FloodRig.flood`), so that baseline presses and presses under
attack interleave in one run (the machine's other load hits both alike).
"""

from __future__ import annotations

import asyncio
import gc
import os
import socket
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from tcp_pendant.serve.cli import set_apart_startup_objects
from tcp_pendant.controller import builtin_tools
from tcp_pendant.job_pool import JobPool, JobTiming
from tcp_pendant.serve.server import AppConfig, PendantApp
from tcp_pendant.session import Session
from tcpcal.tool import Tool

from support.wsclient import ButtonClient, ReadoutClient, wait_until

PLUS_X = "X +"
ATTACK_BUTTONS = ("Check", "Check active tool", "Auto-touch")
"""What the attacker clicks, in turn."""


def pointer_tool() -> Tool:
    """Tool data equal to the pointer's true frame (every check is the same six rotations)."""
    T = builtin_tools()["pointer"].T_flange_tool_true
    return Tool.from_rotation("Pointer", tuple(float(v) * 1000.0 for v in T[:3, 3]), T[:3, :3])


@dataclass
class Presses:
    """The victim's presses of one phase: latencies (s) of those carried out, and how many the
    deadman dropped."""

    latencies: list[float] = field(default_factory=list)
    dropped: int = 0

    @property
    def n(self) -> int:
        return len(self.latencies) + self.dropped

    def p(self, q: float) -> float:
        return float(np.percentile(self.latencies, q)) if self.latencies else float("nan")

    def line(self) -> str:
        if not self.latencies:
            return f"{self.n} presses, none carried out, {self.dropped} dropped"
        return (f"p50 {self.p(50) * 1e3:4.0f} ms, p95 {self.p(95) * 1e3:4.0f} ms, max {max(self.latencies) * 1e3:4.0f} ms, "
                f"{len(self.latencies)} of {self.n} answered, {self.dropped} dropped")


class FloodRig:
    """The rig (module docstring).

    Args:
        tmp_path: folder of the tool library.
        pool: the server's job pool (``keep_history`` on: the tests read the jobs' timings).
        rate_hz: the attacker's clicks per second; 0: as fast as its socket takes them (the
            issue's browser: 3,198 clicks in 25 s, ~128 per second).
    """

    def __init__(self, tmp_path: Path, pool: JobPool | None = None, rate_hz: float = 0.0) -> None:
        self.app = app = PendantApp(AppConfig(port=0, tool_library=tmp_path / "tools.json"))
        self.tool = pointer_tool()
        app.library.save(1, self.tool)
        if pool is not None:
            app.jobs = pool
        self.pool = app.jobs
        app.start()
        set_apart_startup_objects()      # as `tcp-pendant` does once it listens (job_attack.py)
        self.victim_client = ReadoutClient(app.port, (PLUS_X,))
        assert self.victim_client.found.wait(30), "the victim never saw the jog keys"
        wait_until(lambda: len(app.sessions) == 1, what="the victim's session")
        (self.victim,) = app.sessions.values()
        self.loop = self.victim.views["calibrate"].load._impl.gui_api._event_loop
        self.victim_notes: list[tuple[str, str]] = []
        self.victim.notify = lambda title, body, kind="info": self.victim_notes.append((title, body))  # type: ignore[method-assign]
        with self.victim.lock:
            self.victim.tools.set_active_data(self.tool)
            self.victim.jogger.settings = self.victim.jogger.settings.with_(increment="0.1", frame="WORLD")
        self.rate_hz = rate_hz
        self.attacker_notes: list[tuple[str, str]] = []
        """The notifications the attackers' browsers were shown."""
        self.attacker_refusals: list[str] = []
        """Every refusal of an attacker's click, shown or left out (``Session.notify_refusal``)."""
        self.attackers: list[Session] = []
        self.clicks = 0

    # ------------------------------------------------------------ the attack
    @contextmanager
    def flood(self) -> Iterator[Session]:
        """A fresh attacker browser (its own process, its own session, prepared) clicks while
        the block runs; at its end the browser closes (its clicks still in the socket are
        dropped with the connection, as a closed tab's)."""
        n = len(self.app.sessions)
        proc = subprocess.Popen([sys.executable, __file__, str(self.app.port), str(self.rate_hz)],
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1,
                                env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
        assert proc.stdin is not None and proc.stdout is not None
        try:
            assert proc.stdout.readline().strip() == "ready", "the attacker never saw its buttons"
            wait_until(lambda: len(self.app.sessions) > n, what="the attacker's session")
            attacker = next(s for s in self.app.sessions.values() if s is not self.victim and s not in self.attackers)
            self.attackers.append(attacker)
            self._prepare(attacker)
            proc.stdin.write("go\n")
            proc.stdin.flush()
            assert proc.stdout.readline().strip() == "going"
            yield attacker
            proc.stdin.write("stop\n")
            proc.stdin.flush()
            self.clicks += int(proc.stdout.readline().split()[0])
        finally:
            proc.stdin.close()
            try:
                proc.wait(20)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(10)
        wait_until(lambda: attacker.closed, timeout=30, what="the attacker's session closed")
        wait_until(lambda: self.pool.pending(attacker) is None, timeout=30, what="the attack's last job")

    def _prepare(self, a: Session) -> None:
        """Library slot 1 selected, its data active, training on, an XYZ 4-point open; its
        notifications and refusals noted."""
        original_notify = a.notify
        refusals = getattr(a, "refusals", None)       # None: a server without coalesced refusals

        def note(title: str, body: str, kind: str = "info") -> None:
            self.attacker_notes.append((title, body))
            original_notify(title, body, kind=kind)

        a.notify = note  # type: ignore[method-assign]
        if refusals is not None:
            original_body = refusals.body

            def refusal(body: str) -> str | None:
                self.attacker_refusals.append(body)
                return original_body(body)
            refusals.body = refusal
        tools = a.views["tools"]

        async def select() -> None:
            with a.lock:
                a.tools.set_active_data(self.tool, 1)
                a.wizard_commands.set_training(True)
                a.wizard_commands.start("xyz4")
                tools.slots.value = next(o for o in tools.slots.options if str(o).startswith("1"))
        self.on_loop(select())

    def on_loop(self, coro: Any) -> Any:
        """Run ``coro`` on the server's event loop; its value."""
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(60)

    def victim_check(self) -> None:
        """The victim's "Check active tool", as its button's callback runs it."""
        panel = self.victim.views["tools"]
        self.on_loop(panel.run_check(panel._active_for_check))
        assert panel.check_md.content.startswith("**TCP check"), (panel.check_md.content, self.victim_notes)

    # ------------------------------------------------------------ the victim
    def press(self, timeout_s: float = 2.0) -> float | None:
        """Click X+ in the victim's browser and wait for the first message that shows its TCP
        moved (the readout's X): seconds, or None when the deadman dropped the press (or nothing
        came within ``timeout_s``)."""
        client, gate = self.victim_client, self.victim.jogger.gate
        x0 = float(self.victim.controller.T_world_tcp()[0, 3]) * 1000.0
        dropped0, seen = gate.dropped_total, len(client.readouts)
        t0 = time.monotonic()
        client.click(PLUS_X)
        while True:
            for t, x in client.readouts[seen:]:
                if abs(x - x0) > 0.05:
                    return t - t0
            if gate.dropped_total > dropped0 or time.monotonic() - t0 > timeout_s:
                return None
            time.sleep(0.001)

    def presses(self, n: int, into: Presses, gap_s: float) -> None:
        """``n`` presses, ``gap_s`` apart (the issue's trainee: 40 presses in 25 s)."""
        for _ in range(n):
            t0 = time.perf_counter()
            lat = self.press()
            if lat is None:
                into.dropped += 1
            else:
                into.latencies.append(lat)
            time.sleep(max(0.0, gap_s - (time.perf_counter() - t0)))

    def measure(self, presses: int = 40, block: int = 5, gap_s: float = 0.6) -> tuple[Presses, Presses]:
        """``presses`` presses alone and as many under the attack, in alternating blocks of
        ``block``: (baseline, attack)."""
        base, under = Presses(), Presses()
        self.presses(2, Presses(), gap_s)                    # warm
        while under.n < presses:
            self.presses(min(block, presses - base.n), base, gap_s)
            with self.flood():
                time.sleep(0.5)                              # the flood under way
                self.presses(min(block, presses - under.n), under, gap_s)
        return base, under

    def attacker_jobs(self) -> list[JobTiming]:
        return [h for h in self.pool.history or () if h.owner is not self.victim]

    def close(self) -> None:
        self.victim_client.close()
        self.app.stop()
        gc.unfreeze()


# ------------------------------------------------------------ the attacker's process
def _attacker(port: int, rate_hz: float) -> None:
    """Connect, learn the buttons, then on "go" click them in turn as fast as the socket takes
    the clicks until "stop" (answering how many were sent)."""
    client = ButtonClient(port, ATTACK_BUTTONS)
    assert client.found.wait(30)
    print("ready", flush=True)
    go, closed = threading.Event(), threading.Event()
    sent = 0

    def clicker() -> None:
        nonlocal sent
        i = 0
        next_s = time.perf_counter()
        while not closed.is_set():
            go.wait()
            if rate_hz > 0:
                next_s = max(next_s + 1.0 / rate_hz, time.perf_counter() - 0.1)
                time.sleep(max(0.0, next_s - time.perf_counter()))
            try:
                client.click(ATTACK_BUTTONS[i % len(ATTACK_BUTTONS)])
            except Exception:           # the server closed the connection: counted, not clicked
                closed.set()
                return
            i += 1
            sent += 1

    threading.Thread(target=clicker, daemon=True).start()
    for line in sys.stdin:
        if line.strip() == "go":
            sent = 0
            go.set()
            print("going", flush=True)
        elif line.strip() == "stop":
            go.clear()
            time.sleep(0.05)
            print(f"{sent} clicks{' (connection closed)' if closed.is_set() else ''}", flush=True)
    # the tab closes: the connection is reset (its clicks still in the sockets are dropped)
    client.ws.socket.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    client.ws.socket.close()
    os._exit(0)


if __name__ == "__main__":
    _attacker(int(sys.argv[1]), float(sys.argv[2]))
