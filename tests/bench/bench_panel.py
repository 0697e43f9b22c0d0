"""Server CPU of a class's jog step in the jog panel's readouts and in the jogger's own work
around the IK, the app's code against the code as it was (``panel_yardstick.py``), measured in
one process, alternating.

The step is the class's: the pendant's "X +" / "X −" key pressed (0.1 mm increments, WORLD
frame) on the KR 6 with the pointer (the default robot and tool), through the press path a
browser's click takes (``PendantPanel._jog`` -> ``MotionCommands.jog`` -> ``Jogger.key`` -> the change
signal), over N sessions built by ``on_client_connect`` for N headless websocket clients in a
separate process (``bench_server.Rig``: real viser messages are queued and sent). Five presses
one way, five back, round robin over the sessions.

Per step, the thread CPU of the calling thread (``time.thread_time_ns`` around each part: not the
time it waits for the GIL while viser's event loop sends, nor preemption on the shared machine;
each clock read costs ~2 us here, counted alike in old and new - it makes the ratios
conservative, most for the short jogger part) of

* the jog panel's subscriber to the change signal (``PendantPanel.on_change``: status line,
  TCP readout, touch indicator and Δ line, joint readout, sliders; the viser messages queued);
* the jogger's own work: ``Jogger.key`` less ``VirtualController.jog_cartesian`` inside it (the
  true tool tip for the stop at contact, the contact pre-test, the step's arithmetic);
* the whole press (``PendantPanel._jog`` with every subscriber: scene, wizards, ...), for scale.

Rounds in the order old new new old ... (ABBA: cancels a drift), the same sessions; medians of
the steps per round, then the median of the rounds and of the per-round ratios new/old. The
machine is shared: trust the ratios.

    .venv/bin/python tests/bench/bench_panel.py                  # 10 sessions, 8 rounds
    .venv/bin/python tests/bench/bench_panel.py --sessions 30 --rounds 6
    .venv/bin/python tests/bench/bench_panel.py --quick          # smoke test
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

if __name__ == "__main__":                  # run as a script: tests/ on sys.path (support.*, bench.*)
    import _tests_on_path  # noqa: F401
from bench.bench_server import Rig
from bench.panel_yardstick import install_legacy, install_new

PRESS_MM = "0.1"
PARTS = ("panel", "jogger", "press")
LABELS = {"panel": "jog panel (PendantPanel.on_change) per step",
          "jogger": "jogger's own work (Jogger.key - jog_cartesian)",
          "panel+jogger": "the two together",
          "press": "whole press, every subscriber (for scale)"}


class Timers:
    """Per-step thread CPU (ns) of the parts of the step, for the round being measured."""

    def __init__(self) -> None:
        self.panel = 0
        self.key = 0
        self.ik = 0

    def wrap_panel(self, fn: Any) -> Any:
        def timed(change: Any) -> None:
            t0 = time.thread_time_ns()
            try:
                fn(change)
            finally:
                self.panel += time.thread_time_ns() - t0
        return timed

    def install(self, s: Any) -> None:
        key = type(s.jogger).key.__get__(s.jogger)
        jog_cartesian = type(s.controller).jog_cartesian.__get__(s.controller)

        def timed_key(*a: Any, **k: Any) -> Any:
            t0 = time.thread_time_ns()
            try:
                return key(*a, **k)
            finally:
                self.key += time.thread_time_ns() - t0

        def timed_ik(*a: Any, **k: Any) -> Any:
            t0 = time.thread_time_ns()
            try:
                return jog_cartesian(*a, **k)
            finally:
                self.ik += time.thread_time_ns() - t0

        s.jogger.key = timed_key
        s.controller.jog_cartesian = timed_ik


def prepare(sessions: list[Any]) -> None:
    for s in sessions:
        with s.lock:
            s.jogger.settings = s.jogger.settings.with_(increment=PRESS_MM, frame="WORLD", mode="Cartesian")
            s.jogger.release()


def run_round(sessions: list[Any], timers: Timers, steps: int, start: int) -> dict[str, list[float]]:
    """``steps`` presses per session; per-step thread CPU (us) of each part."""
    out: dict[str, list[float]] = {p: [] for p in PARTS}
    for i in range(start, start + steps):
        sign = 1 if (i // 5) % 2 == 0 else -1
        for s in sessions:
            panel = s.views["pendant"]
            timers.panel = timers.key = timers.ik = 0
            t0 = time.thread_time_ns()
            panel._jog("X", sign, hold_tick=False)
            press = time.thread_time_ns() - t0
            out["panel"].append(timers.panel / 1e3)
            out["jogger"].append((timers.key - timers.ik) / 1e3)
            out["press"].append(press / 1e3)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="2 sessions, 2 short rounds: smoke test")
    ap.add_argument("--sessions", type=int, default=10)
    ap.add_argument("--rounds", type=int, default=8, help="rounds, in the order old new new old ...")
    ap.add_argument("--steps", type=int, default=60, help="presses per session per round")
    args = ap.parse_args(argv)
    n, rounds, steps = (2, 2, 10) if args.quick else (args.sessions, max(2, args.rounds), args.steps)
    tmp = Path(tempfile.mkdtemp(prefix="bench_panel_"))
    rig = None
    try:
        rig = Rig(n, tmp)
        sessions = rig.sessions
        timers = Timers()
        for s in sessions:
            timers.install(s)
        prepare(sessions)
        per_round: dict[str, list[dict[str, float]]] = {"old": [], "new": []}
        order = [("old", "new") if r % 2 == 0 else ("new", "old") for r in range(rounds // 2 + rounds % 2)]
        flat = [w for pair in order for w in pair][:2 * ((rounds + 1) // 2)]
        done = 0
        for which in ("old", "new"):                  # warm-up, both
            for s in sessions:
                (install_legacy if which == "old" else install_new)(s, timers.wrap_panel)
            run_round(sessions, timers, 10, done)
            done += 10
        for which in flat:
            for s in sessions:
                (install_legacy if which == "old" else install_new)(s, timers.wrap_panel)
            time.sleep(0.2)                           # the event loop sends what was queued
            out = run_round(sessions, timers, steps, done)
            done += steps
            med = {p: statistics.median(v) for p, v in out.items()}
            med["panel+jogger"] = statistics.median([a + b for a, b in zip(out["panel"], out["jogger"])])
            per_round[which].append(med)
        for s in sessions:
            install_new(s)
        load = os.getloadavg()
        print(f"bench_panel: {n} sessions (real websocket clients in a separate process), presses of "
              f"{PRESS_MM} mm WORLD X of the KR 6 + pointer through PendantPanel._jog; {len(flat)} rounds of "
              f"{steps} presses per session in the order {' '.join(flat)}; thread CPU per step, medians; "
              f"load average {load[0]:.1f} on {os.cpu_count()} CPUs (shared: trust the ratios)")
        print(f"  {'':<58} {'old':>9} {'new':>9}   new/old (median of the rounds' ratios)")
        for part in ("panel", "jogger", "panel+jogger", "press"):
            old = statistics.median(r[part] for r in per_round["old"])
            new = statistics.median(r[part] for r in per_round["new"])
            ratios = [b[part] / a[part] for a, b in zip(per_round["old"], per_round["new"]) if a[part] > 0]
            ratio = statistics.median(ratios) if ratios else float("nan")
            print(f"  {LABELS[part]:<58} {old:7.1f} us {new:7.1f} us   {ratio:.2f}")
        print("  rounds (panel+jogger, us): old " + ", ".join(f"{r['panel+jogger']:.1f}" for r in per_round["old"])
              + "; new " + ", ".join(f"{r['panel+jogger']:.1f}" for r in per_round["new"]))
        both = [b["panel+jogger"] / a["panel+jogger"] for a, b in zip(per_round["old"], per_round["new"])]
        print(f"RESULT panel: the jog panel and the jogger's own work cost {statistics.median(both):.2f}x "
              f"the old code's per press (thread CPU, median of {len(both)} round pairs)")
    finally:
        if rig is not None:
            rig.close()
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
