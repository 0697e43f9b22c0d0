"""The class's trainees in the gradebook: their names, and which browser holds each name.

A browser joins under a name (:meth:`Trainees.join`) and gets a browser key, kept by that
browser and shown to nobody else; only its SHA-256 is stored (``trainees.key_sha256``). The
same browser proves itself with the key after a reload or a server restart; the trainer's
"Release" forgets the key, so the next browser that joins under the name gets the trainee's
records. Names are validated and compared for look-alikes by :mod:`tcp_pendant.classroom.names`.

PostgreSQL: the writes that read names first hold the advisory lock "trainee names".
"""

from __future__ import annotations

import hashlib
import secrets
from dataclasses import dataclass

from tcp_pendant.classroom.gradebook_store import GradebookError, GradebookStore
from tcp_pendant.classroom.gradebook_values import utc_now
from tcp_pendant.classroom.names import TraineeNameError, looks_alike, validate_trainee_name
from tcp_pendant.translation import N_

__all__ = ["BROWSER_KEY_BYTES", "MAX_BROWSER_KEY_CHARS", "TraineeJoin", "Trainees"]

BROWSER_KEY_BYTES = 32
"""Random bytes of a browser key (``secrets.token_urlsafe``: 43 characters)."""
MAX_BROWSER_KEY_CHARS = 200
"""A longer "key" from a browser is not looked at."""
_KEY_CHARS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_")


@dataclass(frozen=True)
class TraineeJoin:
    """A browser accepted under a trainee's name (:meth:`Trainees.join`).

    Attributes:
        trainee_id: the trainee's id (the same on every return of the same browser).
        name: the name as stored.
        new_key: the browser key issued now, to be kept by that browser and shown to nobody
            else; None when the browser proved itself with the key it already had.
    """

    trainee_id: int
    name: str
    new_key: str | None


def _key_digest(key: str) -> str:
    # A browser key is 256 random bits, so a plain SHA-256 keeps it as safe as a slow password
    # hash would: there is no dictionary to try.
    return hashlib.sha256(key.encode("utf-8")).hexdigest()


def _clean_key(key: object) -> str | None:
    """The browser key a browser sent, or None (none, or not the shape of a key we issue)."""
    if not isinstance(key, str):
        return None
    key = key.strip()
    if not key or len(key) > MAX_BROWSER_KEY_CHARS or not set(key) <= _KEY_CHARS:
        return None
    return key


class Trainees:
    """The trainees of the gradebook behind ``store`` (see the module docstring)."""

    def __init__(self, store: GradebookStore) -> None:
        self._store = store

    def add(self, name: str) -> int:
        """The id of the trainee called ``name``, added if new (a reconnect with the same name
        gets the same id).

        Raises:
            GradebookError: the name is refused (``TraineeNameError``'s words: why, what to type).
        """
        try:
            clean = validate_trainee_name(name)
        except TraineeNameError as exc:
            raise GradebookError(str(exc)) from exc
        with self._store.write() as db:
            db.serialize("trainee names")
            row = db.execute("SELECT id FROM trainees WHERE name = ?", (clean,)).fetchone()
            if row is not None:
                return int(row[0])
            return db.insert("INSERT INTO trainees (name, created_at) VALUES (?, ?)", (clean, utc_now()))

    def join(self, name: str, key: object = None) -> TraineeJoin:
        """A browser joins the class as ``name``, showing the browser key it kept (or none).

        - A name no trainee has: refused if it looks like one (``names.looks_alike``: the words
          name the existing name); otherwise the trainee is added with a new browser key.
        - A trainee's name whose key is held by a browser: accepted only with that key (the same
          browser after a reload or a server restart); otherwise refused.
        - A trainee's name no browser holds (released by the trainer, or from a version 1
          file): accepted, with a new browser key.

        Args:
            name: what the browser typed (validated and normalised here).
            key: the browser key the browser kept, or None; anything that is not a key we issue
                counts as none.

        Returns:
            The trainee and, when one was issued, the new key (only its SHA-256 is stored).

        Raises:
            TraineeNameError: the name is refused; the message says why and what to do.
        """
        clean = validate_trainee_name(name)
        shown = _clean_key(key)
        with self._store.write() as db:
            db.serialize("trainee names")        # the look-alike check reads every name
            row = db.execute("SELECT id, key_sha256 FROM trainees WHERE name = ?", (clean,)).fetchone()
            if row is not None:
                tid, digest = int(row[0]), row[1]
                if digest is not None:
                    if shown is None or not secrets.compare_digest(_key_digest(shown), str(digest)):
                        raise TraineeNameError(
                            N_("{name} is already a trainee of this class, joined from another browser; "
                               "use that browser, or ask the trainer to release the name; if you are "
                               "someone else, pick another name."), name=clean)
                    return TraineeJoin(tid, clean, None)
                new_key = secrets.token_urlsafe(BROWSER_KEY_BYTES)
                db.execute("UPDATE trainees SET key_sha256 = ? WHERE id = ?", (_key_digest(new_key), tid))
                return TraineeJoin(tid, clean, new_key)
            for (other,) in db.execute("SELECT name FROM trainees"):
                if looks_alike(clean, other):
                    raise TraineeNameError(
                        N_("{name} looks like {other}, a name already in this class: if you are "
                           "{other}, type your name exactly as before; otherwise pick a name that "
                           "looks different (add an initial or your surname)."), name=clean, other=other)
            new_key = secrets.token_urlsafe(BROWSER_KEY_BYTES)
            tid = db.insert("INSERT INTO trainees (name, created_at, key_sha256) VALUES (?, ?, ?)",
                            (clean, utc_now(), _key_digest(new_key)))
            return TraineeJoin(tid, clean, new_key)

    def holds_key(self, name: str, key: object) -> bool:
        """Whether ``key`` is the browser key of the trainee called ``name`` (False: no such
        trainee, no key held, or another key)."""
        shown = _clean_key(key)
        if shown is None or not isinstance(name, str):
            return False
        with self._store.read() as db:
            row = db.execute("SELECT key_sha256 FROM trainees WHERE name = ?", (name,)).fetchone()
        return row is not None and row[0] is not None and secrets.compare_digest(_key_digest(shown), str(row[0]))

    def release(self, name: str) -> bool:
        """Forget the browser key of the trainee called ``name`` (the trainer's "Release"): the
        next browser that joins under the name gets the trainee's records. Returns whether a
        key was held."""
        with self._store.write() as db:
            return db.execute("UPDATE trainees SET key_sha256 = NULL WHERE name = ? AND key_sha256 IS NOT NULL",
                              (name,)).rowcount > 0

    def names(self) -> list[str]:
        """Every trainee's name, in the order they first joined."""
        with self._store.read() as db:
            return [str(r[0]) for r in db.execute("SELECT name FROM trainees ORDER BY id")]

    def held_names(self) -> list[str]:
        """Names whose browser key a browser holds, sorted (the names a trainer can release)."""
        with self._store.read() as db:
            names = [str(r[0]) for r in db.execute("SELECT name FROM trainees WHERE key_sha256 IS NOT NULL")]
        return sorted(names)              # code point order on every backend (not the server's collation)
