"""``--workers N``: each new connection goes to the server process with the fewest sessions.

The N processes listen on one port with ``SO_REUSEPORT``. Left to itself, Linux hands a new
connection to one of them by a hash of the client's address and port: with 60 trainees the
split was 34 / 26 (0.76 against 0.57 cores busy, ``tests/bench/bench_class_load.py``), and the
busier process sets the class's latency. The kernel lets the group's listeners choose instead
by a classic BPF program attached with ``SO_ATTACH_REUSEPORT_CBPF`` (socket(7)): the program
returns the index of the listener that takes the connection (an index out of range falls back
to the hash). Ours is one instruction, ``ret #k``: k is the listener of the process with the
fewest sessions, and whichever process's session count changes attaches the program anew (a
program attached to one listener serves the whole group).

A listener's index in the group is the order in which the listeners started listening. The
processes keep a small shared record (:class:`BalanceFile`, a JSON file under an exclusive
``flock``): each takes the lock, reads how many listen already (its index), starts listening,
and writes itself in before letting the next one in; the first process listens before it
starts the others, so it is index 0. The record also holds every process's session count.

When a listener closes, the kernel moves the group's last listener into its index, which the
record would not know: a worker that stops turns the balancing off for good
(:meth:`Balance.turn_off`: the program is detached, ``SO_DETACH_REUSEPORT_BPF``, and the
record says so), and Linux's hash spreads the connections again. Between the kernel's choice
and the count's update (the websocket handshake, a few ms) several connections can go to the
same process; the next ones make up for it.
"""

from __future__ import annotations

import ctypes
import fcntl
import json
import os
import socket
import struct
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TypedDict

__all__ = ["BALANCE_ENV", "Balance", "BalanceFile", "attach_listener_choice", "detach_listener_choice"]

BALANCE_ENV = "TCP_PENDANT_BALANCE"
"""The shared record's path in the environment of ``--workers`` processes (set by the first)."""

SO_ATTACH_REUSEPORT_CBPF = getattr(socket, "SO_ATTACH_REUSEPORT_CBPF", 51)   # asm-generic/socket.h
SO_DETACH_REUSEPORT_BPF = getattr(socket, "SO_DETACH_REUSEPORT_BPF", 68)
_BPF_RET_K = 0x06 | 0x00                                                     # linux/filter.h: BPF_RET | BPF_K


def attach_listener_choice(listener: socket.socket, index: int) -> None:
    """Attach ``ret #index`` to ``listener``'s ``SO_REUSEPORT`` group: every new connection
    goes to the group's listener ``index``. Raises OSError where the kernel refuses.

    The ``sock_fprog`` the option takes holds a pointer to the instructions: they are built
    in a ctypes buffer that lives through the call (the kernel copies them)."""
    code = (ctypes.c_uint8 * 8).from_buffer_copy(struct.pack("HBBI", _BPF_RET_K, 0, 0, int(index)))
    prog = struct.pack("HP", 1, ctypes.addressof(code))
    listener.setsockopt(socket.SOL_SOCKET, SO_ATTACH_REUSEPORT_CBPF, prog)


def detach_listener_choice(listener: socket.socket) -> None:
    """The group's program goes: the kernel's hash spreads the connections again."""
    try:
        listener.setsockopt(socket.SOL_SOCKET, SO_DETACH_REUSEPORT_BPF, 0)
    except OSError:
        pass                                      # none attached (ENOENT): nothing to detach


class ListenerRow(TypedDict):
    """One process's line in the shared record."""

    pid: int
    index: int
    sessions: int


class BalanceRecord(TypedDict, total=False):
    """The shared record (:class:`BalanceFile`)."""

    n: int
    off: bool
    chosen: int | None
    listeners: list[ListenerRow]


class BalanceFile:
    """The shared record of the ``--workers`` processes: ``{"n": N, "off": bool, "chosen":
    index or None (the group's program now), "listeners": [{"pid", "index", "sessions"},
    ...]}``, read and written under an exclusive ``flock`` of the file (module docstring)."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)

    @classmethod
    def create(cls, path: Path, n: int) -> BalanceFile:
        """A fresh record for ``n`` processes at ``path`` (the first process, before it listens)."""
        Path(path).write_text(json.dumps({"n": int(n), "off": False, "listeners": []}))
        return cls(path)

    @contextmanager
    def locked(self) -> Iterator[BalanceRecord]:
        """The record, under the lock; what the caller changes in it is written back."""
        with open(self.path, "r+") as f:
            fcntl.flock(f, fcntl.LOCK_EX)
            try:
                record: BalanceRecord = json.loads(f.read() or "{}")
                before = json.dumps(record)
                yield record
                after = json.dumps(record)
                if after != before:
                    f.seek(0)
                    f.truncate()
                    f.write(after)
                    f.flush()
            finally:
                fcntl.flock(f, fcntl.LOCK_UN)

    def read(self) -> BalanceRecord:
        with self.locked() as record:
            return record


def _choice(record: BalanceRecord) -> int | None:
    """The index of the listener with the fewest sessions (the lowest index among equals);
    None while not every process listens, or when the balancing is off."""
    listeners = record.get("listeners", [])
    if record.get("off") or len(listeners) != record.get("n"):
        return None
    return int(min(listeners, key=lambda r: (r["sessions"], r["index"]))["index"])


class Balance:
    """One process's side of the balancing (module docstring).

    Args:
        record: the shared record.
        pid: this process (default: ``os.getpid()``).
    """

    def __init__(self, record: BalanceFile, pid: int | None = None) -> None:
        self.record = record
        self.pid = os.getpid() if pid is None else int(pid)
        self.index: int | None = None
        self.listener: socket.socket | None = None

    @contextmanager
    def listening(self) -> Iterator[None]:
        """Around the start of this process's listener: its index is the number of listeners
        before it (the lock keeps the others out until it listens and is written in)."""
        with self.record.locked() as record:
            listeners = record.setdefault("listeners", [])
            self.index = len(listeners)
            yield
            listeners.append({"pid": self.pid, "index": self.index, "sessions": 0})

    def started(self, listeners: list[socket.socket]) -> None:
        """The listening sockets of this process's server (one per address; the first serves)."""
        self.listener = listeners[0] if listeners else None
        self.sessions(0)

    def sessions(self, count: int) -> int | None:
        """This process now has ``count`` sessions: written in, and the program chosen again.
        Returns the listener index new connections now go to (None: the kernel's hash)."""
        with self.record.locked() as record:
            for row in record.get("listeners", []):
                if row["pid"] == self.pid:
                    row["sessions"] = int(count)
            choice = _choice(record)
            if self.listener is not None and choice != record.get("chosen"):
                try:
                    if choice is None:
                        detach_listener_choice(self.listener)
                    else:
                        attach_listener_choice(self.listener, choice)
                except OSError:
                    record["off"] = True            # a kernel without it: the hash, for every process
                    detach_listener_choice(self.listener)
                    choice = None
                record["chosen"] = choice
            return record.get("chosen")

    def turn_off(self) -> None:
        """A process of the group stopped: the indices no longer hold; the hash from now on."""
        with self.record.locked() as record:
            record["off"] = True
            if self.listener is not None:
                detach_listener_choice(self.listener)
            record["chosen"] = None
