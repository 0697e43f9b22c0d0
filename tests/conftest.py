"""Fixtures shared by several test folders: the pendants and browsers of ``support.fixtures``
(registered below; ``tests/`` is on ``sys.path`` through pyproject.toml's ``pythonpath``, so the
shared helpers import as ``support.*``), a real PostgreSQL server (Debian's packages) for the
gradebook's PostgreSQL backend, the gradebook target parametrized over both backends, and
Debian's nginx for the front-end test.

The server is started once per test session: ``initdb`` into a temporary folder, ``pg_ctl
start`` on a free port of 127.0.0.1 with its unix socket in that folder (password login,
scram-sha-256), stopped and removed at the end. As root the binaries run as the ``postgres``
user (``runuser``; ``nobody`` if the package made no such user): PostgreSQL refuses to run as
root. ``fsync=off`` keeps the tests fast on a shared machine (durability across a power cut is
not what they test; every commit still goes through the server as in a class).

Where the server binaries (``/usr/lib/postgresql/*/bin``, or ``$PG_BIN``), psycopg or nginx
are missing, the tests that need them are skipped with the reason (reported as not run), and
under ``CI=true`` they fail: ``scripts/run-tests.sh`` installs ``postgresql`` and ``nginx`` with
apt-get.

Which tests are slow: the ``browser`` tests are marked ``slow`` here as well (the quick lane,
``scripts/run-tests.sh --quick``, runs ``-m "not slow"``).

Which tests may share the CPU: ``scripts/run-tests.sh`` runs the tests not marked ``serial`` on
two pytest-xdist workers (each worker starts its own PostgreSQL server: a session fixture is one
per process), then the ``serial`` ones in one process. A test is marked ``serial`` here, at
collection, when it is in a folder of :data:`SERIAL_FOLDERS` or has the ``browser`` marker: those
start servers, chromium and websocket clients whose latencies, loads and time bounds they assert
or print, so they run with the machine to themselves as before. Plain ``pytest`` runs everything
in one process, as before.
"""

from __future__ import annotations

import glob
import itertools
import os
import pwd
import re
import secrets
import shutil
import socket
import subprocess
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from urllib.parse import quote

import pytest

pytest_plugins = ["support.fixtures"]


def _missing(reason: str) -> None:
    if os.environ.get("CI") == "true":
        pytest.fail(f"CI=true and {reason}: scripts/run-tests.sh installs Debian's postgresql and nginx "
                    "(apt-get install postgresql nginx) and the test extra's psycopg", pytrace=False)
    pytest.skip(f"not run: {reason}")


def postgres_bin_dir() -> Path | None:
    """The folder of Debian's PostgreSQL server binaries (newest version), or ``$PG_BIN``."""
    if os.environ.get("PG_BIN"):
        return Path(os.environ["PG_BIN"])
    found = glob.glob("/usr/lib/postgresql/*/bin/initdb")
    if not found:
        return None
    newest = max(found, key=lambda p: int(re.sub(r"\D", "", Path(p).parts[-3]) or 0))
    return Path(newest).parent


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@dataclass
class PostgresServer:
    """A running PostgreSQL server for tests (superuser ``user`` with ``password``)."""

    host: str
    port: int
    user: str
    password: str
    folder: Path
    _counter: Any = None
    _admin: Any = None

    def url(self, database: str = "postgres", *, password: str | None = None, schema: str | None = None) -> str:
        """``postgresql://user:password@127.0.0.1:port/database`` (``schema``: its search_path)."""
        pw = self.password if password is None else password
        url = f"postgresql://{self.user}:{quote(pw, safe='')}@{self.host}:{self.port}/{database}"
        if schema is not None:
            url += "?options=" + quote(f"-c search_path={schema}", safe="")
        return url

    def admin(self) -> Any:
        """The superuser's connection to the ``postgres`` database (one for the session)."""
        if self._admin is None or self._admin.closed:
            import psycopg
            self._admin = psycopg.connect(self.url(), autocommit=True)
        return self._admin

    def _next(self) -> int:
        if self._counter is None:
            self._counter = itertools.count(1)
        return int(next(self._counter))

    def fresh_schema(self) -> str:
        """A URL whose tables go into a new, empty schema of the ``postgres`` database (cheap:
        one per test)."""
        name = f"gb_{os.getpid()}_{self._next()}"
        self.admin().execute(f"CREATE SCHEMA {name}")
        return self.url(schema=name)

    def fresh_database(self) -> str:
        """A URL of a new, empty database (its ``public`` schema, as in a class)."""
        name = f"class_{os.getpid()}_{self._next()}"
        self.admin().execute(f"CREATE DATABASE {name} TEMPLATE template0 ENCODING 'UTF8'")
        return self.url(name)


