"""``tcp-pendant --workers 2``: two real server processes on one port. The browsers are spread
over both, each new one to the process with fewer (``tcp_pendant.serve.balance``; each process's pid
is in the gradebook's presence table, ``holder``), and the jog deadman holds in each."""

from __future__ import annotations

import asyncio
import os
import re
import subprocess
import sys
import time
from collections import Counter
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from support.async_clients import PLUS, READOUT_LABEL, TOKEN_LABEL, connect_all

from tcp_pendant.serve.balance import BalanceFile
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.trainer_token import lock_s

ROOT = Path(__file__).resolve().parents[2]
FLOOD_PRESSES = 6000
"""The deadman test's flood: far more 0.1 mm presses than the server carries out within the
deadman's bound (of 1,500, all were carried out in time in one full run)."""
pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="SO_REUSEPORT spreading is Linux's")


async def until(what: str, fn: Callable[[], Any], timeout_s: float = 30.0,
                detail: Callable[[], object] = lambda: "") -> Any:
    """Poll ``fn`` every 20 ms until it returns something true, and return that; fail naming
    ``what`` (and ``detail()``, what was seen) after ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while not (got := fn()):
        assert time.monotonic() < deadline, f"{what}: not within {timeout_s} s ({detail()})"
        await asyncio.sleep(0.02)
    return got


def trainees_per_process(present: list[tuple[str, str, Any]]) -> Counter[int]:
    """How many of the gradebook's presence rows each server process (the pid in the holder,
    ``...:<pid>:<n>``) holds."""
    return Counter(int(holder.split(":")[-2]) for _, holder, _ in present)


def _start_workers2(tmp_path: Path, class_db: str, seed: str,
                    token: str) -> tuple[subprocess.Popen[str], int, list[int], str]:
    """Start ``tcp-pendant --class-db CLASS_DB --workers 2 --port 0`` and wait until it is ready:
    (the first process, the port, both pids, its ready message). The caller terminates it."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT / "src"), str(ROOT / "app")]),
               TCP_PENDANT_TRAINER_TOKEN=token, TMPDIR=str(tmp_path))
    server = subprocess.Popen([sys.executable, "-m", "tcp_pendant", "--port", "0", "--workers", "2", "--class-db",
                               class_db, "--tool-library", str(tmp_path / "tools.json"), "--seed", seed],
                              env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, text=True)
    assert server.stdout is not None
    text = ""
    while "Ctrl-C to stop" not in text:
        line = server.stdout.readline()
        if not line:
            server.terminate()
            raise AssertionError(f"the server exited (code {server.wait()}):\n{text}")
        text += line
    port = re.search(r"http://127\.0\.0\.1:(\d+)", text)
    listed = re.search(r"2 server processes on port \d+ \(pids ([\d, ]+)\)", text)
    if port is None or listed is None:
        server.terminate()
        server.wait(60)
        raise AssertionError(f"no URL or pids in the ready message:\n{text}")
    return server, int(port.group(1)), [int(p) for p in listed.group(1).split(",")], text


@pytest.fixture(scope="module")
def workers2(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[int, list[int], Path]]:
    """``tcp-pendant --class --workers 2 --port 0``: (port, pids, gradebook path); one pair of
    processes for the tests of this file (each names its own trainees), stopped after."""
    tmp_path = tmp_path_factory.mktemp("workers2")
    db = tmp_path / "class.sqlite3"
    server, port, pids, _ = _start_workers2(tmp_path, str(db), "5", "trainer-token-for-tests-0001")
    try:
        assert pids[0] == server.pid and len(set(pids)) == 2
        yield port, pids, db
    finally:
        server.terminate()                       # SIGTERM: the first process stops the other
        server.wait(60)
    assert all(not Path(f"/proc/{pid}").exists() or "zombie" in Path(f"/proc/{pid}/status").read_text()
               for pid in pids[1:])


