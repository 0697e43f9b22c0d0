"""The name prompt of a classroom session: a modal that asks "Your name".

Shown to each browser of a per-browser server with a gradebook (``--shared`` has none). The
modal holds a text field labelled **"Your name"** and a **Join the class** button; the name is
handed to ``on_name`` with what the **Browser key** field holds, and a refused name
(``TraineeNameError`` / ``ValueError``: invalid, a look-alike of a classmate's, connected in
another browser, held by another browser) gets the reason, escaped, in the modal. Below it, a
**Trainer token** field and an **Open trainer view** button, which the page script shows only
on a page opened as ``/?trainer`` (a trainee's welcome window has no trainer rows): the token
is handed to ``on_token``, which says whether it was right (compared with
``secrets.compare_digest`` by the server).

Browser keys and reconnects: viser 1.1 gives the server no per-browser storage, so the page's
own script (``serve/static/pendant.js``, ``serve.client_script``) keeps the accepted name and the browser
key in the browser's ``localStorage``. The server hands a newly issued key to that script in a
hidden element, ``<div hidden data-tcp-pendant-key="KEY">`` (:data:`KEY_ATTRIBUTE`; the key is
ours, 43 characters of ``A-Z a-z 0-9 - _``, never user text), outside the modal. When a new
welcome window appears (reload, reconnect, server restart) the script types the name into
"Your name" and the key into "Browser key" (a row it hides) and presses **Join the class** like
the trainee would: the server checks them exactly as typed ones, and the gradebook files the
new session under the same trainee (the same name, the same id) because the key proves it is
the same browser.

A prompt opened again (:meth:`IdentityPrompt.reopen`: the trainer released the name, or the
same browser joined in another tab) carries a hidden ``data-tcp-pendant-hold`` element (the
script does not join by itself in that window, so two tabs cannot take the name from each
other in a loop) or ``data-tcp-pendant-forget`` (released: the script also forgets the name
and key it kept).

Every callback runs through ``SessionLoop.on_loop``; the name is shown through ``escape_markdown``.
"""

from __future__ import annotations

import re
from collections.abc import Callable

import viser

from tcp_pendant.classroom.names import TraineeNameError
from tcp_pendant.session import Session
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.gui_util import ButtonEvent, set_content, set_value, target_of

__all__ = ["HOLD_ATTRIBUTE", "FORGET_ATTRIBUTE", "IdentityPrompt", "KEY_ATTRIBUTE", "KEY_LABEL", "NAME_LABEL",
           "TOKEN_LABEL"]

NAME_LABEL = "Your name"
KEY_LABEL = "Browser key"
TOKEN_LABEL = "Trainer token"
KEY_ATTRIBUTE = "data-tcp-pendant-key"
"""The hidden element that hands a new browser key to the page script."""
HOLD_ATTRIBUTE = "data-tcp-pendant-hold"
"""In a reopened welcome window: the page script does not join by itself."""
FORGET_ATTRIBUTE = "data-tcp-pendant-forget"
"""In a reopened welcome window: the page script forgets the name and key it kept (and holds)."""
_MAX_TOKEN_CHARS = 200
_MAX_KEY_CHARS = 200
_KEY_SHAPE = re.compile(r"[A-Za-z0-9_-]{1,200}")


