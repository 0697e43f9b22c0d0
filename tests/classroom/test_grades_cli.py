"""``tcp-pendant grades``: the table, the CSV and one error line (exit 2) for a file it cannot read."""

from __future__ import annotations

import csv
import io
import re
import sqlite3
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.classroom import grades_cli
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.gradebook_db import mask_url
from tcp_pendant.classroom.gradebook_schema import SCHEMA_VERSION
from tcp_pendant.classroom.grades_csv import CSV_COLUMNS
from tcp_pendant.classroom.lms import MOODLE_POINTS, PER_TRAINEE_COLUMNS

POSE = np.eye(4)
JOINTS = [0.0] * 6


def _make(path: Path) -> None:
    with Gradebook(path) as g:
        anna = g.records.start_session(g.trainees.add("Anna Meier"), "own")
        cid = g.records.start_calibration(anna, "xyz4", "pointer", np.eye(4))
        for i in range(4):
            g.records.record_touch(cid, i, POSE, JOINTS, 0.1, i == 3)
        g.records.record_crash(cid, penetration_mm=2.0)
        g.records.finish_calibration(cid, {"mean_error_mm": 0.2104, "ci95_mm": 0.84}, position_error_mm=0.2311,
                                     orientation_error_deg=None, grade="good", tcp_mm=(0, 0, 180))
        ben = g.records.start_session(g.trainees.add("Ben <b>"), "own")
        cid = g.records.start_calibration(ben, "abc-world", "torch", np.eye(4))
        g.records.record_touch(cid, 0, POSE, JOINTS, None, True)
        g.records.finish_calibration(cid, {"orthogonality_defect_deg": 0.0}, position_error_mm=None,
                                     orientation_error_deg=1.234, grade="fair")
        left = g.records.start_calibration(ben, "xyz4", "pointer", np.eye(4))  # still in progress
        g.records.record_touch(left, 0, POSE, JOINTS, 0.1, False)
        gone = g.records.start_calibration(ben, "xyz4", "pointer", np.eye(4))  # cancelled: no row
        g.records.cancel_calibration(gone)


