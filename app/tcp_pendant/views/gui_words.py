"""The fixed words of a view's GUI handles in the session's language (viser GUI).

A view builds its handles with English labels and hints marked for extraction
(``gui.add_button(N_("Start"), hint=N_("..."))``) and hands each to :meth:`GuiWords.keep`,
which remembers those English texts as the handle's msgids and shows them in the session's
language at once; on a ``language`` change the view calls :meth:`GuiWords.relabel` and every
kept handle shows its label and hint in the new language. A handle whose label the view
composes itself (a count, a tool name) is not kept: the view's render sets it.
"""

from __future__ import annotations

from typing import TypeVar

from tcp_pendant.translation import Translator

__all__ = ["GuiWords"]

H = TypeVar("H")
"""A viser GUI handle with a label (and maybe a hint: viser's handles share no type for them)."""


class GuiWords:
    """The kept handles of one view with their English label and hint (module docstring)."""

    def __init__(self, tr: Translator) -> None:
        self._tr = tr
        self._kept: list[tuple[object, str, str | None]] = []

    def keep(self, handle: H) -> H:
        """Remember ``handle``'s label and hint (English msgids) and show them in the current
        language; returns ``handle``."""
        label, hint = getattr(handle, "label", None), getattr(handle, "hint", None)
        if not isinstance(label, str):
            raise TypeError(f"{type(handle).__name__} has no label to translate")
        kept = (handle, label, hint if isinstance(hint, str) and hint else None)
        self._kept.append(kept)
        self._show(*kept)
        return handle

    def relabel(self, tr: Translator) -> None:
        """Show every kept handle's label and hint in ``tr``'s language."""
        self._tr = tr
        for handle, label, hint in self._kept:
            self._show(handle, label, hint)

    def _show(self, handle: object, label: str, hint: str | None) -> None:
        text = self._tr.gettext(label)
        if getattr(handle, "label", None) != text:      # an unchanged text sends nothing
            setattr(handle, "label", text)
        if hint is not None:
            words = self._tr.gettext(hint)
            if getattr(handle, "hint", None) != words:
                setattr(handle, "hint", words)