@pytest.mark.slow  # two server processes under load
@pytest.mark.timeout(300)
def test_two_processes_share_the_port_the_class_and_each_keeps_the_deadman(workers2) -> None:
    port, pids, db = workers2

    async def scenario() -> tuple[set[int], list[str], float, float, float, list[tuple[float, float]]]:
        clients = await connect_all("127.0.0.1", port, 20, names="Spread")
        try:
            await asyncio.sleep(0.5)
            book = Gradebook(db)
            try:
                deadline = time.monotonic() + 20
                while len(book.presence.present()) < 20 and time.monotonic() < deadline:
                    await asyncio.sleep(0.1)
                rows = book.presence.present()
            finally:
                book.close()
            holders = {int(holder.split(":")[-2]) for _, holder, _ in rows}
            names = [name for name, _, _ in rows]
            # the deadman: one trainee floods "X +" (0.1 mm) far faster than a step is carried out
            c = clients[0]
            x0 = c.readouts[-1][1]
            c.readouts.clear()
            for _ in range(FLOOD_PRESSES):
                await c.send_update(PLUS, {"value": True})
            last_press = time.monotonic()
            # under overload a press's readout merges with the presses queued behind it: wait for
            # the first readout of the flood (none in 5 s: every press was dropped, and the
            # asserts below say so), so that the BASE switch cannot merge into that one render
            deadline = last_press + 5
            while not c.readouts and time.monotonic() < deadline:
                await asyncio.sleep(0.02)
            await c.send_update(READOUT_LABEL, {"value": "BASE"})   # answered after every press before it
            deadline = time.monotonic() + 30
            while not any(f == "BASE" for _, f in c.frames) and time.monotonic() < deadline:
                await asyncio.sleep(0.05)
            base_at = next(t for t, f in c.frames if f == "BASE")
            return holders, names, x0, last_press, base_at, list(c.readouts)
        finally:
            for cl in clients:
                await cl.close()

    holders, names, x0, last_press, base_at, readouts = asyncio.run(scenario())
    assert names == [f"Spread {i:03d}" for i in range(1, 21)]
    assert holders == set(pids)                        # both processes got browsers
    moves = [(t, x) for t, x in readouts if t < base_at]     # a readout is sent when the text changes
    assert moves, "no press was carried out"
    moved_mm = moves[-1][1] - x0
    assert 0.1 <= moved_mm < FLOOD_PRESSES * 0.1 - 1.0          # the flood outran the server: presses were dropped
    assert max(t for t, _ in moves) - last_press < 1.0  # and the robot stood still within 1 s of the last


@pytest.mark.timeout(300)
def test_wrong_trainer_tokens_lock_the_address_out_on_both_processes(workers2) -> None:
    """Wrong tokens typed on browsers spread over both processes add up to one count for their
    address (127.0.0.1), so the right token is refused on every browser during the lock, on
    both processes: reconnecting to the other process gives no new tries."""
    port, pids, db = workers2

    def failures() -> list[float]:
        with Gradebook(db) as book, book.store.read() as conn:
            return sorted(float(r[0]) for r in conn.execute(
                "SELECT failed_at FROM token_failures WHERE source = '127.0.0.1'"))

    async def wrong(c, k: int) -> None:
        """Client ``c`` types a wrong token once the lock is over; it is the ``k``-th failure."""
        times = failures()
        if times:
            await asyncio.sleep(max(0.0, times[-1] + lock_s(len(times)) - time.time()) + 0.05)
        await c.try_token(f"a-wrong-guess-{k:02d}-xyz")
        await until(f"wrong token {k} counted", lambda: len(failures()) == k)

    async def scenario() -> tuple[list[list[str]], set[int]]:
        clients = await connect_all("127.0.0.1", port, 15)
        try:
            for c in clients:
                await until("the token field", lambda c=c: TOKEN_LABEL in c.uuids)
            for k in range(1, 6):
                await wrong(clients[0], k)              # five: the address is locked for 1 s
            await wrong(clients[1], 6)                  # the sixth, after it: 2 s
            await wrong(clients[2], 7)                  # the seventh: 4 s
            refused = clients[3:]
            for c in refused:                           # the right token, on every browser, in the 4 s
                await c.try_token("trainer-token-for-tests-0001")
            await until("every browser's answer", lambda: all(c.notes for c in refused))
            notes = [list(c.notes) for c in refused]
            for i, c in enumerate(refused):             # which process each browser is on
                await c.join(f"Guess {i + 1:03d}")
            book = Gradebook(db)
            try:
                rows = await until("every browser named", lambda: (
                    named := [r for r in book.presence.present() if r[0].startswith("Guess ")])
                    and len(named) == len(refused) and named)
            finally:
                book.close()
            return notes, {int(holder.split(":")[-2]) for _, holder, _ in rows}
        finally:
            for c in clients:
                await c.close()

    notes, holders = asyncio.run(scenario())
    assert holders == set(pids)                          # the refused browsers were on both processes
    for shown in notes:
        assert shown[0].startswith("⚠ Too many wrong trainer tokens from this browser: try again in ")
        assert not any(n.startswith("### Trainer dashboard") for n in shown)
    assert len(failures()) == 7                          # the refused tries were not counted


