"""Smoke test: the scene-step benchmark still runs (``--quick``) against its yardstick and prints
its three rows with finite figures (the yardstick reads the scene's internals: this fails when
they move without it)."""

from __future__ import annotations

import pytest

import math
import re
import subprocess
import sys
from pathlib import Path

pytestmark = pytest.mark.shares_cpu   # asserts no time or load (tests/conftest.py)

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_scene_step.py"
ROW = re.compile(r"^  (pose state|scene|scene \+ pose state)\s+(\S+)\s+(\S+)\s+(\S+)$", re.MULTILINE)


def test_bench_scene_step_quick_prints_old_new_and_their_ratio() -> None:
    out = subprocess.run([sys.executable, str(BENCH), "--quick"], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    rows = {m.group(1): tuple(float(v) for v in m.group(2, 3, 4)) for m in ROW.finditer(out.stdout)}
    assert set(rows) == {"pose state", "scene", "scene + pose state"}, out.stdout
    for name, (old, new, ratio) in rows.items():
        assert all(math.isfinite(v) and v > 0.0 for v in (old, new, ratio)), (name, out.stdout)
