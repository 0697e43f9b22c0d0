"""``tcp-pendant --workers N``: N server processes on one port, so a class uses every core.

The process the trainer started is the first server process; once it listens (its port bound
with ``SO_REUSEPORT``: ``views.viser_adapter.listen_reuse_port``, so ``--port 0`` gives the
port the others take too) it starts the N - 1 others, each ``python -m tcp_pendant`` with the
same options plus ``--port PORT`` and :data:`WORKER_ENV` in its environment. Every process
binds the same address with ``SO_REUSEPORT`` and the kernel hands each new connection to one
of them: to the one with the fewest browsers (``tcp_pendant.serve.balance``; the record's path is in
the workers' environment, ``BALANCE_ENV``), so a browser's websocket (its whole session) lives
in one process, and its page's static files may come from another: every process serves the
same files.

Each process has its own sessions (a jog step never leaves the process that runs it) and its
own copy of the robot; what the class shares goes through the gradebook (SQLite in WAL mode:
several processes on one machine; ``classroom.class_room``: presence, pushed settings, the
trainer's table). The tool library is a locked JSON file every process re-reads when it
changes. A worker needs the trainer token only as the gradebook keeps it (its SHA-256), which
the first process stored before starting them.

Life cycle: the first process waits for each worker's ready line (``worker ready PID`` on its
stdout; a worker that exits first fails the start, which then stops the others), watches them
(a worker that dies is reported on stderr; its browsers reconnect to the others, which give
their calibrations back from the gradebook) and stops them when it stops. A worker stops by
itself when the first process is gone (its parent changed).
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

__all__ = ["MAX_WORKERS", "WORKER_ENV", "WorkerError", "Workers", "worker_index"]

WORKER_ENV = "TCP_PENDANT_WORKER"
"""Set in a worker's environment to ``k/N:PARENT_PID`` (k = 2..N); unset in the first process."""
MAX_WORKERS = 32
READY_TIMEOUT_S = 180.0
"""How long the first process waits for a worker's ready line (loading the robot takes seconds)."""


class WorkerError(RuntimeError):
    """A worker did not start; the message says which and why."""


def worker_index(environ: dict[str, str] | os._Environ[str] | None = None) -> tuple[int, int, int] | None:
    """``(k, n, parent_pid)`` of this worker process, None in the first (or only) process."""
    value = (os.environ if environ is None else environ).get(WORKER_ENV)
    if not value:
        return None
    try:
        kn, parent = value.split(":")
        k, n = (int(v) for v in kn.split("/"))
        return k, n, int(parent)
    except ValueError:
        raise WorkerError(f"{WORKER_ENV}={value!r} is not k/N:PID; it is set by tcp-pendant --workers, "
                          "not by hand") from None


@dataclass
class Workers:
    """The N - 1 other server processes of the first one (module docstring).

    Args:
        argv: the first process's command-line options (passed on as they are).
        port: the port the first process listens on.
        n: server processes in all (>= 2).
        env: more environment of the workers (the balance record's path: ``tcp_pendant.serve.balance``).
        on_stopped: called once when a worker stops while the class runs (the balance turns off).
    """

    argv: Sequence[str]
    port: int
    n: int
    env: dict[str, str] = field(default_factory=dict)
    on_stopped: Callable[[], None] | None = None
    processes: list[subprocess.Popen[bytes]] = field(default_factory=list)
    _stopping: threading.Event = field(default_factory=threading.Event)

    @property
    def pids(self) -> list[int]:
        return [p.pid for p in self.processes]

    def start(self, timeout_s: float = READY_TIMEOUT_S) -> list[int]:
        """Start the workers and wait until each listens; returns their pids.

        Raises:
            WorkerError: a worker exited or was not ready in ``timeout_s`` (the others stopped).
        """
        cmd = [sys.executable, "-m", "tcp_pendant", *self.argv, "--port", str(self.port), "--workers", "1"]
        for k in range(2, self.n + 1):
            env = dict(os.environ, **self.env, **{WORKER_ENV: f"{k}/{self.n}:{os.getpid()}"})
            self.processes.append(subprocess.Popen(cmd, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE))
        deadline = time.monotonic() + timeout_s
        try:
            for k, p in enumerate(self.processes, start=2):
                self._wait_ready(k, p, deadline)
        except BaseException:
            self.stop()
            raise
        for k, p in enumerate(self.processes, start=2):
            threading.Thread(target=self._watch, args=(k, p), name=f"worker-{k}", daemon=True).start()
        return self.pids

    def _wait_ready(self, k: int, p: subprocess.Popen[bytes], deadline: float) -> None:
        stdout = p.stdout
        assert stdout is not None
        ready = threading.Event()

        def read() -> None:               # viser prints its banner first: the ready line follows
            for raw in stdout:
                if raw.startswith(b"worker ready"):
                    ready.set()
                    return

        reader = threading.Thread(target=read, daemon=True)
        reader.start()
        reader.join(max(0.0, deadline - time.monotonic()))
        if not ready.is_set():
            code = p.poll()
            why = f"exited with code {code}" if code is not None else "was not ready in time"
            raise WorkerError(f"server process {k} of {self.n} {why} (its error is above); the class runs "
                              "with --workers 1")

    def _watch(self, k: int, p: subprocess.Popen[bytes]) -> None:
        code = p.wait()
        if not self._stopping.is_set():
            if self.on_stopped is not None:
                try:
                    self.on_stopped()
                except Exception as exc:  # the warning below must still be printed
                    print(f"WARNING: after server process {k} stopped: {exc}", file=sys.stderr, flush=True)
            print(f"WARNING: server process {k} of {self.n} (pid {p.pid}) stopped (exit code {code}); its "
                  "browsers reconnect to the others and get their calibrations back from the gradebook",
                  file=sys.stderr, flush=True)

    def alive(self) -> int:
        """How many workers still run."""
        return sum(p.poll() is None for p in self.processes)

    def stop(self, timeout_s: float = 10.0) -> None:
        """Stop every worker (SIGTERM, then SIGKILL after ``timeout_s``)."""
        self._stopping.set()
        for p in self.processes:
            if p.poll() is None:
                p.terminate()
        deadline = time.monotonic() + timeout_s
        for p in self.processes:
            try:
                p.wait(max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
            if p.stdout is not None:
                p.stdout.close()
