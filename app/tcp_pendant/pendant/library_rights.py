"""Who a pendant may change the shared tool library as: its :class:`LibraryRights`.

In a class (``--class``) every library slot a trainee saves is that trainee's: the owner is the
trainee's name as the class knows it (``classroom.names.validate_trainee_name``, the name the
gradebook holds for the browser), kept in the library file itself (``tcpcal.library``, the
optional ``owners`` key), so the check and the write are one step under the file's lock and
ownership outlives a restart of the server. A trainee may save into an empty slot or one of
their own, rename and delete only their own, and keep at most ``quota`` slots; a slot saved
without an owner (by the trainer, the ``tcpcal tools`` CLI, or before the class) is not any
trainee's. A pendant that has not joined the class yet changes nothing. The trainer (a
session that opened the trainer view), ``--shared`` and a pendant without a class are
unrestricted, as before.

A refusal names no other trainee: "slot 5 belongs to another trainee" (the class list is the
trainer's to see), and says what to do instead.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from tcpcal.library import OwnerQuotaError, SlotOwnedError, ToolLibraryError

__all__ = ["DEFAULT_LIBRARY_QUOTA", "MAX_LIBRARY_QUOTA", "UNRESTRICTED", "LibraryRights"]

DEFAULT_LIBRARY_QUOTA = 3
"""Library slots one trainee may hold in a class (``--library-quota``)."""
MAX_LIBRARY_QUOTA = 16
"""The library's slot count: a larger quota is no quota."""


@dataclass(frozen=True)
class LibraryRights:
    """How a pendant may change the library.

    Attributes:
        restricted: a class pendant (changes need an ``owner``).
        owner: the trainee's name (None: not joined yet, or unrestricted).
        quota: slots one owner may hold (None: no limit).
    """

    restricted: bool = False
    owner: str | None = None
    quota: int | None = None

    @classmethod
    def trainee(cls, name: str | None, quota: int | None = DEFAULT_LIBRARY_QUOTA) -> LibraryRights:
        """A class pendant: ``name`` the trainee's (None: not joined yet)."""
        return cls(restricted=True, owner=name, quota=quota)

    def owner_kwargs(self) -> dict[str, Any]:
        """The keywords of ``ToolLibrary.rename``/``remove`` for these rights.

        Raises:
            ToolLibraryError: a class pendant that has not joined (the words say what to do).
        """
        if not self.restricted:
            return {}
        if self.owner is None:
            raise ToolLibraryError("Join the class with your name first: in a class each library slot "
                                   "belongs to the trainee who saved it.")
        return {"owner": self.owner}

    def save_kwargs(self) -> dict[str, Any]:
        """The keywords of ``ToolLibrary.save`` (owner and quota) for these rights."""
        kw = self.owner_kwargs()
        if kw and self.quota is not None:
            kw["quota"] = self.quota
        return kw

    def mine(self, owners: dict[int, str], slot: int) -> bool:
        """Whether ``slot`` may be renamed or deleted with these rights."""
        return not self.restricted or (self.owner is not None and owners.get(slot) == self.owner)

    @contextmanager
    def in_words(self) -> Iterator[None]:
        """Turn tcpcal's ownership refusals into a trainee's words (a ``ToolLibraryError``)."""
        try:
            yield
        except SlotOwnedError as exc:
            whose = ("belongs to another trainee" if exc.owner is not None
                     else "is the trainer's (saved without an owner)")
            raise ToolLibraryError(
                f"Slot {exc.slot} {whose}: you can activate and check it, not change it. Save into a "
                "free slot or one of your own, or ask the trainer.") from None
        except OwnerQuotaError as exc:
            slots = ", ".join(map(str, exc.owned))
            n = len(exc.owned)
            raise ToolLibraryError(
                f"You have {n} tool{'s' if n != 1 else ''} in the library (slot{'s' if n != 1 else ''} "
                f"{slots}), the most a trainee may keep ({exc.quota}): delete one of yours first, "
                "or save into one of your slots to replace it.") from None


UNRESTRICTED = LibraryRights()
"""The trainer, ``--shared`` and a pendant without a class."""
