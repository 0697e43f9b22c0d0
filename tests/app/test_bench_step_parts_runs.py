"""Smoke tests: the two benchmarks of a jog step's parts still run (``--quick``) against their
yardsticks and print their rows (old code, new code, ratio) with finite figures:
``bench_panel.py`` (the jog panel and the jogger) and ``bench_scene_step.py`` (the scene and
the pose state; its yardstick reads the scene's internals, so this fails when they move
without it)."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [pytest.mark.shares_cpu,  # asserts no time or load (tests/conftest.py)
              pytest.mark.slow]       # a benchmark's smoke run

BENCH = Path(__file__).resolve().parents[1] / "bench"


def quick_rows(script: str, row: str) -> tuple[str, dict[str, tuple[float, float, float]]]:
    """Run ``tests/bench/<script> --quick``; its stdout and its rows ``name -> (old, new, ratio)``
    as ``row`` (a regex: name, old, new, ratio) reads them."""
    out = subprocess.run([sys.executable, str(BENCH / script), "--quick"], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    rows = {m.group(1).strip(): (float(m.group(2)), float(m.group(3)), float(m.group(4)))
            for m in re.finditer(row, out.stdout, re.MULTILINE)}
    for name, figures in rows.items():
        assert all(math.isfinite(v) and v > 0.0 for v in figures), (name, out.stdout)
    return out.stdout, rows


def test_bench_panel_quick_prints_old_new_and_the_ratio() -> None:
    text, rows = quick_rows("bench_panel.py", r"^  (\S.+?)\s+(\S+) us\s+(\S+) us\s+(\S+)$")
    assert {"jog panel (PendantPanel.on_change) per step", "jogger's own work (Jogger.key - jog_cartesian)",
            "the two together"} <= set(rows), text
    assert re.search(r"^RESULT panel: .* cost \d+\.\d\dx the old code's per press", text, re.MULTILINE), text


def test_bench_scene_step_quick_prints_old_new_and_their_ratio() -> None:
    text, rows = quick_rows("bench_scene_step.py",
                            r"^  (pose state|scene|scene \+ pose state)\s+(\S+)\s+(\S+)\s+(\S+)$")
    assert set(rows) == {"pose state", "scene", "scene + pose state"}, text
