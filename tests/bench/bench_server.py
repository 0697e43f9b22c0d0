"""Server CPU per jog step and how many sessions one core can drive at 30 jog steps/s.

How it measures (printed too): the pendant server runs in this process (a real viser server
on a free port); N headless browsers (websocket clients that speak viser's protocol and
drain every message, tests/app/wsclient.py) run in a *separate process*, so each one has a
real session built by ``on_client_connect`` and every scene/GUI update is really serialised
and sent, while the clients' own CPU is not counted. A jog step is what one press of "X +"
does: ``Jogger.key`` (1 mm Cartesian jog in WORLD: DLS on pinocchio) + ``Session.moved``
(pinocchio link poses -> 8 frame updates, gizmo, readouts, touch indicator, joint sliders,
all in one ``client.atomic()``).

Figures:
* per-step CPU of the calling thread (median, p95): jog + FK + building/queuing the messages;
* total process CPU per step (all threads: includes viser's event loop serialising and sending),
  measured over a round-robin of steps on all N sessions;
* sessions per core at 30 steps/s = 1 / (30 * total CPU per step);
* the same with the baseline scene update ``ViserUrdf.update_cfg`` (yourdfpy FK of the URDF
  and one frame per joint) instead of the pinocchio link poses, in the same run.

    .venv/bin/python tests/bench/bench_server.py            # N = 8 sessions, 150 steps each
    .venv/bin/python tests/bench/bench_server.py --quick    # smoke test
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "app"))

CLIENTS_SCRIPT = """
import sys, time
sys.path.insert(0, {app_tests!r})
from wsclient import DrainingClient
clients = [DrainingClient({port}) for _ in range({n})]
print("connected", flush=True)
sys.stdin.readline()
for c in clients:
    c.close()
"""


def free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def measure(app, sessions, steps: int, label: str) -> dict[str, float]:
    per_step: list[float] = []
    for s in sessions:                               # warm-up: 2 steps each
        for sign in (1, -1):
            with s.lock:
                s.jogger.key("X", sign)
                s.moved()
    p0 = time.process_time()
    w0 = time.perf_counter()
    for i in range(steps):
        sign = 1 if (i // 5) % 2 == 0 else -1         # back and forth, 5 mm each way
        for s in sessions:
            t0 = time.thread_time()
            with s.lock:
                res = s.jogger.key("X", sign)
                s.moved()
            per_step.append(time.thread_time() - t0)
            if res is None or not res.ok:
                raise RuntimeError(f"jog failed: {res}")
    time.sleep(0.3)                                   # let the event loop flush what was queued
    total = time.process_time() - p0
    wall = time.perf_counter() - w0
    n = steps * len(sessions)
    per = np.array(per_step)
    out = {"median_ms": float(np.median(per) * 1e3), "p95_ms": float(np.percentile(per, 95) * 1e3),
           "total_ms": total / n * 1e3, "wall_ms": wall / n * 1e3}
    out["sessions_per_core"] = 1.0 / (30.0 * out["total_ms"] / 1e3)
    print(f"  {label:<34} thread CPU/step median {out['median_ms']:.3f} ms, p95 {out['p95_ms']:.3f} ms; "
          f"process CPU/step {out['total_ms']:.3f} ms -> {out['sessions_per_core']:.0f} sessions/core at 30 steps/s")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="2 sessions, 20 steps: smoke test")
    ap.add_argument("--sessions", type=int, default=8)
    ap.add_argument("--steps", type=int, default=150)
    args = ap.parse_args(argv)
    n, steps = (2, 20) if args.quick else (args.sessions, args.steps)

    from viser.extras import ViserUrdf
    import yourdfpy

    from tcp_pendant.server import AppConfig, PendantApp

    tmp = Path(tempfile.mkdtemp(prefix="bench_server_"))
    app = PendantApp(AppConfig(port=free_port(), tool_library=tmp / "tools.json"))
    app.start()
    clients = subprocess.Popen([sys.executable, "-c", CLIENTS_SCRIPT.format(app_tests=str(ROOT / "tests" / "app"),
                                                                           port=app.port, n=n)],
                               stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert clients.stdout is not None
        clients.stdout.readline()
        deadline = time.monotonic() + 60
        while len(app.sessions) < n and time.monotonic() < deadline:
            time.sleep(0.02)
        sessions = list(app.sessions.values())
        if len(sessions) != n:
            raise RuntimeError(f"only {len(sessions)} of {n} sessions connected")
        print(f"bench_server: {n} sessions built by on_client_connect for {n} headless websocket clients "
              f"(separate process, not counted); server in this process, pid {os.getpid()}; "
              f"{steps} steps per session of a 1 mm Cartesian jog (WORLD X), KR 6 + pointer")
        ours = measure(app, sessions, steps, "pinocchio link poses (app)")

        # baseline: the same step, with the robot drawn by ViserUrdf.update_cfg (yourdfpy FK)
        urdf = yourdfpy.URDF.load(str(app.kinematics.urdf_path), load_meshes=True,
                                  build_collision_scene_graph=False, load_collision_meshes=False)
        for s in sessions:
            scene_view = s.views["scene"]
            vu = ViserUrdf(s.client, urdf, root_node_name="/baseline_robot", load_meshes=True)
            s._renderers[s._renderers.index(scene_view.render)] = (
                lambda s=s, vu=vu: vu.update_cfg(s.controller.q_rad))
        base = measure(app, sessions, steps, "baseline ViserUrdf.update_cfg")
        print(f"  speed-up of the scene update path (process CPU/step): {base['total_ms'] / ours['total_ms']:.2f}x")
        target = ours["sessions_per_core"] >= 30
        print(f"RESULT median {ours['median_ms']:.3f} ms p95 {ours['p95_ms']:.3f} ms per jog step "
              f"(thread), {ours['total_ms']:.3f} ms (process); {ours['sessions_per_core']:.0f} sessions per core "
              f"at 30 steps/s (target >= 30: {'met' if target else 'NOT met'}); baseline "
              f"{base['sessions_per_core']:.0f}")
    finally:
        if clients.stdin is not None:
            clients.stdin.write("\n")
            clients.stdin.flush()
        try:
            clients.wait(20)
        except subprocess.TimeoutExpired:
            clients.kill()
        app.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
