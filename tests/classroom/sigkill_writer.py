"""Child process of test_sigkill.py: writes touches to a gradebook as fast as it can and prints
``ack <touch_id>`` (flushed) after each ``record_touch`` returned, as the GUI acknowledges a
touch on screen after the call. Usage: ``python sigkill_writer.py DB_PATH``."""

from __future__ import annotations

import sys

import numpy as np
from tcp_pendant.classroom.gradebook import Gradebook


def main(path: str) -> None:
    g = Gradebook(path)
    sid = g.records.start_session(g.trainees.add("Killed Kim"), "own")
    cid = g.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
    print(f"calibration {cid}", flush=True)
    pose = np.eye(4)
    i = 0
    while True:
        pose[0, 3] = i * 1e-3
        touch = g.records.record_touch(cid, i % 4, pose, [float(i)] * 6, 0.1, i % 3 == 0)
        print(f"ack {touch}", flush=True)
        i += 1


if __name__ == "__main__":
    main(sys.argv[1])
