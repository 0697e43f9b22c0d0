"""A barrier message on a browser's own socket: after a change made on the server, wait until
the page has applied everything sent before it.

viser sends a client's messages in order on one websocket and its client applies them in order.
:class:`Barrier` keeps one small markdown element in the session's panel; :meth:`Barrier.sync`
sets its content to a fresh token and waits until the page's DOM holds that token: every GUI
and scene message sent before it has reached the page by then. The token is written in the
pseudo-locale's brackets (``⟦barrier 3⟧``), so the pseudo-locale checks
(``support.pseudo_text.untranslated_words``) pass over it.
"""

from __future__ import annotations

import itertools
from typing import Any

__all__ = ["NEXT_FRAMES_JS", "Barrier", "show_tab"]

TIMEOUT_MS = 60_000
NEXT_FRAMES_JS = "() => new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done)))"
"""Resolves after the browser has drawn two more frames (React's updates and the layout done)."""


def show_tab(page: Any, index: int) -> None:
    """Click the page's ``index``-th visible tab and wait until it is selected and drawn (a
    tab's panel is the browser's own business: no server message to wait for)."""
    tab = page.locator("[role=tab]").filter(visible=True).nth(index)
    tab.click()
    page.wait_for_function("e => e.getAttribute('aria-selected') === 'true'", arg=tab.element_handle(),
                           timeout=TIMEOUT_MS)
    page.evaluate(NEXT_FRAMES_JS)


class Barrier:
    """A barrier element in ``session``'s panel (the session's viser target)."""

    def __init__(self, session: Any) -> None:
        self._count = itertools.count(1)
        self.token = "⟦barrier 0⟧"
        self.handle = session.target.gui.add_markdown(self.token)

    def sync(self, page: Any) -> None:
        """Send a new token and wait until ``page`` shows it (attached to the DOM)."""
        self.token = f"⟦barrier {next(self._count)}⟧"
        self.handle.content = self.token
        page.wait_for_function("t => document.body.innerText.includes(t) || document.body.textContent.includes(t)",
                               arg=self.token, timeout=TIMEOUT_MS)
