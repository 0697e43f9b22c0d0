"""Smoke test: the server benchmark still runs (``--quick``) and prints its tables, the
classroom one (gradebook on / off) included, with finite figures, and a verdict that follows
from the steps achieved and the press-to-readout latency."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [pytest.mark.shares_cpu,  # asserts no time or load (tests/conftest.py)
              pytest.mark.slow]       # a benchmark's smoke run

BENCH = Path(__file__).resolve().parents[1] / "bench" / "bench_server.py"
ROW = re.compile(r"^  (\S.+?)\s+(\S+) ms\s+(\S+) ms\s+(\S+)$", re.MULTILINE)

CLASSROOM_ROWS = {
    "A hot loop: thread CPU per step, median", "A hot loop: thread CPU per step, p95",
    "A hot loop: process CPU per step", "B paced 30/s per session, direct: process CPU per step",
    "C paced 30/s per session, end to end: process CPU/step", "wizard touch (Record): thread CPU, median",
    "wizard touch (Record): wall (loop blocked), median", "wizard touch (Record): wall (loop blocked), p95",
    "wizard touch (Record): process CPU per touch",
}


def table(text: str) -> dict[str, tuple[float, float, float]]:
    return {m.group(1).strip(): (float(m.group(2)), float(m.group(3)), float(m.group(4)))
            for m in ROW.finditer(text)}


def half_units(text: str) -> dict[str, tuple[float, float]]:
    """Per row, half a unit of the last digit printed of its first two figures (their rounding)."""
    def half(figure: str) -> float:
        return 0.5 * 10.0 ** -len(figure.partition(".")[2])
    return {m.group(1).strip(): (half(m.group(2)), half(m.group(3))) for m in ROW.finditer(text)}


def test_bench_server_quick_prints_the_classroom_table() -> None:
    out = subprocess.run([sys.executable, str(BENCH), "--quick"], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    text = out.stdout
    assert "app/baseline" in text and "RESULT:" in text
    head, sep, classroom = text.partition("classroom (--class: gradebook on, 2 named trainees)")
    assert sep, text
    app_rows = table(head)
    assert {"A hot loop: thread CPU per step, median", "C paced 30/s per session, end to end: process CPU/step"} \
        <= set(app_rows)
    rows = table(classroom.split("RESULT:")[0])
    assert set(rows) == CLASSROOM_ROWS
    halves = half_units(classroom.split("RESULT:")[0])
    for name, (on, off, ratio) in rows.items():
        assert all(math.isfinite(v) and v > 0 for v in (on, off, ratio)), name
        # the ratio of the unrounded figures, printed to 0.01: within the rounding of all three
        h_on, h_off = halves[name]
        bound = 0.005 + (h_on + on / off * h_off) / (off - h_off) + 1e-9
        assert abs(ratio - on / off) <= bound, (name, on, off, ratio, bound)
    # the class-off column is the app's own figure of the first table
    for name in ("A hot loop: thread CPU per step, median", "C paced 30/s per session, end to end: process CPU/step"):
        assert rows[name][1] == app_rows[name][0]
    # every Record press of the class-on run went into the gradebook (2 sessions x 3 touches)
    assert re.search(r"gradebook: 6 touches written", classroom)
    # the verdict is the steps achieved and the latency from press to readout
    v = re.search(r"RESULT: 2 sessions asked (\S+) jog presses/s each: achieved (\S+) steps/s per session, press to "
                  r"readout p50 (\S+) ms, p95 (\S+) ms, p99 (\S+) ms, (\d+) of (\d+) presses unanswered "
                  r"\((\d+) dropped by the deadman\).*: (MET|NOT MET)$", text, re.MULTILINE)
    assert v, text
    asked, achieved, p50, p95, p99 = (float(x) for x in v.groups()[:5])
    unanswered, presses, dropped = (int(x) for x in v.groups()[5:8])
    assert 0 < achieved <= asked and 0 < p50 <= p95 <= p99 and presses > 0 and dropped <= unanswered <= presses
    assert (v.group(9) == "MET") == (p99 < 100 and unanswered == 0 and achieved >= 0.95 * asked)
    m = re.search(r"RESULT classroom: a jog step with the gradebook on costs (\S+)x .* a recorded wizard touch "
                  r"(\S+)x", text)
    assert m and all(math.isfinite(float(v)) and float(v) > 0 for v in m.groups())
