"""The ``--workers`` connection balance (``tcp_pendant.serve.balance``) on real listening sockets of one
``SO_REUSEPORT`` group in this process: the order of listening gives the indices, the program
the record chooses sends every new connection to the listener with the fewest sessions, and
turning it off gives the connections back to the kernel's hash."""

from __future__ import annotations

import socket
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from tcp_pendant.serve.balance import Balance, BalanceFile

pytestmark = [pytest.mark.skipif(not sys.platform.startswith("linux"), reason="SO_ATTACH_REUSEPORT_CBPF is Linux's"),
              pytest.mark.shares_cpu]


def _listener(port: int) -> socket.socket:
    s = socket.socket()
    s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
    s.bind(("127.0.0.1", port))
    s.listen(64)
    s.setblocking(False)
    return s


def _who_accepts(port: int, listeners: list[socket.socket]) -> int:
    """Connect once; the index (in ``listeners``) of the one that got the connection (on
    loopback the handshake is done when ``connect`` returns: it waits in one accept queue)."""
    with socket.create_connection(("127.0.0.1", port), timeout=5):
        got = []
        for i, s in enumerate(listeners):
            try:
                conn, _ = s.accept()
            except BlockingIOError:
                continue
            conn.close()
            got.append(i)
    assert len(got) == 1, f"accepted by {got}"
    return got[0]


@pytest.fixture
def group(tmp_path: Path) -> Iterator[tuple[int, list[socket.socket], list[Balance]]]:
    """Three processes' sides of the balance (pids 101..103), each listening in turn."""
    record = BalanceFile.create(tmp_path / "balance.json", 3)
    balances = [Balance(record, pid=101 + k) for k in range(3)]
    listeners: list[socket.socket] = []
    port = 0
    for b in balances:
        with b.listening():
            listeners.append(_listener(port))
            port = listeners[0].getsockname()[1]
        b.started(listeners[-1:])
    yield port, listeners, balances
    for s in listeners:
        s.close()


def test_the_indices_follow_the_order_of_listening_and_new_connections_go_to_the_fewest(group) -> None:
    port, listeners, (a, b, c) = group
    assert [x.index for x in (a, b, c)] == [0, 1, 2]
    assert a.record.read()["chosen"] == 0                      # all at 0 sessions: the lowest index
    a.sessions(2)
    b.sessions(1)
    assert c.sessions(0) == 2
    assert [_who_accepts(port, listeners) for _ in range(5)] == [2] * 5
    c.sessions(3)                                              # b has the fewest now; c set the program
    assert [_who_accepts(port, listeners) for _ in range(5)] == [1] * 5
    b.sessions(4)
    assert [_who_accepts(port, listeners) for _ in range(5)] == [0] * 5


def test_one_connection_at_a_time_the_group_stays_even(group) -> None:
    port, listeners, balances = group
    counts = [0, 0, 0]
    for _ in range(30):
        k = _who_accepts(port, listeners)
        counts[k] += 1
        balances[k].sessions(counts[k])                        # that process counts its browser
        assert max(counts) - min(counts) <= 1, counts
    assert counts == [10, 10, 10]


def test_turned_off_the_kernel_hash_spreads_them_again(group) -> None:
    port, listeners, (a, b, c) = group
    a.sessions(5)
    b.sessions(5)
    assert [_who_accepts(port, listeners) for _ in range(3)] == [2] * 3
    b.turn_off()                                               # a process of the group stopped
    assert b.record.read()["off"] is True and a.sessions(0) is None
    seen = {_who_accepts(port, listeners) for _ in range(60)}
    assert seen == {0, 1, 2}                                   # P(a listener missed in 60) < 3e-10


def test_until_every_process_listens_there_is_no_choice(tmp_path: Path) -> None:
    record = BalanceFile.create(tmp_path / "balance.json", 2)
    first = Balance(record, pid=1)
    with first.listening():
        s = _listener(0)
    try:
        first.started([s])
        assert first.sessions(3) is None and record.read().get("chosen") is None
    finally:
        s.close()


def test_a_worker_that_stops_while_the_class_runs_turns_the_balance_off(tmp_path: Path) -> None:
    """``Workers`` calls its ``on_stopped`` (the first process: ``Balance.turn_off``) when a
    worker exits by itself, and not when the class is being stopped."""
    import subprocess

    from tcp_pendant.serve.workers import Workers

    record = BalanceFile.create(tmp_path / "balance.json", 2)
    balance = Balance(record, pid=1)
    workers = Workers([], 0, 2, on_stopped=balance.turn_off)
    died = subprocess.Popen([sys.executable, "-c", "raise SystemExit(3)"])
    workers._watch(2, died)
    assert record.read()["off"] is True
    record = BalanceFile.create(tmp_path / "balance.json", 2)
    workers._stopping.set()                                   # stopped by the first process
    workers._watch(2, subprocess.Popen([sys.executable, "-c", "pass"]))
    assert record.read()["off"] is False
