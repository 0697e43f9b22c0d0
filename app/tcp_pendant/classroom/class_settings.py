"""What the class keeps across restarts of the server, in the gradebook's ``meta`` table: the
exercise seed (key ``exercise_seed``) and the class settings (keys ``class:<name>``, JSON
values: the pushed exercise, the distance-aid lock, the trainer token's hash)."""

from __future__ import annotations

import json
import secrets
from typing import Any

from tcp_pendant.classroom.gradebook_store import GradebookStore
from tcp_pendant.classroom.gradebook_values import label

__all__ = ["ClassSettings"]


class ClassSettings:
    """The kept settings of the gradebook behind ``store`` (see the module docstring)."""

    def __init__(self, store: GradebookStore) -> None:
        self._store = store

    def exercise_seed(self) -> int:
        """The class's exercise seed: drawn with ``secrets`` the first time it is asked for and
        kept in ``meta`` (so a restart with the same gradebook gives every trainee the same
        mystery tool again). A secret: whoever knows it can compute every mystery tool, so it is
        never printed, logged or sent to a browser."""
        with self._store.write() as db:
            db.serialize("exercise seed")
            row = db.execute("SELECT value FROM meta WHERE key = 'exercise_seed'").fetchone()
            if row is not None:
                try:
                    return int(row[0])
                except ValueError:
                    raise self._store.refusal(
                        "has an exercise_seed that is not a whole number in its meta table") from None
            seed = secrets.randbits(63)
            db.execute("INSERT INTO meta (key, value) VALUES ('exercise_seed', ?)", (str(seed),))
            return seed

    def get(self, key: str) -> Any:
        """A class setting kept across restarts (:meth:`set`), None when never set."""
        with self._store.read() as db:
            row = db.execute("SELECT value FROM meta WHERE key = ?", (f"class:{key}",)).fetchone()
        return None if row is None else json.loads(row[0])

    def set(self, key: str, value: object) -> None:
        """Keep a class setting (JSON-ready; the pushed exercise, the distance-aid lock, the
        trainer token's hash) across restarts of the server."""
        text = json.dumps(value, sort_keys=True, allow_nan=False)
        with self._store.write() as db:
            db.execute("INSERT INTO meta (key, value) VALUES (?, ?) ON CONFLICT(key) DO UPDATE SET value = "
                       "excluded.value", (f"class:{label(key, 'setting name')}", text))
