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
def _doc(tools: dict, active=None, **extra) -> dict:
    return {"format": "tcp-pendant-tool-library", "version": 1, "active_slot": active,
            "tools": tools, **extra}


def _entry(name, x=0.0, **kw) -> dict:
    return {"name": name, "tcp_mm": [x, 0.0, 150.0], **kw}


@pytest.mark.parametrize(
    "content",
    [
        b"{not json",
        b"\xff\xfe garbage",
        b"[" * 100_000,  # json gives RecursionError, not JSONDecodeError
        b'{"a": ' * 100_000,
        b"[1, 2, 3]",
        json.dumps({"format": "something-else", "version": 1, "tools": {}}).encode(),
        json.dumps({"format": "tcp-pendant-tool-library", "version": 99, "tools": {}}).encode(),
        json.dumps(_doc(["not", "an", "object"])).encode(),
    ],
    ids=["not-json", "not-utf8", "deep-list", "deep-object", "top-level-list", "format",
         "version", "tools-not-object"],
)
def test_unusable_file_is_moved_aside_whole_and_reported(tmp_path, content):
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
    rec = lib.recovery
    assert rec.whole_file and rec.backup == backup and rec.kept_slots == ()
    assert len(rec.problems) == 1 and len(rec.problems[0]) < 400
    assert str(backup) in rec.summary() and "starts empty" in rec.summary()
    lib.save(1, tool("fresh"))
    assert backup.read_bytes() == content  # the new save did not touch it
    assert list(ToolLibrary(path).tools()) == [1]


def test_deep_nesting_is_named_as_the_reason(tmp_path):
    path = tmp_path / "tools.json"
    path.write_bytes(b"[" * 100_000)
    lib = ToolLibrary(path)
    with pytest.warns(ToolLibraryWarning):
        assert lib.active_slot() is None
    assert lib.recovery.problems == ("nested too deeply to be a tool library",)


def test_nan_tcp_among_four_valid_tools_sets_aside_only_that_entry(tmp_path):
    path = tmp_path / "tools.json"
    entries = {str(s): _entry(f"tool{s}", float(s)) for s in (1, 2, 4, 5)}
    entries["3"] = _entry("broken", float("nan"))
    content = json.dumps(_doc(entries, active=2), indent=2).encode()  # writes NaN
    assert b"NaN" in content
    path.write_bytes(content)
    lib = ToolLibrary(path)
    with pytest.warns(ToolLibraryWarning, match="slot 3"):
        tools = lib.tools()
    assert {s: t.name for s, t in tools.items()} == {1: "tool1", 2: "tool2", 4: "tool4",
                                                      5: "tool5"}
    assert tools[4].tcp_mm == (4.0, 0.0, 150.0)
    assert lib.active_slot() == 2
    rec = lib.recovery
    assert not rec.whole_file and rec.kept_slots == (1, 2, 4, 5)
    assert len(rec.problems) == 1
    assert rec.problems[0].startswith("slot 3:") and "finite" in rec.problems[0]
    assert rec.backup.read_bytes() == content  # the bad entry survives in the backup
    assert rec.backup.parent == tmp_path and rec.backup.name.startswith("tools.corrupt-")
    assert str(rec.backup) in rec.summary() and "slot 3" in rec.summary()
    # the file now holds the valid entries only: another reader sees no damage
    with warnings.catch_warnings():
        warnings.simplefilter("error", ToolLibraryWarning)
        other = ToolLibrary(path)
        assert sorted(other.tools()) == [1, 2, 4, 5]
    assert other.recovery is None
    assert "NaN" not in path.read_text(encoding="utf-8")
    assert len(list(tmp_path.glob("*.corrupt-*"))) == 1


