"""A controller-like tool table persisted as a human-readable JSON file.

File format (UTF-8 JSON, indented, fixed key order, one line per number triple; hand-editable)::

    {
      "format": "tcp-pendant-tool-library",
      "version": 1,
      "active_slot": 1,                 # int 1..16 of an occupied slot, or null
      "tools": {"1": {...}, "3": {...}},# slot number (as a string) -> Tool.to_dict()
      "owners": {"3": "Alice"}          # optional: slot -> who saved it (see "Owners")
    }

The tool dictionaries are those of :meth:`tcpcal.tool.Tool.to_dict` (keys documented in
:mod:`tcpcal.tool`). Default location: ``platformdirs.user_data_dir("tcp-pendant")/tools.json``;
pass another ``path`` to use another file.

Consistency rules:

- Every read (``tools``, ``get``, ``find``, ``active_*``, ``first_free_slot``) reads the file
  afresh, so another process's saves are always seen.
- Every mutation takes an exclusive ``filelock.FileLock`` on ``<path>.lock``, re-reads the
  file, applies the change, writes the whole table to a temporary file in the same directory,
  flushes and fsyncs it, ``os.replace``-s it over the file and fsyncs the directory. A reader
  or a crash therefore sees either the previous or the new file, never a partial one, and two
  processes saving at once lose nothing. Leftover temporary files of a killed writer are
  removed by the next mutation (under the lock).
- A damaged file never costs the valid tools. It is read entry by entry: each bad entry (a
  slot key that is not 1..16, a tool that ``Tool.from_dict`` rejects -- NaN or inf TCP, a
  numeric or over-long name, wrong types, unknown keys --, a name already used by an earlier
  slot, an ``active_slot`` that is not a valid occupied slot, unknown top-level keys) is *set
  aside*: under the lock the file as it was is copied byte for byte to a new
  ``<stem>.corrupt-<UTC timestamp>[-n].json`` next to it (never overwriting an earlier
  backup), then the file is rewritten atomically with the valid entries only.
- A file that cannot be used at all (bad UTF-8, not JSON, nested so deeply that the JSON
  parser gives up, not an object, wrong ``format``/``version``, ``tools`` not an object) is
  moved aside whole to such a backup; the library continues empty.
- An owner entry that is not a non-empty string of at most ``MAX_OWNER_LENGTH`` characters,
  or that names an empty slot, is set aside the same way (the tool stays, unowned).
- Either way :attr:`ToolLibrary.recovery` is a :class:`LibraryRecovery` (backup path, one
  line per problem, the slots kept; ``recovered_backup`` names the backup, for compatibility)
  and a :class:`ToolLibraryWarning` is issued. A file that exists but cannot be read at all
  (permissions, I/O error), or a backup that cannot be written, raises
  :class:`ToolLibraryError` instead: nothing is rewritten without its backup.

Owners (optional; a classroom's trainees): a mutation given ``owner=NAME`` acts for that owner
and is checked under the lock, in the same step that writes: it may save into an empty slot
or one ``NAME`` owns (then the slot is ``NAME``'s), rename or remove only ``NAME``'s slots, and
a save into a new slot is refused once ``NAME`` owns ``quota`` slots (:class:`SlotOwnedError`,
:class:`OwnerQuotaError`). A mutation without ``owner`` is unrestricted (the CLI, a trainer,
a single user); its save leaves the slot unowned, its rename keeps the owner, its remove drops
it. The ``owners`` key is written only when a slot has an owner, so a library that never had
one keeps today's file; a file without it loads with every slot unowned. (A tcpcal older than
the key sets the key aside as unknown, with a backup, and keeps every tool.)
"""

from __future__ import annotations

import dataclasses
import json
import os
import re
import tempfile
import warnings
from datetime import datetime, timezone
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import filelock
import platformdirs

from tcpcal.errors import InvalidInputError, TcpcalError
from tcpcal.tool import Tool

__all__ = [
    "FORMAT_NAME",
    "FORMAT_VERSION",
    "MAX_OWNER_LENGTH",
    "LibraryRecovery",
    "OwnerQuotaError",
    "SlotOwnedError",
    "ToolLibrary",
    "ToolLibraryError",
    "ToolLibraryWarning",
    "default_library_path",
]

