"""Tool library: controller-like slots, JSON file, locking, atomic saves, corrupt-file recovery."""

from __future__ import annotations

import json
import multiprocessing
import os
import random
import signal
import stat
import time
import warnings
from pathlib import Path

import pytest

from tcpcal.errors import InvalidInputError, TcpcalError
from tcpcal.library import (
    ToolLibrary,
    ToolLibraryError,
    ToolLibraryWarning,
    default_library_path,
)
from tcpcal.tool import Calibration, Tool

_fork = multiprocessing.get_context("fork")


def tool(name: str, x: float = 0.0, **kw) -> Tool:
    return Tool(name, (x, 0.0, 150.0), (0.0, -90.0, 0.0), **kw)


def test_default_path_is_in_the_user_data_dir():
    p = default_library_path()
    assert p.name == "tools.json" and p.parent.name == "tcp-pendant"
    assert ToolLibrary().path == p


def test_save_load_activate_rename_remove(tmp_path):
    path = tmp_path / "sub" / "tools.json"  # directory created on first save
    lib = ToolLibrary(path)
    assert lib.tools() == {} and lib.active_tool() is None and lib.first_free_slot() == 1
    cal = Calibration("xyz4-lstsq", "2024-05-01T12:00:00+00:00", {"rms_error_mm": 0.3})
    lib.save(1, tool("pointer", 1.0, calibration=cal))
    lib.save(3, tool("torch", 3.0, mass_kg=2.0), activate=True)
    assert lib.first_free_slot() == 2
    assert lib.get(1) == tool("pointer", 1.0, calibration=cal)
    assert lib.get(2) is None
    assert lib.active_slot() == 3 and lib.active_tool().name == "torch"
    assert lib.find("torch") == (3, tool("torch", 3.0, mass_kg=2.0))
    assert lib.find("nope") is None

    # another object on the same file sees every change (fresh reads)
    other = ToolLibrary(path)
    assert list(other.tools()) == [1, 3]
    other.rename(3, "MIG torch")
    assert lib.active_tool().name == "MIG torch"
    assert lib.find("torch") is None
    lib.activate(1)
    assert other.active_slot() == 1
    lib.activate(None)
    assert other.active_tool() is None
    lib.save(1, tool("pointer", 9.0), activate=True)  # overwrite a slot, same name is fine
    assert other.get(1).tcp_mm[0] == 9.0
    lib.remove(1)
    assert other.active_slot() is None and other.get(1) is None
    assert list(other.tools()) == [3]

    # the file is the documented, human-readable JSON
    doc = json.loads(path.read_text(encoding="utf-8"))
    assert doc["format"] == "tcp-pendant-tool-library" and doc["version"] == 1
    assert doc["active_slot"] is None
    assert doc["tools"]["3"]["name"] == "MIG torch"
    assert doc["tools"]["3"]["tcp_mm"] == [3.0, 0.0, 150.0]
    assert '"tcp_mm": [3.0, 0.0, 150.0]' in path.read_text(encoding="utf-8")


def test_library_errors_say_what_to_do(tmp_path):
    lib = ToolLibrary(tmp_path / "tools.json")
    lib.save(1, tool("a"))
    lib.save(2, tool("b"))
    with pytest.raises(ToolLibraryError, match="already used by slot 1; choose another name"):
        lib.save(5, tool("a"))
    with pytest.raises(ToolLibraryError, match="already used by slot 2"):
        lib.rename(1, "b")
    with pytest.raises(InvalidInputError, match="at most 24"):
        lib.rename(1, "x" * 30)
    for bad in (0, 17, True, 1.0, "3"):
        with pytest.raises(InvalidInputError, match="1..16"):
            lib.save(bad, tool("c"))  # type: ignore[arg-type]
    with pytest.raises(ToolLibraryError, match=r"slot 7: it is empty; occupied slots: \[1, 2\]"):
        lib.remove(7)
    with pytest.raises(ToolLibraryError, match="empty"):
        lib.activate(7)
    with pytest.raises(ToolLibraryError, match="empty"):
        lib.rename(7, "z")
    with pytest.raises(InvalidInputError, match="Tool"):
        lib.save(3, {"name": "d"})  # type: ignore[arg-type]
    assert issubclass(ToolLibraryError, TcpcalError)
    # nothing of the failed operations reached the file
    assert {s: t.name for s, t in lib.tools().items()} == {1: "a", 2: "b"}


