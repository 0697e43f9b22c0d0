"""The gradebook: what is stored, what a grade row says (on SQLite and on PostgreSQL: every test
that takes ``book`` runs on both), and that a file it cannot read is refused with one clear
error and left untouched."""

from __future__ import annotations

import csv
import hashlib
import io
import sqlite3
import threading
from pathlib import Path

import numpy as np
import platformdirs
import pytest
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.gradebook_open import default_gradebook_path
from tcp_pendant.classroom.gradebook_schema import SCHEMA_VERSION
from tcp_pendant.classroom.gradebook_store import GradebookError
from tcp_pendant.classroom.grades_csv import CSV_COLUMNS, to_csv

POSE = np.array([[1.0, 0, 0, 0.5], [0, 1, 0, 0.1], [0, 0, 1, 0.4], [0, 0, 0, 1]])
JOINTS = [10.0, -80.0, 100.0, 20.0, 40.0, 30.0]


@pytest.fixture
def book(gradebook_target: Path | str) -> Gradebook:
    """A new gradebook, once as an SQLite file and once in PostgreSQL (tests/conftest.py)."""
    with Gradebook(gradebook_target) as g:
        yield g


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _finished_xyz4(g: Gradebook, name: str = "Anna") -> int:
    sid = g.records.start_session(g.trainees.add(name), "own")
    cid = g.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
    t0 = g.records.record_touch(cid, 0, POSE, JOINTS, 0.12, False)
    g.records.record_touch(cid, 1, POSE, JOINTS, 0.30, True)
    g.records.record_touch(cid, 0, POSE, JOINTS, 0.05, False, overwritten_touch_id=t0)
    g.records.record_touch(cid, 2, POSE, JOINTS, None, False)
    g.records.record_touch(cid, 3, POSE, JOINTS, 0.2, True)
    g.records.record_crash(cid, penetration_mm=1.5, note="jog")
    g.records.finish_calibration(cid, {"mean_error_mm": 0.21, "ci95_mm": 0.8}, position_error_mm=0.33,
                                 orientation_error_deg=None, grade="good", tcp_mm=(1.0, 2.0, 180.0))
    return cid


def test_a_finished_calibration_is_one_grade_row_with_its_counts(book: Gradebook) -> None:
    cid = _finished_xyz4(book)
    (row,) = book.grades.rows()
    assert row.calibration_id == cid and row.trainee == "Anna" and row.mode == "own"
    assert (row.method, row.tool_key, row.exercise_id) == ("xyz4", "pointer", None)
    # 5 recorded, one overwritten: 4 count, 2 of them by Auto-touch
    assert (row.touches, row.hand, row.auto, row.overwritten, row.crashes) == (4, 2, 2, 1, 1)
    assert row.figures == {"mean_error_mm": 0.21, "ci95_mm": 0.8}
    assert row.tcp_mm == (1.0, 2.0, 180.0) and row.abc_deg is None
    assert (row.position_error_mm, row.orientation_error_deg, row.grade) == (0.33, None, "good")
    assert 0.0 <= row.duration_s < 30.0
    assert row.started_at.endswith("+00:00") and row.finished_at >= row.started_at


def test_touches_keep_pose_joints_distance_auto_and_overwrites(book: Gradebook) -> None:
    cid = _finished_xyz4(book)
    touches = book.records.touches(cid)
    assert len(touches) == 5
    assert np.array_equal(np.array(touches[0]["T_world_flange_m"]), POSE)
    assert touches[0]["joints_deg"] == JOINTS
    assert [t["distance_mm"] for t in touches] == [0.12, 0.30, 0.05, None, 0.2]
    assert [t["auto"] for t in touches] == [False, True, False, False, True]
    assert touches[0]["overwritten_by_touch_id"] == touches[2]["id"]
    assert touches[2]["overwrites_touch_id"] == touches[0]["id"]
    assert book.records.truth(cid) == {"T_flange_tool_true_m": np.eye(4).tolist()}


def test_every_call_is_committed_when_it_returns(tmp_path: Path) -> None:
    """A second connection (another process would see the same) finds each event at once."""
    path = tmp_path / "c.sqlite3"
    g = Gradebook(path)
    other = sqlite3.connect(path)
    count = lambda table: other.execute(f"SELECT COUNT(*) FROM {table}").fetchone()[0]  # noqa: E731
    sid = g.records.start_session(g.trainees.add("Bo"), "own")
    assert count("trainees") == 1 and count("sessions") == 1
    cid = g.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
    assert count("calibrations") == 1
    for n in range(1, 4):
        g.records.record_touch(cid, n - 1, POSE, JOINTS, 0.1, False)
        assert count("touches") == n
    g.records.record_crash(session_id=sid)
    assert count("crashes") == 1
    g.records.finish_calibration(cid, {}, position_error_mm=1.0, orientation_error_deg=None, grade="fair")
    assert other.execute("SELECT status, grade FROM calibrations").fetchone() == ("finished", "fair")
    other.close()
    g.close()


