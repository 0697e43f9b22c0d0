"""Smoke test: the solver benchmark script still runs (``--quick``) and prints its tables."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_solver.py"


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
