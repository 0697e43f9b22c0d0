"""Opening a gradebook: the connection (an SQLite file, or a ``postgresql://`` URL through psycopg
3, :mod:`tcp_pendant.classroom.gradebook_db`), the checks before anything is written, and the
tables made or brought up to date (:mod:`tcp_pendant.classroom.gradebook_schema`).

Safety of the file: the schema is versioned (table ``meta``: ``application`` and
``schema_version``). A version 1 file (before browser keys) is brought to version 2 when it is
opened (one transaction: the column ``trainees.key_sha256`` is added, every trainee without a
key); a TCP Pendant that reads only version 1 then refuses it as newer. Opening checks the file before writing anything to it
(``PRAGMA quick_check``, then ``meta``): a file that is not SQLite, is damaged, is another
program's database or was written by a newer TCP Pendant raises one :class:`GradebookError`
naming the file and what to do; the file is never overwritten or "repaired".

PostgreSQL: the same schema, versioned in the same ``meta`` table; opening holds the "schema"
advisory lock, so two servers starting on an empty database make the tables once.
"""

from __future__ import annotations

import sqlite3
from pathlib import Path
from typing import Literal

import platformdirs

from tcp_pendant.classroom.gradebook_db import (
    GradebookConnection,
    PostgresConnection,
    PostgresUnavailable,
    SqliteConnection,
    is_postgres_url,
)
from tcp_pendant.classroom.gradebook_schema import (
    APPLICATION,
    SCHEMA_VERSION,
    add_missing_parts,
    create_schema,
    migrate,
)
from tcp_pendant.classroom.gradebook_store import GradebookError, GradebookStore

__all__ = ["default_gradebook_path", "open_store"]


def default_gradebook_path() -> Path:
    """``platformdirs.user_data_dir("tcp-pendant")/class.sqlite3`` (next to the tool library)."""
    return Path(platformdirs.user_data_dir("tcp-pendant", appauthor=False)) / "class.sqlite3"


def open_store(path: Path | str | None = None, *, create: bool = True,
               synchronous: Literal["FULL", "NORMAL"] = "FULL", busy_timeout_s: float = 5.0) -> GradebookStore:
    """The gradebook at ``path`` opened, checked and brought up to date (the arguments and
    refusals of :class:`tcp_pendant.classroom.gradebook.Gradebook`); nothing is written to a
    gradebook that is refused."""
    if synchronous not in ("FULL", "NORMAL"):
        raise GradebookError(f"synchronous must be 'FULL' or 'NORMAL', got {synchronous!r}.")
    db, file = _connect(path, create=create, busy_timeout_s=float(busy_timeout_s))
    store = GradebookStore(db, file)
    try:
        _prepare(store, db, synchronous, create)
    except BaseException:
        db.close()
        raise
    return store


def _connect(path: Path | str | None, *, create: bool,
             busy_timeout_s: float) -> tuple[GradebookConnection, Path | None]:
    """The connection to a PostgreSQL URL (no file) or an SQLite file (None: the default one,
    its folder made), or the refusal naming why not."""
    if is_postgres_url(path):
        try:
            return PostgresConnection(str(path), busy_timeout_s=busy_timeout_s), None
        except PostgresUnavailable as exc:
            raise GradebookError(str(exc)) from None
    file = Path(default_gradebook_path() if path is None else path)
    if file.is_dir():
        raise GradebookError(f"Gradebook {file} is a folder; give a file name such as "
                             f"{file / 'class.sqlite3'}.")
    exists = file.exists()
    if not exists and not create:
        raise GradebookError(f"No gradebook at {file}: check the path (the server writes it "
                             "where --class-db says, by default in the user data folder).")
    if not exists and path is None:
        file.parent.mkdir(parents=True, exist_ok=True)
    try:
        return SqliteConnection(file, busy_timeout_s=busy_timeout_s), file
    except sqlite3.Error as exc:
        raise GradebookError(f"Cannot open the gradebook {file}: {exc}; check that the path and "
                             "its folder exist and are readable and writable.") from exc


def _version(store: GradebookStore, db: GradebookConnection, tables: set[str], *,
             check_storage: bool = True) -> int:
    """The schema version of a database that has tables; refuses (nothing written) one that
    is damaged (``check_storage``: SQLite's quick_check), another program's, incomplete, or
    newer than this TCP Pendant reads."""
    try:
        problems = db.integrity_problems() if check_storage else []
    except db.errors as exc:
        raise store.refusal(f"is damaged ({exc})") from exc
    if problems:
        raise store.refusal(f"is damaged (SQLite quick_check: {'; '.join(problems[:3])})")
    if "meta" not in tables:
        raise store.refusal(f"is {db.described} of another program (no 'meta' table)")
    try:
        meta = {str(k): str(v) for k, v in db.execute("SELECT key, value FROM meta")}
    except db.errors as exc:
        raise store.refusal(f"has an unreadable 'meta' table ({exc})") from exc
    if meta.get("application") != APPLICATION:
        raise store.refusal(f"is {db.described} of another program (its meta table does not "
                            f"say {APPLICATION!r})")
    try:
        version = int(meta.get("schema_version", ""))
    except ValueError:
        raise store.refusal(f"has no valid schema_version ({meta.get('schema_version')!r})") from None
    if version > SCHEMA_VERSION:
        raise GradebookError(
            f"Gradebook {store.location} was written by a newer TCP Pendant (schema version {version}; "
            f"this one reads up to {SCHEMA_VERSION}). Nothing was changed in it: upgrade "
            f"tcp-pendant to read it, or give another {db.noun} with --class-db.")
    if version < 1 or not {"trainees", "sessions", "calibrations", "touches", "crashes"} <= tables:
        raise store.refusal(f"is incomplete (schema version {version}, tables {sorted(tables)})")
    return version


def _prepare(store: GradebookStore, db: GradebookConnection, synchronous: str, create: bool) -> None:
    """Check the gradebook (``db``, the connection of ``store``), then (one transaction holding
    the schema) make its tables or migrate them, and add the parts an older writer lacks."""
    try:
        tables = db.tables()
    except db.operational_error as exc:      # cannot open / locked / I/O: not the content
        raise GradebookError(f"Cannot open the gradebook {store.location}: {exc}; check that the path and "
                             "its folder exist and are readable and writable, and that no other "
                             "program holds it locked.") from exc
    except db.errors as exc:
        raise store.refusal(f"is not a readable {db.kind} database ({exc})") from exc
    looked = bool(tables)
    if looked:
        _version(store, db, tables)              # refuses before anything is written
    elif not create and db.noun == "database":
        raise GradebookError(f"No gradebook in {store.location}: the database has no gradebook tables; "
                             "check the URL (the server makes them where --class-db says).")
    try:
        if isinstance(db, SqliteConnection):
            refused = db.configure(synchronous)
            if refused is not None:
                raise GradebookError(
                    f"Gradebook {store.location}: SQLite refused WAL mode (got {refused!r}); put the "
                    "file on a local disk (WAL needs shared memory, network folders lack it).")
        with store.transaction():
            # Again inside the transaction, which holds the schema: another server process may
            # have made or migrated the tables since the look above.
            db.serialize("schema")
            tables = db.tables()
            if not tables:
                create_schema(db)
            else:
                version = _version(store, db, tables, check_storage=not looked)
                if version < SCHEMA_VERSION:
                    migrate(db, version)
            add_missing_parts(db, tables)
    except db.errors as exc:
        raise store.cannot_write(exc) from exc