def test_file_is_wal_with_full_sync_and_a_versioned_schema(tmp_path: Path) -> None:
    path = tmp_path / "c.sqlite3"
    Gradebook(path).close()
    db = sqlite3.connect(path)
    assert db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    assert dict(db.execute("SELECT key, value FROM meta"))["schema_version"] == str(SCHEMA_VERSION)
    db.close()
    g = Gradebook(path)
    assert g.store._db.execute("PRAGMA synchronous").fetchone()[0] == 2  # FULL
    g.close()
    g = Gradebook(path, synchronous="NORMAL")
    assert g.store._db.execute("PRAGMA synchronous").fetchone()[0] == 1
    g.close()


def test_reopening_keeps_everything_and_names_reconnect_to_the_same_trainee(tmp_path: Path) -> None:
    path = tmp_path / "c.sqlite3"
    with Gradebook(path) as g:
        _finished_xyz4(g, "Anna Meier")
        anna = g.trainees.add("Anna Meier")
    with Gradebook(path) as g:
        assert g.trainees.add("  Anna   Meier ") == anna      # normalised to the same name
        assert g.trainees.add("Ben") != anna
        assert [r.trainee for r in g.grades.rows()] == ["Anna Meier"]


def test_cancelled_calibrations_are_not_graded_until_resumed_and_finished(book: Gradebook) -> None:
    sid = book.records.start_session(book.trainees.add("Cy"), "shared")
    cid = book.records.start_calibration(sid, "abc-world", "torch", {"tcp_mm": [0, 0, 200], "abc_deg": [0, 90, 0]},
                                         exercise_id="mystery-7")
    book.records.record_touch(cid, 0, POSE, JOINTS, None, False)
    book.records.cancel_calibration(cid)
    assert book.records.calibration_status(cid) == "cancelled" and book.grades.rows() == []
    with pytest.raises(GradebookError, match="cancelled; resume_calibration"):
        book.records.record_touch(cid, 0, POSE, JOINTS, None, False)
    with pytest.raises(GradebookError, match="cancelled"):
        book.records.finish_calibration(cid, {}, position_error_mm=None, orientation_error_deg=0.3, grade="good")
    book.records.resume_calibration(cid)
    book.records.finish_calibration(cid, {"orthogonality_defect_deg": 0.0}, position_error_mm=None,
                                    orientation_error_deg=0.3, grade="good", abc_deg=(0, 90, 0))
    (row,) = book.grades.rows()
    assert (row.exercise_id, row.orientation_error_deg, row.abc_deg, row.mode) == ("mystery-7", 0.3,
                                                                                   (0.0, 90.0, 0.0), "shared")
    assert book.records.truth(cid) == {"abc_deg": [0, 90, 0], "tcp_mm": [0, 0, 200]}


def test_finishing_again_replaces_the_result(book: Gradebook) -> None:
    cid = _finished_xyz4(book)
    book.records.finish_calibration(cid, {"mean_error_mm": 1.5}, position_error_mm=2.5, orientation_error_deg=None,
                                    grade="poor")
    (row,) = book.grades.rows()
    assert (row.figures, row.position_error_mm, row.grade, row.tcp_mm) == ({"mean_error_mm": 1.5}, 2.5, "poor",
                                                                            None)


