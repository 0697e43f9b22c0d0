"""Benchmark of the TCP origin solvers (tcpcal.origin, tcpcal.pose_quality).

    python tests/bench/bench_solver.py [--quick] [--sets N] [--draws D]

Prints, and says for each target whether it is met:

1. Efficiency: the RMS TCP error of each estimator in units of the Cramer-Rao bound
   (methods.md section 7; the bound ``CRB_t`` from the explicit 3N x 6 matrix A of each set,
   ``poses.crb_tcp``). Over every random touch set and noise draw,
   ``sqrt(mean |t_hat - t|^2 / trace CRB_t(set))``: each set's squared error is measured in
   its own bound, so that a few nearly degenerate sets (huge bounds) do not dominate the
   figure. 1.00 is the physical limit; target for the default ``lstsq``: <= 1.02. The Monte
   Carlo uncertainty (2 standard errors) of the lstsq figure is printed next to it: the
   verdict is only meaningful when it is small against the 2 % margin, which is why each set
   gets several noise draws. Touch sets: N = 4, 8, 20; isotropic touch noise sigma = 0.5 mm
   per axis; the tool leans 20-50 deg or 5-15 deg from vertical in a random direction, with
   a random spin about flange Z; TCP length 100-300 mm. Estimators run without the outlier
   test (pure estimators). "sphere failed" counts solves (sets x draws) the sphere fit refused (coplanar
   flange positions); "flat" is the median thickness / extent of the flange positions
   (smallest / largest singular value of the centred positions), which is what ruins the
   sphere fit at N = 4.
2. Median wall-clock time (us) of ``solve_xyz4`` with the default lstsq estimator and the
   outlier test, and the same without the outlier test, for N = 4, 8, 20 and 1000 (each in hot
   loops of ``HOT_BLOCK`` calls, the columns' blocks taking turns: ``hot_loop_medians_us``), and of the
   first read of the figures the result computes when first asked (``DEFERRED_FIGURES``:
   the angle figures, the 95 % radius, ...; each row also says it in units of the solve),
   against a baseline measured in the same run: ``numpy.linalg.lstsq`` on the
   explicit 3N x 6 system (A prebuilt, only the solve timed; it gives t and r and nothing
   else), and against the bare algebraic solve (``bare_svd_solve``: A and b stacked from the
   touches, ``numpy.linalg.svd``, t, r and the residual lengths). Targets: N = 4 < 100 us and
   <= 1.5 x the bare SVD solve, N = 1000 < 1000 us.
2b. What the quality figures cost against the solve: for N = 4, 1000, 1e5 and 1e6, measured
   round by round interleaved in this process (the load of the shared machine hits every
   column alike), the medians of ``solve_xyz4``, the bare SVD solve and their ratio, the
   least-squares core alone (``tcpcal.origin._lstsq_core``), the angle extremes alone
   (``tcpcal._stats.angle_extremes``) and the first read of every deferred figure, with their
   ratios to the solve and the core, whether the angles are exact, and a MET / NOT MET line per
   target: N = 4 solve <= 1.5 x the bare SVD solve; N = 1000 solve < 1 ms; the angle extremes
   at most the solve at N = 1000 and 1e5 and at most the least-squares core at 1e6.
3. Median time of ``assess_touches`` and ``candidate_gain`` (the wizard calls them live) for
   N = 4 and N = 20. Target: well under 1 ms.
4. Recorded tracker data: ``solve_xyz4`` on 1e4, 1e5 and 1e6 touches and on
   1e5 touches of which half repeat one orientation, each in its own subprocess (wall time of
   the solve, peak RSS of the subprocess from its ``getrusage``), against
   a baseline measured in the same run: the time to generate the touches in that process.
   Targets: 1e6 touches < 10 s and < 2 GB peak RSS; the repeated orientation handled. Before
   (O(N^2) angle figures and duplicate check, figures of the issue): 1e4 ~0.1 s, 1.6e5 75 s,
   1e5 with a repeated orientation MemoryError (a 74.5 GiB allocation).
5. Beam sensor (methods.md section 9): ``tcpcal.solve_beam``'s RMS TCP error over
   the Cramer-Rao bound of the line-constraint model, ``sigma^2 (sum R_i^T P R_i)^-1`` computed
   event by event, and the share of draws whose true TCP lies in the 95 % radius, for 2-16
   tip events (sigma = 0.02 mm) with the tool turned about its own axis, with and without a
   10-30 deg tilt. Target: 1 within 2 standard errors (or 2 %).
6. CLI end to end: ``tcpcal solve xyz4 FILE.csv`` and ``--json`` on a
   generated 1e6-row kuka CSV (written to a temporary directory), each in its own subprocess:
   wall seconds (reading the file, solving, formatting, writing stdout to a file) and peak RSS
   (``os.wait4``), against a baseline measured in the same run: starting the interpreter and
   importing ``tcpcal.cli``. Targets: < 10 s and < 2 GB each. Before (commit 73be3e2, row-by-row
   csv reading, report table and JSON conversion): text 34 s / 1.1 GB, --json 25-43 s / 1.1 GB.

Timings depend on the machine and on what else runs on it (the load average is printed):
re-run when the machine is busy, and trust ratios measured in the same run.

``--quick`` runs a tiny version (used by tests/tcpcal/test_bench_solver_runs.py; table 4 with
1e4 touches and 1e4 with a repeated orientation only; table 6 with a 1e4-row file).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np


from tcpcal._stats import EXACT_ANGLES_MAX_N
from tcpcal.errors import DegenerateTouchesError
from tcpcal.origin import METHODS, solve_xyz4
from tcpcal.pose_quality import assess_touches, candidate_gain

if __name__ == "__main__":                  # run as a script: tests/ on sys.path (support.*, bench.*)
    import _tests_on_path  # noqa: F401
from support.poses import crb_tcp, random_tcp, stacked_a, tilted_rotations, touch_positions

SIGMA = 0.5
NS = (4, 8, 20)
TILTS = ((20.0, 50.0), (5.0, 15.0))
EFFICIENCY_TARGET = 1.02
TIME_TARGETS_US = {4: 100.0, 1000: 1000.0}
BARE_RATIO_TARGET = 1.5
"""N = 4: solve_xyz4 at most this many times the bare SVD solve measured in the same run."""
POSE_QUALITY_TARGET_US = 1000.0
LARGE_TARGET_S = 10.0
LARGE_TARGET_RSS_MB = 2048.0
LARGE_NS = (10_000, 100_000, 1_000_000)
BEFORE_S = {10_000: "~0.1 s", 100_000: "~30 s (1.6e5: 75 s)", 1_000_000: "hours (O(N^2))"}


QUICK = False


def verdict(ok: bool) -> str:
    if QUICK:
        return "(quick run: no verdict)"
    return "met" if ok else "NOT MET"


def efficiency_table(n_sets: int, draws: int, seed: int = 0) -> list[dict]:
    rows = []
    for tilt in TILTS:
        for n in NS:
            rng = np.random.default_rng(seed)
            seed += 1
            ratios: dict[str, list[float]] = {m: [] for m in METHODS}
            failed = {m: 0 for m in METHODS}
            crb_traces, flatness = [], []
            for _ in range(n_sets):
                rot = tilted_rotations(rng, n, tilt)
                tcp = random_tcp(rng, (100.0, 300.0))
                ref = rng.uniform(-500, 500, 3) + [800.0, 0.0, 300.0]
                trace_crb = float(np.trace(crb_tcp(rot, SIGMA)))
                crb_traces.append(trace_crb)
                clean = touch_positions(rot, tcp, ref)
                sv = np.linalg.svd(clean - clean.mean(axis=0), compute_uv=False)
                flatness.append(sv[-1] / sv[0])
                for _ in range(draws):
                    pos = clean + SIGMA * rng.standard_normal(clean.shape)
                    for m in METHODS:
                        try:
                            res = solve_xyz4(rot, pos, method=m, detect_outliers=False)
                        except DegenerateTouchesError:
                            failed[m] += 1
                            continue
                        ratios[m].append(float(np.sum((res.tcp - tcp) ** 2)) / trace_crb)
            row = {"n": n, "tilt": tilt, "sets": n_sets, "draws": draws,
                   "crb_rms": math.sqrt(np.mean(crb_traces)), "flat": float(np.median(flatness))}
            for m in METHODS:
                r = np.asarray(ratios[m])
                row[m] = math.sqrt(r.mean()) if r.size else math.nan
                # 2 standard errors of sqrt(mean r) by the delta method
                row[m + "_2se"] = (2.0 * r.std(ddof=1) / math.sqrt(r.size) / (2.0 * row[m])
                                   if r.size > 1 else math.nan)
                row[m + "_failed"] = failed[m]  # refused solves (sets x draws)
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


HOT_BLOCK = 25
"""Table 2: calls of one function back to back per block (its hot loop)."""


def hot_loop_medians_us(fns: dict[str, Callable[[], object]], repeats: int, apart: tuple[str, ...] = (),
                        block: int = HOT_BLOCK) -> dict[str, float]:
    """Median time (us) of each of ``fns`` over ``repeats`` calls, made in blocks of ``block``
    calls of one function back to back (a hot loop: its code and data stay in the caches),
    the functions' blocks taking turns, in reversed order every other round: the shared
    machine's load then hits every column alike instead of whichever ran during a busy
    second (one untimed call before each block). ``apart``: functions whose blocks run after
    all the others instead (numpy's multi-threaded LAPACK at large N: its threads keep the
    other core busy for a while after it)."""
    times: dict[str, list[float]] = {k: [] for k in fns}
    rounds = max(1, -(-repeats // block))
    turns = [(k, f) for k, f in fns.items() if k not in apart]
    for rnd in range(rounds):
        for k, f in turns if rnd % 2 == 0 else turns[::-1]:
            f()
            for _ in range(block):
                t0 = time.perf_counter()
                f()
                times[k].append(time.perf_counter() - t0)
    medians = {k: float(np.median(v) * 1e6) for k, v in times.items() if k not in apart}
    for k in apart:
        medians[k] = median_us(fns[k], repeats)
    return medians


_MINUS_EYE = -np.eye(3)


def bare_svd_solve(rot: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The algebraic one-step solve (4P-3) written plainly, the yardstick of ``solve_xyz4``:
    stack ``A = [R_i, -I]`` (3N x 6) and ``b = -f_i`` from the touches, ``x = V S^-1 U^T b``
    from ``numpy.linalg.svd``, and the residual vectors ``e = A x - b`` with their lengths.
    No input check, no quality figure, no outlier test. Returns ``(x, |e_i|)``."""
    n = rot.shape[0]
    a = np.empty((n, 3, 6))
    a[:, :, :3] = rot
    a[:, :, 3:] = _MINUS_EYE
    a = a.reshape(3 * n, 6)
    b = -pos.reshape(3 * n)
    u, s, vt = np.linalg.svd(a, full_matrices=False)
    x = vt.T @ ((u.T @ b) / s)
    e = (a @ x - b).reshape(n, 3)
    return x, np.sqrt(np.einsum("ni,ni->n", e, e))


