"""The trainer's controls for the exercise's brief (viser GUI): instructions, the methods
trainees may start and the fewest touches a Finish takes.

:func:`build_exercise_controls` adds them where it is called (the trainer view's panel): an
"Instructions" text area (plain text, at most ``MAX_INSTRUCTIONS_CHARS`` characters: shown
escaped in a banner on every trainee's panel), one checkbox per calibration method (the
registry's, in menu order; all ticked: every method), "Minimum touches" (0: none; it applies to
the methods whose touch count the trainee chooses, ``calibrate.pendant_rules``) and **Push brief
to all trainees** (``ClassRoom.push_brief``). What a browser sends is checked by the class; a
refusal is a notification in words (``SessionLoop.on_loop``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import viser

from tcp_pendant.classroom.exercise_rules import MAX_INSTRUCTIONS_CHARS, MAX_MIN_TOUCHES, clean_min_touches
from tcp_pendant.session import Session
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.views.dashboard_words import DashboardWords
from tcp_pendant.views.gui_util import ButtonEvent
from tcp_pendant.wizards import wizard_classes

__all__ = ["BriefControl", "ExerciseControls", "brief_words", "build_exercise_controls"]


INSTRUCTIONS_HINT = N_("What the trainees should do, plain text (at most {n} characters): a banner at the top "
                       "of every trainee's panel shows it.")
"""The instructions' hint (``{n}``: the most characters)."""


class BriefControl(Protocol):
    """What the exercise controls need of the class (``ClassRoom``)."""

    @property
    def instructions(self) -> str: ...

    @property
    def allowed_methods(self) -> tuple[str, ...] | None: ...

    @property
    def min_touches(self) -> int: ...

    def push_brief(self, instructions: str, allowed_methods: Sequence[str] | str | None,
                   min_touches: int) -> int: ...


def brief_words(control: BriefControl, *, tr: Translator = ENGLISH) -> str:
    """The class's brief in one line for the trainer (plain text), in ``tr``'s language."""
    _ = tr.gettext
    titles = {c.kind: _(c.title) for c in wizard_classes()}
    n = len(control.instructions)
    text = (tr.ngettext("Instructions of {n} character", "Instructions of {n} characters", n).format(n=n) if n
            else _("No instructions"))
    methods = (_("every method") if control.allowed_methods is None
               else ", ".join(titles.get(k, k) for k in control.allowed_methods))
    m = control.min_touches
    touches = (tr.ngettext("at least {n} touch where the trainee chooses how many",
                           "at least {n} touches where the trainee chooses how many", m).format(n=m)
               if m else _("no minimum of touches"))
    return _("{instructions}; {methods}; {touches}.").format(instructions=text, methods=methods, touches=touches)


@dataclass(eq=False)
class ExerciseControls:
    """The widgets of the brief (for tests) and their push.

    Attributes:
        instructions: the text area; methods: wizard kind -> its checkbox; min_touches: the
            number; push: the button; status: what the last push did (markdown).
    """

    session: Session
    control: BriefControl
    instructions: viser.GuiTextHandle
    methods: dict[str, viser.GuiCheckboxHandle]
    min_touches: viser.GuiNumberHandle[int]
    push: viser.GuiButtonHandle
    status: viser.GuiMarkdownHandle
    words: DashboardWords

    def render(self) -> None:
        """Nothing to re-read (the brief changes only by this push): the words in the
        dashboard's language."""
        self.words.follow()
        hint = self.session.translator.gettext(INSTRUCTIONS_HINT).format(n=MAX_INSTRUCTIONS_CHARS)
        if self.instructions.hint != hint:
            self.instructions.hint = hint

    def _push(self, _event: ButtonEvent | None = None) -> None:
        ticked = tuple(kind for kind, box in self.methods.items() if box.value is True)
        if not ticked:
            raise ValueError("Tick at least one method the trainees may use, then push the brief.")
        allowed = None if len(ticked) == len(self.methods) else ticked
        text = self.instructions.value
        if not isinstance(text, str):
            raise ValueError("The instructions must be text.")
        minimum = clean_min_touches(self.min_touches.value)     # a browser may send 3.0
        n = self.control.push_brief(text, allowed, minimum)
        tr = self.session.translator
        pushed = tr.ngettext("Pushed to {n} trainee: {brief}", "Pushed to {n} trainees: {brief}", n)
        self.status.content = escape_markdown(pushed.format(n=n, brief=brief_words(self.control, tr=tr)))


def build_exercise_controls(gui: viser.GuiApi, class_control: BriefControl, session: Session) -> ExerciseControls:
    """Add the brief's controls to ``gui`` (in the container open where it is called) for the
    trainer's ``session``; their push goes to ``class_control``."""
    allowed = class_control.allowed_methods
    words = DashboardWords(session)
    with words(gui.add_folder(""), label=N_("Exercise brief")):
        text = words(gui.add_text("", class_control.instructions, multiline=True), label=N_("Instructions"))
        words(gui.add_markdown(""), content=N_("Methods the trainees may use:"))
        methods = {c.kind: words(gui.add_checkbox("", allowed is None or c.kind in allowed), label=c.title)
                   for c in wizard_classes()}
        minimum = words(gui.add_number("", int(class_control.min_touches), min=0, max=MAX_MIN_TOUCHES, step=1),
                        label=N_("Minimum touches"),
                        hint=N_("0: none. A Finish with fewer touches is refused in the methods whose touch "
                                "count the trainee chooses (XYZ 4-point, TCP & Z, X)."))
        push = words(gui.add_button("", color="blue"), label=N_("Push brief to all trainees"))
        status = gui.add_markdown("")
    controls = ExerciseControls(session, class_control, text, methods, minimum, push, status, words)
    push.on_click(session.loop.on_loop(controls._push))
    controls.render()
    return controls
