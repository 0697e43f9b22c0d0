"""Child process of test_gradebook_postgres.py: one server process of a class. It imports, prints
``ready``, waits for ``go`` on stdin (so that both children start at once), then opens the
gradebook (racing the other for the schema of an empty database), races the other for the name
"Shared Sam", and records a calibration of its own trainee.

Usage: ``python concurrent_writer.py TARGET NAME N_TOUCHES`` (TARGET: a file or a postgresql://
URL). Prints ``shared won`` or ``shared refused``, ``seed <exercise seed>``, ``done <calibration id>``."""

from __future__ import annotations

import sys

import numpy as np
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.names import TraineeNameError


def main(target: str, name: str, n_touches: int) -> None:
    print("ready", flush=True)
    if sys.stdin.readline().strip() != "go":
        return
    with Gradebook(target) as g:
        try:
            g.trainees.join("Shared Sam")
            print("shared won", flush=True)
        except TraineeNameError:
            print("shared refused", flush=True)
        me = g.trainees.join(name)
        sid = g.records.start_session(me.trainee_id, "own")
        cid = g.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
        pose = np.eye(4)
        previous = None
        for i in range(n_touches):       # every odd touch overwrites the one before, at its step
            pose[0, 3] = i * 1e-3
            previous = g.records.record_touch(cid, i // 2, pose, [float(i)] * 6, 0.1, i % 3 == 0,
                                              overwritten_touch_id=previous if i % 2 == 1 else None)
        print(f"seed {g.settings.exercise_seed()}", flush=True)
        g.records.finish_calibration(cid, {"mean_error_mm": 0.1}, position_error_mm=0.2, orientation_error_deg=None,
                                     grade="good")
        print(f"done {cid}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]))