FORMAT_NAME = "tcp-pendant-tool-library"
FORMAT_VERSION = 1
LOCK_TIMEOUT_S = 30.0
MAX_OWNER_LENGTH = 200
"""Longest owner text kept in the file (characters)."""
_NUMBER_ARRAY = re.compile(r"\[\n\s*([-+0-9.eE,\s]+?)\n\s*\]")
_SLOT_KEY = re.compile(r"[0-9]{1,3}")  # ASCII digits only ("\u0663".isdigit() is True)


class ToolLibraryError(TcpcalError):
    """A tool-library operation that cannot be done (duplicate name, empty slot, file I/O)."""


class SlotOwnedError(ToolLibraryError):
    """A mutation for one owner touched a slot that is not theirs.

    Attributes:
        slot: the slot.
        owner: who owns it (None: nobody, i.e. it was saved without an owner).
    """

    def __init__(self, message: str, *, slot: int, owner: str | None) -> None:
        super().__init__(message)
        self.slot = slot
        self.owner = owner


class OwnerQuotaError(ToolLibraryError):
    """A save for one owner into a new slot when the owner already holds ``quota`` slots.

    Attributes:
        owned: the owner's slots, in increasing order.
        quota: slots allowed per owner.
    """

    def __init__(self, message: str, *, owned: tuple[int, ...], quota: int) -> None:
        super().__init__(message)
        self.owned = owned
        self.quota = quota


class ToolLibraryWarning(UserWarning):
    """Issued when a damaged library file was set aside (whole, or some of its entries)."""


class _CorruptFile(Exception):
    """Internal: the file content is not a valid library (message says why)."""


def default_library_path() -> Path:
    """``platformdirs.user_data_dir("tcp-pendant")/tools.json`` (not created until a save)."""
    return Path(platformdirs.user_data_dir("tcp-pendant", appauthor=False)) / "tools.json"


def _check_slot(slot: Any, n_slots: int) -> int:
    if isinstance(slot, bool) or not isinstance(slot, int):
        raise InvalidInputError(f"slot must be a whole number 1..{n_slots}, got {slot!r}.")
    if not 1 <= slot <= n_slots:
        raise InvalidInputError(
            f"slot {slot} does not exist; the tool table has slots 1..{n_slots}."
        )
    return int(slot)


