"""Smoke test: the solver benchmark script still runs (``--quick``) and prints its tables."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_solver.py"


@pytest.mark.slow
def test_bench_solver_quick_runs() -> None:
    out = subprocess.run([sys.executable, str(BENCH), "--quick"], capture_output=True, text=True, timeout=120, check=False)
    assert out.returncode == 0, out.stderr
    text = out.stdout
    assert "RMS TCP error / Cramer-Rao bound" in text
    assert "median solve time" in text and "np.linalg.lstsq" in text
    assert "assess_touches" in text and "candidate_gain" in text
    # one efficiency row per (tilt band, N): 2 x 3 rows, each with a finite lstsq figure
    rows = [line.split() for line in text.splitlines() if line.strip().startswith(("20-50", "5-15"))]
    assert len(rows) == 6
    assert all(0.2 < float(r[3]) < 5.0 for r in rows)
    # table 4: large touch sets, quick run = 10,000 touches and 10,000 with a
    # repeated orientation, each solved (not a MemoryError) with a time and a peak RSS
    assert "recorded tracker data" in text
    large = [re.match(r"\s*10,000(?: touches|, half repeated)\s+([\d.]+)\s+([\d.]+)\s+(\d+)\s", line)
             for line in text.splitlines() if line.strip().startswith("10,000")]
    assert len(large) == 2 and all(large), text
    assert text.count("TCP found") == 2
    for m in large:
        assert 0.0 < float(m.group(1)) < 60.0  # solve seconds
        assert 10 < int(m.group(3)) < 2048  # peak RSS, MB
    # table 2: the bare SVD solve and solve_xyz4's ratio to it, N = 4 row
    m4 = re.search(r"^\s+4\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+< 100 us", text,
                   re.MULTILINE)
    assert m4, text
    full, bare, ratio = float(m4.group(1)), float(m4.group(5)), float(m4.group(6))
    # printed to 0.1 us and 0.01: the ratio of the printed times agrees up to their rounding
    assert bare > 0 and abs(ratio - full / bare) <= 0.005 + 0.05 * (1.0 + full / bare) / bare
    assert "x bare" in text
    # the first read of the deferred figures, timed in the same row, in units of the solve
    figs = re.search(r"^\s+4\s.*\|\s+([\d.]+) \(([\d.]+) x solve\)$", text, re.MULTILINE)
    assert figs and float(figs.group(1)) > 0, text
    # table 2b: the figures against the solve, one row per N (quick: 4, 1000, 2000), each
    # with the solve, the bare SVD solve, their ratio, the least-squares core and the angles
    assert "what the quality figures cost against the solve" in text
    for label in ("4", "1,000", "2,000"):
        row = re.search(rf"^\s+{label}\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s",
                        text, re.MULTILINE)
        assert row and all(float(g) > 0 for g in row.groups()), (label, text)
    assert "N = 1000: angle extremes" in text and "N = 4: solve" in text


def test_the_bare_svd_yardstick_solves_the_same_problem() -> None:
    """The yardstick of table 2 gives the TCP, reference and residuals of solve_xyz4."""
    import numpy as np

    from bench.bench_solver import bare_svd_solve
    from support.poses import random_tcp, tilted_rotations, touch_positions

    from tcpcal.origin import solve_xyz4

    rng = np.random.default_rng(3)
    for n in (4, 8, 20):
        rot = tilted_rotations(rng, n, (20.0, 50.0))
        pos = touch_positions(rot, random_tcp(rng, (100.0, 300.0)), np.array([800.0, 0, 300]), rng, 0.5)
        x, res = bare_svd_solve(rot, pos)
        ref = solve_xyz4(rot, pos, detect_outliers=False)
        np.testing.assert_allclose(x[:3], ref.tcp, atol=1e-9)
        np.testing.assert_allclose(x[3:], ref.reference, atol=1e-9)
        np.testing.assert_allclose(res, ref.residuals, atol=1e-9)
