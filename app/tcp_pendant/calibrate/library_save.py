""""Save to tool library": a finished wizard's tool written to the shared ``tcpcal.ToolLibrary``.

The file I/O of saving lives here, in ``calibrate/``, not in the wizards (state machines that
only compute): :func:`save_result` picks the slot and writes one atomic ``ToolLibrary.save``.
It never sets the library's active slot: which tool is active is the session's (the app's
``SessionTools.apply_saved``; in ``--shared`` mode that also sets the library's active slot).
"""

from __future__ import annotations

from tcp_pendant.calibrate.pendant_rules import UNRESTRICTED, LibraryRights
from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.wizards import Wizard, WizardStateError
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

__all__ = ["save_result"]


def save_result(wizard: Wizard, library: ToolLibrary, name: str, slot: int | None = None,
                rights: LibraryRights = UNRESTRICTED, *, tr: Translator = ENGLISH) -> tuple[int, Tool]:
    """Store ``wizard.to_tool(name)`` in ``slot`` of ``library``.

    Args:
        wizard: a finished wizard.
        library: the tool library.
        name: the tool's logical name.
        slot: 1..16, or None: the slot that already holds a tool of that name, else the first
            free one.
        rights: whose save it is (a class's trainee: their own or a free slot, within their
            quota, checked by the library under its lock; ``calibrate.pendant_rules``).
        tr: the language of the refusals (they reach the trainee's notification).

    Returns:
        (slot, tool) as saved.

    Raises:
        WizardStateError: the wizard is not finished, or the library is full.
        tcpcal.TcpcalError: the library refused (bad slot, name used by another slot, the slot
            is another trainee's, the trainee's quota is full).
    """
    tool = wizard.to_tool(name)
    kwargs = rights.save_kwargs()
    if slot is None:
        found = library.find(name)
        if found is not None and not rights.mine(library.owners(), found[0]):
            raise WizardStateError(tr.gettext("The name {name!r} is taken by slot {slot}, a tool that is not yours: "
                                              "choose another name.").format(name=name, slot=found[0]))
        slot = found[0] if found is not None else library.first_free_slot()
        if slot is None:
            raise WizardStateError(tr.gettext("The tool library is full: pick a slot to overwrite."))
    with rights.in_words():
        library.save(slot, tool, activate=False, **kwargs)
    return slot, tool
