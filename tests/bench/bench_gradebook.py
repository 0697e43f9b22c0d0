"""Benchmark of the class gradebook (tcp_pendant.classroom.gradebook).

    python tests/bench/bench_gradebook.py [--quick] [--dir FOLDER]

Prints the median and 99th percentile (us) of one ``Gradebook.record_touch`` (validation, JSON,
one committed transaction) on a file in FOLDER (default: a temporary folder), with
``synchronous=FULL`` (the default: an fsync per commit) and ``NORMAL``, against baselines
measured in the same run:

1. a plain INSERT + COMMIT of the same row into an in-memory SQLite database (no disk at all);
2. the same plain INSERT + COMMIT into a WAL file with ``synchronous=FULL`` (raw SQLite cost:
   the difference to record_touch is this module's own overhead).

Then ``finish_calibration`` and ``grades()`` over the rows written. The app calls these on
viser's event loop (one per touch, human-paced), so the figure to read is record_touch FULL
against a jog step (~100-200 us, bench_controller.py). ``--quick`` runs few repetitions (used by
tests/classroom/test_bench_gradebook_runs.py).
"""

from __future__ import annotations

import argparse
import json
import sqlite3
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from tcp_pendant.classroom.gradebook import Gradebook

POSE = np.array([[0.0, 0, 1, 0.55], [0, 1, 0, 0.05], [-1, 0, 0, 0.43], [0, 0, 0, 1]])
JOINTS = [10.0, -80.0, 100.0, 20.0, 40.0, 30.0]


def timings_us(fn: Callable[[int], object], repeats: int) -> tuple[float, float]:
    """(median, 99th percentile) of ``fn(i)`` in microseconds."""
    times = []
    for i in range(repeats):
        t0 = time.perf_counter_ns()
        fn(i)
        times.append(time.perf_counter_ns() - t0)
    times.sort()
    return statistics.median(times) / 1000.0, times[min(len(times) - 1, int(0.99 * len(times)))] / 1000.0


def plain_insert(db: sqlite3.Connection) -> Callable[[int], object]:
    db.execute("CREATE TABLE touches (id INTEGER PRIMARY KEY, calibration_id INTEGER, step_index INTEGER, "
               "recorded_at TEXT, pose TEXT, joints TEXT, distance_mm REAL, auto INTEGER)")
    pose, joints = json.dumps(POSE.tolist()), json.dumps(JOINTS)

    def insert(i: int) -> None:
        db.execute("BEGIN IMMEDIATE")
        db.execute("INSERT INTO touches (calibration_id, step_index, recorded_at, pose, joints, distance_mm, "
                   "auto) VALUES (1, ?, '2025-01-01T00:00:00.000+00:00', ?, ?, 0.1, 0)", (i % 4, pose, joints))
        db.execute("COMMIT")
    return insert


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true")
    p.add_argument("--dir", type=Path, default=None)
    args = p.parse_args(argv)
    repeats = 40 if args.quick else 1000
    with tempfile.TemporaryDirectory(dir=args.dir) as folder:
        folder = Path(folder)
        rows: list[tuple[str, float, float]] = []
        memory = sqlite3.connect(":memory:", isolation_level=None)
        rows.append(("baseline: plain INSERT+COMMIT, in-memory", *timings_us(plain_insert(memory), repeats)))
        raw = sqlite3.connect(folder / "raw.sqlite3", isolation_level=None)
        raw.execute("PRAGMA journal_mode = WAL")
        raw.execute("PRAGMA synchronous = FULL")
        rows.append(("baseline: plain INSERT+COMMIT, WAL file FULL", *timings_us(plain_insert(raw), repeats)))
        for sync in ("FULL", "NORMAL"):
            with Gradebook(folder / f"class-{sync}.sqlite3", synchronous=sync) as book:
                sid = book.start_session(book.add_trainee("Bench"), "own")
                cid = book.start_calibration(sid, "xyz4", "pointer", np.eye(4))
                rows.append((f"record_touch, synchronous={sync}",
                             *timings_us(lambda i: book.record_touch(cid, i % 4, POSE, JOINTS, 0.1, i % 2 == 0),
                                         repeats)))
                if sync == "FULL":
                    cids = [book.start_calibration(sid, "xyz4", "pointer", np.eye(4)) for _ in range(repeats)]
                    rows.append(("finish_calibration, synchronous=FULL", *timings_us(
                        lambda i: book.finish_calibration(cids[i], {"mean_error_mm": 0.2, "ci95_mm": 0.8},
                                                          position_error_mm=0.3, orientation_error_deg=None,
                                                          grade="good", tcp_mm=(0, 0, 180)), repeats)))
                    reps = 5 if args.quick else 20
                    rows.append((f"grades() of {repeats} rows, {repeats} touches",
                                 *timings_us(lambda i: book.grades(), reps)))
    base = rows[0][1]
    print(f"gradebook bench ({repeats} calls each; median and p99 in us; x = median / in-memory baseline)")
    for label, med, p99 in rows:
        print(f"  {label:<48} {med:10.1f} {p99:10.1f}   x{med / base:8.1f}")


if __name__ == "__main__":
    main()