def test_all_slots_full(tmp_path):
    lib = ToolLibrary(tmp_path / "tools.json")
    for slot in range(1, 17):
        lib.save(slot, tool(f"t{slot}"))
    assert lib.first_free_slot() is None
    assert len(lib.tools()) == 16


# --------------------------------------------------------------------------- concurrency
def _writer(path: str, tag: str, base: int, rounds: int) -> None:
    lib = ToolLibrary(Path(path))
    for i in range(rounds):
        lib.save(base + i % 8, tool(f"{tag}-{i}", float(i)))


def test_two_processes_saving_at_once_lose_nothing(tmp_path):
    path = tmp_path / "tools.json"
    rounds = 48
    procs = [
        _fork.Process(target=_writer, args=(str(path), "A", 1, rounds)),
        _fork.Process(target=_writer, args=(str(path), "B", 9, rounds)),
    ]
    for p in procs:
        p.start()
    for p in procs:
        p.join(timeout=120)
        assert p.exitcode == 0
    tools = ToolLibrary(path).tools()
    assert sorted(tools) == list(range(1, 17))
    # every slot holds the last tool its process wrote there
    for k in range(8):
        last = max(i for i in range(rounds) if i % 8 == k)
        assert tools[1 + k].name == f"A-{last}" and tools[1 + k].tcp_mm[0] == last
        assert tools[9 + k].name == f"B-{last}"


def test_two_threads_sharing_one_library_object_lose_nothing(tmp_path):
    """The app server shares one ToolLibrary between browser sessions (threads)."""
    import threading

    lib = ToolLibrary(tmp_path / "tools.json")
    rounds = 32

    def work(base: int, tag: str) -> None:
        for i in range(rounds):
            lib.save(base + i % 8, tool(f"{tag}-{i}", float(i)))

    threads = [threading.Thread(target=work, args=(1, "A")),
               threading.Thread(target=work, args=(9, "B"))]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    tools = lib.tools()
    assert sorted(tools) == list(range(1, 17))
    assert tools[8].name == f"A-{rounds - 1}" and tools[16].name == f"B-{rounds - 1}"


def _endless_saver(path: str, slow_disk: bool) -> None:
    # slow_disk: fsync of a regular file (the temporary file) takes 30 ms in this child only,
    # so most kills land between writing the temporary file and os.replace. Otherwise big
    # tools make the writes themselves long, so kills also land while bytes are written.
    real_fsync = os.fsync

    def slow_fsync(fd: int) -> None:
        if stat.S_ISREG(os.fstat(fd).st_mode):
            time.sleep(0.03)
        real_fsync(fd)

    if slow_disk:
        os.fsync = slow_fsync  # type: ignore[assignment]
    size = 20_000 if slow_disk else 300_000
    lib = ToolLibrary(Path(path))
    i = 0
    while True:
        k = i % 16
        lib.save(1 + k, tool(f"t{k}", float(i), notes=f"save {i} " + "x" * size))
        i += 1


