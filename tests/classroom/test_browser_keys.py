"""Names kept for the browser that joined under them (browser keys, hashed in the gradebook),
look-alike names refused, the class's secret exercise seed, and a version 1 gradebook brought to
version 2 when it is opened."""

from __future__ import annotations

import hashlib
import sqlite3
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.gradebook_schema import SCHEMA_VERSION
from tcp_pendant.classroom.gradebook_store import GradebookError
from tcp_pendant.classroom.grades_csv import to_csv
from tcp_pendant.classroom.names import TraineeNameError


@pytest.fixture
def book(gradebook_target: Path | str) -> Gradebook:
    """A new gradebook, once as an SQLite file and once in PostgreSQL (tests/conftest.py)."""
    with Gradebook(gradebook_target) as g:
        yield g


def test_a_name_is_kept_for_the_browser_that_joined_under_it(book: Gradebook) -> None:
    first = book.trainees.join("Alice")
    assert first.name == "Alice" and first.new_key is not None and len(first.new_key) >= 43
    # another browser (no key, a wrong key, a key-shaped guess) is refused, in words
    for key in (None, "", "x" * 43, first.new_key[:-1] + ("A" if first.new_key[-1] != "A" else "B"), 7):
        with pytest.raises(TraineeNameError, match="Alice is already a trainee of this class, joined from "
                                                   "another browser.*ask the trainer to release"):
            book.trainees.join("Alice", key)
    # the same browser (its key): the same trainee, no new key
    again = book.trainees.join("  Alice ", first.new_key)
    assert (again.trainee_id, again.name, again.new_key) == (first.trainee_id, "Alice", None)
    assert book.trainees.holds_key("Alice", first.new_key) and not book.trainees.holds_key("Alice", "nope")
    assert book.trainees.held_names() == ["Alice"]


def test_only_a_hash_of_the_key_is_stored(tmp_path: Path) -> None:
    path = tmp_path / "class.sqlite3"
    with Gradebook(path) as g:
        key = g.trainees.join("Bo").new_key
    assert key is not None
    with sqlite3.connect(path) as db:
        stored = db.execute("SELECT key_sha256 FROM trainees WHERE name = 'Bo'").fetchone()[0]
        dump = "\n".join(db.iterdump())
    assert stored == hashlib.sha256(key.encode()).hexdigest()
    assert key not in dump


def test_released_names_go_to_the_next_browser(book: Gradebook) -> None:
    old = book.trainees.join("Alice").new_key
    assert book.trainees.release("Alice") is True
    assert book.trainees.held_names() == [] and not book.trainees.holds_key("Alice", old)
    new = book.trainees.join("Alice")                     # another browser, no key
    assert new.new_key is not None and new.new_key != old
    with pytest.raises(TraineeNameError, match="joined from another browser"):
        book.trainees.join("Alice", old)                  # the released browser's key no longer works
    assert book.trainees.release("Nobody") is False


@pytest.mark.parametrize("look_alike", ["\u0410lice", "ＡＬＩＣＥ", "A\u013aice", "alice"])
def test_a_look_alike_of_a_name_in_the_class_is_refused_naming_it(book: Gradebook, look_alike: str) -> None:
    book.trainees.join("Alice")
    with pytest.raises(TraineeNameError) as info:
        book.trainees.join(look_alike)
    assert str(info.value).startswith(f"{look_alike} looks like Alice, a name already in this class")
    assert "pick a name that looks different" in str(info.value)
    with book.store.read() as db:
        assert [r[0] for r in db.execute("SELECT name FROM trainees")] == ["Alice"]
    assert book.trainees.join("Alice B.").new_key is not None         # a different name is fine


INVISIBLE_ALICES = ["Alice\ufe0f", "Al\ufe00ice", "Al\U000e0100ice", "Alice\u180b", "Alice\u17b4", "Al\u17b5ice"]
"""Issue 42: "Alice" with a default-ignorable code point that draws nothing (names.py)."""


