"""What the server processes of one class share through the gradebook besides names and pushes:
the wrong trainer tokens per source address, the trainer's messages until each trainee dismisses
them, and who left. Each test opens two connections to one gradebook (two server processes), on
SQLite and on PostgreSQL (``gradebook_target``, tests/conftest.py)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.trainer_token import FORGET_S, lock_s


@pytest.fixture
def pair(gradebook_target: Path | str) -> Iterator[tuple[Gradebook, Gradebook]]:
    a, b = Gradebook(gradebook_target), Gradebook(gradebook_target)
    try:
        yield a, b
    finally:
        a.close()
        b.close()


def _try(book: Gradebook, source: str, now: float) -> tuple[float, int, bool]:
    return book.token_failures.try_token(source, now=now, forget_s=FORGET_S, lock_s=lock_s)


def test_wrong_tokens_are_counted_per_address_on_every_connection_and_survive_a_reopen(
        pair: tuple[Gradebook, Gradebook], gradebook_target: Path | str) -> None:
    a, b = pair
    for i in range(4):                                   # alternately on the two processes
        assert _try((a, b)[i % 2], "10.0.0.5", 1000.0 + i) == (0.0, i + 1, True)
    assert _try(a, "10.0.0.5", 1004.0) == (0.0, 5, True)          # the 5th: 1 s lock from 1004
    assert _try(b, "10.0.0.5", 1004.5) == (0.5, 5, False)         # on the other process too, not counted
    assert _try(b, "10.0.0.6", 1004.5) == (0.0, 1, True)          # another address has its own count
    assert _try(b, "10.0.0.5", 1005.0) == (0.0, 6, True)          # the window passed: 6th, 2 s
    with Gradebook(gradebook_target) as again:                    # a restart keeps the count
        wait, n, counted = _try(again, "10.0.0.5", 1006.25)
        assert (round(wait, 6), n, counted) == (0.75, 6, False)
    assert a.token_failures.forgive("10.0.0.5") == 6              # the right token came
    assert _try(b, "10.0.0.5", 1006.5) == (0.0, 1, True)
    # an hour later the old failures are forgotten, and their rows deleted
    later = 1006.5 + FORGET_S + 1.0
    assert _try(a, "10.0.0.6", later) == (0.0, 1, True)
    with a.store.read() as db:
        assert db.execute("SELECT source, failed_at FROM token_failures").fetchall() == [("10.0.0.6", later)]


def test_messages_are_kept_per_trainee_until_that_trainee_dismisses_them(pair: tuple[Gradebook, Gradebook]) -> None:
    a, b = pair
    text = "Stop *now* <b>please</b>\nline two"
    to_all = a.messages.add(text, ["Anna", "Ben"], to_all=True, sent_at="2026-12-02T09:30:00Z")
    to_ben = a.messages.add("Ben only", ["Ben"], to_all=False, sent_at="2026-12-02T09:31:00Z")
    assert set(to_all) == {"Anna", "Ben"} and to_all["Anna"] != to_all["Ben"]
    assert b.messages.waiting(["Anna", "Ben", "Cleo"]) == {
        "Anna": [(to_all["Anna"], True, "2026-12-02T09:30:00Z", text)],
        "Ben": [(to_all["Ben"], True, "2026-12-02T09:30:00Z", text),
                (to_ben["Ben"], False, "2026-12-02T09:31:00Z", "Ben only")]}
    assert b.messages.dismiss("Anna", [to_ben["Ben"]]) == 0       # another trainee's id: nothing
    assert b.messages.dismiss("Anna", [to_all["Anna"]]) == 1      # Anna's copy only
    assert a.messages.waiting(["Anna"]) == {}
    assert [m[0] for m in a.messages.waiting(["Ben"])["Ben"]] == [to_all["Ben"], to_ben["Ben"]]
    ids = [b.messages.add(f"note {i}", ["Cleo"], to_all=False, sent_at="2026-12-02T09:40:00Z")["Cleo"]
           for i in range(12)]
    assert [m[3] for m in a.messages.waiting(["Cleo"])["Cleo"]] == [f"note {i}" for i in range(2, 12)]  # at most 10
    assert [m[0] for m in a.messages.waiting(["Cleo"])["Cleo"]] == ids[2:]
    assert a.messages.waiting([]) == {}


def test_who_left_is_the_same_on_every_connection(pair: tuple[Gradebook, Gradebook]) -> None:
    a, b = pair
    a.presence.claim("Anna", "A", {"name": "Anna", "touches": 1}, now=100.0)
    b.presence.claim("Ben", "B", {"name": "Ben", "touches": 2}, now=100.0)
    assert b.presence.departed(now=101.0) == []
    assert a.presence.drop("Anna", "A")
    a.presence.depart("Anna", {"name": "Anna", "connected": True, "touches": 3}, now=101.0)
    assert b.presence.departed(now=102.0) == [("Anna", {"name": "Anna", "connected": False, "touches": 3})]
    # B is killed: its trainee counts as gone with the row it last beat, after the stale time
    assert a.presence.departed(now=120.0) == [("Anna", {"name": "Anna", "connected": False, "touches": 3}),
                                              ("Ben", {"name": "Ben", "connected": False, "touches": 2})]
    # Anna connected again (on B): not among those who left any more; a later leave replaces her row
    b.presence.claim("Anna", "B2", {"name": "Anna"}, now=121.0)
    assert [name for name, _ in a.presence.departed(now=122.0)] == ["Ben"]
    b.presence.drop("Anna")
    b.presence.depart("Anna", {"name": "Anna", "touches": 5}, now=123.0)
    assert a.presence.departed(now=124.0)[0] == ("Anna", {"name": "Anna", "connected": False, "touches": 5})
