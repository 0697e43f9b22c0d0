"""Smoke test: the jog panel benchmark still runs (``--quick``) and prints its rows (old code,
new code, ratio) with finite figures and its RESULT line."""

from __future__ import annotations

import pytest

import math
import re
import subprocess
import sys
from pathlib import Path

pytestmark = pytest.mark.shares_cpu   # asserts no time or load (tests/conftest.py)

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_panel.py"
ROW = re.compile(r"^  (\S.+?)\s+(\S+) us\s+(\S+) us\s+(\S+)$", re.MULTILINE)


def test_bench_panel_quick_prints_old_new_and_the_ratio() -> None:
    out = subprocess.run([sys.executable, str(BENCH), "--quick"], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    rows = {m.group(1).strip(): tuple(float(m.group(i)) for i in (2, 3, 4)) for m in ROW.finditer(out.stdout)}
    assert {"jog panel (PendantPanel.on_change) per step", "jogger's own work (Jogger.key - jog_cartesian)",
            "the two together"} <= set(rows), out.stdout
    for old, new, ratio in rows.values():
        assert old > 0 and new > 0 and math.isfinite(ratio) and ratio > 0
    assert re.search(r"^RESULT panel: .* cost \d+\.\d\dx the old code's per press", out.stdout, re.MULTILINE), out.stdout
