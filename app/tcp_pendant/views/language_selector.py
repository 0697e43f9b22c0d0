"""The language selector of one browser: a dropdown of the languages, each named in itself.

Choosing one runs the session's command (:meth:`Session.set_language`), whose ``language``
change makes every view re-render its texts: the pose, the touches and a running wizard stay.
The selector changes only its own session: another browser keeps its language. Its options
are :data:`tcp_pendant.translation.LANGUAGE_NAMES` (the pseudo-locale is listed only in a
session that uses it: the tests set it by the command). Its label is the word "Language" in
the session's language followed by the English word (``Sprache (Language)``), so a trainee
shown a language they cannot read finds the way back.
"""

from __future__ import annotations

import viser

from tcp_pendant.session import Session, SessionChange
from tcp_pendant.translation import LANGUAGE_NAMES, PSEUDO_LANGUAGE, N_, Translator
from tcp_pendant.views.gui_util import set_value, target_of

__all__ = ["LANGUAGE_LABEL", "LanguageSelector", "language_options", "selector_label"]

LANGUAGE_LABEL = N_("Language")
"""The selector's word, in English after the session's language's (:func:`selector_label`)."""
PSEUDO_NAME = "⟦Ƥšéûðö⟧"
"""The pseudo-locale's entry (tests only)."""


def language_options(current: str) -> dict[str, str]:
    """The selector's entries, name → code: the offered languages, and the pseudo-locale when
    it is ``current``."""
    names = {name: code for code, name in LANGUAGE_NAMES.items()}
    if current == PSEUDO_LANGUAGE:
        names[PSEUDO_NAME] = PSEUDO_LANGUAGE
    return names


def selector_label(tr: Translator) -> str:
    """``Language``, or ``Sprache (Language)`` in another language than English."""
    word = tr.gettext(LANGUAGE_LABEL)
    return word if word == LANGUAGE_LABEL else f"{word} ({LANGUAGE_LABEL})"


class LanguageSelector:
    """The dropdown in the current GUI container of ``session.target.gui``."""

    def __init__(self, session: Session) -> None:
        self.session = session
        gui = target_of(session).gui
        self._codes = language_options(session.language)
        self.dropdown: viser.GuiDropdownHandle[str] = gui.add_dropdown(
            self._label(), tuple(self._codes), initial_value=self._name(session.language))
        self.dropdown.on_update(session.loop.on_loop(self._on_choice))
        session.subscribe(self.on_change)

    def _label(self) -> str:
        return selector_label(self.session.translator)

    def _name(self, code: str) -> str:
        return next(name for name, c in self._codes.items() if c == code)

    def _on_choice(self, event: viser.GuiEvent[viser.GuiDropdownHandle[str]]) -> None:
        if event.client is None:
            return                                    # our own assignment
        code = self._codes.get(str(event.target.value))
        if code is None:
            raise ValueError(f"Unknown language {event.target.value!r}; choose one of the list.")
        self.session.set_language(code)

    def on_change(self, change: SessionChange) -> None:
        """The session's language changed (this selector or a command): label and value follow."""
        if not change.language:
            return
        codes = language_options(self.session.language)
        if codes != self._codes:
            self._codes = codes
            self.dropdown.options = tuple(codes)
        self.dropdown.label = self._label()
        name = self._name(self.session.language)
        if self.dropdown.value != name:
            set_value(self.dropdown, name)
