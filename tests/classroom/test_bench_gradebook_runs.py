"""Smoke test: the gradebook benchmark still runs (``--quick``) and prints its figures."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_gradebook.py"


def test_bench_gradebook_quick_runs(tmp_path: Path) -> None:
    out = subprocess.run([sys.executable, str(BENCH), "--quick", "--dir", str(tmp_path)], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    rows = {m.group(1).strip(): (float(m.group(2)), float(m.group(3)))
            for m in re.finditer(r"^  (.+?)\s+(\d+\.\d)\s+(\d+\.\d)\s+x\s*\d", out.stdout, re.MULTILINE)}
    assert set(rows) == {"baseline: plain INSERT+COMMIT, in-memory", "baseline: plain INSERT+COMMIT, WAL file FULL",
                         "record_touch, synchronous=FULL", "record_touch, synchronous=NORMAL",
                         "finish_calibration, synchronous=FULL", "grades() of 40 rows, 40 touches"}
    assert all(med > 0 and p99 >= med for med, p99 in rows.values())
    assert list(tmp_path.iterdir()) == []          # its temporary folder is gone
