"""The trainer dashboard's fixed words in the dashboard browser's own language.

Each folder builder of ``views.dashboard`` hands a handle over with the English messages of its
label, hint or content (``words(handle, label=N_("Reset wizard"), hint=N_(...))``), and makes
its dropdowns with the English messages of their choices (:meth:`DashboardWords.dropdown`;
names such as tool keys stay as they are). :meth:`DashboardWords.relabel` shows them all again in the
session's language at a ``language`` change; a dropdown keeps its choice across the change.
A choice is read back in English (:meth:`DashboardWords.english`) whether the browser sent it in
the language it was shown in or in English.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeVar

import viser

from tcp_pendant.session import Session
from tcp_pendant.translation import Translator
from tcp_pendant.views.gui_util import set_options

__all__ = ["DashboardWords"]

_H = TypeVar("_H")
_TEXTS = ("label", "hint", "content", "title")


_Choice = tuple[viser.GuiDropdownHandle[str], tuple[str, ...], tuple[str, ...]]


class DashboardWords:
    """The dashboard's fixed words of one session (module docstring)."""

    def __init__(self, session: Session) -> None:
        self.session = session
        self._shown_in: Translator = session.translator       # the language the handles show
        self._texts: list[tuple[object, dict[str, str]]] = []
        self._choices: dict[int, _Choice] = {}

    def __call__(self, handle: _H, **messages: str) -> _H:
        """Show ``handle``'s ``label``/``hint``/``content``/``title`` messages (English msgids) in
        the session's language, now and at every :meth:`relabel`; returns ``handle``."""
        unknown = set(messages) - set(_TEXTS)
        if unknown:
            raise ValueError(f"No text {', '.join(sorted(unknown))} on a dashboard handle; use {', '.join(_TEXTS)}.")
        self._texts.append((handle, messages))
        self._show(handle, messages)
        return handle

    def _show(self, handle: object, messages: dict[str, str]) -> None:
        _ = self._shown_in.gettext
        for attribute, message in messages.items():
            text = _(message)
            if getattr(handle, attribute) != text:
                setattr(handle, attribute, text)

    def dropdown(self, gui: viser.GuiApi, label: str, messages: Sequence[str], names: Sequence[str] = (),
                 value: str | None = None, hint: str | None = None) -> viser.GuiDropdownHandle[str]:
        """A new dropdown in ``gui`` made in the session's language at once: its options
        ``messages`` (English msgids) translated, then ``names`` as they are; its value ``value``
        (English or a name; default: the first); ``label`` and ``hint`` English msgids; all
        re-rendered at :meth:`relabel`."""
        _ = self._shown_in.gettext
        options = tuple(_(m) for m in messages) + tuple(names)
        english = (tuple(messages) + tuple(names))[0] if value is None else value
        dropdown = gui.add_dropdown(_(label), options, initial_value=_(english) if english in messages else english,
                                    hint=None if hint is None else _(hint))
        texts = {"label": label} if hint is None else {"label": label, "hint": hint}
        self._texts.append((dropdown, texts))
        self._choices[id(dropdown)] = (dropdown, tuple(messages), tuple(names))
        return dropdown

    def _show_choices(self, entry: _Choice, english: str) -> None:
        dropdown, messages, names = entry
        _ = self._shown_in.gettext
        options = tuple(_(m) for m in messages) + names
        set_options(dropdown, options, _(english) if english in messages else english)

    def english(self, dropdown: viser.GuiDropdownHandle[str]) -> str:
        """The choice of ``dropdown`` as its English message (a name as it is; an unknown text as
        the browser sent it: the caller refuses it). The browser may send the option as shown or
        in English."""
        value = str(dropdown.value)
        entry = self._choices.get(id(dropdown))
        if entry is None:
            return value
        _ = self._shown_in.gettext
        return next((m for m in entry[1] if value in (m, _(m))), value)

    def relabel(self) -> None:
        """Every text and choice handed over, in the session's language (choices kept)."""
        chosen = [(entry, self.english(entry[0])) for entry in self._choices.values()]
        self._shown_in = self.session.translator
        for handle, messages in self._texts:
            self._show(handle, messages)
        for entry, english in chosen:
            self._show_choices(entry, english)

    def follow(self) -> None:
        """:meth:`relabel` when the session's language is not the one shown (a view re-rendered
        with the dashboard calls it at each render)."""
        if self._shown_in is not self.session.translator:
            self.relabel()