def test_kill_during_saves_leaves_a_valid_file(tmp_path):
    path = tmp_path / "tools.json"
    rng = random.Random(1)
    killed_mid_save = 0
    for round_ in range(16):
        p = _fork.Process(target=_endless_saver, args=(str(path), round_ % 2 == 0))
        p.start()
        deadline = time.monotonic() + 30
        while not path.exists() and time.monotonic() < deadline:
            time.sleep(0.005)
        time.sleep(rng.uniform(0.02, 0.2))
        os.kill(p.pid, signal.SIGKILL)
        p.join(timeout=30)
        assert p.exitcode == -signal.SIGKILL
        # a temporary file left behind proves the kill hit the middle of a save
        killed_mid_save += bool(list(tmp_path.glob(".tools.json.*.tmp")))  # stale temp
        json.loads(path.read_text(encoding="utf-8"))  # complete JSON
        lib = ToolLibrary(path)
        with warnings.catch_warnings():
            warnings.simplefilter("error", ToolLibraryWarning)
            tools = lib.tools()
        assert lib.recovered_backup is None
        assert tools and all(t.name == f"t{s - 1}" for s, t in tools.items())
        assert all(t.notes.startswith("save ") for t in tools.values())
    assert killed_mid_save >= 3  # the test really exercised interrupted saves
    # the next save removes temporary files a killed writer left behind
    ToolLibrary(path).save(1, tool("t0"))
    assert not list(tmp_path.glob(".tools.json.*.tmp"))
    assert not list(tmp_path.glob("*.corrupt-*"))


# --------------------------------------------------------------------------- corrupt files
@pytest.mark.parametrize(
    "content",
    [
        b"{not json",
        b"\xff\xfe garbage",
        json.dumps({"format": "something-else", "version": 1, "tools": {}}).encode(),
        json.dumps({"format": "tcp-pendant-tool-library", "version": 99, "tools": {}}).encode(),
        json.dumps({"format": "tcp-pendant-tool-library", "version": 1, "active_slot": None,
                    "tools": {"17": {"name": "a", "tcp_mm": [0, 0, 0]}}}).encode(),
        json.dumps({"format": "tcp-pendant-tool-library", "version": 1, "active_slot": None,
                    "tools": {"1": {"name": "a", "tcp_mm": [0, 0]}}}).encode(),
        json.dumps({"format": "tcp-pendant-tool-library", "version": 1, "active_slot": 2,
                    "tools": {"1": {"name": "a", "tcp_mm": [0, 0, 0]}}}).encode(),
        json.dumps({"format": "tcp-pendant-tool-library", "version": 1, "active_slot": None,
                    "tools": {"1": {"name": "a", "tcp_mm": [0, 0, 0]},
                              "2": {"name": "a", "tcp_mm": [0, 0, 1]}}}).encode(),
    ],
)
def test_corrupt_file_is_moved_aside_and_reported(tmp_path, content):
    path = tmp_path / "tools.json"
    path.write_bytes(content)
    lib = ToolLibrary(path)
    with pytest.warns(ToolLibraryWarning, match="moved aside"):
        assert lib.tools() == {}
    backup = lib.recovered_backup
    assert backup is not None and backup.parent == tmp_path
    assert backup.name.startswith("tools.corrupt-") and backup.suffix == ".json"
    assert backup.read_bytes() == content  # kept exactly, not rewritten
    assert not path.exists()
    lib.save(1, tool("fresh"))
    assert backup.read_bytes() == content  # the new save did not touch it
    assert list(ToolLibrary(path).tools()) == [1]


def test_corrupt_file_found_by_a_save_is_not_overwritten(tmp_path):
    path = tmp_path / "tools.json"
    path.write_text('{"format": "tcp-pendant-tool-library", "version": 1, "tools": {"1": ',
                    encoding="utf-8")
    original = path.read_bytes()
    lib = ToolLibrary(path)
    with pytest.warns(ToolLibraryWarning):
        lib.save(2, tool("new"))
    assert lib.recovered_backup.read_bytes() == original
    assert {s: t.name for s, t in lib.tools().items()} == {2: "new"}


def test_two_corrupt_files_get_two_backups(tmp_path):
    path = tmp_path / "tools.json"
    lib = ToolLibrary(path)
    backups = []
    for content in (b"first broken", b"second broken"):
        path.write_bytes(content)
        with pytest.warns(ToolLibraryWarning):
            lib.tools()
        backups.append(lib.recovered_backup)
    assert backups[0] != backups[1]
    assert [b.read_bytes() for b in backups] == [b"first broken", b"second broken"]
