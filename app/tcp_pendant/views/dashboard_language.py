"""The dashboard's "Language of the trainees" folder: push a language like the other settings.

**Push language to all trainees** sets the chosen language on every trainee's pendant
(``ClassRoom.push_language``: each told in it, pose and wizard kept) and keeps it as the class's:
a browser that connects later starts in it. **Push language to this trainee** sets it on the
trainee chosen in the Trainee folder only (``ClassRoom.push_language_to``). A trainee may switch
back with their own Language selector. The dashboard's own language is its Language selector
under the title (``views.language_selector``); a push never changes it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

from tcp_pendant.classroom.class_language import language_name
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import ENGLISH, LANGUAGE_NAMES, PSEUDO_LANGUAGE, N_, Translator
from tcp_pendant.views.gui_util import ButtonEvent, set_content

if TYPE_CHECKING:
    from tcp_pendant.views.dashboard import TrainerDashboard

__all__ = ["LanguageControl", "language_choices", "language_folder"]


class LanguageControl(Protocol):
    """What the folder needs of the class room."""

    @property
    def class_language(self) -> str | None: ...

    def push_language(self, language: str) -> int: ...

    def push_language_to(self, name: str, language: str, *, tr: Translator = ENGLISH) -> str: ...


def language_choices(current: str | None) -> tuple[str, ...]:
    """The folder's choices: each language named in itself (the pseudo-locale's code when the
    class uses it: tests)."""
    names = tuple(LANGUAGE_NAMES.values())
    return names + (language_name(PSEUDO_LANGUAGE),) if current == PSEUDO_LANGUAGE else names


def _code(name: str) -> str:
    """The language code of a choice (refusing a text that is none of them)."""
    codes = {language_name(code): code for code in (*LANGUAGE_NAMES, PSEUDO_LANGUAGE)}
    if name not in codes:
        raise ValueError(f"Unknown language {name!r:.40}; choose one of the list.")
    return codes[name]


def language_folder(dash: TrainerDashboard) -> None:
    """The chosen language, pushed to all trainees or to the trainee chosen above."""
    gui, words, control = dash.gui, dash.words, dash.control
    kept = control.class_language
    choices = language_choices(kept if kept is not None else dash.session.language)
    with dash.folder(N_("Language of the trainees")):
        dash.language_choice = words.dropdown(
            gui, N_("Language to push"), (), choices, value=language_name(kept) if kept is not None else choices[0],
            hint=N_("Each trainee may switch back with the Language selector of their pendant."))
        dash.push_language = words(gui.add_button("", color="blue"), label=N_("Push language to all trainees"),
                                   hint=N_("Trainees who join later start in it too."))
        dash.push_language_one = words(gui.add_button(""), label=N_("Push language to this trainee"),
                                       hint=N_("The trainee chosen in the Trainee folder only."))
        dash.language_md = gui.add_markdown("")
    on_loop = dash.session.loop.on_loop
    dash.push_language.on_click(on_loop(lambda event: _push_all(dash, event)))
    dash.push_language_one.on_click(on_loop(lambda event: _push_one(dash, event)))


def _push_all(dash: TrainerDashboard, _event: ButtonEvent | None = None) -> None:
    code = _code(str(dash.language_choice.value))
    n = dash.control.push_language(code)
    tr = dash.session.translator
    text = tr.ngettext("{language} pushed to {n} trainee; trainees who join later start in it.",
                       "{language} pushed to {n} trainees; trainees who join later start in it.", n)
    set_content(dash.language_md, escape_markdown(text.format(language=language_name(code), n=n)))


def _push_one(dash: TrainerDashboard, _event: ButtonEvent | None = None) -> None:
    name = dash.chosen()
    _ = dash.session.translator.gettext
    if name is None:
        set_content(dash.language_md, escape_markdown(_("Choose a trainee first.")))
        return
    code = _code(str(dash.language_choice.value))
    set_content(dash.language_md, escape_markdown(dash.control.push_language_to(name, code, tr=dash.session.translator)))
