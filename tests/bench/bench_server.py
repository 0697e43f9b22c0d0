"""Jog latency from press to readout, steps achieved, and the server's CPU per jog step.

What it measures (printed too). The pendant server runs in this process: a real viser server
on a free port. N headless clients run in a *separate process* (tests/support/wsclient.py: real
websockets speaking viser's protocol; they receive every message, and press buttons the way a
browser does), so each one has a real session built by ``on_client_connect``, every scene/GUI
update is really serialised, compressed and sent, and the clients' own CPU is not counted. No
browser renders anything. A jog step is one 1 mm Cartesian jog along WORLD X (back and forth,
5 mm each way) of the KR 6 with the pointer, and everything the server sends for it: link
poses, gizmo, TCP readout, touch indicator, joint readout (and joint sliders when shown).

Three ways of driving the steps, each run twice - with the app and with a *baseline*, the
straightforward implementation: per move ``ViserUrdf.update_cfg`` (yourdfpy FK, one frame per
joint), the gizmo and the three readouts through viser's public setters, each from its own
controller call (scipy conversions), and plain jog-key callbacks (viser's thread pool) - so
that the app is reported as a ratio to a yardstick measured in the same run on the same
(shared, noisy) machine. The baseline replaces the scene's and the jog panel's subscriptions
to the session's change signal and the X keys' hold callbacks; the jog itself (controller) is
the same code in both:

* A  hot loop: steps back to back, round robin over the sessions, called in this process
     (``Jogger.key`` + ``Session.moved``): CPU of the calling thread per step (median, p95)
     and CPU of the whole process per step (includes viser's event loop sending);
* B  paced: every session 30 steps/s for a few seconds, steps called in this process;
* C  paced end to end: every client holds "X +" / "X −" (viser's button-hold messages, 30 per
     second per client, alternating every 5); the server receives them, runs the hold
     callbacks (the app's on viser's event loop, through ``SessionLoop.on_loop`` like every GUI
     callback; the baseline's in viser's thread pool), jogs (continuous mode,
     override set for ~1 mm per tick) and sends the updates. Steps are counted by a motion
     listener. This is the path a browser's jog takes.

A and B call the step from this benchmark's thread (not the event loop, where the app runs it)
to time the step alone; C is the real path.

* D  press to readout (the app only): every client clicks "X +" (0.1 mm increments) 20 times a
     second (a browser's most, HOLD_HZ); the latency of a press is from the client's click to
     the first TCP readout the client receives that shows it (the machine's monotonic clock,
     stamped in the clients' process); the server records which presses it carried out and which
     its deadman dropped (``PressGate``). Printed: p50, p95, p99 and max latency, presses asked,
     answered, dropped and unanswered (not shown 3 s after the last press), steps/s achieved
     (shown by the readout) against asked, per session.

The verdict (RESULT) is D's: steps actually achieved and the latency, not CPU. MET when p99 <
100 ms, every press was answered and at least 95 % of the steps asked were achieved, with the
session count given (``--sessions``). CPU is printed as information: sessions per core at
30 steps/s = 1 / (30 * process CPU per step) (paced runs: includes the CPU the process spends
between steps); budget <= 1.11 ms per step for 30 sessions per core. CPU alone does
not say whether the steps were achieved: C counts the steps its motion listener saw, and held
keys tick on the server's own 20 Hz clock whatever the clients ask.
On this machine a step costs more CPU when the process idles between steps (caches and vCPU
go cold), so B and C, paced like real use, are the honest figures; A is the cost of a step
in a hot loop. Browsers send hold messages through one 50 ms slot (viser's client throttle),
so a real browser jogs at most 20 steps/s (HOLD_HZ): 30/s is the issue's, harder, load.

Classroom ("gradebook writes do not raise the jog step cost"). A second server in the
same process runs in ``--class`` mode (a gradebook in a temporary folder), its N clients' sessions
each named through the "Your name" prompt's own callback, so ``ClassRoom.named`` subscribes a
``TraineeRecorder`` to each session's change signal exactly as for a browser. A, B and C are
measured on both servers in the order off on on off ... (``--rounds``, default 4; the medians
are printed, and each round's figure) and
shown side by side with the ratio on/off; then every session of each server opens an XYZ 4-point
wizard and presses Record ``--touches`` times (the Calibrate tab's click path: lock, batch, one
change signal; with the class on, each press is a committed ``record_touch``): thread CPU, wall
time (the event loop is blocked that long) and process CPU per recorded touch, on and off. The
ratios are the figures (no timed assertion); ``--quick`` is run by
tests/app/test_bench_server_runs.py.

    .venv/bin/python tests/bench/bench_server.py                # 30 sessions (the target)
    .venv/bin/python tests/bench/bench_server.py --sessions 8 --seconds 3
    .venv/bin/python tests/bench/bench_server.py --quick        # smoke test (2 sessions)
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
TESTS = ROOT / "tests"
STEP_HZ = 30.0
TARGET_SESSIONS = 30
PRESS_HZ = 20.0
"""D: presses per second per client (a browser sends at most 20 per second, HOLD_HZ)."""
PRESS_MM = 0.1
ANSWER_WAIT_S = 3.0
"""D: a press not shown by the readout this long after the last press is unanswered."""
P99_TARGET_MS = 100.0
ACHIEVED_SHARE = 0.95
"""The verdict: at least this share of the steps asked must have been achieved (shown)."""
PLUS, MINUS = "X +", "X −"

CLIENTS_SCRIPT = r"""
import json, sys, threading, time
from support.wsclient import ReadoutClient
clients = [ReadoutClient({port}, ({plus!r}, {minus!r})) for _ in range({n})]   # connected in this order
for c in clients:
    if not c.found.wait(60):
        raise SystemExit("a client never saw the jog buttons")