def test_table_has_one_row_per_calibration_with_its_status(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "class.sqlite3"
    _make(path)
    assert grades_cli.main(["--class-db", str(path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"Gradebook {path}: 2 finished calibrations, 1 in progress"
    assert out[1].split()[:5] == ["id", "trainee", "method", "tool", "touches"]
    anna = out[3].split()
    # id, name (2 words), method, tool, touches, hand, auto, overwritten, crashes, duration, mean, ci95, pos, ori,
    # grade, status
    assert anna[:3] == ["1", "Anna", "Meier"] and anna[3:5] == ["xyz4", "pointer"]
    assert anna[5:10] == ["4", "3", "1", "0", "1"]
    assert anna[11:] == ["0.210", "0.840", "0.231", "-", "good", "finished"]
    ben = out[4].split()
    assert ben[:4] == ["2", "Ben", "<b>", "abc-world"]
    assert ben[-6:] == ["-", "-", "-", "1.23", "fair", "finished"]
    left = out[5].split()
    assert left[:4] == ["3", "Ben", "<b>", "xyz4"] and left[-3:] == ["-", "in", "progress"]
    assert len(out) == 6


def test_csv_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "class.sqlite3"
    _make(path)
    assert grades_cli.main(["--class-db", str(path), "--csv"]) == 0
    rows = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    assert tuple(rows[0]) == CSV_COLUMNS
    assert [(r["trainee"], r["method"], r["touches"], r["auto"], r["grade"], r["status"]) for r in rows] == [
        ("Anna Meier", "xyz4", "4", "1", "good", "finished"), ("Ben <b>", "abc-world", "1", "1", "fair", "finished"),
        ("Ben <b>", "xyz4", "1", "0", "", "in_progress")]
    assert rows[2]["finished_at"] == "" and float(rows[2]["duration_s"]) >= 0.0


def _two_attempts(path: Path) -> None:
    """Anna: fair (1.9 mm) then good (0.3 mm) then poor (4.0 mm), and one in progress; Ben: none."""
    with Gradebook(path) as g:
        anna = g.records.start_session(g.trainees.add("Anna"), "own")
        for grade, err in (("fair", 1.9), ("good", 0.3), ("poor", 4.0)):
            cid = g.records.start_calibration(anna, "xyz4", "pointer", np.eye(4))
            g.records.finish_calibration(cid, {}, position_error_mm=err, orientation_error_deg=None, grade=grade)
        g.records.start_calibration(anna, "xyz4", "pointer", np.eye(4))
        ben = g.records.start_session(g.trainees.add("=Ben"), "own")
        g.records.start_calibration(ben, "xyz4", "pointer", np.eye(4))


def test_one_row_per_trainee_with_the_best_and_the_last_grade(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "class.sqlite3"
    _two_attempts(path)
    assert grades_cli.main(["--class-db", str(path), "--per-trainee", "--csv"]) == 0
    rows = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    assert tuple(rows[0]) == PER_TRAINEE_COLUMNS
    anna, ben = (next(r for r in rows if r["trainee"] == n) for n in ("Anna", "'=Ben"))
    assert (anna["trainee"], anna["attempts"], anna["in_progress"]) == ("Anna", "3", "1")
    assert (anna["best_grade"], float(anna["best_position_error_mm"])) == ("good", 0.3)
    assert (anna["last_grade"], float(anna["last_position_error_mm"])) == ("poor", 4.0)
    assert (ben["trainee"], ben["attempts"], ben["in_progress"], ben["best_grade"]) == ("'=Ben", "0", "1", "")
    assert grades_cli.main(["--class-db", str(path), "--per-trainee"]) == 0
    table = capsys.readouterr().out.splitlines()
    assert table[0] == f"Gradebook {path}: 2 trainees"
    assert ["Anna", "3", "1", "good"] in [line.split()[:4] for line in table[3:]]


def test_the_moodle_csv_is_the_layout_moodles_grade_import_reads(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    """Moodle's CSV grade import (docs.moodle.org/en/Grade_import): a header row, one row per
    learner, a column to map to the user, a numeric column per grade item (within the item's
    0..100) and its feedback column; an empty grade leaves the learner's grade as it is."""
    path = tmp_path / "class.sqlite3"
    _two_attempts(path)
    assert grades_cli.main(["--class-db", str(path), "--moodle"]) == 0
    text = capsys.readouterr().out
    assert text.splitlines()[0] == "Username,TCP calibration,TCP calibration feedback"
    rows = sorted(list(csv.reader(io.StringIO(text)))[1:], key=lambda r: r[0] != "Anna")
    assert rows[0][:2] == ["Anna", str(MOODLE_POINTS["good"])] and 0 <= int(rows[0][1]) <= 100
    assert "best: good, TCP 0.30 mm off; 3 attempts; last: poor" == rows[0][2]
    assert rows[1] == ["'=Ben", "", "joined, no calibration finished; 1 in progress"]


def test_empty_gradebook(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "class.sqlite3"
    Gradebook(path).close()
    assert grades_cli.main(["--class-db", str(path)]) == 0
    assert capsys.readouterr().out == f"No calibration in {path} yet.\n"


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


def test_grades_of_a_postgresql_gradebook_match_the_sqlite_ones_without_the_password(
        tmp_path: Path, postgres_server, capsys: pytest.CaptureFixture[str]) -> None:
    url = postgres_server.fresh_schema()
    _make(url)
    _make(tmp_path / "class.sqlite3")
    tables = []
    for target in (url, str(tmp_path / "class.sqlite3")):
        assert grades_cli.main(["--class-db", target]) == 0
        tables.append(capsys.readouterr().out.splitlines())
    pg, lite = tables
    assert pg[0] == f"Gradebook {mask_url(url)}: 2 finished calibrations, 1 in progress"
    assert ":***@" in pg[0] and postgres_server.password not in "\n".join(pg)
    no_duration = lambda lines: [re.sub(r"\b\d+:\d\d\b", "m:ss", line) for line in lines]  # noqa: E731
    assert no_duration(pg[1:]) == no_duration(lite[1:])        # the same rows
    texts = []
    for target in (url, str(tmp_path / "class.sqlite3")):
        assert grades_cli.main(["--class-db", target, "--csv"]) == 0
        texts.append(list(csv.DictReader(io.StringIO(capsys.readouterr().out))))
    strip = ("started_at", "finished_at", "duration_s")
    assert [{k: v for k, v in r.items() if k not in strip} for r in texts[0]] == \
        [{k: v for k, v in r.items() if k not in strip} for r in texts[1]]
    assert len(texts[0]) == 3


def test_an_unreachable_postgresql_gradebook_is_one_line_and_exit_2(postgres_server,
                                                                     capsys: pytest.CaptureFixture[str]) -> None:
    missing = postgres_server.url("no_such_class")
    assert grades_cli.main(["--class-db", missing]) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert captured.out == "" and len(lines) == 1 and lines[0].startswith("tcp-pendant grades: error: Cannot reach")
    assert mask_url(missing) in lines[0] and postgres_server.password not in lines[0]
    empty = postgres_server.fresh_schema()
    assert grades_cli.main(["--class-db", empty]) == 2                  # never makes a gradebook
    assert "No gradebook in" in capsys.readouterr().err
