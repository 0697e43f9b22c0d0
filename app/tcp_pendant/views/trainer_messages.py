"""The trainer's message box (viser GUI): a text to every trainee or to one.

:func:`build_message_controls` adds, where it is called (the trainer view's panel), a
"Message" text area, a "To" dropdown (all trainees, or one connected trainee by name: option
text, never markdown) and **Send** (``ClassRoom.send_message``: the class gradebook keeps the
message for each trainee until they dismiss it, and it reaches them on whichever server process
of the class holds their browser, ``views.class_notices``). :meth:`MessageControls.render`
re-lists the names (the trainer view calls it when the class changes).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import viser

from tcp_pendant.classroom.class_messages import MAX_MESSAGE_CHARS
from tcp_pendant.session import Session
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.gui_util import ButtonEvent, set_options, set_value

__all__ = ["TO_ALL", "MessageControl", "MessageControls", "build_message_controls"]

TO_ALL = "(all trainees) "
"""The first "To" choice (its trailing space keeps it apart from every trainee's name, which is
stripped)."""


class MessageControl(Protocol):
    """What the message box needs of the class (``ClassRoom``)."""

    def connected_names(self) -> list[str]: ...

    def send_message(self, text: str, to: str | None = None) -> str: ...


@dataclass(eq=False)
class MessageControls:
    """The message box's widgets (for tests) and its Send.

    Attributes:
        text: the text area; to: the dropdown; send: the button; status: what the last Send did.
    """

    session: Session
    control: MessageControl
    text: viser.GuiTextHandle
    to: viser.GuiDropdownHandle[str]
    send: viser.GuiButtonHandle
    status: viser.GuiMarkdownHandle

    def render(self) -> None:
        """Re-list the connected trainees in "To" (the choice kept while its trainee is there)."""
        set_options(self.to, (TO_ALL, *self.control.connected_names()))

    def _send(self, _event: ButtonEvent | None = None) -> None:
        text = self.text.value
        if not isinstance(text, str):
            raise ValueError("The message must be text.")
        picked = str(self.to.value)
        to = None if picked == TO_ALL else picked
        self.status.content = escape_markdown(self.control.send_message(text, to))
        set_value(self.text, "")


def build_message_controls(gui: viser.GuiApi, class_control: MessageControl, session: Session) -> MessageControls:
    """Add the message box to ``gui`` (in the container open where it is called) for the
    trainer's ``session``; Send goes to ``class_control``."""
    with gui.add_folder("Message to trainees"):
        text = gui.add_text("Message", "", multiline=True,
                            hint=f"Plain text, at most {MAX_MESSAGE_CHARS} characters; it stays on the "
                                 "trainee's screen until they dismiss it.")
        to = gui.add_dropdown("To", (TO_ALL,), initial_value=TO_ALL)
        send = gui.add_button("Send", color="blue")
        status = gui.add_markdown("")
    controls = MessageControls(session, class_control, text, to, send, status)
    send.on_click(session.loop.on_loop(controls._send))
    controls.render()
    return controls
