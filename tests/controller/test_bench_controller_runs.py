"""Smoke test: the controller benchmark script still runs (``--quick``) and prints its figures."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_controller.py"


@pytest.mark.slow
def test_bench_controller_quick_runs() -> None:
    out = subprocess.run([sys.executable, str(BENCH), "--quick"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    rows = [line.split() for line in out.stdout.splitlines() if line.startswith(("kr6 ", "gp12 "))]
    for robot in ("kr6", "gp12"):
        figures = [r for r in rows if r[0] == robot]
        assert len(figures) == 9
        assert any("pinocchio" in " ".join(r) for r in figures)
        assert any("yourdfpy" in " ".join(r) for r in figures)
        assert any("jog" in " ".join(r) for r in figures)
    # every timing is a positive number (the first decimal number on the row)
    lines = [line for line in out.stdout.splitlines() if line.startswith(("kr6 ", "gp12 "))]
    timings = [float(re.search(r"\s(\d+\.\d)(\s|$)", line).group(1)) for line in lines if "speed-up" not in line]
    assert len(timings) == 16 and all(t > 0.0 for t in timings)
    # the jog increments: new us, baseline us, speed-up for 0.1 mm (the class), 1 mm, 1 deg, ...
    increments = [re.match(r"(.+?)\s+(\d+\.\d)\s+(\d+\.\d)\s+(\d+\.\d\d)x$", line)
                  for line in out.stdout.splitlines() if re.match(r"\d+(\.\d)? (mm|deg) ", line)]
    assert len(increments) == 8 and all(m is not None for m in increments), out.stdout
    labels = [m.group(1) for m in increments]
    assert "0.1 mm WORLD X (the class)" in labels and "1 mm WORLD X" in labels and "1 deg WORLD A" in labels
    assert all(float(m.group(2)) > 0.0 and float(m.group(3)) > 0.0 and float(m.group(4)) > 0.0 for m in increments)
