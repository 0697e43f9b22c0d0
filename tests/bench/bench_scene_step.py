"""Server CPU of the scene and pose-state part of a jog step, against the code as it was.

    python tests/bench/bench_scene_step.py [--quick] [--sessions N] [--steps S] [--rounds R]

The step is the class's: one 0.1 mm WORLD X increment press ("X +", back and forth, 5 presses
each way) of the KR 6 with the pointer (the default robot and tool), ``Jogger.key`` then
``Session.moved`` under the session's lock, round robin over N sessions of one in-process
server (``PendantApp``), each with a headless websocket client (``tests/support/wsclient.py``,
threads of this process draining what the server sends; their CPU is not counted: thread CPU of
the stepping thread only). Timed per step with ``time.thread_time_ns``:

* pose state: ``Session.pose_state`` (its key, its cache, and the one computation per change of
  ``controller.pose_state.pose_state``: link poses, TCP, true TCP, joint angles, touch geometry;
  the old or the new function, switched untimed);
* scene: the scene's subscriber to the change signal, ``SceneView.on_change`` (reference tip
  and beam stand checks, ``_local_poses``, ``PoseSender.send`` with the viser messages it queues).

Against a yardstick measured in the same run, interleaved: every session steps with the old code,
then with the new, ABBA tick by tick (a tick = one step of every session), ``--rounds`` rounds: the same
two parts as they were before the speed work on them (``scene_yardstick.py``: the old
``pose_state`` and the old ``on_change`` / ``_local_poses`` / ``PoseSender.send`` /
``queue_pose``, on the same scene nodes, each starting from the poses the other sent).
Printed: per part, the median over the rounds of each round's median per-step thread CPU, old and
new, and the median of the per-round ratios new / old. ``--quick`` is a smoke run.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import tcp_pendant.session as session_module
from tcp_pendant.controller.pose_state import pose_state as new_pose_state
from tcp_pendant.controller.pose_state import pose_state_key as new_pose_state_key
from tcp_pendant.serve.server import AppConfig, PendantApp

if __name__ == "__main__":                  # run as a script: tests/ on sys.path (support.*, bench.*)
    import _tests_on_path  # noqa: F401
from bench.scene_yardstick import LegacyScenePoses, legacy_pose_state, legacy_pose_state_key
from support.wsclient import DrainingClient, wait_until

PARTS = ("pose state", "scene")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="2 sessions, 2 short rounds: smoke test")
    ap.add_argument("--sessions", type=int, default=8)
    ap.add_argument("--steps", type=int, default=60, help="steps per session per round")
    ap.add_argument("--rounds", type=int, default=10, help="rounds of --steps ticks of each code, interleaved ABBA")
    args = ap.parse_args(argv)
    n, steps, rounds = (2, 10, 2) if args.quick else (args.sessions, args.steps, max(2, args.rounds))

    tmp = Path(tempfile.mkdtemp(prefix="bench_scene_"))
    app = PendantApp(AppConfig(port=0, tool_library=tmp / "tools.json"))
    app.start()
    clients: list[DrainingClient] = []
    real_pose_state, real_key = session_module.pose_state, session_module.pose_state_key
    try:
        clients = [DrainingClient(app.port) for _ in range(n)]
        wait_until(lambda: len(app.sessions) == n, timeout=120, what=f"{n} sessions")
        sessions = list(app.sessions.values())
        mode = ["new"]
        acc = {p: 0 for p in PARTS}

        def switched_pose_state(controller: Any, key: Any = None) -> Any:
            return (legacy_pose_state if mode[0] == "old" else new_pose_state)(controller, key)

        def switched_key(controller: Any) -> Any:
            return (legacy_pose_state_key if mode[0] == "old" else new_pose_state_key)(controller)

        session_module.pose_state = switched_pose_state  # type: ignore[assignment]
        session_module.pose_state_key = switched_key  # type: ignore[assignment]
        for s in sessions:
            def timed_pose_state(real: Callable[[], Any] = s.pose_state) -> Any:
                t0 = time.thread_time_ns()
                try:
                    return real()
                finally:
                    acc["pose state"] += time.thread_time_ns() - t0
            s.pose_state = timed_pose_state  # type: ignore[method-assign]
        legacies: list[LegacyScenePoses] = []
        for s in sessions:
            with s.lock:
                s.jogger.settings = s.jogger.settings.with_(increment="0.1", override_pct=100.0, frame="WORLD",
                                                            mode="Cartesian")
                s.jogger.release()
                scene = s.views["scene"]
                legacy = LegacyScenePoses(scene)
                legacies.append(legacy)
                i = next(j for j, f in enumerate(s._subscribers) if getattr(f, "__self__", None) is scene)

                def timed_scene(change: Any, new: Callable[[Any], None] = scene.on_change,
                                old: Callable[[Any], None] = legacy.on_change) -> None:
                    fn = old if mode[0] == "old" else new
                    t0 = time.thread_time_ns()
                    try:
                        fn(change)
                    finally:
                        acc["scene"] += time.thread_time_ns() - t0

                s._subscribers[i] = timed_scene

        def tick(which: str, sign: int, per: dict[str, list[int]]) -> None:
            """One step of every session with the old or the new code."""
            mode[0] = which
            if which == "old":
                for legacy in legacies:
                    legacy.take_sent()
            for s in sessions:
                for p in PARTS:
                    acc[p] = 0
                with s.lock:
                    res = s.jogger.key("X", sign)
                    s.moved()
                if res is None or not res.ok:
                    raise RuntimeError(f"jog failed: {res}")
                for p in PARTS:
                    per[p].append(acc[p])
            if which == "old":
                for legacy in legacies:
                    legacy.give_sent()

        def run_round(first: str) -> dict[str, dict[str, float]]:
            """``steps`` ticks of each, alternating tick by tick, ``first`` first."""
            second = "new" if first == "old" else "old"
            per: dict[str, dict[str, list[int]]] = {w: {p: [] for p in PARTS} for w in ("old", "new")}
            for i in range(steps):
                sign = 1 if (i // 5) % 2 == 0 else -1      # a tick of each goes the same way
                tick(first, sign, per[first])
                tick(second, -sign, per[second])          # and back: the robot stays near its start
                tick(second, sign, per[second])
                tick(first, -sign, per[first])
            time.sleep(0.05)                            # the event loop sends what was queued
            return {w: {p: statistics.median(v) / 1e3 for p, v in d.items()} for w, d in per.items()}

        run_round("old")                                # warm-up
        results: dict[str, list[dict[str, float]]] = {"old": [], "new": []}
        for r in range(rounds):
            got = run_round("old" if r % 2 == 0 else "new")
            for w in ("old", "new"):
                results[w].append(got[w])
        print(f"bench_scene_step: {n} sessions, {steps} steps each per round, {rounds} rounds (ticks of old and new code interleaved ABBA); a step = "
              f"0.1 mm WORLD X press of the KR 6 + pointer; thread CPU per step (us), median of the rounds' medians")
        print(f"  {'part':<44} {'old':>9} {'new':>9}   new/old (median of rounds)")
        rows = list(PARTS) + ["scene + pose state"]
        for p in rows:
            def fig(which: str, r: int, p: str = p) -> float:
                d = results[which][r]
                return d["scene"] + d["pose state"] if p == "scene + pose state" else d[p]
            old = statistics.median(fig("old", r) for r in range(rounds))
            new = statistics.median(fig("new", r) for r in range(rounds))
            ratio = statistics.median(fig("new", r) / fig("old", r) for r in range(rounds))
            print(f"  {p:<44} {old:9.2f} {new:9.2f}   {ratio:6.3f}")
        print("  per round, scene + pose state old/new (us): " + ", ".join(
            f"{results['old'][r]['scene'] + results['old'][r]['pose state']:.1f}/"
            f"{results['new'][r]['scene'] + results['new'][r]['pose state']:.1f}" for r in range(rounds)))
    finally:
        session_module.pose_state = real_pose_state  # type: ignore[assignment]
        session_module.pose_state_key = real_key  # type: ignore[assignment]
        for s in list(app.sessions.values()):
            s.__dict__.pop("pose_state", None)
        for c in clients:
            c.close()
        app.stop()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
