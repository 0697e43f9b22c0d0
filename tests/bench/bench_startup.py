"""Start-up time of the pendant: from launching ``python -m tcp_pendant`` to the first HTTP 200
(issue target: ready to serve in under 5 s), against a baseline measured in the same run: a
bare viser server started by ``python -c`` (the floor: interpreter, imports, the web server).

Each figure is the median of ``--runs`` fresh processes (default 5). The pendant's own share is
the difference: URDF loading with pinocchio and yourdfpy, meshes parsed and cached, the tool
library opened.

    .venv/bin/python tests/bench/bench_startup.py [--runs 5]
"""

from __future__ import annotations

import argparse
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

TARGET_S = 5.0
BARE_VISER = (
    "import sys, time, viser\n"
    "s = viser.ViserServer(host='127.0.0.1', port=int(sys.argv[1]), verbose=False)\n"
    "time.sleep(600)\n"
)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def time_to_first_200(cmd: list[str], port: int, timeout_s: float = 60.0) -> float:
    """Seconds from spawning ``cmd`` until http://127.0.0.1:port answers 200."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        while time.perf_counter() - t0 < timeout_s:
            if proc.poll() is not None:
                raise SystemExit(f"{cmd[:3]} exited with {proc.returncode}")
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}", timeout=1.0) as r:
                    if r.status == 200:
                        return time.perf_counter() - t0
            except OSError:
                time.sleep(0.02)
        raise SystemExit(f"{cmd[:3]} did not answer within {timeout_s} s")
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    pendant: list[float] = []
    bare: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.runs):                   # interleaved, so both see the same load
            port = free_port()
            bare.append(time_to_first_200([sys.executable, "-c", BARE_VISER, str(port)], port))
            port = free_port()
            lib = Path(tmp) / f"tools_{i}.json"
            pendant.append(time_to_first_200([sys.executable, "-m", "tcp_pendant", "--port", str(port),
                                              "--tool-library", str(lib)], port))
    p, b = statistics.median(pendant), statistics.median(bare)
    print(f"Start-up to first HTTP 200, median of {args.runs} fresh processes (spawn included)")
    print(f"  bare viser server (baseline)   {b:6.2f} s")
    print(f"  tcp-pendant, default options   {p:6.2f} s   ({p / b:.2f}x the baseline; "
          f"its own share {p - b:.2f} s)")
    print(f"RESULT tcp-pendant ready in {p:.2f} s (target < {TARGET_S:g} s: {'met' if p < TARGET_S else 'NOT met'})")


if __name__ == "__main__":
    main()
