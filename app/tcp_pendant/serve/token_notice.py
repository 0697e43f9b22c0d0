"""What the server's terminal says about the trainer token: its first :data:`SHOWN_CHARS`
characters and where to read the whole token, never the token itself (the terminal is often
the projected screen), unless ``tcp-pendant --print-token``.

Where the token comes from (:func:`token_source`): ``--trainer-token`` (the trainer typed it),
``--trainer-token-file PATH`` (read it there), ``$TCP_PENDANT_TRAINER_TOKEN`` (the server's
environment) or, when none gives one, a random token that the server writes to a file the
trainer can read (:func:`keep_random_token`: next to an SQLite gradebook, ``<gradebook>.trainer-token``,
else in the user's data directory; owner-only permissions). That file's first line is the
token, so ``--trainer-token-file`` reads it next time; its second line is the trainer's
address with the token (``/?trainer=TOKEN``).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import platformdirs

from tcp_pendant.classroom.trainer_token import TOKEN_ENV

__all__ = ["SHOWN_CHARS", "TOKEN_FILE_SUFFIX", "class_lines", "keep_random_token", "masked", "token_file_for",
           "token_source"]

SHOWN_CHARS = 4
"""How many of the token's first characters the terminal shows."""
TOKEN_FILE_SUFFIX = ".trainer-token"
"""A random token's file: the SQLite gradebook's path with this added."""


def token_source(option: str | None, file: Path | None, environ: Mapping[str, str]) -> str:
    """Where the trainer token came from, in words for the terminal ("" none: a random one),
    in the order ``resolve_trainer_token`` picks it."""
    if option is not None:
        return "the --trainer-token you gave"
    if file is not None:
        return f"read it in {file}"
    if environ.get(TOKEN_ENV):
        return f"read it in the environment variable {TOKEN_ENV}"
    return ""


def masked(token: str) -> str:
    """The token's first :data:`SHOWN_CHARS` characters and an ellipsis."""
    return f"{token[:SHOWN_CHARS]}…"


def token_file_for(gradebook_path: Path | None) -> Path:
    """Where a random token is kept: next to an SQLite gradebook, else (PostgreSQL) in the
    user's data directory."""
    if gradebook_path is not None:
        return gradebook_path.with_name(gradebook_path.name + TOKEN_FILE_SUFFIX)
    return Path(platformdirs.user_data_dir("tcp-pendant", appauthor=False)) / "trainer-token"


def keep_random_token(token: str, trainer_url: str | None, path: Path) -> None:
    """Write ``token`` (first line) and the trainer's address (second line) to ``path``, readable
    by its owner only (mode 0600, also when the file was there).

    Raises:
        OSError: the file cannot be written.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        f.write(token + "\n" + (trainer_url or "") + "\n")
    os.chmod(path, 0o600)


def class_lines(app: Any, source: str = "", print_token: bool = False) -> str:
    """The classroom lines of the ready message (empty without a gradebook): the gradebook and
    the trainer view, with the token masked and where to read it (module docstring), or whole
    with ``print_token``. The page to type the token in is ``/?trainer`` (a trainee's welcome
    window has no trainer-token field)."""
    room = getattr(app, "classroom", None)
    if room is None:
        return ""
    trainer_page = f"{str(app.url).rstrip('/')}/?trainer"
    exercise = "mystery tools" if room.exercise == "mystery" else "free practice"
    head = f"  class gradebook {room.gradebook.location} ({exercise})\n"
    if room.trainer_token is None:
        kept = token_file_for(room.gradebook.path)
        where = f" ({source})" if source else f" (a random one is in {kept})" if kept.exists() else ""
        return (head + f"Trainer view: {trainer_page} with the trainer token this class began with{where}; kept hashed in "
                "the gradebook, so an open trainer page reconnects; give --trainer-token-file to set a new one\n")
    token = room.trainer_token
    if print_token:
        return (head + f"Trainer view: {app.trainer_url}  trainer token: {token}\n"
                "  (open that address: the page fills in the token and drops it from the address bar; or open "
                f"{trainer_page} and type the token in \"Trainer token\" of the welcome window; keep both secret)\n")
    if not source:
        path = token_file_for(room.gradebook.path)
        try:
            keep_random_token(token, app.trainer_url, path)
            source = f"a random one: read it, and the trainer address, in {path}"
        except OSError as exc:
            source = f"a random one that could not be written to {path} ({exc}); restart with --print-token"
    return (head + f"Trainer view: {trainer_page}  trainer token {masked(token)} ({source})\n"
            "  (open that page and type the token in \"Trainer token\" of the welcome window, or open the trainer "
            "address /?trainer=TOKEN; the token is not shown here: --print-token shows it; keep it secret)\n")
