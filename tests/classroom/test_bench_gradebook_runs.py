"""Smoke test: the gradebook benchmark still runs (``--quick``, and with ``--postgres`` on the test
server) and prints its figures."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_gradebook.py"


FILE_ROWS = {"baseline: plain INSERT+COMMIT, in-memory", "baseline: plain INSERT+COMMIT, WAL file FULL",
             "record_touch, synchronous=FULL", "record_touch, synchronous=NORMAL",
             "finish_calibration, synchronous=FULL", "grades() of 40 rows, 40 touches"}


def _rows(text: str) -> dict[str, tuple[float, float]]:
    return {m.group(1).strip(): (float(m.group(2)), float(m.group(3)))
            for m in re.finditer(r"^  (.+?)\s+(\d+\.\d)\s+(\d+\.\d)\s+x\s*\d", text, re.MULTILINE)}


@pytest.mark.slow
def test_bench_gradebook_quick_runs(tmp_path: Path) -> None:
    out = subprocess.run([sys.executable, str(BENCH), "--quick", "--dir", str(tmp_path)], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    rows = _rows(out.stdout)
    assert set(rows) == FILE_ROWS
    assert all(med > 0 and p99 >= med for med, p99 in rows.values())
    assert list(tmp_path.iterdir()) == []          # its temporary folder is gone


@pytest.mark.slow
def test_bench_gradebook_quick_runs_on_postgresql(tmp_path: Path, postgres_server,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    spec = importlib.util.spec_from_file_location("bench_gradebook", BENCH)   # in this process: no start-up
    assert spec is not None and spec.loader is not None
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    bench.main(["--quick", "--dir", str(tmp_path), "--postgres", postgres_server.fresh_schema()])
    rows = _rows(capsys.readouterr().out)
    assert set(rows) == FILE_ROWS | {"baseline: plain INSERT+COMMIT, PostgreSQL", "record_touch, PostgreSQL",
                                     "grades() of 40 rows, PostgreSQL"}
    assert all(med > 0 and p99 >= med for med, p99 in rows.values())
