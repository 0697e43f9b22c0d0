"""Smoke test: ``tests/bench/bench_jobs.py --flood --quick`` (issue 42's browser job flood)
still runs and prints the victim's jog figures, baseline and attack side by side, and the p95
ratio against its target (met or not: the figure is the bench's, not this test's)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [pytest.mark.shares_cpu,  # asserts no time or load (tests/conftest.py)
              pytest.mark.slow]       # a benchmark's smoke run

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_jobs.py"


def test_bench_jobs_flood_quick_prints_baseline_and_attack_side_by_side() -> None:
    out = subprocess.run([sys.executable, str(BENCH), "--flood", "--quick"], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    text = out.stdout
    for label in ("baseline", "attack"):
        assert re.search(rf"^{label}\s+\d+ms\s+\d+ms\s+\d+ms\s+\d+/6\s+\d+$", text, re.MULTILINE), text
    assert re.search(r"clicks sent, \d+ of its jobs ran, \d+ clicks refused in words", text), text
    assert re.search(r"^RESULT flood: attack p95 / baseline p95 = \d+\.\d\dx \(target <= 1\.5x, none dropped\): "
                     r"(met|NOT MET)$", text, re.MULTILINE), text
