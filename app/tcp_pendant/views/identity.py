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

from tcp_pendant.controller.words import error_text
from tcp_pendant.classroom.names import TraineeNameError
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.text_escape import escape_html, escape_markdown
from tcp_pendant.translation import N_, Translator
from tcp_pendant.views.gui_util import ButtonEvent, set_content, set_value, target_of

__all__ = ["HOLD_ATTRIBUTE", "FORGET_ATTRIBUTE", "IdentityPrompt", "KEY_ATTRIBUTE", "KEY_LABEL", "LABELS_ATTRIBUTE",
           "NAME_LABEL", "TOKEN_LABEL", "labels_html"]

NAME_LABEL = N_("Your name")
KEY_LABEL = N_("Browser key")
TOKEN_LABEL = N_("Trainer token")
JOIN_LABEL = N_("Join the class")
OPEN_TRAINER_LABEL = N_("Open trainer view")
TRAINER_LINE = N_("*Trainer:* open the trainer address the server printed (/?trainer=...), or open /?trainer and "
                  "type the token here.")
BANNER = N_("Trainee: **{name}**")
LABELS_ATTRIBUTE = "data-tcp-pendant-labels"
"""The hidden element that hands the page script the welcome window's labels in the session's
language (``data-name``, ``data-key``, ``data-join``, ``data-token``, ``data-open-trainer``,
``data-trainer-line``, ``data-banner``; the script looks for them by their text)."""
KEY_ATTRIBUTE = "data-tcp-pendant-key"
"""The hidden element that hands a new browser key to the page script."""
HOLD_ATTRIBUTE = "data-tcp-pendant-hold"
"""In a reopened welcome window: the page script does not join by itself."""
FORGET_ATTRIBUTE = "data-tcp-pendant-forget"
"""In a reopened welcome window: the page script forgets the name and key it kept (and holds)."""
_MAX_TOKEN_CHARS = 200
_MAX_KEY_CHARS = 200
_KEY_SHAPE = re.compile(r"[A-Za-z0-9_-]{1,200}")


def labels_html(tr: Translator) -> str:
    """The hidden element of :data:`LABELS_ATTRIBUTE`: the welcome window's labels in ``tr``'s
    language (escaped attribute values; the banner's text before the name)."""
    _ = tr.gettext
    labels = {"name": _(NAME_LABEL), "key": _(KEY_LABEL), "join": _(JOIN_LABEL), "token": _(TOKEN_LABEL),
              "open-trainer": _(OPEN_TRAINER_LABEL),
              "trainer-line": _(TRAINER_LINE).replace("*", "").split(" ", 1)[0],
              "banner": _(BANNER).split("**", 1)[0].strip()}
    attributes = " ".join(f'data-{key}="{escape_html(value)}"' for key, value in labels.items())
    return f"<div hidden {LABELS_ATTRIBUTE} {attributes}></div>"


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
        self.labels_html = gui.add_html(labels_html(session.translator), order=-1002.0)
        self.key_html: viser.GuiHtmlHandle | None = None
        self.marker_html: viser.GuiHtmlHandle | None = None
        self._marker = ""
        self._message: tuple[str, dict[str, str]] | None = None    # the modal's warning: msgid, values
        self._build("")
        session.subscribe(self.on_change)

    def on_change(self, change: SessionChange) -> None:
        """The session's language changed: the welcome window (rebuilt, what was typed kept), its
        banner and the labels the page script looks for, in it."""
        if not change.language:
            return
        tr = self.session.translator
        set_content(self.labels_html, labels_html(tr))
        if self.name is not None:
            set_content(self.banner, tr.gettext(BANNER).format(name=escape_markdown(self.name)))
        if self._modal_open:
            typed = (self.name_field.value, self.key_field.value, self.token_field.value)
            self._close_modal()
            self._build(self._marker)
            set_value(self.name_field, typed[0])
            set_value(self.key_field, typed[1])
            set_value(self.token_field, typed[2])
            self._show_message()

    def _say(self, message: str, **values: str) -> None:
        """A warning in the modal: ``message`` (an English msgid) with ``values`` (plain text,
        escaped here), in the session's language (again after a language change)."""
        self._message = (message, values)
        self._show_message()

    def _show_message(self) -> None:
        if self._message is None:
            return
        message, values = self._message
        text = self.session.translator.gettext(message) if message else "{text}"
        set_content(self.message, "⚠ " + text.format(**{k: escape_markdown(v) for k, v in values.items()}))

    def _build(self, marker: str) -> None:
        gui = target_of(self.session).gui
        _ = self.session.translator.gettext
        self._marker = marker
        self.modal = gui.add_modal(_("Welcome to the TCP Pendant"))
        with self.modal:
            gui.add_markdown(_("Type the name your trainer should see in the class list "
                               "(this browser remembers it for reconnects)."))
            self.name_field = gui.add_text(_(NAME_LABEL), "")
            self.key_field = gui.add_text(_(KEY_LABEL), "", hint=_("Filled in by this page for a browser that "
                                                                   "joined before; leave it empty."))
            self.start = gui.add_button(_(JOIN_LABEL), color="green")
            self.message = gui.add_markdown("")
            self.marker_html = gui.add_html(f"<div hidden {marker}></div>") if marker else None
            gui.add_markdown(_(TRAINER_LINE))
            self.token_field = gui.add_text(_(TOKEN_LABEL), "")
            self.open_trainer = gui.add_button(_(OPEN_TRAINER_LABEL))
        self._modal_open = True
        self.start.on_click(self.session.loop.on_loop(self._start))
        self.open_trainer.on_click(self.session.loop.on_loop(self._trainer))

    def _start(self, _event: ButtonEvent | None = None) -> None:
        if self.name is not None:
            return
        key = str(self.key_field.value or "")[:_MAX_KEY_CHARS]
        try:
            name, new_key = self._on_name(self.name_field.value, key)
        except TraineeNameError as exc:
            self._say(exc.message, **exc.values)
            return
        except ValueError as exc:
            self._say("", text=error_text(exc, self.session.translator))
            return
        set_value(self.key_field, "")
        self.accepted(name, new_key)

    def accepted(self, name: str, new_key: str | None) -> None:
        """The class took the browser as ``name``: close the modal, show the banner, and hand a
        newly issued key to the page script."""
        self.name = name
        self._message = None
        self._close_modal()
        self.banner.content = self.session.translator.gettext(BANNER).format(name=escape_markdown(name))
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
        self._say("", text=message)

    def _trainer(self, _event: ButtonEvent | None = None) -> None:
        token = str(self.token_field.value)[:_MAX_TOKEN_CHARS]
        set_value(self.token_field, "")
        try:
            opened = self._on_token(token)
        except ValueError as exc:                  # too many wrong tokens: wait
            self._say("", text=error_text(exc, self.session.translator))
            return
        if not opened:
            self._say(N_("That trainer token is not right; type the token the server printed."))
            return
        if self.session.views.get("identity") is self:    # else the dashboard cleared the GUI, this modal too
            self._close_modal()

    def _close_modal(self) -> None:
        if self._modal_open:
            self._modal_open = False
            self.modal.close()
