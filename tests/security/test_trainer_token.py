"""The trainer token cannot be guessed at speed: it has at least 16 characters, it can be given
without showing in the process list (a file or an environment variable), and a browser that
types wrong tokens is locked out after five for a window that doubles, logged with no more than
a two-character prefix of each guess."""

from __future__ import annotations

import logging
import math
import os
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.trainer_token import (
    TOKEN_ENV,
    TrainerTokenError,
    TrainerTokenLocked,
    lock_s,
    locked,
    resolve_trainer_token,
)
from tcp_pendant.serve.cli import main
from tcp_pendant.serve.server import PendantApp

from support.wsclient import InputsClient, wait_until

TOKEN = "the-trainers-own-token"


@pytest.mark.parametrize("token", ["abcdefgh", "fifteen-chars!!", "x" * 201, "sixteen\tcharacters"])
def test_a_short_or_unprintable_trainer_token_is_refused_with_exit_2(token: str, capsys) -> None:
    assert main(["--port", "0", "--trainer-token", token]) == 2
    assert "--trainer-token must be 16 to 200 printable characters" in capsys.readouterr().err


def test_the_token_comes_from_the_option_the_file_or_the_environment(tmp_path: Path) -> None:
    f = tmp_path / "token.txt"
    f.write_text(TOKEN + "\nsecond line\n")
    assert resolve_trainer_token(None, f, {}) == TOKEN
    assert resolve_trainer_token(None, None, {TOKEN_ENV: TOKEN}) == TOKEN
    assert resolve_trainer_token("an-option-token-16", None, {TOKEN_ENV: TOKEN}) == "an-option-token-16"
    assert resolve_trainer_token(None, None, {}) is None
    with pytest.raises(TrainerTokenError, match="not both"):
        resolve_trainer_token(TOKEN, f, {})
    with pytest.raises(TrainerTokenError, match=f"{TOKEN_ENV} must be 16 to 200"):
        resolve_trainer_token(None, None, {TOKEN_ENV: "short"})
    with pytest.raises(TrainerTokenError, match="cannot read --trainer-token-file"):
        resolve_trainer_token(None, tmp_path / "missing.txt", {})


@pytest.mark.parametrize("how", ["file", "environment"])
def test_a_token_from_a_file_or_the_environment_is_not_in_the_process_list(tmp_path: Path, how: str) -> None:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path("src").resolve()), str(Path("app").resolve())]))
    args = [sys.executable, "-m", "tcp_pendant", "--port", "0", "--tool-library", str(tmp_path / "t.json"),
            "--class-db", str(tmp_path / "class.sqlite3")]
    if how == "file":
        (tmp_path / "token").write_text(TOKEN + "\n")
        args += ["--trainer-token-file", str(tmp_path / "token")]
    else:
        env[TOKEN_ENV] = TOKEN
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        lines = []
        for line in proc.stdout:                             # type: ignore[union-attr]
            lines.append(line)
            if line.startswith("Trainer view:"):
                break
        where = f"read it in {tmp_path / 'token'}" if how == "file" else f"read it in the environment variable {TOKEN_ENV}"
        assert f"trainer token {TOKEN[:4]}… ({where})" in "".join(lines), "".join(lines)
        assert TOKEN not in "".join(lines)                   # only its first 4 characters
        cmdline = Path(f"/proc/{proc.pid}/cmdline").read_bytes()
        assert TOKEN.encode() not in cmdline and b"tcp_pendant" in cmdline
    finally:
        proc.terminate()
        proc.wait(timeout=30)


def test_the_lockout_doubles_from_the_fifth_wrong_token_up_to_five_minutes(tmp_path: Path) -> None:
    assert [lock_s(n) for n in range(1, 16)] == [0, 0, 0, 0, 1, 2, 4, 8, 16, 32, 64, 128, 256, 300, 300]
    with Gradebook(tmp_path / "class.sqlite3") as book:      # the count the app keeps (never forgotten here)
        def attempt(now: float) -> tuple[float, int, bool]:
            return book.token_failures.try_token("10.0.0.5", now=now, forget_s=math.inf, lock_s=lock_s)

        for i in range(15):                                  # each try after the previous window
            assert attempt(1000.0 * i) == (0.0, i + 1, True)
        wait, failures, counted = attempt(14_000.0)          # the 15th's window: 300 s
        assert (wait, failures, counted) == (300.0, 15, False)
        with pytest.raises(TrainerTokenLocked, match=r"try again in 300 s\."):
            raise locked(wait)
        assert attempt(14_299.0) == (1.0, 15, False)
        assert attempt(14_300.0) == (0.0, 16, True)


@pytest.fixture
def app(app_factory: Callable[..., PendantApp], tmp_path: Path) -> PendantApp:
    return app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN)


def test_guessing_over_a_websocket_is_locked_out_after_five_and_logged_short(app: PendantApp, caplog) -> None:
    now = [100.0]
    assert app.classroom is not None
    app.classroom.clock = lambda: now[0]
    c = InputsClient(app.port)
    try:
        wait_until(lambda: {"Trainer token", "Open trainer view", "X +"} <= c.labels(), what="the welcome window")
        wait_until(lambda: len(app.sessions) == 1, what="the session")
        (session,) = app.sessions.values()
        moves: list[int] = []
        session.add_motion_listener(lambda: moves.append(1))

        def try_token(token: str) -> None:
            c.send({"type": "GuiUpdateMessage", "uuid": c.uuid_of("Trainer token"), "updates": {"value": token}})
            c.send({"type": "GuiUpdateMessage", "uuid": c.uuid_of("Open trainer view"), "updates": {"value": True}})

        guesses = [f"guess-{i:03d}-abcdefghijkl" for i in range(20)]
        with caplog.at_level(logging.WARNING):
            for g in guesses:
                try_token(g)
            try_token(TOKEN)                                 # the right one, inside the window
            c.send({"type": "GuiUpdateMessage", "uuid": c.uuid_of("X +"), "updates": {"value": True}})
            wait_until(lambda: len(moves) > 0, what="a jog behind the guesses")
        wrong = [r.getMessage() for r in caplog.records if r.getMessage().startswith("wrong trainer token")]
        assert len(wrong) == 5                               # the other 15 and the right one were not tried
        assert wrong[0] == "wrong trainer token from browser 0 (try 1, 22 characters, 'gu...')"
        assert any("typed 5 wrong tokens; no token is tried from it for 1 s" in r.getMessage() for r in caplog.records)
        assert not any(g in caplog.text for g in guesses) and TOKEN not in caplog.text
        assert app.classroom.dashboards.views == {}
        assert session.views["identity"].message.content.startswith(     # (markdown-escaped)
            "⚠ Too many wrong trainer tokens from this browser: try again in 1 s")
        now[0] += 1.5                                        # the window has passed
        try_token(TOKEN)
        wait_until(lambda: len(app.classroom.dashboards.views) == 1, what="the trainer view")
    finally:
        c.ws.close()


def test_a_bad_environment_token_is_refused_for_a_class(tmp_path: Path, monkeypatch, capsys) -> None:
    monkeypatch.setenv(TOKEN_ENV, "short")
    assert main(["--port", "0", "--class", "--class-db", str(tmp_path / "c.sqlite3")]) == 2
    assert f"{TOKEN_ENV} must be 16 to 200 printable characters" in capsys.readouterr().err
