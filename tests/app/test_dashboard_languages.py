"""The trainer's dashboard and languages, over real websockets: the dashboard's own Language
selector switches the dashboard's browser only; a language pushed to the class reaches every
trainee (told in it, pose and wizard kept) and is the start language of a browser that joins
later, over ``--language`` and ``Accept-Language``; a push to one trainee changes that one only;
a trainee may switch back. With the pseudo-locale every text of every dashboard handle is from
the catalogs except names and numbers."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import numpy as np
import viser

from support.guiclick import choose, click
from support.pseudo_text import WORD, gui_texts, untranslated_words
from support.wsclient import InputsClient, wait_until

from tcp_pendant.classroom.push_words import PUSH_TITLE, push_words
from tcp_pendant.classroom.class_language import LANGUAGE_PUSHED_BODY, LANGUAGE_PUSHED_TITLE, LANGUAGE_SETTING
from tcp_pendant.session import Session
from tcp_pendant.translation import LANGUAGE_NAMES, PSEUDO_LANGUAGE, translator
from tcp_pendant.views.dashboard import TrainerDashboard
from tcp_pendant.wizards import wizard_classes

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

TOKEN = "trainer-token-of-16"


def _connect(app: Any, clients: list[InputsClient], headers: dict[str, str] | None = None) -> Session:
    n = len(app.sessions)
    clients.append(InputsClient(app.port, headers))
    wait_until(lambda: len(app.sessions) == n + 1 and "identity" in list(app.sessions.values())[-1].views,
               what="a session with its welcome window")
    return list(app.sessions.values())[-1]


def _join(session: Session, name: str) -> None:
    p = session.views["identity"]
    choose(p.name_field, name, session.client)
    click(p.start, session.client)
    assert p.name == name


def _dashboard(session: Session) -> TrainerDashboard:
    q = session.views["identity"]
    choose(q.token_field, TOKEN, session.client)
    click(q.open_trainer, session.client)
    dash: TrainerDashboard = session.views["trainer"]
    return dash


def _notices(client: InputsClient) -> list[tuple[str, str]]:
    return [(m["props"]["title"], m["props"]["body"]) for m in list(client.messages)
            if m.get("type") == "NotificationShowMessage"]


def test_a_pushed_language_reaches_the_class_or_one_trainee_and_the_selector_only_the_dashboard(
        app_factory: Any, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, seed=11)
    clients: list[InputsClient] = []
    try:
        anna = _connect(app, clients)
        _join(anna, "Anna")
        ben = _connect(app, clients)
        _join(ben, "Ben")
        with anna.lock:
            anna.motion.jog("Z", -1)
            anna.wizard_commands.start("xyz4")
        q_before, wizard_before = anna.controller.q_rad.copy(), anna.workflow.wizard
        trainer = _connect(app, clients)
        dash = _dashboard(trainer)
        t_client = clients[2]

        # the dashboard's own selector, as the browser sends it: the dashboard in German, nobody else
        selector = dash.language.dropdown._impl.uuid                   # not the welcome window's pendant's
        wait_until(lambda: selector in t_client.inputs, what="the dashboard's selector")
        t_client.send({"type": "GuiUpdateMessage", "uuid": selector, "updates": {"value": "Deutsch"}})
        wait_until(lambda: trainer.language == "de", what="the dashboard in German")
        with trainer.lock:                                # the change signal ran to its end
            assert dash.language.dropdown.label == "Sprache (Language)"
        assert (anna.language, ben.language) == ("en", "en")

        # push German to Ben only: Anna keeps English; Ben is told in German; his dashboard row stays
        choose(dash.trainee, "Ben", trainer.client)
        choose(dash.language_choice, "Deutsch", trainer.client)
        click(dash.push_language_one, trainer.client)
        wait_until(lambda: ben.language == "de", what="Ben in German")
        de = translator("de")
        wait_until(lambda: (de.gettext(LANGUAGE_PUSHED_TITLE),
                            de.gettext(LANGUAGE_PUSHED_BODY).format(language="Deutsch")) in _notices(clients[1]),
                   what="Ben's notice in German")
        assert anna.language == "en" and not any(t == de.gettext(LANGUAGE_PUSHED_TITLE) for t, _ in _notices(clients[0]))
        assert ben.views["pendant"].increment.label == "Inkrement"
        assert "Ben" in dash.language_md.content

        # push Русский to the class: both trainees, Anna's pose and wizard kept; the dashboard stays German
        choose(dash.language_choice, "Русский", trainer.client)
        click(dash.push_language, trainer.client)
        wait_until(lambda: (anna.language, ben.language) == ("ru", "ru"), what="the class in Russian")
        np.testing.assert_array_equal(anna.controller.q_rad, q_before)
        assert anna.workflow.wizard is wizard_before is not None
        assert trainer.language == "de"
        ru = translator("ru")
        wait_until(lambda: any(t == ru.gettext(LANGUAGE_PUSHED_TITLE) for t, _ in _notices(clients[0])),
                   what="Anna's notice in Russian")
        assert app.gradebook.settings.get(LANGUAGE_SETTING) == "ru"

        # Anna switches back with her own selector: only hers
        clients[0].send({"type": "GuiUpdateMessage", "uuid": anna.views["pendant"].language.dropdown._impl.uuid,
                         "updates": {"value": "English"}})
        wait_until(lambda: anna.language == "en", what="Anna back in English")
        assert ben.language == "ru"

        # a browser joining later starts in the class's language, over its Accept-Language
        cleo = _connect(app, clients, {"Accept-Language": "de-DE,de;q=0.9"})
        assert cleo.language == "ru"
        _join(cleo, "Cleo")
        assert cleo.language == "ru"
    finally:
        for c in clients:
            c.ws.close()


def test_the_class_language_wins_over_the_language_option_after_a_restart(app_factory: Any, tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    app = app_factory(class_db=db, trainer_token=TOKEN, seed=11, language="de")
    clients: list[InputsClient] = []
    try:
        trainer = _connect(app, clients)
        assert trainer.language == "de"
        dash = _dashboard(trainer)
        choose(dash.language_choice, "Español", trainer.client)
        click(dash.push_language, trainer.client)
        assert "0" in dash.language_md.content          # nobody named yet: pushed to 0 trainees
    finally:
        for c in clients:
            c.ws.close()
    app.stop()
    app = app_factory(class_db=db, trainer_token=TOKEN, seed=11, language="de")
    clients = []
    try:
        assert _connect(app, clients).language == "es"
    finally:
        for c in clients:
            c.ws.close()


def _dashboard_handles(dash: TrainerDashboard) -> list[tuple[str, object]]:
    kinds = (viser.GuiMarkdownHandle | viser.GuiButtonHandle | viser.GuiDropdownHandle | viser.GuiNumberHandle
             | viser.GuiHtmlHandle | viser.GuiUploadButtonHandle | viser.GuiFolderHandle)
    handles = [(name, h) for name, h in vars(dash).items() if isinstance(h, kinds)]
    handles += [(f"folder {title}", f) for title, f in dash.folders.items()]
    handles.append(("language", dash.language.dropdown))
    for extra in dash.class_extras:                       # the brief's and the message box's controls
        for name, value in vars(extra).items():
            for item in value.values() if isinstance(value, dict) else (value,):
                if isinstance(item, kinds | viser.GuiTextHandle | viser.GuiCheckboxHandle):
                    handles.append((f"{type(extra).__name__}.{name}", item))
        handles += [(f"{type(extra).__name__} words", h) for h, _ in extra.words._texts]   # its folder, its line
    return handles


def test_with_the_pseudo_locale_every_text_of_the_dashboard_is_from_the_catalogs(app_factory: Any,
                                                                                 tmp_path: Path) -> None:
    """Labels, hints, options, markdown and tables of every handle the dashboard builds (its
    own folders, the brief's and the message box's, the replay's touch choices; the tool library
    is its owner's view),
    with two trainees in the table, after a push to all, a push to one and a push of a
    language; names only outside ``⟦ ⟧``: trainee and tool names, language names, units and
    the English word "Language" the selector keeps."""
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, seed=11, language=PSEUDO_LANGUAGE)
    clients: list[InputsClient] = []
    try:
        anna = _connect(app, clients)
        _join(anna, "Anna")
        ben = _connect(app, clients)
        _join(ben, "Ben")
        trainer = _connect(app, clients)
        dash = _dashboard(trainer)
        assert trainer.language == PSEUDO_LANGUAGE
        qps = translator(PSEUDO_LANGUAGE)
        unmarked_titles = {w for c in wizard_classes() if qps.gettext(c.title) == c.title   # marked by the wizards'
                           for w in WORD.findall(c.title)}                                   # owner (N_), not here
        names = ({"Anna", "Ben", "Language", "mm", "TCP", "CSV", "JSON", "XYZ", "Z", "X"} | unmarked_titles
                 | {w for n in LANGUAGE_NAMES.values() for w in WORD.findall(n)})

        def check(state: str) -> None:
            with trainer.lock:
                for name, handle in _dashboard_handles(dash):
                    for text in gui_texts(handle):
                        assert untranslated_words(text, names) == [], (state, name, text)
                chart = dash.chart
                for text in (chart.title or "", *(str(s.get("label", "")) for s in chart.series),
                             str((chart.axes or ({},))[0].get("label", ""))):
                    assert untranslated_words(text, names) == [], (state, "chart", text)

        check("built")
        click(dash.push, trainer.client)                               # push to all: the rules line
        check("pushed to all")
        click(dash.push_one, trainer.client)                           # nobody chosen: "choose a trainee"
        check("nobody chosen")
        choose(dash.trainee, "Anna", trainer.client)
        click(dash.reset, trainer.client)                              # no wizard running
        check("reset")
        click(dash.push_one, trainer.client)
        check("pushed to one")
        click(dash.push_language_one, trainer.client)
        check("language pushed to one")
        click(dash.push_language, trainer.client)
        check("language pushed to all")
        messages = next(extra for extra in dash.class_extras if hasattr(extra, "send"))
        choose(messages.text, "Hello", trainer.client)
        click(messages.send, trainer.client)
        assert untranslated_words(messages.status.content, names) == [], messages.status.content
        choose(dash.trainee, "Ben", trainer.client)
        click(dash.release, trainer.client)
        check("released")

        # the dashboard back in English: every word again, the choices kept
        choose(dash.hide_distance, qps.gettext("on, locked"), trainer.client)
        trainer.set_language("en")
        with trainer.lock:
            assert (dash.push.label, dash.folders["Trainee"].label) == ("Push to all trainees", "Trainee")
            assert tuple(dash.hide_distance.options) == ("(keep)", "on, locked", "on", "off")
            assert dash.hide_distance.value == "on, locked"
            assert dash.chart.title == "Last position error per trainee (mm)"
            assert "<th" in dash.table_html.content and ">Trainee</th>" in dash.table_html.content
            assert dash.trainee.options[0] == "(choose a trainee) "
            assert tuple(dash.replay_touch.options) == ("(no replay) ",)
            assert messages.send.label == "Send" and messages.to.options[0] == "(all trainees) "
    finally:
        for c in clients:
            c.ws.close()


def test_what_a_push_tells_the_trainee_is_from_the_catalogs() -> None:
    qps = translator(PSEUDO_LANGUAGE)
    for exercise, tool, aids, auto in ((False, None, "locked", False), (None, "Torch", "shown", True),
                                       ("mystery", None, "hidden", None), (False, None, None, None)):
        assert untranslated_words(push_words(exercise, tool, aids, auto, tr=qps), {"Torch"}) == []
    assert untranslated_words(qps.gettext(PUSH_TITLE), set()) == []


def test_the_welcome_window_and_the_trainers_message_follow_the_language(app_factory: Any, tmp_path: Path) -> None:
    """In the pseudo-locale: the welcome window's labels, hints and warnings, the banner, the
    page script's hidden labels, and the trainer's message box; a switch to English re-renders
    them (what was typed kept)."""
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, seed=11, language=PSEUDO_LANGUAGE)
    clients: list[InputsClient] = []
    try:
        anna = _connect(app, clients)
        prompt = anna.views["identity"]
        choose(prompt.token_field, "wrong-token-of-16", anna.client)
        click(prompt.open_trainer, anna.client)                     # a wrong token: the warning
        welcome = (prompt.name_field, prompt.key_field, prompt.start, prompt.message, prompt.token_field,
                   prompt.open_trainer)
        for handle in welcome:
            for text in gui_texts(handle):
                assert untranslated_words(text, set()) == [], text
        assert 'data-join="⟦' in prompt.labels_html.content
        choose(prompt.name_field, "x" * 41, anna.client)
        click(prompt.start, anna.client)                            # refused: too long, said in the catalogs' words
        assert prompt.name is None
        assert untranslated_words(prompt.message.content, set()) == [], prompt.message.content
        choose(prompt.name_field, "Anna", anna.client)
        anna.set_language("en")                                      # the window again, in English, "Anna" kept
        assert (prompt.name_field.label, prompt.start.label) == ("Your name", "Join the class")
        assert prompt.name_field.value == "Anna"
        assert prompt.message.content == "⚠ your name has 41 characters; shorten it to at most 40."
        assert 'data-join="Join the class"' in prompt.labels_html.content
        anna.set_language(PSEUDO_LANGUAGE)
        click(prompt.start, anna.client)
        assert prompt.name == "Anna"
        assert untranslated_words(prompt.banner.content, {"Anna"}) == []

        app.classroom.send_message("Hello", to=None)
        notices = anna.views["notices"]
        wait_until(lambda: notices.shown is not None, what="the message on show")
        with anna.lock:
            for handle in (notices.box, notices.message_md, notices.dismiss):
                for text in gui_texts(handle):
                    assert untranslated_words(text, {"Hello", "UTC"}) == [], text
        anna.set_language("en")
        with anna.lock:
            assert notices.message_md.content.startswith("**Message from the trainer** to the class, ")
            assert notices.dismiss.label == "Dismiss"
    finally:
        for c in clients:
            c.ws.close()