@pytest.fixture(scope="session")
def postgres_server() -> Iterator[PostgresServer]:
    """One PostgreSQL server for the whole test session (see the module docstring)."""
    bin_dir = postgres_bin_dir()
    if bin_dir is None or not (bin_dir / "pg_ctl").exists():
        _missing("no PostgreSQL server binaries in /usr/lib/postgresql/*/bin (set PG_BIN to another folder)")
    try:
        import psycopg  # noqa: F401
    except ImportError:
        _missing("psycopg is not installed (pip install 'psycopg[binary]')")
    assert bin_dir is not None
    run_as: list[str] = []
    owner: pwd.struct_passwd | None = None
    if os.geteuid() == 0:
        for name in ("postgres", "nobody"):
            try:
                owner = pwd.getpwnam(name)
                break
            except KeyError:
                continue
        if owner is None or shutil.which("runuser") is None:
            _missing("running as root with neither a postgres nor a nobody user and runuser")
        assert owner is not None
        run_as = ["runuser", "-u", owner.pw_name, "--"]
    folder = Path(tempfile.mkdtemp(prefix="tcp-pendant-pg-"))
    password = secrets.token_urlsafe(18)
    (folder / "pw").write_text(password + "\n")
    os.chmod(folder / "pw", 0o600)
    if owner is not None:
        os.chmod(folder, 0o755)
        os.chown(folder, owner.pw_uid, owner.pw_gid)
        os.chown(folder / "pw", owner.pw_uid, owner.pw_gid)
    data = folder / "data"
    port = free_port()
    user = "tcp_pendant_test"

    def run(*args: str, check: bool = True) -> subprocess.CompletedProcess[str]:
        return subprocess.run([*run_as, *args], cwd=folder, capture_output=True, text=True, timeout=60,
                              check=check)

    started = False
    try:
        try:
            run(str(bin_dir / "initdb"), "-D", str(data), "-U", user, f"--pwfile={folder / 'pw'}",
                "-A", "scram-sha-256", "-E", "UTF8", "--locale=C.UTF-8", "--no-sync")
            options = (f"-c listen_addresses=127.0.0.1 -p {port} -k {folder} -c fsync=off "
                       "-c synchronous_commit=off -c full_page_writes=off -c max_connections=40 "
                       "-c shared_buffers=16MB")
            run(str(bin_dir / "pg_ctl"), "-D", str(data), "-l", str(folder / "server.log"), "-w", "-t", "30",
                "-o", options, "start")
            started = True
        except subprocess.CalledProcessError as exc:
            log = folder / "server.log"
            tail = log.read_text(errors="replace")[-2000:] if log.exists() else ""
            pytest.fail(f"PostgreSQL did not start: {exc.cmd[len(run_as):]} exited {exc.returncode}: "
                        f"{exc.stderr.strip()}\n{tail}", pytrace=False)
        server = PostgresServer("127.0.0.1", port, user, password, folder)
        try:
            yield server
        finally:
            if server._admin is not None:
                server._admin.close()
    finally:
        if started:
            run(str(bin_dir / "pg_ctl"), "-D", str(data), "-m", "fast", "-w", "-t", "30", "stop",
                check=False)
        shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(scope="session")
def nginx_binary() -> Path:
    """Debian's nginx (``$NGINX``, else ``$PATH`` or /usr/sbin/nginx); skipped where missing, failed
    under CI=true."""
    if os.environ.get("NGINX"):
        found = os.environ["NGINX"] if os.access(os.environ["NGINX"], os.X_OK) else None
    else:
        found = shutil.which("nginx") or ("/usr/sbin/nginx" if os.access("/usr/sbin/nginx", os.X_OK) else None)
    if found is None:
        _missing("nginx is not installed (apt-get install nginx)")
    assert found is not None
    return Path(found)


@pytest.fixture(params=["sqlite", "postgresql"])
def gradebook_target(request: pytest.FixtureRequest, tmp_path: Path) -> str | Path:
    """Where a test's gradebook goes: a new SQLite file, or a new empty schema of the test
    PostgreSQL server (a ``postgresql://`` URL)."""
    if request.param == "sqlite":
        return tmp_path / "class.sqlite3"
    server: PostgresServer = request.getfixturevalue("postgres_server")
    return server.fresh_schema()


SERIAL_FOLDERS = ("app", "browser", "security")
"""Folders of ``tests/`` whose tests are ``serial`` (module docstring): in-process and real
pendant servers with headless clients (deadman, latency, load, threading, workers), chromium,
and the security tests' attack loads and latency bounds."""

_TESTS = Path(__file__).resolve().parent


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark ``serial`` every test of :data:`SERIAL_FOLDERS` and every ``browser`` test, but
    not a module of those folders marked ``shares_cpu`` (it asserts no time, latency or load:
    a unit test of an app module, a benchmark's smoke run that checks what it prints). Mark
    ``slow`` every ``browser`` test too: chromium draws WebGL in software here, 7-35 s a test,
    about 9 of the full run's minutes on two cores, so the quick lane (``run-tests.sh
    --quick``: ``-m "not slow"``) leaves them to the full run and ``-m browser``."""
    for item in items:
        if item.get_closest_marker("browser") is not None:
            item.add_marker(pytest.mark.slow)
        try:
            folder = item.path.resolve().relative_to(_TESTS).parts[0]
        except ValueError:                      # a test outside tests/ (given on the command line)
            folder = ""
        if item.get_closest_marker("shares_cpu") is not None and item.get_closest_marker("browser") is None:
            continue
        if folder in SERIAL_FOLDERS or item.get_closest_marker("browser") is not None:
            item.add_marker(pytest.mark.serial)