@pytest.mark.parametrize("invisible", INVISIBLE_ALICES)
def test_alice_with_an_invisible_mark_is_refused_while_alice_is_in_the_class(book: Gradebook,
                                                                             invisible: str) -> None:
    book.trainees.join("Alice")
    with pytest.raises(TraineeNameError, match=f"U\\+{ord(next(c for c in invisible if c not in 'Alice')):04X}"):
        book.trainees.join(invisible)
    with pytest.raises(GradebookError, match="invisible"):
        book.trainees.add(invisible)
    assert book.trainees.names() == ["Alice"]


@pytest.mark.parametrize("stored", INVISIBLE_ALICES)
def test_a_name_with_an_invisible_mark_kept_in_the_book_blocks_its_look_alikes(book: Gradebook,
                                                                              stored: str) -> None:
    """A gradebook written before the default-ignorables were refused may hold such a name:
    the comparison reads the stored names and drops the marks, so "Alice" looks like it."""
    with book.store.write() as db:
        db.insert("INSERT INTO trainees (name, created_at, key_sha256) VALUES (?, ?, ?)",
                  (stored, "2025-01-01T00:00:00Z", "0" * 64))
    with pytest.raises(TraineeNameError, match=f"^Alice looks like {stored}, a name already in this class"):
        book.trainees.join("Alice")
    assert book.trainees.names() == [stored]


def test_a_joiner_kept_in_a_name_does_not_make_a_second_trainee(book: Gradebook) -> None:
    """Persian "Ali-Akbar" with and without the zero-width non-joiner (kept in a name where
    it breaks a cursive join, dropped when names are compared)."""
    joined, bare = "\u0639\u0644\u06cc\u200c\u0627\u06a9\u0628\u0631", "\u0639\u0644\u06cc\u0627\u06a9\u0628\u0631"
    assert book.trainees.join(joined).name == joined
    with pytest.raises(TraineeNameError, match=f"^{bare} looks like {joined}, a name already in this class"):
        book.trainees.join(bare)
    assert book.trainees.names() == [joined]


def test_the_exercise_seed_is_random_per_class_and_kept(tmp_path: Path) -> None:
    with Gradebook(tmp_path / "a.sqlite3") as a, Gradebook(tmp_path / "b.sqlite3") as b:
        seed_a, seed_b = a.settings.exercise_seed(), b.settings.exercise_seed()
        assert seed_a != seed_b and seed_a >= 0 and seed_a.bit_length() > 20     # not 0, not small
        assert a.settings.exercise_seed() == seed_a
        a.trainees.join("Anna")
        assert str(seed_a) not in to_csv(a.grades.rows())
    with Gradebook(tmp_path / "a.sqlite3") as again:                # a restart with the same file
        assert again.settings.exercise_seed() == seed_a


def _version_1_file(path: Path) -> None:
    """A gradebook as version 1 wrote it: no browser keys in ``trainees``."""
    with Gradebook(path) as g:
        sid = g.records.start_session(g.trainees.add("Anna"), "per-browser")
        cid = g.records.start_calibration(sid, "xyz4", "pointer", np.eye(4))
        g.records.finish_calibration(cid, {}, position_error_mm=0.2, orientation_error_deg=None, grade="good")
    with sqlite3.connect(path) as db:
        db.execute("ALTER TABLE trainees DROP COLUMN key_sha256")
        db.execute("UPDATE meta SET value = '1' WHERE key = 'schema_version'")
    db.close()


def test_a_version_1_gradebook_still_opens_and_keeps_its_records(tmp_path: Path) -> None:
    path = tmp_path / "class.sqlite3"
    _version_1_file(path)
    with Gradebook(path) as g:
        (row,) = g.grades.rows()
        assert (row.trainee, row.grade) == ("Anna", "good")
        with g.store.read() as db:
            assert dict(db.execute("SELECT key, value FROM meta"))["schema_version"] == str(SCHEMA_VERSION) == "2"
        claim = g.trainees.join("Anna")              # a trainee of a version 1 file: no browser holds it yet
        assert claim.new_key is not None and claim.trainee_id == g.trainees.add("Anna")
    with Gradebook(path) as g:                       # opened again: nothing to migrate, the key kept
        assert g.trainees.holds_key("Anna", claim.new_key)