@pytest.mark.parametrize("call, match", [
    (lambda g, c: g.records.record_touch(c, 0, np.full((4, 4), np.nan), JOINTS, 0.1, False), "finite 4x4"),
    (lambda g, c: g.records.record_touch(c, 0, np.eye(3), JOINTS, 0.1, False), "4x4"),
    (lambda g, c: g.records.record_touch(c, 0, POSE, [1.0, float("inf")], 0.1, False), "joints_deg"),
    (lambda g, c: g.records.record_touch(c, -1, POSE, JOINTS, 0.1, False), "step_index"),
    (lambda g, c: g.records.record_touch(c, 0, POSE, JOINTS, float("nan"), False), "distance_mm"),
    (lambda g, c: g.records.record_touch(c, 0, POSE, JOINTS, 0.1, "yes"), "auto must be"),
    (lambda g, c: g.records.record_touch(c + 99, 0, POSE, JOINTS, 0.1, False), "No calibration"),
    (lambda g, c: g.records.finish_calibration(c, {}, position_error_mm=0.1, orientation_error_deg=None,
                                               grade="excellent"), "grade must be"),
    (lambda g, c: g.records.finish_calibration(c, {"x": "1"}, position_error_mm=0.1, orientation_error_deg=None,
                                               grade=None), "must be a number"),
    (lambda g, c: g.records.start_calibration(999, "xyz4", "pointer", np.eye(4)), "No session 999"),
    (lambda g, c: g.records.start_calibration(1, "xyz4", "pointer", {"T": float("nan")}), "finite"),
    (lambda g, c: g.records.record_crash(), "calibration_id or the session_id"),
    (lambda g, c: g.records.record_crash(c, session_id=99), "belongs to session"),
    (lambda g, c: g.trainees.add("\u200b"), "invisible"),
    (lambda g, c: g.records.start_session(42, "own"), "No trainee 42"),
])
def test_bad_calls_are_refused_and_store_nothing(book: Gradebook, call, match) -> None:
    sid = book.records.start_session(book.trainees.add("Dee"), "own")
    cid = book.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
    before = book.store._db.execute("SELECT (SELECT COUNT(*) FROM touches), (SELECT COUNT(*) FROM crashes), "
                                    "(SELECT COUNT(*) FROM calibrations), (SELECT COUNT(*) FROM trainees)").fetchone()
    with pytest.raises(GradebookError, match=match):
        call(book, cid)
    after = book.store._db.execute("SELECT (SELECT COUNT(*) FROM touches), (SELECT COUNT(*) FROM crashes), "
                                   "(SELECT COUNT(*) FROM calibrations), (SELECT COUNT(*) FROM trainees)").fetchone()
    assert after == before
    assert book.records.calibration_status(cid) == "in_progress"


def test_an_overwrite_must_name_a_live_touch_of_the_same_calibration(book: Gradebook) -> None:
    sid = book.records.start_session(book.trainees.add("Eve"), "own")
    a = book.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
    b = book.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
    ta = book.records.record_touch(a, 0, POSE, JOINTS, 0.1, False)
    with pytest.raises(GradebookError, match="not a touch of calibration"):
        book.records.record_touch(b, 0, POSE, JOINTS, 0.1, False, overwritten_touch_id=ta)
    ta2 = book.records.record_touch(a, 0, POSE, JOINTS, 0.1, False, overwritten_touch_id=ta)
    with pytest.raises(GradebookError, match=f"already overwritten by touch {ta2}"):
        book.records.record_touch(a, 0, POSE, JOINTS, 0.1, False, overwritten_touch_id=ta)


def test_threads_may_write_at_once(book: Gradebook) -> None:
    sid = book.records.start_session(book.trainees.add("Fay"), "own")
    cids = [book.records.start_calibration(sid, "xyz4", "pointer", np.eye(4)) for _ in range(4)]
    errors: list[BaseException] = []

    def work(cid: int) -> None:
        try:
            for i in range(40):
                book.records.record_touch(cid, i, POSE, JOINTS, 0.1, i % 2 == 0)
        except BaseException as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(c,)) for c in cids]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert [len(book.records.touches(c)) for c in cids] == [40] * 4


# ------------------------------------------------------------------- files it must not touch

def test_a_newer_schema_is_refused_and_left_unchanged(tmp_path: Path) -> None:
    path = tmp_path / "c.sqlite3"
    with Gradebook(path) as g:
        _finished_xyz4(g)
    db = sqlite3.connect(path)
    db.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'", (str(SCHEMA_VERSION + 1),))
    db.commit()
    db.close()
    digest = _sha(path)
    with pytest.raises(GradebookError) as info:
        Gradebook(path)
    message = str(info.value)
    assert str(path) in message and "newer TCP Pendant" in message and "--class-db" in message
    assert _sha(path) == digest


def test_a_file_that_is_not_sqlite_is_refused_and_left_unchanged(tmp_path: Path) -> None:
    path = tmp_path / "c.sqlite3"
    path.write_bytes(b"name,grade\nAnna,good\n" * 100)
    digest = _sha(path)
    with pytest.raises(GradebookError, match="is not a readable SQLite database") as info:
        Gradebook(path)
    assert str(path) in str(info.value) and "move it aside" in str(info.value)
    assert _sha(path) == digest


def test_a_damaged_gradebook_is_refused_and_left_unchanged(tmp_path: Path) -> None:
    path = tmp_path / "c.sqlite3"
    with Gradebook(path) as g:
        for i in range(20):
            _finished_xyz4(g, f"Trainee {i}")
    data = bytearray(path.read_bytes())
    page = 4096
    assert len(data) > 4 * page
    data[2 * page + 10: 3 * page] = b"\xff" * (page - 10)    # a b-tree page overwritten
    path.write_bytes(bytes(data))
    with pytest.raises(GradebookError, match="damaged|not a readable") as info:
        Gradebook(path)
    assert str(path) in str(info.value)
    assert path.read_bytes() == bytes(data)