@pytest.mark.parametrize(
    ("bad_key", "bad_value", "active", "expect"),
    [
        ("3", _entry(42), None, "slot 3: tool name must be a string, got 42"),
        ("3", _entry("x" * 30), None, "slot 3: tool name"),
        ("3", _entry("tab\there"), None, "slot 3: tool name"),
        ("3", {"name": "a3", "tcp_mm": [0, 0]}, None, "slot 3: tcp_mm must be 3 numbers"),
        ("3", {"name": "a3", "tcp_mm": [0, 0, 0], "abc_deg": "0,0,0"}, None, "slot 3: abc_deg"),
        ("3", {"name": "a3", "tcp_mm": [0, 0, 0], "colour": "red"}, None,
         "slot 3: tool has unknown keys ['colour']"),
        ("3", "a string", None, "slot 3: a tool must be an object"),
        ("3", _entry("tool1"), None, "slot 3: the name 'tool1' is already used by slot 1"),
        ("17", _entry("a17"), None, "entry '17': not a slot number 1..16"),
        ("x", _entry("ax"), None, "entry 'x': not a slot number"),
        ("\u00b2", _entry("sq"), None, "not a slot number"),  # '²'.isdigit() but int() fails
        ("\u0663", _entry("arabic3"), None, "not a slot number"),
        ("01", _entry("dup"), None, "slot 1 appears twice"),
        (None, None, 7, "'active_slot' 7 is not a valid occupied slot"),
        (None, None, True, "'active_slot' True"),
    ],
)
def test_one_bad_entry_is_set_aside_and_the_others_kept(tmp_path, bad_key, bad_value, active,
                                                       expect):
    path = tmp_path / "tools.json"
    entries = {"1": _entry("tool1", 1.0), "2": _entry("tool2", 2.0)}
    if bad_key is not None:
        entries[bad_key] = bad_value
    content = json.dumps(_doc(entries, active=active), ensure_ascii=False).encode()
    path.write_bytes(content)
    lib = ToolLibrary(path)
    with pytest.warns(ToolLibraryWarning, match="set aside"):
        tools = lib.tools()
    assert {s: t.name for s, t in tools.items()} == {1: "tool1", 2: "tool2"}
    assert lib.recovery.problems == tuple(p for p in lib.recovery.problems if expect in p)
    assert len(lib.recovery.problems) == 1
    assert lib.recovered_backup.read_bytes() == content
    assert lib.active_slot() is None


def test_unknown_top_level_key_is_reported_and_tools_kept(tmp_path):
    path = tmp_path / "tools.json"
    path.write_text(json.dumps(_doc({"1": _entry("a")}, active=1, comment="mine")),
                    encoding="utf-8")
    lib = ToolLibrary(path)
    with pytest.warns(ToolLibraryWarning):
        assert lib.active_tool().name == "a"
    assert lib.recovery.problems == ("unknown top-level keys ['comment'] dropped",)
    assert "comment" in lib.recovered_backup.read_text(encoding="utf-8")


def test_a_huge_bad_entry_gives_a_short_problem_line(tmp_path):
    path = tmp_path / "tools.json"
    notes = [[[[["x" * 1000] * 100]]]]  # not a string; its repr is ~100 kB
    path.write_text(json.dumps(_doc({"1": _entry("a"), "2": _entry("b", notes=notes)})),
                    encoding="utf-8")
    lib = ToolLibrary(path)
    with pytest.warns(ToolLibraryWarning):
        assert list(lib.tools()) == [1]
    (line,) = lib.recovery.problems
    assert line.startswith("slot 2: notes must be a string") and len(line) <= 200


def test_save_after_a_recovery_keeps_the_valid_tools_and_the_backup(tmp_path):
    path = tmp_path / "tools.json"
    content = json.dumps(_doc({"1": _entry("a"), "2": _entry(5), "3": _entry("c")})).encode()
    path.write_bytes(content)
    lib = ToolLibrary(path)
    with pytest.warns(ToolLibraryWarning):
        lib.save(4, tool("d"), activate=True)  # the save itself finds the damage
    assert {s: t.name for s, t in ToolLibrary(path).tools().items()} == {1: "a", 3: "c", 4: "d"}
    assert ToolLibrary(path).active_slot() == 4
    assert lib.recovered_backup.read_bytes() == content
    lib.rename(1, "a2")
    lib.remove(3)
    assert {s: t.name for s, t in lib.tools().items()} == {1: "a2", 4: "d"}
    assert lib.recovered_backup.read_bytes() == content
    assert len(lib.recoveries) == 1


def test_two_successive_recoveries_keep_distinct_backups(tmp_path):
    path = tmp_path / "tools.json"
    lib = ToolLibrary(path)
    contents = [
        json.dumps(_doc({"1": _entry("a"), "2": _entry(1)})).encode(),
        json.dumps(_doc({"1": _entry("a"), "2": _entry(2)})).encode(),
        b"[" * 5000,
        json.dumps(_doc({"1": _entry("a"), "5": _entry(float("inf"))})).encode(),
    ]
    for content in contents:  # within the same second: the timestamps collide
        path.write_bytes(content)
        with pytest.warns(ToolLibraryWarning):
            lib.tools()
    backups = [r.backup for r in lib.recoveries]
    assert len(set(backups)) == 4
    assert [b.read_bytes() for b in backups] == contents
    assert [r.whole_file for r in lib.recoveries] == [False, False, True, False]
    assert lib.recovery is lib.recoveries[-1]


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
