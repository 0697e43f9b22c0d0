"""Benchmark of the TCP origin solvers (tcpcal.origin, tcpcal.pose_quality).

    python tests/bench/bench_solver.py [--quick]

Prints:
1. Efficiency: RMS TCP error of each estimator over many random touch sets divided by the
   RMS Cramer-Rao bound ``sqrt(mean trace CRB_t)`` (methods.md section 7; CRB from the explicit
   3N x 6 matrix A). 1.00 is the physical limit; target for the default ``lstsq``: <= 1.02.
   Touch sets: N = 4, 8, 20; isotropic touch noise sigma = 0.5 mm; the tool leans 20-50 deg or
   5-15 deg from vertical in a random direction, with a random spin about flange Z; TCP length
   100-300 mm. Estimators run without outlier detection (pure estimators). The sphere fit's
   "failed" column counts sets it refused (coplanar flange positions).
2. Median solve time (us) of ``solve_xyz4`` (default: lstsq with every quality figure and the
   outlier test; and the same without the outlier test) for N = 4 and N = 1000, against a
   baseline measured in the same run: ``numpy.linalg.lstsq`` on the explicit 3N x 6 system
   (A prebuilt, only the solve timed).
3. Median time of ``assess_touches`` and ``candidate_gain`` for N = 20.

``--quick`` runs a tiny version (used by tests/tcpcal/test_bench_solver_runs.py).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tcpcal"))
from poses import crb_tcp, random_tcp, stacked_a, tilted_rotations, touch_positions  # noqa: E402

from tcpcal.errors import DegenerateTouchesError  # noqa: E402
from tcpcal.origin import METHODS, solve_xyz4  # noqa: E402
from tcpcal.pose_quality import assess_touches, candidate_gain  # noqa: E402

SIGMA = 0.5
NS = (4, 8, 20)
TILTS = ((20.0, 50.0), (5.0, 15.0))


def efficiency_table(n_sets: int, seed: int = 0) -> list[dict]:
    rows = []
    for tilt in TILTS:
        for n in NS:
            rng = np.random.default_rng(seed)
            seed += 1
            sq = {m: 0.0 for m in METHODS}
            ok = {m: 0 for m in METHODS}
            crb_sum = {m: 0.0 for m in METHODS}
            failed = {m: 0 for m in METHODS}
            for _ in range(n_sets):
                rot = tilted_rotations(rng, n, tilt)
                tcp = random_tcp(rng, (100.0, 300.0))
                ref = rng.uniform(-500, 500, 3) + [800.0, 0.0, 300.0]
                pos = touch_positions(rot, tcp, ref, rng, SIGMA)
                trace_crb = float(np.trace(crb_tcp(rot, SIGMA)))
                for m in METHODS:
                    try:
                        res = solve_xyz4(rot, pos, method=m, detect_outliers=False)
                    except DegenerateTouchesError:
                        failed[m] += 1
                        continue
                    sq[m] += float(np.sum((res.tcp - tcp) ** 2))
                    crb_sum[m] += trace_crb
                    ok[m] += 1
            row = {"n": n, "tilt": tilt, "sets": n_sets,
                   "crb_rms": math.sqrt(crb_sum["lstsq"] / max(ok["lstsq"], 1))}
            for m in METHODS:
                row[m] = math.sqrt(sq[m] / crb_sum[m]) if ok[m] else math.nan
                row[m + "_failed"] = failed[m]
            rows.append(row)
    return rows


def median_us(fn: Callable[[], object], repeats: int) -> float:
    fn()
    times = np.empty(repeats)
    for k in range(repeats):
        t0 = time.perf_counter()
        fn()
        times[k] = time.perf_counter() - t0
    return float(np.median(times) * 1e6)


def timing_table(repeats: int) -> list[tuple[int, float, float, float]]:
    out = []
    rng = np.random.default_rng(99)
    for n in (4, 1000):
        rot = tilted_rotations(rng, n, (20.0, 50.0))
        pos = touch_positions(rot, random_tcp(rng, (100.0, 300.0)), np.array([800.0, 0, 300]), rng, SIGMA)
        a = stacked_a(rot)
        b = -pos.reshape(-1)
        full = median_us(lambda: solve_xyz4(rot, pos), repeats)
        no_outl = median_us(lambda: solve_xyz4(rot, pos, detect_outliers=False), repeats)
        base = median_us(lambda: np.linalg.lstsq(a, b, rcond=None), repeats)
        out.append((n, full, no_outl, base))
    return out


def pose_quality_timing(repeats: int) -> tuple[float, float]:
    rng = np.random.default_rng(7)
    rot = tilted_rotations(rng, 20, (20.0, 50.0))
    cand = tilted_rotations(rng, 1, (20.0, 50.0))[0]
    return (median_us(lambda: assess_touches(rot), repeats),
            median_us(lambda: candidate_gain(rot, cand), repeats))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny run (smoke test)")
    ap.add_argument("--sets", type=int, default=None, help="random sets per row (default 2000)")
    args = ap.parse_args(argv)
    n_sets = args.sets or (20 if args.quick else 2000)
    repeats = 20 if args.quick else 2000

    print(f"tcpcal solver benchmark  (sigma = {SIGMA} mm per axis, {n_sets} random sets per row)")
    print()
    print("1. RMS TCP error / Cramer-Rao bound  (1.00 = limit; target lstsq <= 1.02)")
    hdr = f"{'tilt deg':>9} {'N':>3} {'CRB rms mm':>10} " + " ".join(f"{m:>9}" for m in METHODS) + f" {'sphere failed':>14}"
    print(hdr)
    print("-" * len(hdr))
    for r in efficiency_table(n_sets):
        tilt = f"{r['tilt'][0]:.0f}-{r['tilt'][1]:.0f}"
        vals = " ".join(f"{r[m]:9.3f}" for m in METHODS)
        print(f"{tilt:>9} {r['n']:>3} {r['crb_rms']:10.3f} {vals} {r['sphere_failed']:>14d}")
    print()
    print(f"2. median solve time, us ({repeats} repeats)  (targets: N=4 < 100, N=1000 < 1000)")
    hdr = f"{'N':>5} {'solve_xyz4':>11} {'no outlier test':>16} {'np.linalg.lstsq 3Nx6':>21}"
    print(hdr)
    print("-" * len(hdr))
    for n, full, no_outl, base in timing_table(repeats):
        print(f"{n:>5} {full:11.1f} {no_outl:16.1f} {base:21.1f}")
    print()
    a_us, c_us = pose_quality_timing(repeats)
    print("3. pose quality, N = 20, median us  (target well under 1000)")
    print(f"   assess_touches {a_us:8.1f}    candidate_gain {c_us:8.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