class _State:
    """In-memory content of the library file."""

    def __init__(self, tools: dict[int, Tool] | None = None, active: int | None = None,
                 owners: dict[int, str] | None = None) -> None:
        self.tools: dict[int, Tool] = dict(tools or {})
        self.active: int | None = active
        self.owners: dict[int, str] = dict(owners or {})

    def to_json(self) -> str:
        doc: dict[str, Any] = {
            "format": FORMAT_NAME,
            "version": FORMAT_VERSION,
            "active_slot": self.active,
            "tools": {str(k): self.tools[k].to_dict() for k in sorted(self.tools)},
        }
        owners = {str(k): self.owners[k] for k in sorted(self.owners) if k in self.tools}
        if owners:
            doc["owners"] = owners
        text = json.dumps(doc, indent=2, ensure_ascii=False, allow_nan=False)
        # Put arrays of numbers (tcp_mm, abc_deg) on one line; a literal newline never occurs
        # inside a JSON string, so this cannot touch names or notes.
        text = _NUMBER_ARRAY.sub(
            lambda m: "[" + ", ".join(x.strip() for x in m.group(1).split(",")) + "]", text
        )
        return text + "\n"

    @classmethod
    def from_json(cls, text: str, n_slots: int) -> tuple[_State, list[str]]:
        """Parse ``text`` entry by entry: ``(state of the valid entries, problems)``.

        Raises:
            _CorruptFile: the file cannot be used at all (not JSON, nested too deeply, not a
                library object, wrong format or version, ``tools`` not an object).
        """
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as exc:
            raise _CorruptFile(f"not valid JSON ({exc})") from None
        except RecursionError:
            raise _CorruptFile("nested too deeply to be a tool library") from None
        if not isinstance(doc, dict):
            raise _CorruptFile("the top level is not a JSON object")
        if doc.get("format") != FORMAT_NAME:
            raise _CorruptFile(
                f"'format' is {_short(repr(doc.get('format')))}, expected {FORMAT_NAME!r}"
            )
        if doc.get("version") != FORMAT_VERSION:
            raise _CorruptFile(
                f"'version' is {_short(repr(doc.get('version')))}; this tcpcal reads version "
                f"{FORMAT_VERSION}"
            )
        raw_tools = doc.get("tools", {})
        if not isinstance(raw_tools, dict):
            raise _CorruptFile("'tools' is not an object of slot -> tool")
        problems: list[str] = []
        unknown = sorted(set(doc) - {"format", "version", "active_slot", "tools", "owners"})
        if unknown:
            problems.append(f"unknown top-level keys {_short(repr(unknown))} dropped")
        tools: dict[int, Tool] = {}
        names: dict[str, int] = {}
        for key, value in raw_tools.items():
            if not (_SLOT_KEY.fullmatch(key) and 1 <= int(key) <= n_slots):
                problems.append(
                    f"entry {_short(repr(key))}: not a slot number 1..{n_slots}"
                )
                continue
            slot = int(key)
            if slot in tools:
                problems.append(f"entry {key!r}: slot {slot} appears twice (first one kept)")
                continue
            try:
                tool = Tool.from_dict(value)
            except TcpcalError as exc:
                problems.append(f"slot {slot}: {_short(str(exc))}")
                continue
            except RecursionError:
                problems.append(f"slot {slot}: nested too deeply to be a tool")
                continue
            if tool.name in names:
                problems.append(
                    f"slot {slot}: the name {tool.name!r} is already used by slot "
                    f"{names[tool.name]}"
                )
                continue
            names[tool.name] = slot
            tools[slot] = tool
        active = doc.get("active_slot")
        if active is not None and (
            isinstance(active, bool) or not isinstance(active, int) or active not in tools
        ):
            problems.append(
                f"'active_slot' {_short(repr(active))} is not a valid occupied slot; no tool "
                "is active"
            )
            active = None
        return cls(tools, active, _parse_owners(doc.get("owners", {}), tools, problems)), problems


def _parse_owners(raw: Any, tools: dict[int, Tool], problems: list[str]) -> dict[int, str]:
    """The valid entries of the optional ``owners`` object (slot -> owner of an occupied slot);
    each bad one is added to ``problems``."""
    if not isinstance(raw, dict):
        problems.append("'owners' is not an object of slot -> owner; every slot is unowned")
        return {}
    owners: dict[int, str] = {}
    for key, value in raw.items():
        slot = int(key) if _SLOT_KEY.fullmatch(key) else None
        if slot is None or slot not in tools:
            problems.append(f"owner entry {_short(repr(key))}: not an occupied slot; dropped")
        elif not (isinstance(value, str) and value.strip() and len(value) <= MAX_OWNER_LENGTH):
            problems.append(f"owner of slot {slot}: {_short(repr(value))} is not a name of 1 to "
                            f"{MAX_OWNER_LENGTH} characters; the slot is unowned")
        else:
            owners[slot] = value
    return owners


