"""Smoke test: ``tests/bench/bench_trainee.py`` (issue 44's scripted trainee by the two tip
views) still runs and prints its table (presses, true distance, reachable per touch on the
KR 6, the GP12 and the ROS-Industrial KR 16) and its three targets, met or not (the figures
are the bench's, not this test's)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [pytest.mark.shares_cpu,  # asserts no time or load (tests/conftest.py)
              pytest.mark.slow]       # a benchmark's smoke run

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_trainee.py"


def test_bench_trainee_prints_its_table_and_targets() -> None:
    out = subprocess.run([sys.executable, str(BENCH)], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    text = out.stdout
    rows = re.findall(r"^(kr6|gp12|kr16)\s+([1-4])\s+(\d+)\s+(\d+\.\d{3})\s+(-|yes|NO)\s+(.+)$", text, re.MULTILINE)
    assert [(r[0], r[1]) for r in rows] == [(robot, str(k)) for robot in ("kr6", "gp12", "kr16") for k in range(1, 5)]
    assert all(r[4] == "-" for r in rows if r[1] == "1")                     # touch 1: no tilt asked
    assert all(r[5].startswith("Tilt next:") or r[5].startswith("✔") for r in rows if r[1] != "1"), rows
    for target in (r"at most 30 presses per touch", r"every touch within 0\.5 mm \(max \d+\.\d{3} mm\)",
                   r"every suggested tilt reachable on kr6, gp12, kr16 \(\d+ of \d+\)"):
        assert re.search(rf"^TARGET {target}: (MET|NOT MET)$", text, re.MULTILINE), (target, text)
