"""Tests of ``tcpcal tools ...`` and ``tcpcal convert`` on a temporary library path."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from tcpcal.cli import main


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def ok(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    code, out, err = run(argv, capsys)
    assert code == 0, err
    return out


def one_error_line(argv: list[str], capsys: pytest.CaptureFixture[str], *words: str) -> str:
    code, out, err = run(argv, capsys)
    assert code == 2, (code, out, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for w in words:
        assert re.search(w, err), (w, err)
    return err


def rot_abc(a: float, b: float, c: float) -> np.ndarray:
    """R = Rz(A) Ry(B) Rx(C), by hand."""
    a, b, c = np.radians([a, b, c])
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    rx = np.array([[1, 0, 0], [0, np.cos(c), -np.sin(c)], [0, np.sin(c), np.cos(c)]])
    return rz @ ry @ rx


def test_tools_lifecycle(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    lib = tmp_path / "lib" / "tools.json"
    L = ["--library", str(lib)]
    out = ok(["tools", *L, "list"], capsys)
    assert "No tools stored" in out
    ok(["tools", "add", "3", "torch", "--xyz", "12.5,-30.25,180.75", "--abc", "10,-20,30",
        "--mass", "1.5", "--notes", "MIG torch 22 deg", *L], capsys)
    ok(["tools", "add", "5", "pointer", "--xyz", "0,0,150", "--activate", *L], capsys)
    assert lib.exists()

    d = json.loads(ok(["tools", "list", "--json", *L], capsys))
    assert d["active_slot"] == 5
    by_slot = {t["slot"]: t for t in d["tools"]}
    assert set(by_slot) == {3, 5}
    assert by_slot[3]["name"] == "torch" and by_slot[3]["tcp_mm"] == [12.5, -30.25, 180.75]
    assert by_slot[3]["abc_deg"] == pytest.approx([10, -20, 30])
    assert by_slot[3]["mass_kg"] == 1.5 and by_slot[3]["active"] is False
    np.testing.assert_allclose(by_slot[3]["rotation_matrix"], rot_abc(10, -20, 30), atol=1e-12)
    assert by_slot[5]["active"] is True

    out = ok(["tools", *L, "list"], capsys)
    assert re.search(r"^\* +5 +pointer", out, re.MULTILINE) and re.search(r"^  +3 +torch", out, re.MULTILINE)

    out = ok(["tools", *L, "show", "torch"], capsys)   # by name
    assert "Slot 3: torch" in out and "12.500" in out and "-30.250" in out and "1.5 kg" in out

    ok(["tools", *L, "activate", "3"], capsys)
    assert json.loads(ok(["tools", *L, "show", "3", "--json"], capsys))["active"] is True
    ok(["tools", *L, "activate", "none"], capsys)
    assert json.loads(ok(["tools", *L, "list", "--json"], capsys))["active_slot"] is None

    ok(["tools", *L, "remove", "5"], capsys)
    d = json.loads(ok(["tools", *L, "list", "--json"], capsys))
    assert [t["slot"] for t in d["tools"]] == [3]


def test_tools_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    L = ["--library", str(tmp_path / "tools.json")]
    ok(["tools", *L, "add", "1", "gripper", "--xyz", "0,0,100"], capsys)
    one_error_line(["tools", *L, "add", "1", "other", "--xyz", "1,2,3"], capsys,
                   "slot 1 holds 'gripper'", "--replace")
    ok(["tools", *L, "add", "1", "other", "--xyz", "1,2,3", "--replace"], capsys)
    one_error_line(["tools", *L, "show", "2"], capsys, "slot 2 is empty")
    one_error_line(["tools", *L, "show", "17"], capsys, "out of range 1..16")
    one_error_line(["tools", *L, "add", "0", "x", "--xyz", "1,2,3"], capsys, "out of range")
    one_error_line(["tools", *L, "export", "nosuch", "--format", "kuka"], capsys,
                   "no tool named 'nosuch'")
    one_error_line(["tools", *L, "add", "2", "bad", "--xyz", "1,2,nan"], capsys, "finite")
    one_error_line(["tools", *L, "export", "1"], capsys, "--format")


def test_tools_corrupt_library_is_reported(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    lib = tmp_path / "tools.json"
    lib.write_text("{ this is not json")
    code, out, err = run(["tools", "--library", str(lib), "list"], capsys)
    assert code == 0
    assert "No tools stored" in out
    assert err.count("\n") == 1 and "corrupt" in err and "moved aside" in err
    backups = list(tmp_path.glob("tools.corrupt-*"))
    assert len(backups) == 1 and backups[0].read_text() == "{ this is not json"


def _library_text(entries: dict, active=None) -> str:
    return json.dumps({"format": "tcp-pendant-tool-library", "version": 1,
                       "active_slot": active, "tools": entries})


def test_tools_bad_entry_is_set_aside_and_the_rest_listed(tmp_path: Path,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    lib = tmp_path / "tools.json"
    entries = {str(s): {"name": f"tool{s}", "tcp_mm": [s, 0, 100]} for s in (1, 2, 4, 5)}
    entries["3"] = {"name": "broken", "tcp_mm": [float("nan"), 0, 100]}
    text = _library_text(entries, active=4)
    lib.write_text(text)
    code, out, err = run(["tools", "--library", str(lib), "list", "--json"], capsys)
    assert code == 0
    d = json.loads(out)
    assert [t["slot"] for t in d["tools"]] == [1, 2, 4, 5] and d["active_slot"] == 4
    (backup,) = tmp_path.glob("tools.corrupt-*")
    assert backup.read_text() == text
    assert err.count("\n") == 1 and err.startswith("tcpcal: warning: the tool library")
    assert "slot 3: tcp_mm[0] must be a finite number" in err and str(backup) in err
    assert "slots 1, 2, 4, 5" in err
    # the next command sees a clean library: no warning any more
    code, out, err = run(["tools", "--library", str(lib), "show", "tool4"], capsys)
    assert code == 0 and err == "" and "Slot 4: tool4" in out


def test_tools_error_after_a_recovery_is_still_one_line(tmp_path: Path,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    lib = tmp_path / "tools.json"
    lib.write_text(_library_text({"1": {"name": "a", "tcp_mm": [0, 0, 1]},
                                  "3": {"name": 3, "tcp_mm": [0, 0, 1]}}))
    err = one_error_line(["tools", "--library", str(lib), "show", "3"], capsys,
                         "slot 3 is empty", r"note: the tool library .* had 1 bad entry",
                         "slot 3: tool name must be a string", "tools.corrupt-")
    assert err.startswith("tcpcal: error: ")


@pytest.mark.parametrize("content", [b"[" * 100_000, b'{"tools": ' * 100_000])
def test_tools_deeply_nested_library_is_moved_aside_not_a_traceback(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], content: bytes) -> None:
    lib = tmp_path / "tools.json"
    lib.write_bytes(content)
    code, out, err = run(["tools", "--library", str(lib), "list"], capsys)
    assert code == 0, err
    assert "No tools stored" in out
    assert err.count("\n") == 1 and "nested too deeply" in err and "moved aside" in err
    assert "Traceback" not in err and "RecursionError" not in err
    (backup,) = tmp_path.glob("tools.corrupt-*")
    assert backup.read_bytes() == content
    ok(["tools", "--library", str(lib), "add", "1", "fresh", "--xyz", "0,0,100"], capsys)
    assert backup.read_bytes() == content


def test_tools_unmovable_corrupt_library_is_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    import tcpcal.library

    lib = tmp_path / "tools.json"
    lib.write_bytes(b"[" * 100_000)

    def refuse(src, dst):  # a read-only directory (the tests may run as root)
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tcpcal.library.os, "replace", refuse)
    one_error_line(["tools", "--library", str(lib), "list"], capsys,
                   "nested too deeply", "could not be moved aside", "Permission denied")
    assert lib.read_bytes() == b"[" * 100_000
    assert not list(tmp_path.glob("tools.corrupt-*"))


# ---------------------------------------------------------------------------------- convert
def test_convert_kuka_numbers_to_abb(capsys: pytest.CaptureFixture[str]) -> None:
    d = json.loads(ok(["convert", "--from", "kuka", "--to", "abb", "10,20,30,0,-90,0",
                       "--json"], capsys))
    np.testing.assert_allclose(d["rotation_matrix"], rot_abc(0, -90, 0), atol=1e-12)
    assert d["tcp_mm"] == [10, 20, 30]
    # Ry(-90 deg) as a unit quaternion, scalar first: (cos -45 deg, 0, sin -45 deg, 0)
    quat = re.search(r"\[\[10(?:\.0)?,20(?:\.0)?,30(?:\.0)?\],\[([^\]]+)\]\]", d["text"])
    assert quat, d["text"]
    np.testing.assert_allclose([float(v) for v in quat.group(1).split(",")],
                               [np.sqrt(0.5), 0, -np.sqrt(0.5), 0], atol=1e-12)
    # the plain output is the same text
    assert ok(["convert", "--from", "kuka", "--to", "abb", "10,20,30,0,-90,0"], capsys) \
        .strip() == d["text"].strip()


def test_convert_fanuc_ur_and_matrix_numbers(capsys: pytest.CaptureFixture[str]) -> None:
    # FANUC W = 90 deg about fixed X is KUKA C = 90 deg; negative first value is not an option
    d = json.loads(ok(["convert", "--from", "fanuc", "--to", "kuka", "-10,20,30,90,0,0",
                       "--json"], capsys))
    assert d["tcp_mm"] == [-10, 20, 30]
    np.testing.assert_allclose(d["kuka_abc_deg"], [0, 0, 90], atol=1e-9)
    assert "TOOL_DATA[1]" in d["text"]
    # UR: metres and a rotation vector in rad (here 90 deg about Z), space-separated values
    d = json.loads(ok(["convert", "--from", "ur", "--to", "kuka", "0.01", "0.02", "-0.03", "0",
                       "0", str(np.pi / 2), "--json"], capsys))
    np.testing.assert_allclose(d["tcp_mm"], [10, 20, -30], atol=1e-12)
    np.testing.assert_allclose(d["rotation_matrix"], rot_abc(90, 0, 0), atol=1e-12)
    # matrix: 16 numbers row-major
    T = np.eye(4)
    T[:3, :3] = rot_abc(30, 20, 10)
    T[:3, 3] = [1, 2, 3]
    d = json.loads(ok(["convert", "--from", "matrix", "--to", "kuka",
                       ",".join(repr(float(v)) for v in T.reshape(-1)), "--json"], capsys))
    np.testing.assert_allclose(d["kuka_abc_deg"], [30, 20, 10], atol=1e-9)


def test_convert_controller_text_and_stdin(capsys: pytest.CaptureFixture[str],
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    text = 'TOOL_DATA[4]={X 12.5,Y -3,Z 180.25,A 0,B 90,C 0}'
    d = json.loads(ok(["convert", "--from", "kuka", "--to", "matrix", text, "--json"], capsys))
    np.testing.assert_allclose(d["tcp_mm"], [12.5, -3, 180.25])
    np.testing.assert_allclose(d["rotation_matrix"], rot_abc(0, 90, 0), atol=1e-12)
    rows = [[float(v) for v in ln.split()] for ln in d["text"].strip().splitlines()]
    np.testing.assert_allclose(np.array(rows)[:3, :3], rot_abc(0, 90, 0), atol=1e-12)
    # the matrix text read back from stdin gives the KUKA values again
    import io
    monkeypatch.setattr("sys.stdin", io.StringIO(d["text"]))
    back = json.loads(ok(["convert", "--from", "matrix", "--to", "kuka", "-", "--json"], capsys))
    np.testing.assert_allclose(back["tcp_mm"], [12.5, -3, 180.25], atol=1e-9)
    np.testing.assert_allclose(back["kuka_abc_deg"], [0, 90, 0], atol=1e-9)


def test_convert_errors(capsys: pytest.CaptureFixture[str]) -> None:
    one_error_line(["convert", "--from", "kuka", "--to", "abb", "1,2,3"], capsys,
                   "3 numbers given, 6 expected")
    one_error_line(["convert", "--from", "abb", "--to", "kuka", "1,2,3,0.5,0.5,0.5,0.1"],
                   capsys, "norm")
    one_error_line(["convert", "--from", "kuka", "--to", "abb", "TOOL_DATA[1]={X_1}"], capsys,
                   "convert: kuka")
    one_error_line(["convert", "--from", "kuka", "--to", "abb", "1,2,3,nan,0,0"], capsys,
                   "finite")
    one_error_line(["convert", "--from", "kuka", "--to", "cnc", "1,2,3,0,0,0"], capsys,
                   "invalid choice")


def test_tools_export_reads_back(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    L = ["--library", str(tmp_path / "t.json")]
    ok(["tools", *L, "add", "7", "spindle", "--xyz", "1.5,-2,250", "--abc", "0,-90,0"], capsys)
    for fmt in ("kuka", "abb", "fanuc", "ur", "matrix"):
        text = ok(["tools", *L, "export", "spindle", "--format", fmt], capsys)
        if fmt == "kuka":
            assert text.startswith("TOOL_DATA[7]=")
        back = json.loads(ok(["convert", "--from", fmt, "--to", "kuka", text, "--json"], capsys))
        np.testing.assert_allclose(back["tcp_mm"], [1.5, -2, 250], atol=1e-9)
        np.testing.assert_allclose(back["rotation_matrix"], rot_abc(0, -90, 0), atol=1e-9)
