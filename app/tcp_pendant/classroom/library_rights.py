"""The class's library rights: how many slots a trainee may hold, and a trainee's rights (no viser).

In a class (``--class``) every library slot a trainee saves is that trainee's: the owner is the
trainee's name as the class knows it (``classroom.names.validate_trainee_name``, the name the
gradebook holds for the browser), kept in the library file itself (``tcpcal.library``, the
optional ``owners`` key), so ownership outlives a restart of the server. A trainee may save into
an empty slot or one of their own, rename and delete only their own, and keep at most ``quota``
slots (:data:`DEFAULT_LIBRARY_QUOTA`, ``--library-quota`` up to :data:`MAX_LIBRARY_QUOTA`); a
slot saved without an owner (by the trainer, the ``tcpcal tools`` CLI, or before the class) is
not any trainee's. A pendant that has not joined the class yet changes nothing. The trainer (a
session that opened the trainer view), ``--shared`` and a pendant without a class are
unrestricted.

The classroom makes each pendant's rights here (:func:`trainee_rights`, or
``calibrate.pendant_rules.UNRESTRICTED``) and gives them to the session
(``SessionTools.set_library_rights``); ``calibrate.pendant_rules.LibraryRights`` checks them and
words the refusals.
"""

from __future__ import annotations

from tcp_pendant.calibrate.pendant_rules import LibraryRights

__all__ = ["DEFAULT_LIBRARY_QUOTA", "MAX_LIBRARY_QUOTA", "trainee_rights"]

DEFAULT_LIBRARY_QUOTA = 3
"""Library slots one trainee may hold in a class (``--library-quota``)."""
MAX_LIBRARY_QUOTA = 16
"""The library's slot count: a larger quota is no quota."""


def trainee_rights(name: str | None, quota: int | None = DEFAULT_LIBRARY_QUOTA) -> LibraryRights:
    """The rights of a class pendant: ``name`` the trainee's (None: not joined yet, it changes
    nothing), at most ``quota`` slots (None: no limit)."""
    return LibraryRights(restricted=True, owner=name, quota=quota)