class IdentityPrompt:
    """The "Your name" modal of one session.

    Args:
        session: the browser's session (its target is the client).
        on_name: called with the typed name (as the browser sent it) and browser key; returns
            the name as stored and the browser key issued now (to hand to the page script) or
            None; it may raise ``ValueError`` (shown in the modal).
        on_token: called with the typed token; returns True when it opened the trainer view; it
            may raise ``ValueError`` (too many wrong tokens: shown in the modal).

    Attributes:
        name: the accepted name (None until then, and again after :meth:`reopen`).
        modal, name_field, key_field, start, message, token_field, open_trainer: the widgets of
            the modal on show (for tests); marker_html: its hold or forget element (None: a
            first welcome window); key_html: the element holding the last issued key (None:
            none issued to this session).
    """

    def __init__(self, session: Session, on_name: Callable[[object, str], tuple[str, str | None]],
                 on_token: Callable[[str], bool]) -> None:
        self.session = session
        self.name: str | None = None
        self._on_name = on_name
        self._on_token = on_token
        gui = target_of(session).gui
        self.banner = gui.add_markdown("", order=-1000.0, visible=False)
        self.key_html: viser.GuiHtmlHandle | None = None
        self.marker_html: viser.GuiHtmlHandle | None = None
        self._build("")

    def _build(self, marker: str) -> None:
        gui = target_of(self.session).gui
        self.modal = gui.add_modal("Welcome to the TCP Pendant")
        with self.modal:
            gui.add_markdown("Type the name your trainer should see in the class list "
                             "(this browser remembers it for reconnects).")
            self.name_field = gui.add_text(NAME_LABEL, "")
            self.key_field = gui.add_text(KEY_LABEL, "", hint="Filled in by this page for a browser that "
                                          "joined before; leave it empty.")
            self.start = gui.add_button("Join the class", color="green")
            self.message = gui.add_markdown("")
            self.marker_html = gui.add_html(f"<div hidden {marker}></div>") if marker else None
            gui.add_markdown("*Trainer:* open the trainer address the server printed (/?trainer=...), "
                             "or open /?trainer and type the token here.")
            self.token_field = gui.add_text(TOKEN_LABEL, "")
            self.open_trainer = gui.add_button("Open trainer view")
        self._modal_open = True
        self.start.on_click(self.session.loop.on_loop(self._start))
        self.open_trainer.on_click(self.session.loop.on_loop(self._trainer))

    def _start(self, _event: ButtonEvent | None = None) -> None:
        if self.name is not None:
            return
        key = str(self.key_field.value or "")[:_MAX_KEY_CHARS]
        try:
            name, new_key = self._on_name(self.name_field.value, key)
        except (TraineeNameError, ValueError) as exc:
            self.message.content = f"⚠ {escape_markdown(str(exc))}"
            return
        set_value(self.key_field, "")
        self.accepted(name, new_key)

    def accepted(self, name: str, new_key: str | None) -> None:
        """The class took the browser as ``name``: close the modal, show the banner, and hand a
        newly issued key to the page script."""
        self.name = name
        self._close_modal()
        self.banner.content = f"Trainee: **{escape_markdown(name)}**"
        self.banner.visible = True
        if new_key is not None:
            if not _KEY_SHAPE.fullmatch(new_key):        # ours, but it goes into HTML: check anyway
                raise ValueError("a browser key must be letters, digits, '-' and '_' only")
            if self.key_html is not None:
                self.key_html.remove()
            self.key_html = target_of(self.session).gui.add_html(f'<div hidden {KEY_ATTRIBUTE}="{new_key}"></div>',
                                                                 order=-1001.0)

    def reopen(self, message: str, *, forget: bool) -> None:
        """Show the welcome window again with ``message`` (plain text): the session is no longer
        the trainee it was. ``forget``: the page script also drops the name and key it kept."""
        self.name = None
        self.banner.visible = False
        if self.key_html is not None:
            self.key_html.remove()
            self.key_html = None
        self._close_modal()
        self._build(FORGET_ATTRIBUTE if forget else HOLD_ATTRIBUTE)
        self.message.content = f"⚠ {escape_markdown(message)}"

    def _trainer(self, _event: ButtonEvent | None = None) -> None:
        token = str(self.token_field.value)[:_MAX_TOKEN_CHARS]
        set_value(self.token_field, "")
        try:
            opened = self._on_token(token)
        except ValueError as exc:                  # too many wrong tokens: wait
            set_content(self.message, f"⚠ {escape_markdown(str(exc))}")
            return
        if not opened:
            self.message.content = "⚠ That trainer token is not right; type the token the server printed."
            return
        if self.session.views.get("identity") is self:    # else the dashboard cleared the GUI, this modal too
            self._close_modal()

    def _close_modal(self) -> None:
        if self._modal_open:
            self._modal_open = False
            self.modal.close()
