"""A pendant server in a subprocess (``python -m tcp_pendant``), as a user starts it: the
``pendant_server`` fixture's (``support.fixtures``) start and stop.

:func:`start` runs it on a free port (or a given one) with a fresh tool library, waits until its
HTTP port answers (up to :data:`READY_TIMEOUT_S`) and returns a :class:`ServerProcess`
(``url``, ``library_path``, ``log()``); :func:`stop` terminates it.
"""

from __future__ import annotations

import subprocess
import sys
import time
import urllib.request
from dataclasses import dataclass, field
from pathlib import Path

from support.wsclient import free_port

READY_TIMEOUT_S = 60.0

BROWSER_SEED = 11
"""``--seed`` of every pendant a browser test starts: a random Auto-touch direction whose 60 mm
back-off is out of reach is retried at a shorter distance, and a test that reads the distances
(TCP & Z, X's "displacement lengths 60.0 mm") then depended on the draw."""


@dataclass
class ServerProcess:
    """A pendant server running in a subprocess."""

    proc: subprocess.Popen[bytes]
    port: int
    library_path: Path
    log_path: Path
    startup_s: float = field(default=float("nan"))

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    def log(self) -> str:
        return self.log_path.read_text(errors="replace") if self.log_path.exists() else ""


class PortTakenError(RuntimeError):
    """The free port was taken by someone else before the server bound it."""


def start(tmp_path: Path, *extra: str, attempts: int = 3) -> ServerProcess:
    """Start a server on a port free right now; another process may take that port before the
    server binds it (tcp-pendant then refuses to start), so a few ports are tried."""
    for attempt in range(attempts):
        try:
            return start_on(tmp_path, free_port(), *extra)
        except PortTakenError:
            if attempt == attempts - 1:
                raise
    raise AssertionError("unreachable")


def start_on(tmp_path: Path, port: int, *extra: str) -> ServerProcess:
    """Start a server on ``port`` with the tool library ``tmp_path/tools.json`` and the CLI
    options ``extra`` (``--seed`` :data:`BROWSER_SEED` unless they give one); its output goes to
    ``tmp_path/server_<port>.log``."""
    lib = tmp_path / "tools.json"
    log_path = tmp_path / f"server_{port}.log"
    k = 1
    while log_path.exists():                     # a server started again on the same port
        log_path, k = tmp_path / f"server_{port}_{k}.log", k + 1
    seed = () if "--seed" in extra else ("--seed", str(BROWSER_SEED))   # Auto-touch's directions replay
    cmd = [sys.executable, "-m", "tcp_pendant", "--port", str(port), "--tool-library", str(lib), *seed, *extra]
    t0 = time.perf_counter()
    with open(log_path, "wb") as logf:
        proc = subprocess.Popen(cmd, stdout=logf, stderr=subprocess.STDOUT)
    sp = ServerProcess(proc, port, lib, log_path)
    deadline = time.monotonic() + READY_TIMEOUT_S
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            if "already in use" in sp.log():
                raise PortTakenError(sp.log())
            raise RuntimeError(f"tcp-pendant exited with {proc.returncode}:\n{sp.log()}")
        try:
            with urllib.request.urlopen(sp.url, timeout=1.0) as r:
                if r.status == 200:
                    sp.startup_s = time.perf_counter() - t0
                    return sp
        except OSError:
            time.sleep(0.05)
    proc.kill()
    raise RuntimeError(f"tcp-pendant did not answer on {sp.url} within {READY_TIMEOUT_S} s:\n{sp.log()}")


def stop(sp: ServerProcess) -> None:
    """Terminate the server (killed if it has not exited 10 s later)."""
    if sp.proc.poll() is None:
        sp.proc.terminate()
        try:
            sp.proc.wait(10)
        except subprocess.TimeoutExpired:
            sp.proc.kill()
            sp.proc.wait(5)
