"""``tcp-pendant grades`` and the classroom options of ``tcp-pendant``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.grades_csv import CSV_COLUMNS
from tcp_pendant.serve.cli import build_parser, main

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _book_with_one_row(path: Path) -> None:
    with Gradebook(path, synchronous="NORMAL") as g:
        sid = g.records.start_session(g.trainees.add("=Anna"), "per-browser")
        cal = g.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
        g.records.record_touch(cal, 0, np.eye(4), [0.0] * 6, 0.1, False)
        g.records.finish_calibration(cal, {"mean_error_mm": 0.2}, position_error_mm=0.3, orientation_error_deg=None,
                                     grade="good", tcp_mm=(1.0, 2.0, 3.0))


def test_grades_subcommand_prints_the_csv(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    db = tmp_path / "class.sqlite3"
    _book_with_one_row(db)
    assert main(["grades", "--class-db", str(db), "--csv"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].split(",") == list(CSV_COLUMNS)
    assert out[1].split(",")[1] == "'=Anna"             # a formula-looking name is defused
    assert main(["grades", "--class-db", str(db)]) == 0
    table = capsys.readouterr().out
    assert "=Anna" in table and "good" in table and "0.300" in table


def test_grades_of_a_missing_or_foreign_file_is_one_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["grades", "--class-db", str(tmp_path / "none.sqlite3")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tcp-pendant grades: error:") and len(err.strip().splitlines()) == 1
    foreign = tmp_path / "notes.txt"
    foreign.write_text("not a database")
    assert main(["grades", "--class-db", str(foreign)]) == 2
    assert foreign.read_text() == "not a database"


def test_server_refuses_a_damaged_gradebook_and_classroom_options_with_shared(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "class.sqlite3"
    bad.write_bytes(b"garbage" * 100)
    assert main(["--port", "0", "--tool-library", str(tmp_path / "t.json"), "--class-db", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "gradebook" in err.lower() and str(bad) in err
    assert bad.read_bytes() == b"garbage" * 100
    assert main(["--shared", "--exercise", "mystery"]) == 2
    assert "--shared" in capsys.readouterr().err
    assert main(["--trainer-token", "short"]) == 2
    assert "--trainer-token" in capsys.readouterr().err


def test_parser_knows_the_classroom_options() -> None:
    args = build_parser().parse_args(["--class-db", "x.sqlite3", "--exercise", "mystery", "--exercise-seed", "7",
                                      "--trainer-token", "abcdefgh-16chars"])
    assert (args.class_db, args.exercise, args.exercise_seed, args.trainer_token) == \
        (Path("x.sqlite3"), "mystery", 7, "abcdefgh-16chars")
    with pytest.raises(SystemExit):
        build_parser().parse_args(["--exercise", "other"])


def test_the_class_is_opt_in(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Without --class (or a class option) no gradebook is opened and no name is asked; with
    --class the default gradebook path is used."""
    import tcp_pendant.serve.server as server

    seen: list[object] = []

    class Stop(Exception):
        pass

    class FakeApp:
        def __init__(self, config: object) -> None:
            seen.append(config)
            raise Stop

    monkeypatch.setattr(server, "PendantApp", FakeApp)
    import tcp_pendant.classroom.gradebook_open as gb

    monkeypatch.setattr(gb, "default_gradebook_path", lambda: tmp_path / "data" / "class.sqlite3")
    for argv in (["--port", "0"], ["--port", "0", "--class"], ["--port", "0", "--exercise", "mystery"]):
        with pytest.raises(Stop):
            main(argv)
    assert [c.class_db for c in seen] == [None, tmp_path / "data" / "class.sqlite3",
                                          tmp_path / "data" / "class.sqlite3"]
    assert seen[2].exercise == "mystery"


def test_the_exercise_seed_is_the_classs_unless_given_and_never_printed(tmp_path: Path) -> None:
    """No --exercise-seed: None (the gradebook's secret seed); the ready message shows the
    gradebook and the trainer address but not the seed."""
    from types import SimpleNamespace

    from tcp_pendant.classroom.class_room import ClassRoom
    from tcp_pendant.serve.cli import _class_lines

    assert build_parser().parse_args(["--exercise", "mystery"]).exercise_seed is None
    with Gradebook(tmp_path / "class.sqlite3") as book:
        room = ClassRoom(book, {}, trainer_token="trainer-tok-12345678", exercise="mystery")
        seed = room._seed()
        assert seed == book.settings.exercise_seed() and seed.bit_length() > 20
        lines = _class_lines(SimpleNamespace(classroom=room, url="http://127.0.0.1:1",
                                             trainer_url="http://127.0.0.1:1/?trainer=tok-12345678"))
        assert "class gradebook" in lines and str(seed) not in lines
        assert ClassRoom(book, {}, trainer_token="trainer-tok-12345678", exercise_seed=7)._seed() == 7   # a demo's
        assert book.settings.exercise_seed() == seed                                          # kept


def test_server_with_an_unreachable_postgresql_gradebook_says_so_without_the_password(
        tmp_path: Path, postgres_server, capsys: pytest.CaptureFixture[str]) -> None:
    url = postgres_server.url("no_such_class")
    assert main(["--port", "0", "--tool-library", str(tmp_path / "t.json"), "--class-db", url]) == 2
    err = capsys.readouterr().err
    assert postgres_server.password not in err
    note, error = err.strip().splitlines()
    assert note.startswith("tcp-pendant: note: a password in the --class-db URL shows in the process list")
    assert error.startswith("tcp-pendant: error: Cannot reach the PostgreSQL gradebook "
                            f"postgresql://{postgres_server.user}:***@127.0.0.1:{postgres_server.port}/no_such_class")
    assert 'database "no_such_class" does not exist' in error
    assert build_parser().parse_args(["--class-db", url]).class_db == url      # a URL stays a URL


def test_the_ready_message_names_a_postgresql_gradebook_without_its_password(postgres_server) -> None:
    from types import SimpleNamespace

    from tcp_pendant.classroom.class_room import ClassRoom
    from tcp_pendant.classroom.gradebook_db import mask_url
    from tcp_pendant.serve.cli import _class_lines

    url = postgres_server.fresh_schema()
    with Gradebook(url) as book:
        room = ClassRoom(book, {}, trainer_token="trainer-tok-12345678")
        lines = _class_lines(SimpleNamespace(classroom=room, url="http://127.0.0.1:1",
                                             trainer_url="http://127.0.0.1:1/?trainer=tok-12345678"))
    assert f"  class gradebook {mask_url(url)} (free practice)\n" in lines
    assert ":***@" in lines and postgres_server.password not in lines
