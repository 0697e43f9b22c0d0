"""The trainer's pushes of class settings, kept in order (table ``class_pushes``) so every server
process of the class applies the ones it has not seen (``ClassRoom.beat``). A push is a JSON
object (its ``kind``: settings, brief, reset, push_to, language,
language_to); ids grow."""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from tcp_pendant.classroom.gradebook_store import GradebookStore
from tcp_pendant.classroom.gradebook_values import utc_now

__all__ = ["ClassPushes"]


class ClassPushes:
    """The kept pushes of the gradebook behind ``store`` (see the module docstring)."""

    def __init__(self, store: GradebookStore) -> None:
        self._store = store

    def add(self, push: Mapping[str, object]) -> int:
        """Keep one push of the trainer's class settings (JSON-ready); returns its id (ids grow)."""
        text = json.dumps(dict(push), sort_keys=True, allow_nan=False)
        with self._store.write() as db:
            return db.insert("INSERT INTO class_pushes (pushed_at, push_json) VALUES (?, ?)", (utc_now(), text))

    def after(self, push_id: int) -> list[tuple[int, dict[str, Any]]]:
        """``(id, push)`` of the pushes kept after ``push_id``, in order (0: all)."""
        with self._store.read() as db:
            rows = db.execute("SELECT id, push_json FROM class_pushes WHERE id > ? ORDER BY id",
                              (int(push_id),)).fetchall()
        return [(int(i), json.loads(p)) for i, p in rows]

    def last_id(self) -> int:
        """The id of the last push kept (0: none)."""
        with self._store.read() as db:
            row = db.execute("SELECT MAX(id) FROM class_pushes").fetchone()
        return 0 if row is None or row[0] is None else int(row[0])