def test_another_programs_database_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "other.db"
    db = sqlite3.connect(path)
    db.execute("CREATE TABLE meta (key TEXT, value TEXT)")
    db.execute("INSERT INTO meta VALUES ('application', 'something else')")
    db.commit()
    db.close()
    digest = _sha(path)
    with pytest.raises(GradebookError, match="another program"):
        Gradebook(path)
    assert _sha(path) == digest


def test_create_false_does_not_make_a_file(tmp_path: Path) -> None:
    path = tmp_path / "missing.sqlite3"
    with pytest.raises(GradebookError, match="No gradebook at"):
        Gradebook(path, create=False)
    assert not path.exists()
    with pytest.raises(GradebookError, match="is a folder"):
        Gradebook(tmp_path)


def test_a_path_in_a_missing_folder_says_so(tmp_path: Path) -> None:
    path = tmp_path / "no-such-folder" / "c.sqlite3"
    with pytest.raises(GradebookError, match="Cannot open the gradebook .*folder exist"):
        Gradebook(path)
    assert not path.parent.exists()


def test_default_path_is_in_the_user_data_folder() -> None:
    expected = Path(platformdirs.user_data_dir("tcp-pendant", appauthor=False)) / "class.sqlite3"
    assert default_gradebook_path() == expected


def test_closed_gradebook_refuses_calls(tmp_path: Path) -> None:
    g = Gradebook(tmp_path / "c.sqlite3")
    g.close()
    g.close()
    with pytest.raises(GradebookError, match="closed"):
        g.trainees.add("Gil")


# ------------------------------------------------------------------------------ CSV

def test_csv_has_the_documented_columns_and_one_line_per_row(book: Gradebook) -> None:
    _finished_xyz4(book, "Anna")
    _finished_xyz4(book, "=HYPERLINK(\"http://x\")")
    text = to_csv(book.grades.rows())
    rows = list(csv.DictReader(io.StringIO(text)))
    assert tuple(rows[0].keys()) == CSV_COLUMNS
    assert [r["trainee"] for r in rows] == ["Anna", "'=HYPERLINK(\"http://x\")"]
    r = rows[0]
    assert (r["touches"], r["hand"], r["auto"], r["overwritten"], r["crashes"]) == ("4", "2", "2", "1", "1")
    assert (r["tcp_x_mm"], r["tcp_z_mm"], r["a_deg"]) == ("1.0", "180.0", "")
    assert (r["mean_error_mm"], r["ci95_mm"], r["max_error_mm"]) == ("0.21", "0.8", "")
    assert (r["position_error_mm"], r["orientation_error_deg"], r["grade"]) == ("0.33", "", "good")
    assert r["figures_json"] == '{"ci95_mm": 0.8, "mean_error_mm": 0.21}'
    assert to_csv([]) == ",".join(CSV_COLUMNS) + "\r\n"


def test_presence_rows_follow_claims_heartbeats_and_their_holders(tmp_path) -> None:
    db = tmp_path / "class.sqlite3"
    a, b = Gradebook(db), Gradebook(db)                  # two server processes' connections
    try:
        assert a.presence.claim("Anna", "A", {"name": "Anna", "touches": 0}, now=100.0) is None
        assert b.presence.holder("Anna", now=105.0) == "A"
        assert b.presence.holder("Anna", now=110.5) is None              # A stopped beating 10 s ago
        assert b.presence.present(now=105.0) == [("Anna", "A", {"name": "Anna", "touches": 0})]
        assert a.presence.beat("A", {"Anna": {"name": "Anna", "touches": 2}}, now=109.0) == {"Anna"}
        assert b.presence.holder("Anna", now=118.0) == "A"
        assert b.presence.present(now=118.0)[0][2]["touches"] == 2
        assert b.presence.claim("Anna", "B", {"name": "Anna"}, now=118.0) == "A"   # taken over
        assert a.presence.beat("A", {"Anna": {"name": "Anna"}}, now=119.0) == set()
        assert not a.presence.drop("Anna", "A")          # not A's any more: B's row stays
        assert a.presence.holder("Anna", now=119.0) == "B"
        b.presence.claim("Ben", "B", {"name": "Ben"}, now=119.0)
        assert [n for n, _, _ in a.presence.present(now=119.0)] == ["Anna", "Ben"]
        assert b.presence.drop_holder("B") == 2 and a.presence.present(now=119.0) == []
        assert a.pushes.last_id() == 0
        first = a.pushes.add({"exercise": "mystery"})
        second = b.pushes.add({"exercise": None, "hide_distance": "shown"})
        assert second > first
        assert b.pushes.after(0) == [(first, {"exercise": "mystery"}),
                                     (second, {"exercise": None, "hide_distance": "shown"})]
        assert a.pushes.after(first) == [(second, {"exercise": None, "hide_distance": "shown"})]
        assert a.pushes.last_id() == second
    finally:
        a.close()
        b.close()
