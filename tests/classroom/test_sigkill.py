"""A kill -9 of the writer loses nothing that was acknowledged."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from tcp_pendant.classroom.gradebook import Gradebook

WRITER = Path(__file__).with_name("sigkill_writer.py")


@pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="SIGKILL is POSIX only")
@pytest.mark.parametrize("n_acks", [1, 57])
def test_sigkill_after_n_acknowledgements_keeps_all_n(tmp_path: Path, n_acks: int) -> None:
    path = tmp_path / "class.sqlite3"
    proc = subprocess.Popen([sys.executable, str(WRITER), str(path)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    acked: list[int] = []
    try:
        first = proc.stdout.readline()
        assert first.startswith("calibration "), first + proc.stderr.read()
        calibration_id = int(first.split()[1])
        while len(acked) < n_acks:
            line = proc.stdout.readline()
            assert line.startswith("ack "), line + proc.stderr.read()
            acked.append(int(line.split()[1]))
        os.kill(proc.pid, signal.SIGKILL)    # mid-stream: the writer is inside its next write
        # what it had printed but we had not read yet was acknowledged too
        printed = acked + [int(line.split()[1]) for line in proc.stdout.read().splitlines()
                           if line.startswith("ack ")]
    finally:
        proc.kill()
        proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL
    with Gradebook(path, create=False) as g:
        stored = {t["id"]: t for t in g.records.touches(calibration_id)}
    assert set(printed) <= set(stored), f"lost acknowledged touches {sorted(set(printed) - set(stored))}"
    # the acknowledged ones are whole: pose and joints as written
    for k, touch_id in enumerate(printed):
        assert stored[touch_id]["T_world_flange_m"][0][3] == pytest.approx(k * 1e-3, abs=1e-15)
        assert stored[touch_id]["joints_deg"] == [float(k)] * 6
    # at most the one in flight when killed was stored without being acknowledged
    assert len(stored) - len(printed) in (0, 1)
