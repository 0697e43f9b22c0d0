"""The server's terminal (often the projected screen) shows the trainer token's first 4
characters and where to read it, never the whole token, unless ``--print-token``."""

from __future__ import annotations

import stat
from pathlib import Path
from types import SimpleNamespace

import pytest

from tcp_pendant.classroom.class_room import ClassRoom
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.trainer_token import TOKEN_ENV, resolve_trainer_token
from tcp_pendant.serve.cli import _class_lines, build_parser
from tcp_pendant.serve.token_notice import token_source

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

URL = "http://127.0.0.1:8080"


def _app(room: ClassRoom) -> SimpleNamespace:
    token = room.trainer_token
    return SimpleNamespace(classroom=room, url=URL, trainer_url=None if token is None else f"{URL}/?trainer={token}")


def test_a_random_token_is_written_to_a_file_for_the_trainer_and_shown_masked(tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    with Gradebook(db) as book:
        room = ClassRoom(book, {}, trainer_token=None)
        token = room.trainer_token
        assert token is not None and len(token) >= 16
        lines = _class_lines(_app(room), token_source(None, None, {}))
    kept = tmp_path / "class.sqlite3.trainer-token"
    assert token not in lines and f"trainer token {token[:4]}… (a random one: read it, and the trainer address, " \
        f"in {kept})" in lines
    assert "--print-token" in lines
    assert kept.read_text().splitlines() == [token, f"{URL}/?trainer={token}"]
    assert stat.S_IMODE(kept.stat().st_mode) == 0o600                       # the owner's only
    assert resolve_trainer_token(None, kept, {}) == token                   # --trainer-token-file reads it next time
    with Gradebook(db) as book:                                              # a restart without a token
        room = ClassRoom(book, {}, trainer_token=None)
        assert room.trainer_token is None
        again = _class_lines(_app(room), token_source(None, None, {}))
    assert f"(a random one is in {kept})" in again and token not in again


def test_a_given_token_is_masked_with_where_to_read_it_unless_print_token(tmp_path: Path) -> None:
    token = "Zq9!-the-trainers-own-token"
    with Gradebook(tmp_path / "class.sqlite3") as book:
        room = ClassRoom(book, {}, trainer_token=token)
        app = _app(room)
        for source, words in ((token_source(None, tmp_path / "tok.txt", {}), f"read it in {tmp_path / 'tok.txt'}"),
                              (token_source(None, None, {TOKEN_ENV: token}),
                               f"read it in the environment variable {TOKEN_ENV}"),
                              (token_source(token, None, {}), "the --trainer-token you gave")):
            lines = _class_lines(app, source)
            assert f"trainer token Zq9!… ({words})" in lines and token not in lines and "?trainer=" + token not in lines
        shown = _class_lines(app, token_source(token, None, {}), print_token=True)
    assert f"Trainer view: {URL}/?trainer={token}  trainer token: {token}\n" in shown
    assert not (tmp_path / "class.sqlite3.trainer-token").exists()            # a given token is not written anywhere


def test_print_token_is_an_option_of_tcp_pendant() -> None:
    assert build_parser().parse_args(["--print-token"]).print_token is True
    assert build_parser().parse_args([]).print_token is False
    assert "--print-token" in build_parser().format_help()