print("ready", flush=True)

def hold(c, i, hz, seconds, frequency, n):
    period = 1.0 / hz
    t0 = time.perf_counter() + period * i / n          # spread the clients over the period
    k = 0
    while True:
        t = t0 + k * period
        if t - t0 > seconds:
            break
        delay = t - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        c.hold_tick({plus!r} if (k // 5) % 2 == 0 else {minus!r}, frequency)
        k += 1

def press(c, i, hz, seconds, n, sends):
    period = 1.0 / hz
    t0 = time.perf_counter() + period * i / n
    k = 0
    while k * period <= seconds:
        delay = t0 + k * period - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        sends.append(time.monotonic())
        c.click({plus!r})
        k += 1

for line in sys.stdin:
    cmd = line.split()
    if not cmd or cmd[0] == "quit":
        break
    if cmd[0] == "press":                      # press X + at hz for seconds, wait, report the timings
        hz, seconds, wait = (float(v) for v in cmd[1:4])
        marks = [len(c.readouts) for c in clients]
        x0 = [c.readouts[-1][1] if c.readouts else None for c in clients]
        sends = [[] for _ in clients]
        threads = [threading.Thread(target=press, args=(c, i, hz, seconds, len(clients), sends[i]))
                   for i, c in enumerate(clients)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        time.sleep(wait)
        print(json.dumps({{"sends": sends, "x0": x0,
                           "readouts": [c.readouts[m:] for c, m in zip(clients, marks)]}}), flush=True)
        continue
    hz, seconds, frequency = (float(v) for v in cmd[1:4])
    threads = [threading.Thread(target=hold, args=(c, i, hz, seconds, frequency, len(clients)))
               for i, c in enumerate(clients)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    print("done", flush=True)
for c in clients:
    c.close()
"""


def free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def install_baseline(session: Any) -> None:
    """Swap the scene's and jog panel's subscriptions for :class:`NaiveRenderer` and its X jog keys' hold
    callbacks for plain ones (viser runs those in its thread pool: the straightforward way)."""
    from tcp_pendant.views.pendant_panel import HOLD_HZ

    with session.lock:
        naive = NaiveRenderer(session)

        def baseline(change: Any) -> None:
            if change.pose:
                naive()
        # the scene's and the jog panel's subscriptions out, the baseline in
        session._subscribers[:] = [baseline] + [f for f in session._subscribers
                                                if type(getattr(f, "__self__", None)).__name__
                                                not in ("SceneView", "PendantPanel")]
        pendant = session.views["pendant"]
        for sign in (1, -1):
            def hold(_event: Any, sign: int = sign) -> None:
                pendant._jog("X", sign, hold_tick=True)
            pendant.cart_buttons[("X", sign)]._button_impl.hold_cbs_from_freq[HOLD_HZ] = [session.loop.guard(hold)]


class NaiveRenderer:
    """The baseline: what a straightforward implementation sends per move (module docstring)."""

    def __init__(self, session: Any) -> None:
        import yourdfpy
        from viser.extras import ViserUrdf

        self.session = session
        client = session.client
        urdf = yourdfpy.URDF.load(str(session.controller.kinematics.urdf_path), load_meshes=False,
                                  build_collision_scene_graph=False, load_collision_meshes=False)
        self.robot = ViserUrdf(client, urdf, root_node_name="/baseline_robot", load_meshes=False)
        self.gizmo = client.scene.add_transform_controls("/baseline_gizmo", scale=0.14)
        self.tcp_md = client.gui.add_markdown("")
        self.touch_md = client.gui.add_markdown("")
        self.joints_md = client.gui.add_markdown("")

    def __call__(self) -> None:
        from scipy.spatial.transform import Rotation

        from tcp_pendant.pendant import joint_readout_markdown, tcp_readout_markdown, touch_indicator_markdown

        c = self.session.controller
        self.robot.update_cfg(c.q_rad)
        T = c.T_world_tcp()
        self.gizmo.wxyz = np.roll(Rotation.from_matrix(T[:3, :3]).as_quat(), 1)
        self.gizmo.position = T[:3, 3]
        tool = c.active_tool
        self.tcp_md.content = tcp_readout_markdown(c.readout("WORLD"), None if tool is None else tool.name)
        self.touch_md.content = touch_indicator_markdown(c.touch_geometry(), hide_distance=False)
        self.joints_md.content = joint_readout_markdown(c.joint_angles_deg())


def set_increment(sessions: list[Any], increment: str, override_pct: float) -> None:
    for s in sessions:
        with s.lock:
            s.jogger.settings = s.jogger.settings.with_(increment=increment, override_pct=override_pct,
                                                        frame="WORLD", mode="Cartesian")
            s.jogger.release()


def step(s: Any, sign: int) -> None:
    with s.lock:
        res = s.jogger.key("X", sign)
        s.moved()
    if res is None or not res.ok:
        raise RuntimeError(f"jog failed: {res}")


def hot_loop(sessions: list[Any], steps: int) -> dict[str, float]:
    """A: back to back."""
    set_increment(sessions, "1", 50.0)
    for s in sessions:                                  # warm-up
        step(s, 1)
        step(s, -1)
    time.sleep(0.3)
    per_step: list[float] = []
    p0 = time.process_time()
    for i in range(steps):
        sign = 1 if (i // 5) % 2 == 0 else -1
        for s in sessions:
            t0 = time.thread_time()
            step(s, sign)
            per_step.append(time.thread_time() - t0)
    time.sleep(0.3)                                    # let the event loop send what was queued
    n = steps * len(sessions)
    per = np.array(per_step) * 1e3
    return {"median_ms": float(np.median(per)), "p95_ms": float(np.percentile(per, 95)),
            "process_ms": (time.process_time() - p0) / n * 1e3}


def breakdown(sessions: list[Any], steps: int) -> tuple[list[tuple[str, float]], float, float, list[tuple[str, float]]]:
    """Where the thread's time goes in a hot-loop step (instrumented pass, not used for the
    figures above): per-step thread CPU of the jog, of each subscriber to the change signal, the
    rest of ``Session.moved``; plus viser messages queued per step and process CPU per step; and
    (not additive, the last list) two parts of the rest - the pose state (one FK pass) and the
    atomic block's end (viser wakes its loop) - and ``Session.moved`` as a whole in a second,
    uninstrumented pass (median: the wrappers' own clock calls are not in it)."""
    from viser.infra._async_message_buffer import AsyncMessageBuffer

    acc: dict[str, float] = {}
    pushes = [0]
    POSE, ATOMIC = "of the rest: the pose state (Session.pose_state, one FK pass)", \
        "of the rest: the atomic block's end (viser wakes its event loop)"

    def timed(name: str, fn: Any) -> Any:
        def wrapper(*a: Any, **k: Any) -> Any:
            t0 = time.thread_time()
            try:
                return fn(*a, **k)
            finally:
                acc[name] = acc.get(name, 0.0) + time.thread_time() - t0
        return wrapper

    def label(fn: Any, kind: str) -> str:
        name = getattr(fn, "__qualname__", type(fn).__name__)
        return f"{kind} {name.replace('.<locals>', '')}"

    saved = []
    for s in sessions:
        saved.append((s, list(s._subscribers), s.jogger.key))
        s._subscribers[:] = [timed(label(f, "subscriber"), f) for f in s._subscribers]
        s.jogger.key = timed("jog (controller)", s.jogger.key)
        s.pose_state = timed(POSE, s.pose_state)
    real_push, real_end = AsyncMessageBuffer.push, AsyncMessageBuffer.atomic_end

    def counting_push(self: Any, message: Any) -> None:
        pushes[0] += 1
        real_push(self, message)

    AsyncMessageBuffer.push = counting_push  # type: ignore[method-assign]
    AsyncMessageBuffer.atomic_end = timed(ATOMIC, real_end)  # type: ignore[method-assign]
    set_increment(sessions, "1", 50.0)
    try:
        time.sleep(0.3)
        moved = 0.0
        p0 = time.process_time()
        for i in range(steps):
            sign = 1 if (i // 5) % 2 == 0 else -1
            for s in sessions:
                with s.lock:
                    s.jogger.key("X", sign)
                    t0 = time.thread_time()
                    s.moved()
                    moved += time.thread_time() - t0
        time.sleep(0.3)
        process = time.process_time() - p0
    finally:
        AsyncMessageBuffer.push = real_push  # type: ignore[method-assign]
        AsyncMessageBuffer.atomic_end = real_end  # type: ignore[method-assign]
        for s, subscribers, key in saved:
            s._subscribers[:] = subscribers
            s.jogger.key = key
            del s.pose_state                             # the class's method again
    n = steps * len(sessions)
    parts = [(k, v / n * 1e3) for k, v in acc.items() if k not in (POSE, ATOMIC)]
    inside = sum(v for k, v in parts if not k.startswith("jog"))
    parts.append(("rest of Session.moved (lock, pose state, atomic block, subscriber loop)", moved / n * 1e3 - inside))
    alone: list[float] = []
    for i in range(steps):                               # the same steps back, nothing instrumented
        sign = -1 if (i // 5) % 2 == 0 else 1
        for s in sessions:
            with s.lock:
                s.jogger.key("X", sign)
                t0 = time.thread_time()
                s.moved()
                alone.append(time.thread_time() - t0)
    time.sleep(0.3)
    of_rest = [(k, acc.get(k, 0.0) / n * 1e3) for k in (POSE, ATOMIC)]
    of_rest.append(("Session.moved as a whole, uninstrumented pass (median)", float(np.median(alone)) * 1e3))
    return parts, pushes[0] / n, process / n * 1e3, of_rest


def paced_direct(sessions: list[Any], seconds: float) -> dict[str, float]:
    """B: every session STEP_HZ steps/s, spread evenly, called from this thread."""
    set_increment(sessions, "1", 50.0)
    period = 1.0 / STEP_HZ
    n = len(sessions)
    ticks = int(seconds * STEP_HZ)
    time.sleep(0.3)
    p0, w0 = time.process_time(), time.perf_counter()
    for k in range(ticks):
        sign = 1 if (k // 5) % 2 == 0 else -1
        for j, s in enumerate(sessions):
            delay = w0 + (k + j / n) * period - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
            step(s, sign)
    wall = time.perf_counter() - w0
    time.sleep(0.3)
    steps = ticks * n
    return {"process_ms": (time.process_time() - p0) / steps * 1e3, "rate": steps / wall / n}


def paced_end_to_end(sessions: list[Any], clients: subprocess.Popen[str], seconds: float,
                     counts: dict[int, int]) -> dict[str, float]:
    """C: the clients hold the X keys at STEP_HZ; the server does the rest."""
    from tcp_pendant.pendant.jogging import LINEAR_SPEED_MM_S
    from tcp_pendant.views.pendant_panel import HOLD_HZ

    # continuous jog: speed * override * dt = 1 mm per tick at STEP_HZ
    set_increment(sessions, "Cont.", 100.0 * STEP_HZ / LINEAR_SPEED_MM_S)
    time.sleep(0.3)
    before = sum(counts.values())
    p0, w0 = time.process_time(), time.perf_counter()
    assert clients.stdin is not None and clients.stdout is not None
    clients.stdin.write(f"hold {STEP_HZ} {seconds} {HOLD_HZ}\n")
    clients.stdin.flush()
    if clients.stdout.readline().strip() != "done":
        raise RuntimeError("the clients did not finish holding")
    wall = time.perf_counter() - w0
    last, still = -1, 0
    while still < 3:                                  # until the last queued ticks are done
        time.sleep(0.1)
        now = sum(counts.values())
        still = still + 1 if now == last else 0
        last = now
    steps = sum(counts.values()) - before
    if steps == 0:
        raise RuntimeError("no jog step was made by the hold messages")
    return {"process_ms": (time.process_time() - p0) / steps * 1e3, "rate": steps / wall / len(sessions)}


def press_to_readout(rig: Any, hz: float, seconds: float) -> dict[str, Any]:
    """D: every client clicks "X +" (0.1 mm increments) ``hz`` times a second for ``seconds``;
    the latency of a press is from the client's click to the first TCP readout the client
    receives that shows it (both stamped with the machine's monotonic clock, in the clients'
    process). Which presses the server carried out (in order) and which its deadman dropped
    is recorded on the server (``Jogger.key``, ``PressGate.admit``); the m-th press carried out is shown once the
    readout is ``m * 0.1 mm`` past where it was. Unanswered: presses not shown within
    ``ANSWER_WAIT_S`` of the last press (dropped, never reached, or not yet shown).
    Returns the latencies (ms) and the counts."""
    sessions = [rig.app.sessions[k] for k in sorted(rig.app.sessions)]   # client id = connection order
    set_increment(sessions, str(PRESS_MM), 50.0)
    outcomes: list[list[bool | None]] = [[] for _ in sessions]   # per press: moved fully, or None: dropped
    saved = []
    for s, out in zip(sessions, outcomes):
        key, admit = s.jogger.key, s.jogger.gate.admit

        def recording(axis: Any, sign: int, *, hold_tick: bool = False, key: Any = key,
                      out: list[bool | None] = out) -> Any:
            res = key(axis, sign, hold_tick=hold_tick)
            if not hold_tick:
                out.append(res is not None and bool(res.ok))
            return res

        def gate(arrived_s: float | None, admit: Any = admit, out: list[bool | None] = out) -> bool:
            ok = bool(admit(arrived_s))
            if not ok:
                out.append(None)
            return ok
        s.jogger.key = recording
        s.jogger.gate.admit = gate
        saved.append((s, key, admit))
    time.sleep(0.3)
    clients = rig.clients
    assert clients.stdin is not None and clients.stdout is not None
    steps0 = sum(rig.counts.values())
    p0 = time.process_time()
    try:
        clients.stdin.write(f"press {hz} {seconds} {ANSWER_WAIT_S}\n")
        clients.stdin.flush()
        data = json.loads(clients.stdout.readline())
    finally:
        for s, key, admit in saved:
            s.jogger.key = key
            s.jogger.gate.admit = admit
    process = time.process_time() - p0
    latencies: list[float] = []
    asked = answered = dropped = 0
    for i, (out, sends, x0, reads) in enumerate(zip(outcomes, data["sends"], data["x0"], data["readouts"])):
        if x0 is None:
            raise RuntimeError(f"client {i} never saw a TCP readout")
        if False in out:
            raise RuntimeError(f"session {i}: a press did not move its full {PRESS_MM} mm (a limit or contact)")
        asked += len(sends)
        dropped += out.count(None)
        carried = [k for k, o in enumerate(out) if o]
        shown = [(t, round((x - x0) / PRESS_MM)) for t, x in reads]
        if shown and shown[-1][1] > len(carried):
            raise RuntimeError(f"client {i}'s readout shows {shown[-1][1]} presses, its session carried out "
                               f"{len(carried)}: clients and sessions are not paired as they connected")
        j = 0
        for m, k in enumerate(carried, start=1):
            while j < len(shown) and shown[j][1] < m:
                j += 1
            if j == len(shown):
                break
            latencies.append((shown[j][0] - sends[k]) * 1e3)
            answered += 1
    lat = np.array(latencies) if latencies else np.array([math.nan])
    steps = sum(rig.counts.values()) - steps0
    return {"p50": float(np.percentile(lat, 50)), "p95": float(np.percentile(lat, 95)),
            "p99": float(np.percentile(lat, 99)), "max": float(lat.max()), "asked": asked,
            "answered": answered, "dropped": dropped, "unanswered": asked - answered,
            "rate": answered / seconds / len(sessions), "asked_rate": asked / seconds / len(sessions),
            "process_ms": process / max(steps, 1) * 1e3}


def press_verdict(d: dict[str, Any]) -> tuple[bool, str]:
    """MET when p99 < P99_TARGET_MS, every press was answered and at least ACHIEVED_SHARE of
    the steps asked were achieved (shown by the readout)."""
    ok = (d["p99"] < P99_TARGET_MS and d["unanswered"] == 0 and d["rate"] >= ACHIEVED_SHARE * d["asked_rate"])
    return ok, "MET" if ok else "NOT MET"


def per_core(process_ms: float) -> float:
    return 1.0 / (STEP_HZ * process_ms / 1e3)


class Rig:
    """One pendant server in this process and its headless clients (a separate process).

    Args:
        n: sessions (= websocket clients).
        tmp: folder of the tool library (and of the gradebook).
        class_db: the gradebook file: ``--class`` mode, every session named by its "Your name"
            prompt (the server's own wiring: ``ClassRoom.attach`` at connect, the prompt's Join
            calls ``ClassRoom.named``, which subscribes the session's ``TraineeRecorder``);
            None: the app as it runs without a class.
    """

    def __init__(self, n: int, tmp: Path, class_db: Path | None = None) -> None:
        from tcp_pendant.serve.server import AppConfig, PendantApp

        tmp.mkdir(parents=True, exist_ok=True)
        self.app = PendantApp(AppConfig(port=free_port(), tool_library=tmp / "tools.json", class_db=class_db))
        self.app.start()
        script = CLIENTS_SCRIPT.format(port=self.app.port, n=n, plus=PLUS, minus=MINUS)
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")]))
        self.clients = subprocess.Popen([sys.executable, "-c", script], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, text=True, env=env)   # support.wsclient
        self.counts: dict[int, int] = {}
        self.sessions: list[Any] = []
        assert self.clients.stdout is not None
        if self.clients.stdout.readline().strip() != "ready":
            raise RuntimeError("the clients did not connect")
        deadline = time.monotonic() + 60
        while len(self.app.sessions) < n and time.monotonic() < deadline:
            time.sleep(0.02)
        self.sessions = list(self.app.sessions.values())
        if len(self.sessions) != n:
            raise RuntimeError(f"only {len(self.sessions)} of {n} sessions connected")
        lock = threading.Lock()
        for i, s in enumerate(self.sessions):
            self.counts[i] = 0

            def count(i: int = i) -> None:
                with lock:
                    self.counts[i] += 1
            s.add_motion_listener(count)
        if class_db is not None:
            self._name_trainees()

    def _name_trainees(self) -> None:
        """Every session types a name and joins the class (the prompt's own callback)."""
        classroom = self.app.classroom
        if classroom is None:
            raise RuntimeError("the server did not start its classroom")
        for i, s in enumerate(self.sessions):
            prompt = s.views["identity"]
            with s.lock:
                prompt.name_field.value = f"Trainee {i + 1:02d}"
                prompt._start()
            if prompt.name is None:
                raise RuntimeError(f"session {i + 1} was not named: {prompt.message.content}")
        named = [row for row in classroom.trainee_statuses() if row.connected]
        if len(named) != len(self.sessions):
            raise RuntimeError(f"{len(named)} of {len(self.sessions)} sessions have a recorder")

    def measure(self, steps: int, seconds: float) -> dict[str, dict[str, float]]:
        """A, B and C on this rig's sessions."""
        return {"A": hot_loop(self.sessions, steps), "B": paced_direct(self.sessions, seconds),
                "C": paced_end_to_end(self.sessions, self.clients, seconds, self.counts)}

    def close(self) -> None:
        if self.clients.stdin is not None:
            try:
                self.clients.stdin.write("quit\n")
                self.clients.stdin.flush()
            except OSError:
                pass
        try:
            self.clients.wait(30)
        except subprocess.TimeoutExpired:
            self.clients.kill()
        self.app.stop()


def _in_action(s: Any, fn: Any) -> None:
    """``fn()`` the way a Calibrate click runs (``WizardMenuView.action``): session lock, one
    batch, one change signal with ``wizard``."""
    with s.lock:
        with s.batch():
            try:
                fn()
            finally:
                s.changed(wizard=True)


def wizard_touches(sessions: list[Any], per_session: int) -> dict[str, float]:
    """CPU of a recorded wizard touch: every session opens an XYZ 4-point wizard and presses
    Record ``per_session`` times (each press stores a new pose for the step: a new touch),
    round robin; then the wizards are cancelled (so the later runs jog without one).

    Returns thread CPU per touch (median; the Record click: workflow, every view's re-render,
    with the classroom the recorder's gradebook write), its wall time (median, p95: the event
    loop is blocked that long; includes the write's fsync) and process CPU per touch."""
    for s in sessions:
        _in_action(s, lambda s=s: s.wizard_commands.start("xyz4"))
    time.sleep(0.3)
    cpu: list[float] = []
    wall: list[float] = []
    p0 = time.process_time()
    for _ in range(per_session):
        for s in sessions:
            t0, w0 = time.thread_time(), time.perf_counter()
            _in_action(s, s.wizard_commands.record_step)
            cpu.append(time.thread_time() - t0)
            wall.append(time.perf_counter() - w0)
    time.sleep(0.3)
    process = time.process_time() - p0
    for s in sessions:
        _in_action(s, s.wizard_commands.cancel)
    time.sleep(0.3)
    n = len(cpu)
    return {"thread_ms": float(np.median(cpu)) * 1e3, "wall_ms": float(np.median(wall)) * 1e3,
            "wall_p95_ms": float(np.percentile(wall, 95)) * 1e3, "process_ms": process / n * 1e3}


def median_of(rounds: list[dict[str, dict[str, float]]]) -> dict[str, dict[str, float]]:
    """Median of each figure over the rounds (one round disturbed by another process on the
    shared machine does not move it)."""
    return {k: {f: float(np.median([r[k][f] for r in rounds])) for f in rounds[0][k]} for k in rounds[0]}


def row(name: str, a: float, b: float, unit: str = "ms") -> None:
    """One line of a comparison table: ``a``, ``b`` and their ratio ``a / b``."""
    print(f"  {name:<58} {a:8.3f} {unit}  {b:8.3f} {unit}   {a / b:6.2f}")


def step_rows(a: dict[str, dict[str, float]], b: dict[str, dict[str, float]]) -> None:
    """The jog-step rows (A hot loop, B paced, C end to end) of two measured variants."""
    row("A hot loop: thread CPU per step, median", a["A"]["median_ms"], b["A"]["median_ms"])
    row("A hot loop: thread CPU per step, p95", a["A"]["p95_ms"], b["A"]["p95_ms"])
    row("A hot loop: process CPU per step", a["A"]["process_ms"], b["A"]["process_ms"])
    row(f"B paced {STEP_HZ:.0f}/s per session, direct: process CPU per step",
        a["B"]["process_ms"], b["B"]["process_ms"])
    row(f"C paced {STEP_HZ:.0f}/s per session, end to end: process CPU/step",
        a["C"]["process_ms"], b["C"]["process_ms"])

def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="2 sessions, short runs: smoke test")
    ap.add_argument("--sessions", type=int, default=TARGET_SESSIONS)
    ap.add_argument("--seconds", type=float, default=4.0, help="length of each paced run")
    ap.add_argument("--steps", type=int, default=40, help="hot-loop steps per session")
    ap.add_argument("--touches", type=int, default=10, help="wizard touches per session")
    ap.add_argument("--rounds", type=int, default=4,
                    help="classroom off/on rounds, in the order off on on off ... (ABBA: cancels a drift); "
                         "the median of the rounds is printed")
    args = ap.parse_args(argv)
    n, seconds, steps, touches, rounds = ((2, 1.0, 10, 3, 1) if args.quick else
                                          (args.sessions, args.seconds, args.steps, args.touches,
                                           max(1, args.rounds)))

    tmp = Path(tempfile.mkdtemp(prefix="bench_server_"))
    rigs: dict[str, Rig] = {}
    try:
        rigs["off"] = Rig(n, tmp / "off")
        rigs["on"] = Rig(n, tmp / "on", class_db=tmp / "on" / "class.db")
        load = os.getloadavg()
        print(f"bench_server: {n} sessions built by on_client_connect for {n} real websocket clients (headless, "
              f"viser protocol, separate process: their CPU is not counted; no browser); server in this "
              f"process, pid {os.getpid()}; a step = 1 mm Cartesian jog WORLD X of the KR 6 + pointer and "
              f"every update sent; load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f} on "
              f"{os.cpu_count()} CPUs (shared: trust the ratios)")
        print(f"  two servers in this process, each with {n} clients: the app as today (no class) and "
              f"--class (a gradebook in a temporary folder, every session a named trainee with its "
              f"recorder); measured in the order {' '.join(['off on', 'on off'][r % 2] for r in range(rounds))}")
        measured: dict[str, list[dict[str, dict[str, float]]]] = {"off": [], "on": []}
        touch_runs: dict[str, list[dict[str, float]]] = {"off": [], "on": []}
        for r in range(rounds):
            for which in (("off", "on") if r % 2 == 0 else ("on", "off")):
                measured[which].append(rigs[which].measure(steps, seconds))
        press = press_to_readout(rigs["off"], PRESS_HZ, seconds)
        for which in ("off", "on"):
            touch_runs[which].append(wizard_touches(rigs[which].sessions, touches))
        parts, msgs, process, of_rest = breakdown(rigs["off"].sessions, max(5, steps // 4))
        parts_on, _, _, _ = breakdown(rigs["on"].sessions, max(5, steps // 4))
        app_r = median_of(measured["off"])
        class_r = median_of(measured["on"])
        book = rigs["on"].app.gradebook
        assert book is not None
        rigs["on"].close()
        del rigs["on"]
        time.sleep(1.0)
        for s in rigs["off"].sessions:
            install_baseline(s)
        time.sleep(1.0)
        base_r = rigs["off"].measure(steps, seconds)

        print(f"  {'':<58} {'app':>11}  {'baseline':>11}   app/baseline")
        step_rows(app_r, base_r)
        for key, what in (("B", "direct"), ("C", "end to end")):
            print(f"  {key} achieved steps/s per session ({what}): app {app_r[key]['rate']:.1f}, "
                  f"baseline {base_r[key]['rate']:.1f} (asked {STEP_HZ:.0f})")
        print(f"  D press to readout (the app; every client clicks X + {PRESS_HZ:.0f} times a second, "
              f"{PRESS_MM} mm, for {seconds:g} s; from the click to the readout that shows it, at the client):")
        print(f"    p50 {press['p50']:.1f} ms, p95 {press['p95']:.1f} ms, p99 {press['p99']:.1f} ms, max "
              f"{press['max']:.1f} ms; {press['asked']} presses, {press['answered']} answered, "
              f"{press['dropped']} dropped by the deadman (the server was busy), {press['unanswered']} unanswered "
              f"{ANSWER_WAIT_S:g} s after the last; achieved {press['rate']:.1f} steps/s per session (asked "
              f"{press['asked_rate']:.1f}); process CPU {press['process_ms']:.3f} ms per step")
        total = sum(v for _, v in parts)
        print(f"  where a hot-loop step of the app goes (instrumented pass; thread CPU per step; "
              f"{msgs:.1f} viser messages queued per step; the session computes the pose state, one "
              f"FK pass, once per change signal, in 'rest of Session.moved'):")
        for name, v in parts:
            print(f"    {name:<72} {v:6.3f} ms")
        for name, v in of_rest:
            print(f"      {name:<70} {v:6.3f} ms")
        print(f"    {'viser event loop and other threads (process - thread: serialise, compress, send)':<72} "
              f"{process - total:6.3f} ms")
        budget = 1e3 / (STEP_HZ * TARGET_SESSIONS)
        for key, what in (("A", "hot loop"), ("B", "paced, direct"), ("C", "paced, end to end")):
            a, b = per_core(app_r[key]["process_ms"]), per_core(base_r[key]["process_ms"])
            print(f"  sessions per core at {STEP_HZ:.0f} steps/s ({key}, {what}): app {a:.1f}, baseline {b:.1f}")

        print_classroom(n, app_r, class_r, touch_runs, parts, parts_on, book_rows=book_touches(tmp / "on" / "class.db"))
        print("  the same figures round by round (process CPU per step, ms; the spread is the noise the ratios "
              "above sit in):")
        for key in ("A", "B", "C"):
            print(f"    {key}: class off " + ", ".join(f"{r[key]['process_ms']:.3f}" for r in measured["off"])
                  + "; class on " + ", ".join(f"{r[key]['process_ms']:.3f}" for r in measured["on"]))

        c_sessions = per_core(app_r["C"]["process_ms"])
        _, verdict = press_verdict(press)
        print(f"RESULT: {n} sessions asked {press['asked_rate']:.1f} jog presses/s each: achieved "
              f"{press['rate']:.1f} steps/s per session, press to readout p50 {press['p50']:.1f} ms, p95 "
              f"{press['p95']:.1f} ms, p99 {press['p99']:.1f} ms, {press['unanswered']} of {press['asked']} presses "
              f"unanswered ({press['dropped']} dropped by the deadman). Target: p99 < {P99_TARGET_MS:.0f} ms, every "
              f"press answered, >= {ACHIEVED_SHARE:.0%} of the steps asked achieved: {verdict}")
        print(f"  CPU (information, not the verdict): {c_sessions:.1f} sessions per core at {STEP_HZ:.0f} steps/s "
              f"by CPU alone, end to end (process CPU {app_r['C']['process_ms']:.3f} ms per step, "
              f"{app_r['C']['process_ms'] / base_r['C']['process_ms']:.2f}x the baseline's; budget {budget:.2f} ms); C "
              f"achieved {app_r['C']['rate']:.1f} of {STEP_HZ:.0f} steps/s asked (held keys tick on the server's "
              f"20 Hz clock); hot loop {app_r['A']['median_ms']:.3f} ms median, {app_r['A']['p95_ms']:.3f} ms p95 "
              f"per step (thread)")
        jog = class_r["C"]["process_ms"] / app_r["C"]["process_ms"]
        print(f"RESULT classroom: a jog step with the gradebook on costs {jog:.2f}x the app's without (C, end to "
              f"end, {n} sessions); a recorded wizard touch {touch_ratio(touch_runs):.2f}x (process CPU)")
    finally:
        for rig in rigs.values():
            rig.close()
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


def book_touches(db: Path) -> int:
    """Touches in the gradebook file (the writes really happened)."""
    import sqlite3

    with sqlite3.connect(db) as con:
        return int(con.execute("SELECT COUNT(*) FROM touches").fetchone()[0])


def touch_ratio(touch_runs: dict[str, list[dict[str, float]]]) -> float:
    on = float(np.mean([t["process_ms"] for t in touch_runs["on"]]))
    off = float(np.mean([t["process_ms"] for t in touch_runs["off"]]))
    return on / off


def print_classroom(n: int, app_r: dict[str, dict[str, float]], class_r: dict[str, dict[str, float]],
                    touch_runs: dict[str, list[dict[str, float]]], parts: list[tuple[str, float]],
                    parts_on: list[tuple[str, float]], book_rows: int) -> None:
    """The classroom table: the same figures with the gradebook on and off, and their ratio."""
    print(f"  classroom (--class: gradebook on, {n} named trainees) against the app as today (no class), "
          f"same run, same session count:")
    print(f"  {'':<58} {'class on':>11}  {'class off':>11}   on/off")

    step_rows(class_r, app_r)
    on = {f: float(np.mean([t[f] for t in touch_runs["on"]])) for f in touch_runs["on"][0]}
    off = {f: float(np.mean([t[f] for t in touch_runs["off"]])) for f in touch_runs["off"][0]}
    row("wizard touch (Record): thread CPU, median", on["thread_ms"], off["thread_ms"])
    row("wizard touch (Record): wall (loop blocked), median", on["wall_ms"], off["wall_ms"])
    row("wizard touch (Record): wall (loop blocked), p95", on["wall_p95_ms"], off["wall_p95_ms"])
    row("wizard touch (Record): process CPU per touch", on["process_ms"], off["process_ms"])
    extra = [(name, v) for name, v in parts_on if name not in dict(parts)]
    for name, v in extra:
        print(f"    classroom's own subscriber in a hot-loop step: {name:<40} {v:6.3f} ms")
    print(f"  gradebook: {book_rows} touches written (every Record press of the class-on run)")


if __name__ == "__main__":
    sys.exit(main())
