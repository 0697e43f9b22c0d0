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
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.views.dashboard_words import DashboardWords
from tcp_pendant.views.gui_util import ButtonEvent, set_options, set_value

__all__ = ["TO_ALL", "MessageControl", "MessageControls", "build_message_controls"]

MESSAGE_HINT = N_("Plain text, at most {n} characters; it stays on the trainee's screen until they dismiss it.")
"""The message box's hint (``{n}``: the most characters)."""
TO_ALL_WORDS = N_("(all trainees)")
TO_ALL = TO_ALL_WORDS + " "
"""The first "To" choice (its trailing space keeps it apart from every trainee's name, which is
stripped), in English; shown in the dashboard's language."""


class MessageControl(Protocol):
    """What the message box needs of the class (``ClassRoom``)."""

    def connected_names(self) -> list[str]: ...

    def send_message(self, text: str, to: str | None = None, *, tr: Translator = ENGLISH) -> str: ...


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
    words: DashboardWords

    def _to_all(self) -> str:
        return self.session.translator.gettext(TO_ALL_WORDS) + " "

    def render(self) -> None:
        """Re-list the connected trainees in "To" (the choice kept while its trainee is there),
        the words in the dashboard's language."""
        self.words.follow()
        hint = self.session.translator.gettext(MESSAGE_HINT).format(n=MAX_MESSAGE_CHARS)
        if self.text.hint != hint:
            self.text.hint = hint
        to_all = self._to_all()
        keep = to_all if str(self.to.value).endswith(" ") else None       # "(all trainees) " in any language
        set_options(self.to, (to_all, *self.control.connected_names()), keep)

    def _send(self, _event: ButtonEvent | None = None) -> None:
        text = self.text.value
        if not isinstance(text, str):
            raise ValueError("The message must be text.")
        picked = str(self.to.value)
        to = None if picked in (TO_ALL, self._to_all()) else picked
        self.status.content = escape_markdown(self.control.send_message(text, to, tr=self.session.translator))
        set_value(self.text, "")


def build_message_controls(gui: viser.GuiApi, class_control: MessageControl, session: Session) -> MessageControls:
    """Add the message box to ``gui`` (in the container open where it is called) for the
    trainer's ``session``; Send goes to ``class_control``."""
    words = DashboardWords(session)
    with words(gui.add_folder(""), label=N_("Message to trainees")):
        text = words(gui.add_text("", "", multiline=True), label=N_("Message"))
        to_all = session.translator.gettext(TO_ALL_WORDS) + " "
        to = words(gui.add_dropdown("", (to_all,), initial_value=to_all), label=N_("To"))
        send = words(gui.add_button("", color="blue"), label=N_("Send"))
        status = gui.add_markdown("")
    controls = MessageControls(session, class_control, text, to, send, status, words)
    send.on_click(session.loop.on_loop(controls._send))
    controls.render()
    return controls
