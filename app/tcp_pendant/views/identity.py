"""The name prompt of a classroom session: a modal that asks "Your name".

Shown to each browser of a per-browser server with a gradebook (``--shared`` has none). The
modal holds a text field labelled **"Your name"** and a **Join the class** button; the name is checked by
``classroom.names.validate_trainee_name`` (a refused name gets the reason, escaped, in the
modal) and handed to ``on_name``. Below it, a **Trainer token** field and an **Open trainer
view** button: the token is handed to ``on_token``, which says whether it was right (compared
with ``secrets.compare_digest`` by the server).

Reconnects: viser 1.1 gives the server no per-browser storage, so the page's own script
(``static/pendant.js``, ``client_script``) keeps an accepted name in the browser's
``localStorage`` and, when a new welcome window appears (reload, reconnect), types it into
"Your name" and presses **Join the class** like the trainee would: the server validates and
escapes it exactly as a typed name, and the gradebook files the new session under the same
trainee (the same name, the same id). The same script types the token of a ``/?trainer=TOKEN``
address into "Trainer token" (``PendantApp.trainer_url``).

Every callback runs through ``Session.on_loop``; the name is shown through ``escape_markdown``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from tcp_pendant.classroom.names import TraineeNameError, validate_trainee_name
from tcp_pendant.session import Session
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.gui_util import ButtonEvent, set_content, set_value, target_of

__all__ = ["IdentityPrompt", "NAME_LABEL", "TOKEN_LABEL"]

NAME_LABEL = "Your name"
TOKEN_LABEL = "Trainer token"
_MAX_TOKEN_CHARS = 200


class IdentityPrompt:
    """The "Your name" modal of one session.

    Args:
        session: the browser's session (its target is the client).
        on_name: called with the validated name; it may raise ``ValueError`` (shown in the modal).
        on_token: called with the typed token; returns True when it opened the trainer view; it
            may raise ``ValueError`` (too many wrong tokens: shown in the modal).

    Attributes:
        name: the accepted name (None until then).
        modal, name_field, start, message, token_field, open_trainer: the widgets (for tests).
    """

    def __init__(self, session: Session, on_name: Callable[[str], object],
                 on_token: Callable[[str], bool]) -> None:
        self.session = session
        self.name: str | None = None
        self._on_name = on_name
        self._on_token = on_token
        gui = target_of(session).gui
        self.modal = gui.add_modal("Welcome to the TCP Pendant")
        with self.modal:
            gui.add_markdown("Type the name your trainer should see in the class list "
                             "(this browser remembers it for reconnects).")
            self.name_field = gui.add_text(NAME_LABEL, "")
            self.start = gui.add_button("Join the class", color="green")
            self.message = gui.add_markdown("")
            gui.add_markdown("---\n*Trainer:* open the trainer address the server printed, or type "
                             "its token here.")
            self.token_field = gui.add_text(TOKEN_LABEL, "")
            self.open_trainer = gui.add_button("Open trainer view")
        self.banner = gui.add_markdown("", order=-1000.0, visible=False)
        self.start.on_click(session.on_loop(self._start))
        self.open_trainer.on_click(session.on_loop(self._trainer))

    def _start(self, _event: ButtonEvent | None = None) -> None:
        try:
            name = validate_trainee_name(self.name_field.value)
            self._on_name(name)
        except (TraineeNameError, ValueError) as exc:
            self.message.content = f"⚠ {escape_markdown(str(exc))}"
            return
        self.name = name
        self.modal.close()
        self.banner.content = f"Trainee: **{escape_markdown(name)}**"
        self.banner.visible = True

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
        self.modal.close()
