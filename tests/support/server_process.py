"""Reusable fixtures for browser end-to-end tests (pytest + Playwright + Debian's chromium).

* ``pendant_server(*extra_args, port=None)`` (factory fixture): starts ``python -m tcp_pendant``
  in a subprocess on a free port (or ``port``) with a fresh tool library under ``tmp_path``, waits until the
  HTTP port answers (up to 60 s), yields a :class:`ServerProcess` (``url``, ``library_path``,
  ``log()``), and terminates it at the end of the test.
* ``server``: one such server with default options.
* ``browser``: a chromium launched once per session with ``executable_path='/usr/bin/chromium'``
  (or ``$CHROMIUM``) and ``--no-sandbox --disable-gpu --disable-background-networking
  --disable-component-update``.
* ``new_page(url)`` (factory fixture): a fresh browser context + page at ``url`` (its 3D view at
  ``chromium_session.RENDER_SCALE`` device pixels per CSS pixel), waits for the pendant's GUI
  ("Record point" button), closed at the end.
* ``shot(page, name)``: screenshot into the test's ``tmp_path`` (returns the path).

Software WebGL is slow: wait on conditions with generous timeouts, never fixed sleeps.
"""

from __future__ import annotations

import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
import chromium_session  # noqa: E402  (one chromium per process, shared with tests/security)
from chromium_session import CHROMIUM, CHROMIUM_ARGS  # noqa: E402,F401  (re-exported)

READY_TIMEOUT_S = 60.0
UI_TIMEOUT_MS = 60_000


def free_port() -> int:
    """A TCP port that is free right now on 127.0.0.1."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


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


def _start(tmp_path: Path, *extra: str, attempts: int = 3) -> ServerProcess:
    """Start a server on a port free right now; another process may take that port before the
    server binds it (tcp-pendant then refuses to start), so a few ports are tried."""
    for attempt in range(attempts):
        try:
            return _start_on(tmp_path, free_port(), *extra)
        except PortTakenError:
            if attempt == attempts - 1:
                raise
    raise AssertionError("unreachable")


class PortTakenError(RuntimeError):
    """The free port was taken by someone else before the server bound it."""


BROWSER_SEED = 11
"""``--seed`` of every pendant a browser test starts: a random Auto-touch direction whose 60 mm
back-off is out of reach is retried at a shorter distance, and a test that reads the distances
(TCP & Z, X's "displacement lengths 60.0 mm") then depended on the draw."""


def _start_on(tmp_path: Path, port: int, *extra: str) -> ServerProcess:
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


def _stop(sp: ServerProcess) -> None:
    if sp.proc.poll() is None:
        sp.proc.terminate()
        try:
            sp.proc.wait(10)
        except subprocess.TimeoutExpired:
            sp.proc.kill()
            sp.proc.wait(5)


@pytest.fixture
def pendant_server(tmp_path: Path) -> Iterator[Callable[..., ServerProcess]]:
    """Factory: ``pendant_server("--shared", ...)`` starts a server with extra CLI options
    (``port=N``: on that port, e.g. again on the port of a server that was killed)."""
    started: list[ServerProcess] = []

    def factory(*extra: str, port: int | None = None) -> ServerProcess:
        sp = _start(tmp_path, *extra) if port is None else _start_on(tmp_path, port, *extra)
        started.append(sp)
        return sp

    yield factory
    for sp in started:
        _stop(sp)


@pytest.fixture
def server(pendant_server: Callable[..., ServerProcess]) -> ServerProcess:
    """A pendant server with default options (KR 6, pointer) and an empty tool library."""
    return pendant_server()


@pytest.fixture(scope="session")
def browser() -> Iterator[object]:
    """Chromium (Debian's) driven by Playwright, shared by the browser tests of one run."""
    try:
        b = chromium_session.acquire()
    except FileNotFoundError as exc:
        pytest.fail(str(exc))
    try:
        yield b
    finally:
        chromium_session.release()


@pytest.fixture
def new_page(browser: object) -> Iterator[Callable[..., object]]:
    """Factory: ``new_page(url)`` opens a fresh context (its own viser client) at ``url`` and
    waits until the pendant GUI is there (``init_script``: JavaScript run first in its pages)."""
    contexts: list[object] = []

    def factory(url: str, *, width: int = 1400, height: int = 900, wait_for: str = "Record point",
                init_script: str | None = None) -> object:
        ctx = browser.new_context(viewport={"width": width, "height": height})  # type: ignore[attr-defined]
        contexts.append(ctx)
        if init_script is not None:                # runs in every page of the context before its own scripts
            ctx.add_init_script(init_script)  # type: ignore[attr-defined]
        page = ctx.new_page()
        page.set_default_timeout(UI_TIMEOUT_MS)
        page.goto(chromium_session.with_render_scale(url))
        if wait_for:
            page.get_by_role("button", name=wait_for).first.wait_for(state="visible", timeout=UI_TIMEOUT_MS)
        return page

    yield factory
    for ctx in contexts:
        try:
            ctx.close()  # type: ignore[attr-defined]
        except Exception:
            pass


@pytest.fixture
def shot(tmp_path: Path) -> Callable[[object, str], Path]:
    """``shot(page, "name")`` saves ``tmp_path/name.png`` and returns its path."""

    def take(page: object, name: str) -> Path:
        path = tmp_path / f"{name}.png"
        page.screenshot(path=str(path))  # type: ignore[attr-defined]
        return path

    return take
