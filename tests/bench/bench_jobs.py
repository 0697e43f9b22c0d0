"""The victim's TCP check and jogs while 20 sessions keep the server's job pool busy.

The rig of ``tests/security/test_job_pool.py`` (``tests/support/job_attack.py``): a pendant
server in this process, the victim's browser over a real websocket, 20 attacker sessions on the
same server each running the Tool tab's TCP check job again the moment its result is back. The
victim runs its check alone, then under the attack (each check after ~0.6 s of jogging), and
the figures printed are its check latency alone and under attack (p50 / p95 / max), their
ratio (p50), the jog latency between its checks, and how many other sessions' jobs started
while its check waited (the pool's rule: none).

Each run is done three times in the same process: with the server's pool (:class:`JobPool`: a
rested session first) at the switch interval the server sets
(:data:`~tcp_pendant.job_pool.LOOP_SWITCH_INTERVAL_S`, 1 ms); the same at Python's default
interval (5 ms), where every hop of the loop while a worker runs waits up to 5 ms for the GIL;
and with the pool serving first come, first served (``rest_s=0``: every session counts as
rested), the order the single-thread executor per job kind gave before the pool. All are
measured here, so the ratios compare like with like.

With ``--attack beam`` the attackers run the TCP service's beam check instead (a job several
times longer than the victim's check): the victim then waits for the running scan, so its
factor is about (scan + check) / check, the bound of a pool that does not interrupt a job.

With ``--flood`` (issue 42, item 5; the rig of ``tests/support/browser_flood.py``) the attack
is one attacker *browser* instead, in a process of its own, clicking Check, "Check active tool"
and Auto-touch in turn as fast as its socket takes the clicks (``--rate`` clicks a second to
pace it: the issue's browser made ~128), while the victim's browser presses X+ (``--presses``
presses, 0.6 s apart, as the issue's 40 in 25 s) alone and under the attack, in alternating
blocks in one run. Printed side by side: the victim's press-to-readout latency p50 / p95 / max
and the presses the deadman dropped, baseline and attack, and the attack's p95 over the
baseline's against the 1.5x target ("met" / "NOT MET").

Run: ``PYTHONPATH=src:app .venv/bin/python tests/bench/bench_jobs.py [--checks N] [--workers W]
[--attack check|beam]`` (about 30-90 s), or ``... bench_jobs.py --flood [--presses N] [--rate HZ]
[--quick]`` (about 60 s for 40 presses; ``--quick``: 6 presses).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

from tcp_pendant.job_pool import LOOP_SWITCH_INTERVAL_S, JobPool, default_workers

if __name__ == "__main__":                  # run as a script: tests/ on sys.path (support.*, bench.*)
    import _tests_on_path  # noqa: F401
from support.browser_flood import FloodRig
from support.job_attack import Classroom, Measured


PYTHON_DEFAULT_SWITCH_S = 0.005
RIG_BURST_S = 60.0
"""The pool's credit per session in the 20-session rig (``JobPool``'s ``burst_s``)."""
P95_TARGET = 1.5
"""The victim's jog p95 under the browser flood over its baseline p95, at most (issue 42)."""


def run(policy: str, checks: int, workers: int | None, attackers: int, attack: str,
        switch_interval_s: float = LOOP_SWITCH_INTERVAL_S) -> Measured:
    """One rig with a pool of ``policy`` ("fair": the server's; "fifo": first come, first
    served), at Python thread switch interval ``switch_interval_s`` (set after the server's
    start, which sets its own)."""
    # the victim's checks come back to back (a script's pace): a credit that holds them all, so
    # this measures the order rule (the share per session is --flood's)
    pool = (JobPool(workers, keep_history=True, burst_s=RIG_BURST_S) if policy == "fair"
            else JobPool(workers, rest_s=0.0, keep_history=True, burst_s=RIG_BURST_S))
    with tempfile.TemporaryDirectory() as tmp:
        rig = Classroom(Path(tmp), pool, attackers=attackers, attack=attack)
        sys.setswitchinterval(switch_interval_s)
        try:
            return rig.measure(n_alone=checks, n_under=checks)
        finally:
            rig.close()