DEFERRED_FIGURES = ("mean_error", "max_error", "ci95_radius", "max_angle_deg", "min_angle_deg",
                    "condition_number", "warnings", "max_angle_exact", "max_angle_upper_deg", "min_angle_exact",
                    "covariance")
"""The figures of solve_xyz4's result computed on their first read (tcpcal.origin._LazyTcpResult;
the covariance for lstsq up to 64 touches)."""


def figures_us(rot: np.ndarray, pos: np.ndarray, repeats: int) -> float:
    """Median time (us) of the first read of every deferred figure of a fresh result."""
    times = np.empty(repeats)
    for k in range(repeats):
        res = solve_xyz4(rot, pos)
        t0 = time.perf_counter()
        for name in DEFERRED_FIGURES:
            getattr(res, name)
        times[k] = time.perf_counter() - t0
    return float(np.median(times) * 1e6)


def timing_table(repeats: int) -> list[tuple[int, float, float, float, float, float]]:
    out = []
    rng = np.random.default_rng(99)
    for n in (4, 8, 20, 1000):
        rot = tilted_rotations(rng, n, (20.0, 50.0))
        pos = touch_positions(rot, random_tcp(rng, (100.0, 300.0)), np.array([800.0, 0, 300]), rng, SIGMA)
        a = stacked_a(rot)
        b = -pos.reshape(-1)
        reps = repeats if n < 1000 else max(repeats // 4, 10)
        med = hot_loop_medians_us({
            "full": lambda rot=rot, pos=pos: solve_xyz4(rot, pos),
            "no_outl": lambda rot=rot, pos=pos: solve_xyz4(rot, pos, detect_outliers=False),
            "base": lambda a=a, b=b: np.linalg.lstsq(a, b, rcond=None),
            "bare": lambda rot=rot, pos=pos: bare_svd_solve(rot, pos),
        }, reps, apart=("base", "bare") if n >= 1000 else (), block=min(HOT_BLOCK, reps))
        out.append((n, med["full"], med["no_outl"], med["base"], med["bare"], figures_us(rot, pos, reps)))
    return out


FIGURE_NS = (4, 1000, 100_000, 1_000_000)
FIGURE_ROUNDS = {4: 2000, 1000: 200, 100_000: 7, 1_000_000: 3}


def figure_cost_table(quick: bool, in_process: bool = False) -> list[dict]:
    """Table 2b: for N = 4, 1000, 1e5, 1e6, interleaved round by round in this process (ABAB:
    the machine's load hits every column alike), the medians (us) of ``solve_xyz4`` (default:
    lstsq with the outlier test), the bare SVD solve, the least-squares core alone
    (``tcpcal.origin._lstsq_core`` on checked arrays: the sums, t, r and the residuals), the
    angle extremes alone (``tcpcal._stats.angle_extremes``, as the result computes them) and
    the first read of every deferred figure of a fresh result. N >= 1e5 each in a subprocess
    (unless ``in_process``)."""
    from tcpcal import _stats
    from tcpcal.origin import _lstsq_core
    from tcpcal.validation import as_positions, rotations_and_soa

    rows = []
    ns = FIGURE_NS[:2] + (2000,) if quick else FIGURE_NS
    for n in ns:
        if n >= 100_000 and not in_process:  # its own process: this one's peak RSS (inherited
            # by the later subprocesses of tables 4 and 6 on Linux) stays that of small sets
            proc = subprocess.run([sys.executable, __file__, "--figure-case", str(n)],
                                  capture_output=True, text=True, check=True)
            rows.append(json.loads(proc.stdout.strip().splitlines()[-1]))
            continue
        rng = np.random.default_rng(n + 3)
        rot = tilted_rotations(rng, n, (20.0, 50.0))
        pos = touch_positions(rot, random_tcp(rng, (100.0, 300.0)), np.array([800.0, 0, 300]), rng, SIGMA)
        r_chk, y = rotations_and_soa(rot)
        f_chk = as_positions(pos, n)
        info = _stats.information(r_chk, y)
        m_inv = info.m_inv()
        fns: dict[str, Callable[[], object]] = {
            "solve": lambda: solve_xyz4(rot, pos),
            "bare": lambda: bare_svd_solve(rot, pos),
            "core": lambda: _lstsq_core(info, m_inv, r_chk, f_chk),
            "angles": lambda: _stats.angle_extremes(r_chk, y),
        }
        times: dict[str, list[float]] = {k: [] for k in (*fns, "figures")}
        rounds = 20 if quick and n <= 1000 else (2 if quick else FIGURE_ROUNDS[n])
        # From N = 1000 numpy's SVD of the 3N x 6 matrix runs on several threads (OpenBLAS),
        # which keep spinning on the other core for a while after it: interleaved, it would
        # slow whatever is timed next. There it is timed in its own loop after the others.
        apart = ("bare",) if n >= 1000 else ()
        for f in fns.values():
            f()
        for _ in range(rounds):
            for k, f in fns.items():
                if k in apart:
                    continue
                t0 = time.perf_counter()
                f()
                times[k].append(time.perf_counter() - t0)
            res = solve_xyz4(rot, pos)
            t0 = time.perf_counter()
            for name in DEFERRED_FIGURES:
                getattr(res, name)
            times["figures"].append(time.perf_counter() - t0)
        for k in apart:
            for _ in range(rounds):
                t0 = time.perf_counter()
                fns[k]()
                times[k].append(time.perf_counter() - t0)
        row = {k: float(np.median(v) * 1e6) for k, v in times.items()}
        row["n"] = n
        row["min_exact"], row["max_exact"] = res.min_angle_exact, res.max_angle_exact
        rows.append(row)
        fns.clear()  # the next N is the largest: let this one's arrays go
    return rows


def print_figure_cost_table(quick: bool) -> None:
    print("2b. what the quality figures cost against the solve, medians (us) interleaved round by round")
    print("    (from N = 1000 the bare SVD solve, multi-threaded, in a loop of its own after the others)")
    print(f"    (targets: N=4 solve <= {BARE_RATIO_TARGET} x bare SVD; N=1000 solve < 1000 us; N=1000 and 1e5 angle")
    print("    extremes <= the solve; N=1e6 angle extremes <= the least-squares core)")
    hdr = (f"{'N':>9} {'solve':>10} {'bare SVD':>10} {'ratio':>6} {'LS core':>10} {'angles':>10} "
           f"{'/solve':>7} {'/core':>6} {'figures':>10} {'/solve':>7} {'exact min/max':>14}")
    print(hdr)
    print("-" * len(hdr))
    rows = figure_cost_table(quick)
    for r in rows:
        print(f"{r['n']:>9,} {r['solve']:10.1f} {r['bare']:10.1f} {r['solve'] / r['bare']:6.2f} {r['core']:10.1f} "
              f"{r['angles']:10.1f} {r['angles'] / r['solve']:7.2f} {r['angles'] / r['core']:6.2f} "
              f"{r['figures']:10.1f} {r['figures'] / r['solve']:7.2f} "
              f"{str(r['min_exact']).lower():>6}/{str(r['max_exact']).lower():<7}")
    by_n = {r["n"]: r for r in rows}
    checks = []
    if 4 in by_n:
        r = by_n[4]
        checks.append((f"N = 4: solve {r['solve']:.1f} us <= {BARE_RATIO_TARGET} x bare SVD {r['bare']:.1f} us "
                       f"(ratio {r['solve'] / r['bare']:.2f})", r["solve"] <= BARE_RATIO_TARGET * r["bare"]))
    if 1000 in by_n:
        r = by_n[1000]
        checks.append((f"N = 1000: solve {r['solve']:.1f} us < 1000 us", r["solve"] < 1000.0))
        checks.append((f"N = 1000: angle extremes {r['angles']:.1f} us <= solve {r['solve']:.1f} us "
                       f"(ratio {r['angles'] / r['solve']:.2f})", r["angles"] <= r["solve"]))
    if 100_000 in by_n:
        r = by_n[100_000]
        checks.append((f"N = 1e5: angle extremes {r['angles'] / 1e3:.2f} ms <= solve {r['solve'] / 1e3:.2f} ms "
                       f"(ratio {r['angles'] / r['solve']:.2f})", r["angles"] <= r["solve"]))
    if 1_000_000 in by_n:
        r = by_n[1_000_000]
        checks.append((f"N = 1e6: angle extremes {r['angles'] / 1e3:.1f} ms <= least-squares core "
                       f"{r['core'] / 1e3:.1f} ms (ratio {r['angles'] / r['core']:.2f})", r["angles"] <= r["core"]))
    for text, ok in checks:
        print(f"   {text}: {'MET' if ok else 'NOT MET'}" if not QUICK else f"   {text}: {verdict(ok)}")
    print(f"   Angle figures up to {EXACT_ANGLES_MAX_N} touches: exact (every pair). Above: the smallest from a sample")
    print("   of consecutive pairs (an upper bound; exact when 0), the largest from the sample's farthest pair")
    print("   and one pass over every touch (exact when its bounds meet), each flagged when an estimate")
    print("   (min_angle_exact / max_angle_exact false; '<=' / '>=' in the report).")


def pose_quality_timing(repeats: int) -> list[tuple[int, float, float]]:
    rng = np.random.default_rng(7)
    out = []
    for n in (4, 20):
        rot = tilted_rotations(rng, n, (20.0, 50.0))
        cand = tilted_rotations(rng, 1, (20.0, 50.0))[0]
        out.append((n, median_us(lambda rot=rot: assess_touches(rot), repeats),
                    median_us(lambda rot=rot, cand=cand: candidate_gain(rot, cand), repeats)))
    return out


def large_case(n: int, repeated: bool) -> dict:
    """One large solve (run in a subprocess by :func:`large_table`): touches leaning 20-50 deg,
    0.5 mm noise; ``repeated``: every second touch has touch 0's orientation."""
    rng = np.random.default_rng(n)
    t0 = time.perf_counter()
    rot = tilted_rotations(rng, n, (20.0, 50.0))
    if repeated:
        rot[::2] = rot[0]
    pos = touch_positions(rot, random_tcp(rng, (100.0, 300.0)), np.array([800.0, 0, 300]), rng, SIGMA)
    gen = time.perf_counter() - t0
    t0 = time.perf_counter()
    try:
        res = solve_xyz4(rot, pos)
        min_est = "" if getattr(res, "min_angle_exact", True) else "<= "
        outcome = (f"TCP found, {len(res.outliers)} outliers, min angle {min_est}{res.min_angle_deg:.3f} deg, "
                   f"max {'' if res.max_angle_exact else '>= '}{res.max_angle_deg:.2f} deg")
    except DegenerateTouchesError as exc:
        outcome = f"DegenerateTouchesError: {str(exc)[:60]}..."
    return {"solve_s": time.perf_counter() - t0, "gen_s": gen, "outcome": outcome,
            "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0}  # kB on Linux


def large_table(ns: tuple[int, ...], repeated_n: int) -> list[tuple[str, int, dict, float]]:
    """Each case in a fresh subprocess, which reports its solve time and its own peak RSS (MB,
    ``getrusage(RUSAGE_SELF).ru_maxrss``: the whole process, interpreter and touches included)."""
    out = []
    cases = [(f"{n:,} touches", n, False) for n in ns] + [(f"{repeated_n:,}, half repeated", repeated_n, True)]
    for label, n, rep_ in cases:
        proc = subprocess.run([sys.executable, __file__, "--large-case", str(n), *(["--repeated"] if rep_ else [])],
                              capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            row = {"solve_s": math.nan, "gen_s": math.nan, "rss_mb": math.nan,
                   "outcome": f"FAILED: {proc.stderr.strip()[-200:]}"}
        else:
            row = json.loads(proc.stdout.strip().splitlines()[-1])
        out.append((label, n, row, row["rss_mb"]))
    return out


BEAM_SIGMA = 0.02  # mm: the sensor's default repeatability
BEAM_NS = (2, 4, 8, 16)
BEAM_PATTERNS = ("spin only", "spin + tilt 10-30")


def beam_efficiency_table(n_sets: int, draws: int, seed: int = 100) -> list[dict]:
    """Table 5: tcpcal.solve_beam's RMS TCP error over the Cramer-Rao bound of the
    line-constraint model (methods.md section 9), sigma^2 (sum_i R_i^T P R_i)^-1 computed here
    event by event, and how often the true TCP lies in the 95 % radius (noise estimated).

    Events: the tool pointing down at a horizontal beam (WORLD Y), turned about its own axis by
    a random angle ("spin only"), or also tilted 10-30 deg about a random horizontal axis; the
    tip on the beam line plus isotropic noise BEAM_SIGMA per axis on the flange position.
    """
    from scipy.spatial.transform import Rotation

    from tcpcal.beam import solve_beam

    b, u = np.array([900.0, 150.0, 400.0]), np.array([0.0, 1.0, 0.0])
    p = np.eye(3) - np.outer(u, u)
    down = Rotation.from_euler("y", 180.0, degrees=True)
    rows = []
    for pattern in BEAM_PATTERNS:
        for n in BEAM_NS:
            rng = np.random.default_rng(seed)
            seed += 1
            ratios, inside, refused, traces = [], 0, 0, []
            for _ in range(n_sets):
                spin = Rotation.from_euler("z", rng.uniform(-180.0, 180.0, (n, 1)), degrees=True)
                rot = down * spin
                if pattern != "spin only":
                    az = rng.uniform(0.0, 2.0 * np.pi, n)
                    tilt = np.radians(rng.uniform(10.0, 30.0, n))
                    axes = np.stack([np.cos(az), np.sin(az), np.zeros(n)], axis=1)
                    rot = Rotation.from_rotvec(axes * tilt[:, None]) * rot
                rm = rot.as_matrix()
                tcp = random_tcp(rng, (100.0, 300.0))
                m = sum(r.T @ p @ r for r in rm)
                crb = BEAM_SIGMA**2 * np.linalg.inv(m)
                traces.append(float(np.trace(crb)))
                clean = b + rng.uniform(-10.0, 10.0, n)[:, None] * u - rm @ tcp
                for _ in range(draws):
                    pos = clean + BEAM_SIGMA * rng.standard_normal(clean.shape)
                    try:
                        res = solve_beam(rm, pos, b, u)
                    except DegenerateTouchesError:
                        refused += 1
                        continue
                    err2 = float(np.sum((res.tcp - tcp) ** 2))
                    ratios.append(err2 / traces[-1])
                    inside += math.sqrt(err2) <= res.ci95_radius
            r = np.asarray(ratios)
            eff = math.sqrt(r.mean()) if r.size else math.nan
            rows.append({"pattern": pattern, "n": n, "crb_rms": math.sqrt(np.median(traces)),
                         "efficiency": eff,
                         "eff_2se": (2.0 * r.std(ddof=1) / math.sqrt(r.size) / (2.0 * eff)
                                     if r.size > 1 else math.nan),
                         "coverage": inside / r.size if r.size else math.nan,
                         "refused": refused})
    return rows


def print_beam_table(n_sets: int, draws: int) -> None:
    print(f"5. beam: efficiency vs the Cramer-Rao bound of the line-constraint model  "
          f"(sigma = {BEAM_SIGMA} mm; 1.00 = limit; target: 1 within 2 SE or {EFFICIENCY_TARGET})")
    hdr = (f"{'pattern':>18} {'N':>3} {'CRB rms mm':>10} {'RMS/CRB':>8} {'+-2SE':>6} "
           f"{'in 95 % radius':>15} {'refused':>8}  target")
    print(hdr)
    print("-" * len(hdr))
    for r in beam_efficiency_table(n_sets, draws):
        ok = abs(r["efficiency"] - 1.0) <= max(r["eff_2se"], EFFICIENCY_TARGET - 1.0)
        print(f"{r['pattern']:>18} {r['n']:>3} {r['crb_rms']:10.4f} {r['efficiency']:8.3f} "
              f"{r['eff_2se']:6.3f} {r['coverage']:15.3f} {r['refused']:>8d}  {verdict(ok)}")
    print("   solve_beam is linear least squares on a linear Gaussian model: it reaches the bound")
    print("   (ratio 1 within the sampling error); N = 2 events leave 1 degree of freedom for the")
    print("   noise, so its 95 % radius is wide but still covers 95 %. Turning the tool about its")
    print("   own axis alone observes the TCP (the beam direction seen in FLANGE turns with it);")
    print("   turning it only about the beam would not (methods.md section 9).")


CLI_NS = (1_000_000,)
CLI_BEFORE = {1_000_000: {"text": "34 s / 1.1 GB", "--json": "25-43 s / 1.1 GB"}}
CLI_JSON_BEFORE = "12.0 s wall, 12.7 s CPU, 881 MB, stdout 104 MB (1e6 rows; text 8.2 s)"


def _cli_workers() -> int:
    from tcpcal.cli import _json_workers

    return _json_workers()


def write_cli_file(path: Path, n: int) -> None:
    """A kuka-layout POSES.csv of ``n`` touches (20-50 deg lean, 0.5 mm noise, 4 decimals)."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(n + 6)
    rot = tilted_rotations(rng, n, (20.0, 50.0))
    pos = touch_positions(rot, random_tcp(rng, (100.0, 300.0)), np.array([800.0, 0, 300]), rng, SIGMA)
    abc = Rotation.from_matrix(rot).as_euler("ZYX", degrees=True)
    with open(path, "w", encoding="utf-8") as f:
        f.write("x,y,z,a,b,c\n")
        np.savetxt(f, np.hstack([pos, abc]), fmt="%.4f", delimiter=",")


def timed_subprocess(cmd: list[str], stdout_path: Path) -> tuple[float, float, float, int]:
    """Wall seconds, CPU seconds (user + system), peak RSS (MB) of ``cmd`` alone (``os.wait4``)
    and its exit status, its stdout written to ``stdout_path``."""
    with open(stdout_path, "wb") as out:
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.DEVNULL)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    cpu = usage.ru_utime + usage.ru_stime
    return wall, cpu, usage.ru_maxrss / 1024.0, proc.returncode  # ru_maxrss: kB on Linux


def print_cli_table(ns: tuple[int, ...]) -> None:
    """Table 6: the whole ``tcpcal solve xyz4`` command on large files (text and --json)."""
    import tempfile

    print(f"6. CLI end to end: tcpcal solve xyz4 on a large CSV, each run in its own process "
          f"(targets: 1e6 rows < {LARGE_TARGET_S:.0f} s and < {LARGE_TARGET_RSS_MB:.0f} MB peak RSS)")
    hdr = (f"{'output':>7} {'rows':>10} {'wall s':>7} {'CPU s':>6} {'peak RSS MB':>12} {'stdout MB':>10} "
           f"{'before (73be3e2)':>17}  target")
    print(hdr)
    print("-" * len(hdr))
    with tempfile.TemporaryDirectory(prefix="tcpcal-bench-") as tmp:
        base_s, _, base_mb, _ = timed_subprocess([sys.executable, "-c", "import tcpcal.cli"],
                                              Path(tmp) / "base.out")
        for n in ns:
            csv_path = Path(tmp) / f"touches_{n}.csv"
            write_cli_file(csv_path, n)
            for kind, extra in (("text", []), ("--json", ["--json"])):
                out = Path(tmp) / "out.txt"
                wall, cpu, rss, code = timed_subprocess(
                    [sys.executable, "-m", "tcpcal", "solve", "xyz4", *extra, str(csv_path)], out)
                size = out.stat().st_size / 1e6
                ok = code == 0 and wall < LARGE_TARGET_S and rss < LARGE_TARGET_RSS_MB
                before = CLI_BEFORE.get(n, {}).get(kind, "")
                status = "" if code == 0 else f"  EXIT {code}"
                tgt = verdict(ok) if n == 1_000_000 or code != 0 else "-"
                print(f"{kind:>7} {n:>10,} {wall:7.2f} {cpu:6.2f} {rss:12.0f} {size:10.1f} {before:>17}  "
                      f"{tgt}{status}")
    print(f"   baseline: starting Python and importing tcpcal.cli takes {base_s:.2f} s, "
          f"{base_mb:.0f} MB. The file ({ns[-1]:,} rows) is")
    print("   converted by blocks of rows (numpy.loadtxt; the csv module and the cell-by-cell checks")
    print("   only for quoted cells or to name an error), the residual table by one % format per")
    print("   row mapped over numpy columns, the JSON number lists dumped at once (tcpcal.report); the")
    print("   JSON float arrays (10^6 residuals and residual vectors) by one %r pass over their flat values,")
    print(f"   by blocks of rows in {_cli_workers()} process(es) (forked; json_dumps workers = the CPUs, at most 4).")
    print(f"   Before that (idle machine): --json {CLI_JSON_BEFORE}.")
    print("   On a busy machine (load average above the CPU count) wall s exceeds CPU s: the text")
    print("   command runs on one core (numpy may add short threads), so its CPU s is close to an idle")
    print("   machine's time; --json's CPU s counts its formatting processes too (the same text in less")
    print("   wall time, not less CPU).")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny run (smoke test)")
    ap.add_argument("--sets", type=int, default=None, help="random sets per row (default 2000)")
    ap.add_argument("--draws", type=int, default=None, help="noise draws per set (default 5)")
    ap.add_argument("--large-case", type=int, default=None, help=argparse.SUPPRESS)
    ap.add_argument("--repeated", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--figure-case", type=int, default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.figure_case is not None:  # one large row of table 2b, in its own process
        global FIGURE_NS
        FIGURE_NS = (args.figure_case,)
        print(json.dumps(figure_cost_table(False, in_process=True)[0]))
        return 0
    if args.large_case is not None:  # one case of table 4, in its own process
        print(json.dumps(large_case(args.large_case, args.repeated)))
        return 0
    global QUICK
    QUICK = args.quick
    n_sets = args.sets or (20 if args.quick else 2000)
    draws = args.draws or (2 if args.quick else 5)
    repeats = 20 if args.quick else 2000

    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    print(f"tcpcal solver benchmark  (sigma = {SIGMA} mm per axis; {n_sets} random sets per row, "
          f"{draws} noise draws each; load average {load:.1f} on {os.cpu_count()} CPUs)")
    print()
    print("1. RMS TCP error / Cramer-Rao bound, each set's error in its own bound  "
          f"(1.00 = limit; target lstsq <= {EFFICIENCY_TARGET})")
    hdr = (f"{'tilt deg':>9} {'N':>3} {'CRB rms mm':>10} " + " ".join(f"{m:>9}" for m in METHODS)
           + f" {'lstsq +-2SE':>11} {'sphere failed':>14} {'flat':>6}  lstsq target")
    print(hdr)
    print("-" * len(hdr))
    table = efficiency_table(n_sets, draws)
    all_met = True
    for r in table:
        tilt = f"{r['tilt'][0]:.0f}-{r['tilt'][1]:.0f}"
        vals = " ".join(f"{r[m]:9.3f}" for m in METHODS)
        ok = r["lstsq"] <= EFFICIENCY_TARGET
        all_met &= ok
        print(f"{tilt:>9} {r['n']:>3} {r['crb_rms']:10.3f} {vals} {r['lstsq_2se']:11.3f} "
              f"{r['sphere_failed']:>14d} {r['flat']:6.3f}  {verdict(ok)}")
    worst_sphere = max(table, key=lambda r: r["sphere"])
    print(f"   lstsq <= {EFFICIENCY_TARGET} in every row: {verdict(all_met)}.")
    print(f"   The sphere fit is far from the bound when the flange positions are nearly coplanar: "
          f"{worst_sphere['sphere']:.1f} x the bound at N = {worst_sphere['n']}, tilt "
          f"{worst_sphere['tilt'][0]:.0f}-{worst_sphere['tilt'][1]:.0f} deg (median thickness / "
          f"extent {worst_sphere['flat']:.3f}); pairwise differences discard information "
          f"(~{np.mean([r['pairwise'] for r in table]):.2f} x).")
    print()
    print(f"2. median solve time, us ({repeats} repeats; N = 1000: {max(repeats // 4, 10)})  "
          f"(targets: N=4 < {TIME_TARGETS_US[4]:.0f} and <= {BARE_RATIO_TARGET} x the bare SVD solve, "
          f"N=1000 < {TIME_TARGETS_US[1000]:.0f})")
    hdr = (f"{'N':>5} {'solve_xyz4':>11} {'no outlier test':>16} {'np.linalg.lstsq 3Nx6':>21} "
           f"{'ratio':>6} {'bare SVD solve':>15} {'ratio':>6}  target  {'| figures read':>14}")
    print(hdr)
    print("-" * len(hdr))
    for n, full, no_outl, base, bare, figs in timing_table(repeats):
        target = TIME_TARGETS_US.get(n)
        tgt = f"< {target:.0f} us: {verdict(full < target)}" if target else "-"
        if n == 4:
            tgt += f"; <= {BARE_RATIO_TARGET} x bare: {verdict(full <= BARE_RATIO_TARGET * bare)}"
        print(f"{n:>5} {full:11.1f} {no_outl:16.1f} {base:21.1f} {full / base:6.1f} {bare:15.1f} "
              f"{full / bare:6.2f}  {tgt}  | {figs:8.1f} ({figs / full:.2f} x solve)")
    print("   solve_xyz4 includes input checks, the residuals, noise (and the covariance above 64 touches),")
    print("   the check for repeated orientations and the outlier test; np.linalg.lstsq (A prebuilt) gives")
    print("   t and r only; the bare SVD solve builds A and b from the touches, solves by numpy.linalg.svd")
    print("   and gives t, r and the residual lengths (bare_svd_solve: no check, no quality figure).")
    print("   'figures read': the first read of the figures the result computes when first asked (mean")
    print("   and largest residual, 95 % radius, the largest/smallest angle between touches, condition")
    print("   number, warnings; all at once; and the covariance, one product, up to 64 touches), after a")
    print("   solve; the solve's time does not include it.")
    print(f"   Each column here is one function called back to back in blocks of {HOT_BLOCK} calls (a hot loop:")
    print("   its code and data stay in the caches), the columns' blocks taking turns so that the machine's")
    print("   load hits them alike (N = 1000: the multi-threaded lstsq and SVD after the others); the bare")
    print("   SVD solve (one LAPACK call) gains more from hot caches than solve_xyz4 (~30 small numpy")
    print("   calls), so the N = 4 ratio here is higher than in table 2b, where the functions take turns")
    print("   call by call as they do in use (the wizard solves once between other work).")
    print()
    print_figure_cost_table(QUICK)
    print()
    print(f"3. pose quality, median us  (target well under {POSE_QUALITY_TARGET_US:.0f})")
    for n, a_us, c_us in pose_quality_timing(repeats):
        ok = max(a_us, c_us) < POSE_QUALITY_TARGET_US
        print(f"   N = {n:2d}   assess_touches {a_us:8.1f}    candidate_gain {c_us:8.1f}    "
              f"{verdict(ok)}")
    print()
    ns = LARGE_NS[:1] if QUICK else LARGE_NS
    rep_n = 10_000 if QUICK else 100_000
    print(f"4. recorded tracker data: solve_xyz4 on many touches, each case in its own process "
          f"(targets: 1e6 < {LARGE_TARGET_S:.0f} s and < {LARGE_TARGET_RSS_MB:.0f} MB peak RSS)")
    hdr = (f"{'case':>22} {'solve s':>8} {'make touches s':>15} {'peak RSS MB':>12} "
           f"{'before':>20}  outcome / target")
    print(hdr)
    print("-" * len(hdr))
    for label, n, row, rss in large_table(ns, rep_n):
        before = BEFORE_S.get(n, "") if "repeated" not in label else "1e5: MemoryError"
        tgt = ""
        if n == 1_000_000:
            tgt = f"  {verdict(row['solve_s'] < LARGE_TARGET_S and rss < LARGE_TARGET_RSS_MB)}"
        print(f"{label:>22} {row['solve_s']:8.2f} {row['gen_s']:15.2f} {rss:12.0f} {before:>20}  "
              f"{row['outcome']}{tgt}")
    print(f"   Angle figures above {EXACT_ANGLES_MAX_N} touches: both from a sample and one pass over the touches,")
    print("   flagged when estimates ('<=' for the smallest, min_angle_exact false; '>=' for the largest,")
    print("   max_angle_exact false; table 2b). Memory O(N), never N x N.")
    print()
    print_beam_table(n_sets, draws)
    print()
    print_cli_table((10_000,) if QUICK else CLI_NS)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