@pytest.mark.timeout(300)
def test_browsers_arriving_one_by_one_are_split_evenly_over_the_processes(workers2) -> None:
    """Trainees who arrive one after another (each one's session built before the next comes)
    are split 8 / 8, each process's share read from the gradebook's presence (the pid that
    holds the name), and never more than one apart on the way: the kernel's hash alone splits
    16 browsers 8 / 8 in 20 % of the classes and keeps them one apart throughout in < 1 %."""
    port, pids, db = workers2
    (record_path,) = (db.parent).glob("tcp-pendant-workers-*/balance.json")
    record = BalanceFile(record_path)

    def browsers() -> list[int]:
        return [row["sessions"] for row in record.read()["listeners"]]

    async def scenario() -> tuple[list[list[int]], Counter[int]]:
        await until("the other tests' browsers gone", lambda: sum(browsers()) == 0, detail=browsers)
        clients, seen = [], []
        try:
            for i in range(16):
                clients += await connect_all("127.0.0.1", port, 1, names="Even", first=i)
                await until(f"browser {i + 1} counted", lambda: sum(browsers()) == i + 1, detail=browsers)
                seen.append(browsers())
            book = Gradebook(db)
            try:
                await until("every trainee present", lambda: len(
                    [r for r in book.presence.present() if r[0].startswith("Even ")]) == 16, detail=browsers)
                rows = [r for r in book.presence.present() if r[0].startswith("Even ")]
            finally:
                book.close()
            return seen, trainees_per_process(rows)
        finally:
            for c in clients:
                await c.close()

    seen, per_pid = asyncio.run(scenario())
    assert all(max(counts) - min(counts) <= 1 for counts in seen), seen
    assert per_pid == {pids[0]: 8, pids[1]: 8}


@pytest.mark.slow  # two server processes
@pytest.mark.timeout(300)
def test_two_processes_share_one_postgresql_gradebook(tmp_path: Path, postgres_server) -> None:
    """``--workers 2 --class-db postgresql://...`` (docs/large-class.md, "1,000 trainees on ten machines",
    one machine of them with its cores in use): both processes keep their trainees in the one
    PostgreSQL gradebook, six arriving trainees are split three per process (each one's
    process read from the database's presence rows), and a name already joined is refused to a
    second browser, whichever process that reaches."""
    url = postgres_server.fresh_schema()
    server, port, pids, text = _start_workers2(tmp_path, url, "6", "trainer-token-for-tests-0002")
    try:
        assert postgres_server.password not in text

        async def scenario() -> tuple[Counter[int], list[str]]:
            clients = []
            book = Gradebook(url)
            try:
                for i in range(6):                  # one after another, as a class arrives
                    clients += await connect_all("127.0.0.1", port, 1, names="Pg", first=i)
                    await until(f"trainee {i + 1} present", lambda: len(book.presence.present()) >= i + 1,
                                detail=book.presence.present)
                per_pid = trainees_per_process(book.presence.present())
                # the same name again, from a new browser: whichever process it reaches refuses it
                intruder = (await connect_all("127.0.0.1", port, 1, names="Pg", first=0))[0]
                clients.append(intruder)
                refusal = "⚠ Pg 001 is already connected in another browser"
                await until("the second 'Pg 001' refused",
                            lambda: any(n.startswith(refusal) for n in intruder.notes),
                            detail=lambda: intruder.notes)
                return per_pid, sorted(name for name, _, _ in book.presence.present())
            finally:
                book.close()
                for c in clients:
                    await c.close()

        per_pid, names = asyncio.run(scenario())
        assert per_pid == {pids[0]: 3, pids[1]: 3}
        assert names == [f"Pg {i:03d}" for i in range(1, 7)]
    finally:
        server.terminate()
        server.wait(60)
