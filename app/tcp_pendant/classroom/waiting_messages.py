"""The trainer's messages each trainee has not dismissed yet (table ``class_messages``: one row
per trainee a message was sent to), so a trainee gets them wherever and whenever they connect
(another server process, a reload, a restart). At most ``MAX_WAITING_MESSAGES`` per trainee:
a newer one pushes out the oldest."""

from __future__ import annotations

from collections.abc import Sequence

from tcp_pendant.classroom.gradebook_store import GradebookStore
from tcp_pendant.classroom.gradebook_values import whole_id
from tcp_pendant.session import MAX_WAITING_MESSAGES

__all__ = ["WaitingMessages"]


class WaitingMessages:
    """The undismissed messages of the gradebook behind ``store`` (see the module docstring)."""

    def __init__(self, store: GradebookStore) -> None:
        self._store = store

    def add(self, text: str, names: Sequence[str], *, to_all: bool, sent_at: str) -> dict[str, int]:
        """Keep the trainer's message ``text`` (plain text, cleaned by the caller) for each of
        ``names`` until that trainee dismisses it; beyond ``MAX_WAITING_MESSAGES`` a trainee's
        oldest go. ``to_all``: it was sent to the class. Returns each name's message id."""
        ids: dict[str, int] = {}
        with self._store.write() as db:
            for name in dict.fromkeys(str(n) for n in names):
                ids[name] = db.insert("INSERT INTO class_messages (name, to_all, sent_at, text) VALUES (?, ?, ?, ?)",
                                      (name, int(bool(to_all)), str(sent_at), str(text)))
                db.execute("DELETE FROM class_messages WHERE name = ? AND id NOT IN (SELECT id FROM class_messages "
                           "WHERE name = ? ORDER BY id DESC LIMIT ?)", (name, name, MAX_WAITING_MESSAGES))
        return ids

    def waiting(self, names: Sequence[str]) -> dict[str, list[tuple[int, bool, str, str]]]:
        """The messages kept for each of ``names`` (not dismissed), oldest first:
        ``{name: [(id, to_all, sent_at, text), ...]}`` (a name without any is missing)."""
        wanted = sorted({str(n) for n in names})
        out: dict[str, list[tuple[int, bool, str, str]]] = {}
        if not wanted:
            return out
        with self._store.read() as db:
            rows = db.execute("SELECT id, name, to_all, sent_at, text FROM class_messages WHERE name IN ("
                              + ", ".join("?" * len(wanted)) + ") ORDER BY id", wanted).fetchall()
        for mid, name, to_all, sent, text in rows:
            out.setdefault(str(name), []).append((int(mid), bool(to_all), str(sent), str(text)))
        return out

    def dismiss(self, name: str, message_ids: Sequence[int]) -> int:
        """``name`` dismissed the messages ``message_ids`` (theirs only: another trainee's id
        dismisses nothing). Returns how many went."""
        ids = [whole_id(i, "message id") for i in message_ids]
        if not ids:
            return 0
        with self._store.write() as db:
            return sum(db.execute("DELETE FROM class_messages WHERE id = ? AND name = ?", (i, str(name))).rowcount
                       for i in ids)