def flood(presses: int, rate_hz: float, block: int) -> bool:
    """The browser flood (module docstring): prints the figures side by side; True when the
    p95 target is met and no press was dropped."""
    with tempfile.TemporaryDirectory() as tmp:
        rig = FloodRig(Path(tmp), JobPool(keep_history=True), rate_hz=rate_hz)
        try:
            base, under = rig.measure(presses=presses, block=block)
            shown = len(rig.attacker_notes)                 # every notification its browser was sent
            refusals = len(rig.attacker_refusals) or shown   # a server without coalescing: one per refusal
            jobs = len(rig.attacker_jobs())
        finally:
            rig.close()
    pace = "as fast as its socket takes them" if rate_hz <= 0 else f"{rate_hz:.0f} a second"
    print(f"one attacker browser clicking Check / Check active tool / Auto-touch, {pace}: {rig.clicks} clicks "
          f"sent, {jobs} of its jobs ran, {refusals} clicks refused in words ({shown} notices shown)")
    print(f"{'victim jog (press to readout)':32s} {'p50':>7s} {'p95':>7s} {'max':>7s} {'answered':>9s} {'dropped':>8s}")
    for label, p in (("baseline", base), ("attack", under)):
        print(f"{label:32s} {p.p(50) * 1e3:5.0f}ms {p.p(95) * 1e3:5.0f}ms {max(p.latencies, default=float('nan')) * 1e3:5.0f}ms "
              f"{len(p.latencies):>4d}/{p.n:<4d} {p.dropped:>8d}")
    ratio = under.p(95) / base.p(95)
    met = ratio <= P95_TARGET and under.dropped == 0
    print(f"RESULT flood: attack p95 / baseline p95 = {ratio:.2f}x (target <= {P95_TARGET}x, none dropped): "
          f"{'met' if met else 'NOT MET'}")
    return met


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--checks", type=int, default=10, help="victim checks alone and under attack (default 10)")
    ap.add_argument("--workers", type=int, default=None, help=f"pool workers (default {default_workers()})")
    ap.add_argument("--attackers", type=int, default=20)
    ap.add_argument("--attack", choices=("check", "beam"), default="check",
                    help="the attackers' job: the TCP check (default) or the beam check (longer)")
    ap.add_argument("--flood", action="store_true",
                    help="the browser flood of issue 42 (one attacker browser clicking job buttons)")
    ap.add_argument("--presses", type=int, default=40, help="--flood: the victim's presses alone and under attack")
    ap.add_argument("--rate", type=float, default=0.0,
                    help="--flood: the attacker's clicks a second (default 0: as fast as its socket takes them)")
    ap.add_argument("--quick", action="store_true", help="--flood: 6 presses (a smoke run)")
    args = ap.parse_args(argv)
    if args.flood:
        presses = 6 if args.quick else args.presses
        flood(presses, args.rate, block=3 if args.quick else 5)
        return 0
    print(f"{args.attackers} attacker sessions resubmitting {'TCP' if args.attack == 'check' else 'beam'} checks; "
          f"the victim runs its TCP check {args.checks} times alone, then under attack\n")
    runs = {"fair": ("fair", LOOP_SWITCH_INTERVAL_S), "fair, 5 ms switch": ("fair", PYTHON_DEFAULT_SWITCH_S),
            "fifo": ("fifo", LOOP_SWITCH_INTERVAL_S)}
    results = {}
    for label, (policy, switch_s) in runs.items():
        m = results[label] = run(policy, args.checks, args.workers, args.attackers, args.attack, switch_s)
        ahead = [len(a) for a in m.ahead]
        busy = [len([h for h in a if h.busy]) for a in m.ahead]
        print(f"[{label}] {m.summary()}")
        print(f"[{label}] other sessions' jobs started while the victim's check waited: max {max(ahead)}, "
              f"mean {np.mean(ahead):.1f} (of busy sessions: max {max(busy)})\n")
    fair, slow, fifo = results["fair"], results["fair, 5 ms switch"], results["fifo"]
    print(f"victim's check latency under attack / alone (p50): pool {fair.factor:.2f}x, "
          f"first come first served {fifo.factor:.2f}x, pool at a 5 ms switch interval {slow.factor:.2f}x; "
          f"max under attack {max(fair.under) * 1e3:.0f} / {max(fifo.under) * 1e3:.0f} / {max(slow.under) * 1e3:.0f} ms; "
          f"victim jog p95 {np.percentile(fair.jogs, 95) * 1e3:.0f} / {np.percentile(fifo.jogs, 95) * 1e3:.0f} / "
          f"{np.percentile(slow.jogs, 95) * 1e3:.0f} ms")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
