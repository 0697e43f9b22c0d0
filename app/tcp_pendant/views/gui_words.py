"""The fixed words of a view's GUI handles in the session's language (viser GUI).

A view builds its handles with English labels and hints marked for extraction
(``gui.add_button(N_("Start"), hint=N_("..."))``) and hands each to :meth:`GuiWords.keep`,
which remembers those English texts as the handle's msgids and shows them in the session's
language at once; on a ``language`` change the view calls :meth:`GuiWords.relabel` and every
kept handle shows its label and hint in the new language. A handle whose label the view
composes itself (a count, a tool name) is not kept: the view's render sets it.
"""

from __future__ import annotations

from typing import Protocol, TypeVar

from tcp_pendant.translation import Translator

__all__ = ["GuiWords"]


class _Labelled(Protocol):
    label: str


H = TypeVar("H", bound=_Labelled)
"""A viser GUI handle with a label (and maybe a hint)."""


class GuiWords:
    """The kept handles of one view with their English label and hint (module docstring)."""

    def __init__(self, tr: Translator) -> None:
        self._tr = tr
        self._kept: list[tuple[_Labelled, str, str | None]] = []

    def keep(self, handle: H) -> H:
        """Remember ``handle``'s label and hint (English msgids) and show them in the current
        language; returns ``handle``."""
        hint = getattr(handle, "hint", None)
        self._kept.append((handle, handle.label, hint if isinstance(hint, str) and hint else None))
        self._show(handle, handle.label, hint if isinstance(hint, str) and hint else None)
        return handle

    def relabel(self, tr: Translator) -> None:
        """Show every kept handle's label and hint in ``tr``'s language."""
        self._tr = tr
        for handle, label, hint in self._kept:
            self._show(handle, label, hint)

    def _show(self, handle: _Labelled, label: str, hint: str | None) -> None:
        text = self._tr.gettext(label)
        if handle.label != text:                 # an unchanged text sends nothing
            handle.label = text
        if hint is not None:
            words = self._tr.gettext(hint)
            if getattr(handle, "hint", None) != words:
                setattr(handle, "hint", words)
