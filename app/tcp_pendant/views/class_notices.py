"""The trainee's side of the trainer's words (viser GUI): the exercise's instructions and the
trainer's messages, pinned at the top of the panel.

* **Instructions banner**: while the class's rules carry instructions
  (``Session.rules.instructions``, set by the classroom), the first element of the panel shows
  them, above the tabs; in an exercise whose trainer typed none, the default brief
  (``calibrate.exercise_brief``: what to calibrate, how it is graded, what is hidden); hidden
  in free practice without instructions.
* **Message box**: the oldest message the session keeps (``Session.messages``) with who it was
  for and when, how many more wait, and a **Dismiss** button (``Session.dismiss_message`` of
  the message shown: a click that arrives after another message took its place dismisses
  nothing else). Messages queue: the next one shows when this one is dismissed. The box is a
  folder holding an empty marker of class ``trainer-message`` (a constant): the page script
  (``serve/static/pendant.js``) pins it at the top of the panel while the panel scrolls, so it is
  in view on whatever tab and wherever the trainee scrolled to.
* **Toast**: each message this view shows for the first time also comes as a notification
  (``Session.notify``), in the corner of the screen, whatever the trainee is looking at.

Both texts are the trainer's browser's (a stranger's): every line goes through
``text_escape.escape_markdown_lines``. The view renders from the session's state on its
``notice`` signal; the only command it sends is Dismiss (``SessionLoop.on_loop``).
"""

from __future__ import annotations

from tcp_pendant.calibrate.exercise_brief import default_instructions_markdown
from tcp_pendant.session import ClassMessage
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.text_escape import escape_markdown, escape_markdown_lines
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.views.gui_util import ButtonEvent, set_content, target_of

__all__ = ["PIN_CLASS", "TOAST_TITLE", "ClassNoticeView", "instructions_markdown", "message_markdown"]

PIN_CLASS = "trainer-message"
"""The class of the empty marker in the message's folder: the page script pins the folder."""
TOAST_TITLE = N_("Message from the trainer")
MESSAGE_FOLDER = N_("Message")
DISMISS = N_("Dismiss")
DISMISS_HINT = N_("The message goes; the next one, if any, shows.")
BANNER_ORDER = -1100.0
"""The instructions' place: above every other element of the panel (the identity banner is -1000)."""


def instructions_markdown(instructions: str, *, tr: Translator = ENGLISH) -> str:
    """The banner's markdown for the exercise's ``instructions`` (plain text, escaped), its
    heading in ``tr``'s language."""
    heading = tr.gettext("**Exercise**")
    return f"{heading}\n\n{escape_markdown_lines(instructions)}"


def message_markdown(message: ClassMessage, waiting: int, *, tr: Translator = ENGLISH) -> str:
    """The message box's markdown in ``tr``'s language: who it was for, when (UTC), the text
    (escaped, as the trainer typed it) and how many more messages wait after it."""
    _ = tr.gettext
    when = message.sent_at_utc[11:16]
    head = (_("**Message from the trainer** to the class, {time} UTC").format(time=when) if message.to is None
            else _("**Message from the trainer** to you ({name}), {time} UTC").format(
                name=escape_markdown(message.to), time=when))
    more = ("\n\n" + tr.ngettext("*{n} more message after this one.*", "*{n} more messages after this one.*",
                                  waiting).format(n=waiting)) if waiting else ""
    return f"{head}\n\n{escape_markdown_lines(message.text)}{more}"


class ClassNoticeView:
    """The instructions banner and the message box of one session (see the module docstring).

    Attributes:
        banner, box, message_md, dismiss: the widgets (for tests).
        shown: the message on show (None: none).
    """

    def __init__(self, session: Session) -> None:
        self.session = session
        gui = target_of(session).gui
        self.banner = gui.add_markdown("", order=BANNER_ORDER, visible=False)
        _ = session.translator.gettext
        self.box = gui.add_folder(_(MESSAGE_FOLDER), order=BANNER_ORDER + 1, visible=False)
        with self.box:
            gui.add_html(f'<span class="{PIN_CLASS}"></span>')    # a constant: the page script pins the folder
            self.message_md = gui.add_markdown("")
            self.dismiss = gui.add_button(_(DISMISS), hint=_(DISMISS_HINT))
        self.shown: ClassMessage | None = None
        self._toasted: set[int] = set()
        self.dismiss.on_click(session.loop.on_loop(self._on_dismiss))
        session.subscribe(self.on_change)
        self.render()

    def on_change(self, change: SessionChange) -> None:
        if change.language:
            _ = self.session.translator.gettext
            self.box.label, self.dismiss.label, self.dismiss.hint = _(MESSAGE_FOLDER), _(DISMISS), _(DISMISS_HINT)
        if change.notice or change.language:
            self.render()

    def _on_dismiss(self, _event: ButtonEvent | None = None) -> None:
        if self.shown is not None:
            self.session.dismiss_message(self.shown.message_id)

    def render(self) -> None:
        """The banner and the message box from the session's rules and messages."""
        if self.session.closed:
            return
        rules, tr = self.session.rules, self.session.translator
        text = (instructions_markdown(rules.instructions, tr=tr) if rules.instructions
                else tr.gettext("**Exercise**") + f"\n\n{default_instructions_markdown(rules, tr=tr)}"
                if rules.exercise is not None else "")
        if text:
            set_content(self.banner, text)
        self.banner.visible = bool(text)
        messages = self.session.messages
        self.shown = messages[0] if messages else None
        if self.shown is not None:
            set_content(self.message_md, message_markdown(self.shown, len(messages) - 1, tr=tr))
        self.box.visible = self.message_md.visible = self.dismiss.visible = self.shown is not None
        for m in messages:                  # a toast for each message new to this browser's view
            if m.message_id not in self._toasted:
                self._toasted.add(m.message_id)
                self.session.notify(tr.gettext(TOAST_TITLE), m.text)
