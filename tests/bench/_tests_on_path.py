"""What a benchmark run as a script imports first.

``python tests/bench/bench_x.py`` puts only ``tests/bench`` on ``sys.path``; this adds ``tests/``
after it, as pytest's ``pythonpath`` (pyproject.toml) does for the tests, so that a benchmark
imports the tests' shared helpers (``support.*``) and the other benchmarks (``bench.*``) by the
names the tests use. A benchmark imported by a test (as ``bench.bench_x``) does not import it.
"""

import sys
from pathlib import Path

TESTS = str(Path(__file__).resolve().parents[1])
if TESTS not in sys.path:
    sys.path.insert(1, TESTS)
