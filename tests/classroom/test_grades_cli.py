"""``tcp-pendant grades``: the table, the CSV and one error line (exit 2) for a file it cannot read."""

from __future__ import annotations

import csv
import io
import sqlite3
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.classroom import grades_cli
from tcp_pendant.classroom.gradebook import CSV_COLUMNS, SCHEMA_VERSION, Gradebook

POSE = np.eye(4)
JOINTS = [0.0] * 6


def _make(path: Path) -> None:
    with Gradebook(path) as g:
        anna = g.start_session(g.add_trainee("Anna Meier"), "own")
        cid = g.start_calibration(anna, "xyz4", "pointer", np.eye(4))
        for i in range(4):
            g.record_touch(cid, i, POSE, JOINTS, 0.1, i == 3)
        g.record_crash(cid, penetration_mm=2.0)
        g.finish_calibration(cid, {"mean_error_mm": 0.2104, "ci95_mm": 0.84}, position_error_mm=0.2311,
                             orientation_error_deg=None, grade="good", tcp_mm=(0, 0, 180))
        ben = g.start_session(g.add_trainee("Ben <b>"), "own")
        cid = g.start_calibration(ben, "abc-world", "torch", np.eye(4))
        g.record_touch(cid, 0, POSE, JOINTS, None, True)
        g.finish_calibration(cid, {"orthogonality_defect_deg": 0.0}, position_error_mm=None,
                             orientation_error_deg=1.234, grade="fair")
        left = g.start_calibration(ben, "xyz4", "pointer", np.eye(4))      # never finished: no row
        g.record_touch(left, 0, POSE, JOINTS, 0.1, False)


def test_table_has_one_row_per_finished_calibration(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "class.sqlite3"
    _make(path)
    assert grades_cli.main(["--class-db", str(path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"Gradebook {path}: 2 finished calibrations"
    assert out[1].split()[:5] == ["id", "trainee", "method", "tool", "touches"]
    anna = out[3].split()
    # id, name (2 words), method, tool, touches, hand, auto, overwritten, crashes, duration, mean, ci95, pos, ori, grade
    assert anna[:3] == ["1", "Anna", "Meier"] and anna[3:5] == ["xyz4", "pointer"]
    assert anna[5:10] == ["4", "3", "1", "0", "1"]
    assert anna[11:] == ["0.210", "0.840", "0.231", "-", "good"]
    ben = out[4].split()
    assert ben[:4] == ["2", "Ben", "<b>", "abc-world"]
    assert ben[-5:] == ["-", "-", "-", "1.23", "fair"]
    assert len(out) == 5


def test_csv_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "class.sqlite3"
    _make(path)
    assert grades_cli.main(["--class-db", str(path), "--csv"]) == 0
    rows = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    assert tuple(rows[0]) == CSV_COLUMNS
    assert [(r["trainee"], r["method"], r["touches"], r["auto"], r["grade"]) for r in rows] == [
        ("Anna Meier", "xyz4", "4", "1", "good"), ("Ben <b>", "abc-world", "1", "1", "fair")]


def test_empty_gradebook(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "class.sqlite3"
    Gradebook(path).close()
    assert grades_cli.main(["--class-db", str(path)]) == 0
    assert capsys.readouterr().out == f"No finished calibration in {path} yet.\n"


def _newer(path: Path) -> None:
    _make(path)
    db = sqlite3.connect(path)
    db.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'", (str(SCHEMA_VERSION + 3),))
    db.commit()
    db.close()


@pytest.mark.parametrize("prepare, words", [
    (lambda p: None, "No gradebook at"),
    (lambda p: p.write_text("not a database at all\n" * 50), "is not a readable SQLite database"),
    (_newer, f"newer TCP Pendant (schema version {SCHEMA_VERSION + 3}"),
])
def test_bad_gradebook_is_one_line_and_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                               prepare, words: str) -> None:
    path = tmp_path / "class.sqlite3"
    prepare(path)
    before = path.read_bytes() if path.exists() else None
    assert grades_cli.main(["--class-db", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("tcp-pendant grades: error: ")
    assert words in lines[0] and str(path) in lines[0]
    assert (path.read_bytes() if path.exists() else None) == before


def test_default_path_is_the_servers(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                     capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "data" / "class.sqlite3"
    path.parent.mkdir()
    _make(path)
    monkeypatch.setattr(grades_cli, "default_gradebook_path", lambda: path)
    assert grades_cli.main([]) == 0
    assert capsys.readouterr().out.startswith(f"Gradebook {path}: 2 finished")


def test_bad_option_exits_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert grades_cli.main(["--nope"]) == 2
    assert "unrecognized arguments: --nope" in capsys.readouterr().err


def test_terminal_never_gets_control_characters() -> None:
    assert grades_cli._terminal_text("Ben\x1b[31m", 24) == "Ben?[31m"
    assert grades_cli._terminal_text("x" * 30, 24) == "x" * 23 + "…"
