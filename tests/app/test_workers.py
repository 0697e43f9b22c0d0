"""``tcp-pendant --workers 2``: two real server processes on one port. The kernel spreads the
browsers over both (each process's pid is in the gradebook's presence table, ``holder``), and
the jog deadman holds in each."""

from __future__ import annotations

import asyncio
import os
import re
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from async_clients import PLUS, READOUT_LABEL, connect_all  # noqa: E402

from tcp_pendant.classroom.gradebook import Gradebook

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="SO_REUSEPORT spreading is Linux's")


@pytest.fixture
def workers2(tmp_path: Path) -> Iterator[tuple[int, list[int], Path]]:
    """``tcp-pendant --class --workers 2 --port 0``: (port, pids, gradebook path); stopped after."""
    db = tmp_path / "class.sqlite3"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT / "src"), str(ROOT / "app")]),
               TCP_PENDANT_TRAINER_TOKEN="trainer-token-for-tests-0001")
    server = subprocess.Popen([sys.executable, "-m", "tcp_pendant", "--port", "0", "--workers", "2", "--class-db",
                               str(db), "--tool-library", str(tmp_path / "tools.json"), "--seed", "5"],
                              env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, text=True)
    try:
        assert server.stdout is not None
        text = ""
        while "Ctrl-C to stop" not in text:
            line = server.stdout.readline()
            assert line, f"the server exited (code {server.wait()}):\n{text}"
            text += line
        port = int(re.search(r"http://127\.0\.0\.1:(\d+)", text).group(1))   # type: ignore[union-attr]
        pids = [int(p) for p in re.search(r"2 server processes on port \d+ \(pids ([\d, ]+)\)",   # type: ignore[union-attr]
                                          text).group(1).split(",")]
        assert pids[0] == server.pid and len(set(pids)) == 2
        yield port, pids, db
    finally:
        server.terminate()                       # SIGTERM: the first process stops the other
        server.wait(60)
    assert all(not Path(f"/proc/{pid}").exists() or "zombie" in Path(f"/proc/{pid}/status").read_text()
               for pid in pids[1:])


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
                while len(book.present()) < 20 and time.monotonic() < deadline:
                    await asyncio.sleep(0.1)
                rows = book.present()
            finally:
                book.close()
            holders = {int(holder.split(":")[-2]) for _, holder, _ in rows}
            names = [name for name, _, _ in rows]
            # the deadman: one trainee floods "X +" (0.1 mm) far faster than a step is carried out
            c = clients[0]
            x0 = c.readouts[-1][1]
            c.readouts.clear()
            for _ in range(1500):
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
    assert 0.1 <= moved_mm < 1500 * 0.1 - 1.0          # the flood outran the server: presses were dropped
    assert max(t for t, _ in moves) - last_press < 1.0  # and the robot stood still within 1 s of the last