def _short(text: str, limit: int = 160) -> str:
    """``text`` cut to ``limit`` characters (a problem line must stay one readable line)."""
    text = " ".join(text.split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


@dataclasses.dataclass(frozen=True)
class LibraryRecovery:
    """What one load of a damaged library file set aside (``ToolLibrary.recovery``).

    Attributes:
        path: the library file.
        backup: the copy of the file as it was found (bytes unchanged), next to it.
        problems: one line per entry set aside, e.g. ``"slot 3: tcp_mm[0] must be a finite
            number, got nan."``; for a file unusable as a whole, one line saying why.
        kept_slots: slots of the valid tools kept in the library (empty if ``whole_file``).
        whole_file: True when the file could not be used at all and the library starts empty.
    """

    path: Path
    backup: Path
    problems: tuple[str, ...]
    kept_slots: tuple[int, ...] = ()
    whole_file: bool = False

    def summary(self, max_problems: int = 5) -> str:
        """One plain-text paragraph: what was set aside, what was kept, where the backup is."""
        shown = list(self.problems[:max_problems])
        if len(self.problems) > max_problems:
            shown.append(f"and {len(self.problems) - max_problems} more")
        what = "; ".join(shown)
        if self.whole_file:
            return (
                f"The tool library {self.path} is corrupt ({what}); the whole file was "
                f"moved aside to {self.backup} and the library starts empty. Repair that file by "
                "hand to recover its tools."
            )
        kept = ", ".join(str(s) for s in self.kept_slots) or "none"
        return (
            f"The tool library {self.path} had {len(self.problems)} bad "
            f"{'entry' if len(self.problems) == 1 else 'entries'} ({what}); "
            f"{'it was' if len(self.problems) == 1 else 'they were'} set aside (the file as it "
            f"was is kept in {self.backup}); the valid tools were kept (slots {kept})."
        )


class ToolLibrary:
    """Controller-like tool table: slots 1..16 with unique names, at most one active tool.

    Args:
        path: library file; default :func:`default_library_path`. The directory is created on
            the first save.

    Attributes:
        path: the library file.
        recovery: what the last load of a damaged file by this object set aside, or None.
        recoveries: every such :class:`LibraryRecovery` of this object, oldest first.
        recovered_backup: ``recovery.backup`` (where the file as it was is kept), or None.
    """

    N_SLOTS = 16

    def __init__(self, path: Path | str | None = None) -> None:
        self.path: Path = Path(path) if path is not None else default_library_path()
        self.recoveries: tuple[LibraryRecovery, ...] = ()
        self._lock = filelock.FileLock(str(self.path) + ".lock", timeout=LOCK_TIMEOUT_S)

    # ------------------------------------------------------------------ reading
    @property
    def recovery(self) -> LibraryRecovery | None:
        """The last :class:`LibraryRecovery` of this object, or None."""
        recoveries = self.recoveries
        return recoveries[-1] if recoveries else None

    @property
    def recovered_backup(self) -> Path | None:
        """Backup of the last damaged file this object set aside, or None (compatibility)."""
        recovery = self.recovery
        return None if recovery is None else recovery.backup

    def _read_bytes(self) -> bytes | None:
        try:
            return self.path.read_bytes()
        except FileNotFoundError:
            return None
        except OSError as exc:
            raise ToolLibraryError(
                f"cannot read the tool library {self.path}: {exc.strerror or exc}; check the "
                "file's permissions or pass another path."
            ) from None

    def _load(self) -> tuple[_State, list[str], bytes]:
        """Read and parse the file: ``(valid entries, problems, the bytes read)``.

        Raises:
            _CorruptFile: the file cannot be used at all.
        """
        data = self._read_bytes()
        if data is None:
            return _State(), [], b""
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise _CorruptFile(f"not UTF-8 text ({exc})") from None
        state, problems = _State.from_json(text, self.N_SLOTS)
        return state, problems, data

    def _backup_path(self) -> tuple[Path, int]:
        """A new ``<stem>.corrupt-<UTC timestamp>[-n].json`` next to the file, reserved by
        creating it empty (O_EXCL), so no earlier backup is ever overwritten."""
        stamp = datetime.now(timezone.utc).strftime("%Y%m%dT%H%M%SZ")
        base = f"{self.path.stem}.corrupt-{stamp}"
        n = 0
        while True:
            backup = self.path.with_name(f"{base}.json" if n == 0 else f"{base}-{n}.json")
            try:
                fd = os.open(backup, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
            except FileExistsError:
                n += 1
                continue
            return backup, fd

    def _record(self, recovery: LibraryRecovery) -> None:
        self.recoveries = (*self.recoveries, recovery)
        warnings.warn(recovery.summary(max_problems=10), ToolLibraryWarning, stacklevel=5)

    def _move_aside(self, reason: str) -> None:
        """Move the unusable file to a new backup name (caller holds the lock)."""
        backup: Path | None = None
        try:
            backup, fd = self._backup_path()
            os.close(fd)
            os.replace(self.path, backup)
        except OSError as exc:
            if backup is not None:  # the reserved name stays free
                backup.unlink(missing_ok=True)
            raise ToolLibraryError(
                f"the tool library {self.path} is corrupt ({reason}) and could not be moved "
                f"aside: {exc.strerror or exc}; move or repair it by hand."
            ) from None
        self._fsync_dir()
        self._record(LibraryRecovery(self.path, backup, (reason,), (), True))

    def _set_aside_entries(self, state: _State, problems: list[str], data: bytes) -> None:
        """Keep the file as it was in a backup, then rewrite it with the valid entries only
        (caller holds the lock). The backup is complete before the file is replaced."""
        try:
            backup, fd = self._backup_path()
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
            self._fsync_dir()
        except OSError as exc:
            raise ToolLibraryError(
                f"the tool library {self.path} has bad entries ({'; '.join(problems[:3])}) "
                f"and no backup of it could be written: {exc.strerror or exc}; repair it by "
                "hand or make its directory writable."
            ) from None
        self._write_or_raise(state)
        self._record(
            LibraryRecovery(self.path, backup, tuple(problems), tuple(sorted(state.tools)))
        )

    def _read_locked(self) -> _State:
        """Read the file; caller holds the lock, so damaged parts can be set aside."""
        try:
            state, problems, data = self._load()
        except _CorruptFile as exc:
            self._move_aside(str(exc))
            return _State()
        if problems:
            self._set_aside_entries(state, problems, data)
        return state

    def _read(self) -> _State:
        """Fresh read without the lock (writes are atomic); take the lock only if damaged."""
        try:
            state, problems, _ = self._load()
        except _CorruptFile:
            problems = ["corrupt"]
        if not problems:
            return state
        with self._locked():
            return self._read_locked()

    # ------------------------------------------------------------------ writing
    def _locked(self) -> filelock.BaseFileLock:
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ToolLibraryError(
                f"cannot create the directory {self.path.parent}: {exc.strerror or exc}; pass a "
                "path in a writable directory."
            ) from None
        return _LockContext(self._lock, self.path)  # type: ignore[return-value]

    def _fsync_dir(self) -> None:
        if os.name != "posix":  # directories cannot be opened for fsync on Windows
            return
        fd = os.open(self.path.parent, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)

    def _tmp_prefix(self) -> str:
        return f".{self.path.name}."

    def _remove_stale_temps(self) -> None:
        """Delete temporary files left by a killed writer (safe: we hold the lock)."""
        for p in self.path.parent.glob(self._tmp_prefix() + "*.tmp"):
            try:
                p.unlink()
            except OSError:
                pass

    def _write_locked(self, state: _State) -> None:
        text = state.to_json()
        self._remove_stale_temps()
        fd, tmp = tempfile.mkstemp(dir=self.path.parent, prefix=self._tmp_prefix(), suffix=".tmp")
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                fh.write(text)
                fh.flush()
                os.fsync(fh.fileno())
            try:
                mode = self.path.stat().st_mode & 0o777
            except OSError:
                mode = 0o644
            os.chmod(tmp, mode)
            os.replace(tmp, self.path)
        except BaseException:
            try:
                os.unlink(tmp)
            except OSError:
                pass
            raise
        self._fsync_dir()

    def _write_or_raise(self, state: _State) -> None:
        try:
            self._write_locked(state)
        except OSError as exc:
            raise ToolLibraryError(
                f"cannot write the tool library {self.path}: {exc.strerror or exc}; check "
                "the free space and the permissions of its directory."
            ) from None

    def _mutate(self, change: Any) -> None:
        """Lock, re-read, apply ``change(state)``, write atomically, unlock."""
        with self._locked():
            state = self._read_locked()
            change(state)
            self._write_or_raise(state)

    # ------------------------------------------------------------------ public reads
    def tools(self) -> dict[int, Tool]:
        """All stored tools by slot (fresh read from disk), slots in increasing order."""
        state = self._read()
        return {k: state.tools[k] for k in sorted(state.tools)}

    def get(self, slot: int) -> Tool | None:
        """The tool in ``slot`` (1..16) or None if the slot is empty."""
        return self._read().tools.get(_check_slot(slot, self.N_SLOTS))

    def find(self, name: str) -> tuple[int, Tool] | None:
        """``(slot, tool)`` of the tool called exactly ``name``, or None."""
        for slot, tool in self.tools().items():
            if tool.name == name:
                return slot, tool
        return None

    def owners(self) -> dict[int, str]:
        """Owner of each owned slot (fresh read), slots in increasing order; unowned slots
        are not listed."""
        state = self._read()
        return {k: state.owners[k] for k in sorted(state.owners)}

    def active_slot(self) -> int | None:
        """Slot of the active tool, or None (TCP = flange)."""
        return self._read().active

    def active_tool(self) -> Tool | None:
        """The active tool, or None."""
        state = self._read()
        return None if state.active is None else state.tools[state.active]

    def first_free_slot(self) -> int | None:
        """Lowest empty slot, or None when all 16 are used."""
        used = self._read().tools
        for slot in range(1, self.N_SLOTS + 1):
            if slot not in used:
                return slot
        return None

    # ------------------------------------------------------------------ public mutations
    def save(self, slot: int, tool: Tool, *, activate: bool = False, owner: str | None = None,
             quota: int | None = None) -> None:
        """Store ``tool`` in ``slot``, replacing what was there; optionally make it active.

        Args:
            slot: 1..16.
            tool: the tool.
            activate: also make it the active tool.
            owner: save for this owner (module docstring, "Owners"): ``slot`` must be empty or
                theirs, and it is theirs afterwards. None: unrestricted, the slot is unowned.
            quota: with ``owner``: how many slots an owner may hold (None: no limit).

        Raises:
            InvalidInputError: bad slot number or not a Tool.
            ToolLibraryError: another slot already holds a tool of that name.
            SlotOwnedError: ``slot`` holds a tool that is not ``owner``'s.
            OwnerQuotaError: ``slot`` is not ``owner``'s and they already hold ``quota`` slots.
        """
        slot = _check_slot(slot, self.N_SLOTS)
        if not isinstance(tool, Tool):
            raise InvalidInputError(f"save() needs a tcpcal.Tool, got {type(tool).__name__}.")
        if owner is not None:
            owner = self._check_owner(owner)

        def change(state: _State) -> None:
            if owner is not None:
                self._check_owned_by(state, slot, owner, "save into", empty_ok=True)
                self._check_quota(state, slot, owner, quota)
            self._check_unique(state, tool.name, slot)
            state.tools[slot] = tool
            if owner is None:
                state.owners.pop(slot, None)
            else:
                state.owners[slot] = owner
            if activate:
                state.active = slot

        self._mutate(change)

    def save_many(self, tools: Mapping[int, Tool]
                  | Callable[[dict[int, Tool]], Mapping[int, Tool]]) -> dict[int, Tool]:
        """Store several tools at once, in one locked change (all or nothing): each slot's
        tool replaced (unowned afterwards); names must be unique in the table that results.

        Args:
            tools: slot -> tool, or a function that computes them under the lock from the
                table as it is (slot -> tool); raising there changes nothing.

        Returns:
            The slots and tools stored.

        Raises:
            InvalidInputError: a bad slot number or not a Tool.
            ToolLibraryError: two slots of the resulting table would hold the same name.
        """
        stored: dict[int, Tool] = {}

        def change(state: _State) -> None:
            given = tools(dict(state.tools)) if callable(tools) else tools
            items = {_check_slot(slot, self.N_SLOTS): tool for slot, tool in given.items()}
            for tool in items.values():
                if not isinstance(tool, Tool):
                    raise InvalidInputError(
                        f"save_many() needs tcpcal.Tool values, got {type(tool).__name__}.")
            result = {**state.tools, **items}
            seen: dict[str, int] = {}
            for slot in sorted(result):
                name = result[slot].name
                if name in seen:
                    raise ToolLibraryError(
                        f"the name {name!r} would be in slot {seen[name]} and slot {slot}; "
                        "rename one of them first.")
                seen[name] = slot
            state.tools = result
            for slot in items:
                state.owners.pop(slot, None)
            stored.update(items)

        self._mutate(change)
        return stored

    def remove(self, slot: int, *, owner: str | None = None) -> None:
        """Empty ``slot``; if it was the active tool, no tool is active afterwards.

        Args:
            slot: 1..16.
            owner: remove only if the slot is this owner's (None: unrestricted).

        Raises:
            ToolLibraryError: the slot is already empty.
            SlotOwnedError: the slot is not ``owner``'s.
        """
        slot = _check_slot(slot, self.N_SLOTS)
        if owner is not None:
            owner = self._check_owner(owner)

        def change(state: _State) -> None:
            self._check_occupied(state, slot, "remove")
            if owner is not None:
                self._check_owned_by(state, slot, owner, "remove")
            del state.tools[slot]
            state.owners.pop(slot, None)
            if state.active == slot:
                state.active = None

        self._mutate(change)

    def rename(self, slot: int, name: str, *, owner: str | None = None) -> None:
        """Give the tool in ``slot`` a new name (validated like ``Tool.name``, unique); its
        owner stays.

        Raises:
            SlotOwnedError: ``owner`` given and the slot is not theirs.
        """
        slot = _check_slot(slot, self.N_SLOTS)
        if owner is not None:
            owner = self._check_owner(owner)

        def change(state: _State) -> None:
            self._check_occupied(state, slot, "rename")
            if owner is not None:
                self._check_owned_by(state, slot, owner, "rename")
            renamed = dataclasses.replace(state.tools[slot], name=name)
            self._check_unique(state, renamed.name, slot)
            state.tools[slot] = renamed

        self._mutate(change)

    def activate(self, slot: int | None) -> None:
        """Make the tool in ``slot`` active, or deactivate every tool with None."""
        if slot is not None:
            slot = _check_slot(slot, self.N_SLOTS)

        def change(state: _State) -> None:
            if slot is not None:
                self._check_occupied(state, slot, "activate")
            state.active = slot

        self._mutate(change)

    # ------------------------------------------------------------------ helpers
    @staticmethod
    def _check_unique(state: _State, name: str, slot: int) -> None:
        for other, tool in state.tools.items():
            if other != slot and tool.name == name:
                raise ToolLibraryError(
                    f"the name {name!r} is already used by slot {other}; choose another name, "
                    f"rename or remove slot {other}, or save into slot {other} to replace it."
                )

    @staticmethod
    def _check_owner(owner: Any) -> str:
        if not (isinstance(owner, str) and owner.strip() and len(owner) <= MAX_OWNER_LENGTH):
            raise InvalidInputError(f"owner must be a name of 1 to {MAX_OWNER_LENGTH} characters, "
                                    f"got {_short(repr(owner), 60)}.")
        return owner

    @staticmethod
    def _check_owned_by(state: _State, slot: int, owner: str, action: str, *, empty_ok: bool = False) -> None:
        if empty_ok and slot not in state.tools:
            return
        holder = state.owners.get(slot)
        if holder != owner:
            whose = "nobody's (saved without an owner)" if holder is None else "another owner's"
            raise SlotOwnedError(
                f"cannot {action} slot {slot}: it is {whose}; only its owner or an unrestricted "
                "user may change it.", slot=slot, owner=holder)

    @staticmethod
    def _check_quota(state: _State, slot: int, owner: str, quota: int | None) -> None:
        if quota is None or state.owners.get(slot) == owner:
            return
        owned = tuple(sorted(k for k, v in state.owners.items() if v == owner and k in state.tools))
        if len(owned) >= quota:
            raise OwnerQuotaError(
                f"cannot save into slot {slot}: the owner already holds {len(owned)} slots "
                f"({', '.join(map(str, owned))}), the most allowed; remove one of them or save "
                "into one of them.", owned=owned, quota=quota)

    @staticmethod
    def _check_occupied(state: _State, slot: int, action: str) -> None:
        if slot not in state.tools:
            used = sorted(state.tools)
            raise ToolLibraryError(
                f"cannot {action} slot {slot}: it is empty; occupied slots: "
                f"{used if used else 'none'}."
            )

    def __repr__(self) -> str:
        return f"ToolLibrary({str(self.path)!r})"


class _LockContext:
    """FileLock context that turns a lock timeout into a ToolLibraryError."""

    def __init__(self, lock: filelock.BaseFileLock, path: Path) -> None:
        self._lock = lock
        self._path = path

    def __enter__(self) -> None:
        try:
            self._lock.acquire()
        except filelock.Timeout:
            raise ToolLibraryError(
                f"another program has held the lock {self._lock.lock_file} for more than "
                f"{LOCK_TIMEOUT_S:g} s; close the other program using {self._path} and retry."
            ) from None

    def __exit__(self, *exc: object) -> None:
        self._lock.release()
