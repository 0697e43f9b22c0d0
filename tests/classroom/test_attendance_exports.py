"""Every trainee who joined is in every grade export (``tcp-pendant grades`` table, ``--csv``,
``--per-trainee``, ``--moodle`` and the dashboard's download), with an empty grade and the
reason, and the Moodle grade of one without a result is the trainer's choice; every export
writes a number the same way (``classroom.export_numbers``). SQLite and PostgreSQL."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.classroom import grades_cli
from tcp_pendant.classroom.class_room import ClassRoom
from tcp_pendant.classroom.export_numbers import export_cell
from tcp_pendant.classroom.grade_rows import NO_RESULT_REASON
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.grades_csv import CSV_COLUMNS, IN_PROGRESS_NOTE
from tcp_pendant.classroom.lms import PER_TRAINEE_COLUMNS
from tcp_pendant.controller import builtin_tools

POSE = np.eye(4)
JOINTS = [0.0] * 6
TINY = 1.99562e-12
"""A position error of round-off size, as a perfect simulated solve leaves it (mm)."""


def _class(target: Path | str) -> None:
    """ana finished (good, error ``TINY``), ben in progress, chen joined and did nothing, dora
    only cancelled, and "ghost" was added but never joined (no session)."""
    with Gradebook(target) as g:
        ana = g.records.start_session(g.trainees.add("ana"), "per-browser")
        cid = g.records.start_calibration(ana, "xyz4", "pointer", np.eye(4), exercise_id="mystery")
        for i in range(4):
            g.records.record_touch(cid, i, POSE, JOINTS, None, False)
        g.records.finish_calibration(cid, {"mean_error_mm": -TINY, "ci95_mm": 0.5}, position_error_mm=TINY,
                                     orientation_error_deg=None, grade="good", tcp_mm=(1.0, 2.0, 180.0))
        ben = g.records.start_session(g.trainees.add("ben"), "per-browser")
        g.records.record_touch(g.records.start_calibration(ben, "xyz4", "pointer", np.eye(4)), 0, POSE, JOINTS,
                               None, False)
        g.records.start_session(g.trainees.add("chen"), "per-browser")
        dora = g.records.start_session(g.trainees.add("=dora"), "per-browser")
        g.records.cancel_calibration(g.records.start_calibration(dora, "xyz4", "pointer", np.eye(4)))
        g.trainees.add("ghost")


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    assert grades_cli.main(list(args)) == 0
    return capsys.readouterr().out


def test_the_csv_has_an_attendance_row_for_a_trainee_without_a_calibration(
        gradebook_target: Path | str, capsys: pytest.CaptureFixture[str]) -> None:
    _class(gradebook_target)
    rows = list(csv.DictReader(io.StringIO(_run(capsys, "--class-db", str(gradebook_target), "--csv"))))
    assert tuple(rows[0]) == CSV_COLUMNS and CSV_COLUMNS[-1] == "note"
    by = {r["trainee"]: r for r in rows}
    assert [r["trainee"] for r in rows] == ["ana", "ben", "chen", "'=dora"]        # ghost never joined
    assert (by["ana"]["grade"], by["ana"]["position_error_mm"], by["ana"]["mean_error_mm"], by["ana"]["note"]) == (
        "good", "0.0", "0.0", "")
    assert (by["ben"]["status"], by["ben"]["grade"], by["ben"]["note"]) == ("in_progress", "", IN_PROGRESS_NOTE)
    for name in ("chen", "'=dora"):
        r = by[name]
        assert (r["calibration_id"], r["grade"], r["status"], r["note"]) == ("", "", "joined", NO_RESULT_REASON)
        assert all(r[c] == "" for c in CSV_COLUMNS if c not in ("trainee", "status", "note"))


def test_per_trainee_and_the_table_list_every_trainee_who_joined(gradebook_target: Path | str,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    _class(gradebook_target)
    db = str(gradebook_target)
    rows = list(csv.DictReader(io.StringIO(_run(capsys, "--class-db", db, "--per-trainee", "--csv"))))
    assert tuple(rows[0]) == PER_TRAINEE_COLUMNS
    by = {r["trainee"]: r for r in rows}
    assert sorted(by) == ["'=dora", "ana", "ben", "chen"]
    assert (by["ana"]["best_grade"], by["ana"]["best_position_error_mm"], by["ana"]["note"]) == ("good", "0.0", "")
    for name, in_progress in (("ben", "1"), ("chen", "0"), ("'=dora", "0")):
        assert (by[name]["attempts"], by[name]["in_progress"], by[name]["best_grade"], by[name]["note"]) == (
            "0", in_progress, "", NO_RESULT_REASON)
    table = _run(capsys, "--class-db", db).splitlines()
    chen = next(line for line in table if line.split()[1:2] == ["chen"])
    assert chen.split()[0] == "-" and chen.endswith(NO_RESULT_REASON)
    assert not any("ghost" in line for line in table)
    per = _run(capsys, "--class-db", db, "--per-trainee").splitlines()
    assert per[0].endswith(": 4 trainees") and any(line.startswith("chen") and line.endswith(NO_RESULT_REASON)
                                                   for line in per)


@pytest.mark.parametrize("absent, points", [(None, ""), ("empty", ""), ("0", "0")])
def test_the_moodle_grade_of_a_trainee_without_a_result_is_the_trainers_choice(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], absent: str | None, points: str) -> None:
    path = tmp_path / "class.sqlite3"
    _class(path)
    args = ["--class-db", str(path), "--moodle"] + ([] if absent is None else ["--moodle-absent", absent])
    rows = {r[0]: r[1:] for r in list(csv.reader(io.StringIO(_run(capsys, *args))))[1:]}
    assert rows["ana"][0] == "100"
    assert rows["ben"] == [points, f"{NO_RESULT_REASON}; 1 in progress"]
    assert rows["chen"] == [points, NO_RESULT_REASON] and rows["'=dora"] == [points, NO_RESULT_REASON]
    assert "ghost" not in rows


def test_a_moodle_absent_grade_outside_the_choices_is_refused(tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "class.sqlite3"
    _class(path)
    assert grades_cli.main(["--class-db", str(path), "--moodle", "--moodle-absent", "50"]) == 2
    err = capsys.readouterr().err
    assert "--moodle-absent" in err and "'0'" in err and "'empty'" in err


def test_the_dashboards_download_lists_every_trainee_who_joined(tmp_path: Path) -> None:
    path = tmp_path / "class.sqlite3"
    _class(path)
    with Gradebook(path) as book:
        room = ClassRoom(book, builtin_tools(), trainer_token="t" * 20)
        rows = list(csv.DictReader(io.StringIO(room.grades_csv())))
    assert {r["trainee"]: (r["status"], r["note"]) for r in rows} == {
        "ana": ("finished", ""), "chen": ("joined", NO_RESULT_REASON), "ben": ("joined", NO_RESULT_REASON),
        "'=dora": ("joined", NO_RESULT_REASON)}


def test_every_export_writes_the_same_number_the_same_way(tmp_path: Path,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    """The same position error in the plain CSV and in --per-trainee (1.99562e-12 was 0.0 in one
    and 1.99562e-12 in the other): one text, no exponent, no -0.0."""
    path = tmp_path / "class.sqlite3"
    with Gradebook(path) as g:
        sid = g.records.start_session(g.trainees.add("ana"), "per-browser")
        for err in (TINY, 0.00001, 0.1234567891, 12.5):
            cid = g.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
            g.records.finish_calibration(cid, {}, position_error_mm=err, orientation_error_deg=-TINY, grade="good")
    plain = list(csv.DictReader(io.StringIO(_run(capsys, "--class-db", str(path), "--csv"))))
    assert [r["position_error_mm"] for r in plain] == ["0.0", "0.00001", "0.123457", "12.5"]
    assert {r["orientation_error_deg"] for r in plain} == {"0.0"}
    per = next(csv.DictReader(io.StringIO(_run(capsys, "--class-db", str(path), "--per-trainee", "--csv"))))
    assert per["best_position_error_mm"] == plain[0]["position_error_mm"] == "0.0"
    assert per["last_position_error_mm"] == plain[-1]["position_error_mm"] == "12.5"
    assert [export_cell(v) for v in (None, float("nan"), -0.0, 3, 180.0)] == ["", "", "0.0", "3", "180.0"]
