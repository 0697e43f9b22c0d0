"""The titles of the pendant's three tabs (Jog, Tool, Calibrate) in the session's language.

viser 1.1 cannot retitle a tab through its public API: a ``language`` change retitles them
through ``viser_adapter.set_tab_label``.
"""

from __future__ import annotations

from collections.abc import Callable

import viser

from tcp_pendant.session import Session, SessionChange
from tcp_pendant.translation import Translator
from tcp_pendant.views.viser_adapter import set_tab_label

__all__ = ["TAB_TITLES", "TabTitles", "tab_title"]

TAB_TITLES: dict[str, Callable[[Translator], str]] = {
    "jog": lambda tr: tr.pgettext("tab", "Jog"),
    "tool": lambda tr: tr.pgettext("tab", "Tool"),
    "calibrate": lambda tr: tr.pgettext("tab", "Calibrate"),
}
"""The tabs' titles by key, in a translator's language (msgids in the context ``tab``)."""


def tab_title(key: str, tr: Translator) -> str:
    """The title of the tab ``key`` (a key of :data:`TAB_TITLES`) in ``tr``'s language."""
    return TAB_TITLES[key](tr)


class TabTitles:
    """Keeps the tabs' titles in the session's language (``tabs``: key → tab)."""

    def __init__(self, session: Session, tabs: dict[str, viser.GuiTabHandle]) -> None:
        self.session = session
        self.tabs = tabs
        session.subscribe(self.on_change)

    def on_change(self, change: SessionChange) -> None:
        """A ``language`` change retitles the tabs."""
        if change.language:
            self.render()

    def render(self) -> None:
        """Every tab's title in the session's language."""
        for key, tab in self.tabs.items():
            set_tab_label(tab, tab_title(key, self.session.translator))
