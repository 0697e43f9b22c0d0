"""Smoke test: the class-load benchmark still runs on a real ``tcp-pendant --class --workers 2``
(two trainees, two seconds) and prints a row whose figures add up: every press asked is
answered or counted unanswered, the percentiles are ordered, the two trainees are split one
per server process (the connection balance, read from the gradebook's presence), each server
process used some CPU over the presses and no process more than a core, ms/step is the servers'
CPU per step achieved, and the load generator's own delay ("sent late") is printed. The two
clients run in one client process, so the second arrives after the first's handshake and the
benchmark's arrival gap, as in a class, not at the same instant from two processes. The clients
run at the servers' priority (``--client-nice 0``): niced in a busy test run they could be
starved for seconds."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [pytest.mark.shares_cpu,  # asserts no time or load (tests/conftest.py)
              pytest.mark.slow]       # a benchmark's smoke run

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_class_load.py"
ROW = re.compile(r"^ +2 +(?P<p50>\S+) +(?P<p95>\S+) +(?P<p99>\S+) +(?P<max>\S+) +(?P<asked>\d+) +(?P<unanswered>\d+) "
                 r"+(?P<steps>\S+) +(?P<per_k>\S+) +(?P<ms_step>\S+) +(?P<cpu1>\S+) (?P<cpu2>\S+) +(?P<clients>\S+) "
                 r"+(?P<wait1>\S+) (?P<wait2>\S+) +(?P<split>\d+/\d+) +(?P<late50>\S+)/(?P<late99>\S+)$", re.MULTILINE)


def test_bench_class_load_prints_a_row_that_adds_up_and_the_split() -> None:
    out = subprocess.run([sys.executable, str(BENCH), "--counts", "2", "--duration", "2", "--client-procs", "1",
                          "--client-nice", "0"], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "clients in 1 processes at nice 0 " in out.stdout, out.stdout
    m = ROW.search(out.stdout)
    assert m, out.stdout
    p50, p95, p99, worst = (float(m.group(k)) for k in ("p50", "p95", "p99", "max"))
    assert all(math.isfinite(v) and v > 0 for v in (p50, p95, p99, worst)) and p50 <= p95 <= p99 <= worst
    asked, unanswered = int(m.group("asked")), int(m.group("unanswered"))
    assert asked >= 2 * 2 * 20 * 0.9 and 0 <= unanswered <= asked
    assert m.group("split") == "1/1"
    # CPU over the presses: each server process did work (~40 steps; the client's two trainees may
    # print 0.00), no process more than a core
    cores = [float(m.group(k)) for k in ("cpu1", "cpu2", "clients")]
    assert 0.0 < cores[0] <= 1.0 and 0.0 < cores[1] <= 1.0 and 0.0 <= cores[2] <= 1.0, cores
    assert 0.0 <= float(m.group("wait1")) <= 1.0 and 0.0 <= float(m.group("wait2")) <= 1.0
    steps = float(m.group("steps"))              # ms/step is the two processes' CPU per step achieved; the
    rounding_ms = 0.01 / steps * 1e3 + 0.01      # cores are printed to 0.01 each, ms/step to 0.01
    assert abs(float(m.group("ms_step")) - (cores[0] + cores[1]) / steps * 1e3) <= rounding_ms
    late50, late99 = float(m.group("late50")), float(m.group("late99"))   # the load generator's own delay, ms
    assert -1.0 <= late50 <= late99 < 2000.0
    assert re.search(r"^RESULT: 2 trainees asked .*: (MET|NOT MET)$", out.stdout, re.MULTILINE), out.stdout
