"""Each browser its own language, over real websockets: ``Accept-Language`` picks the start
language, ``--language`` every browser's, the Language selector switches one browser live (the pose
and the wizard stay; another browser keeps its language), and with the pseudo-locale every
text of the Jog panel is in the catalogs except names and numbers."""

from __future__ import annotations

import html
import re
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
import viser

from support.pseudo_text import WORD, gui_texts, untranslated_words
from support.wsclient import DrainingClient, InputsClient, wait_until

from tcp_pendant.controller import TouchGeometry
from tcp_pendant.pendant.formatting import dropped_presses_text, touch_indicator_markdown
from tcp_pendant.pendant.jogging import JOG_FRAMES, JogMode
from tcp_pendant.serve.server import AppConfig, PendantApp
from tcp_pendant.session import Session
from tcp_pendant.translation import LANGUAGE_NAMES, PSEUDO_LANGUAGE, translator
from tcp_pendant.views.pendant_panel import PendantPanel

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _session(app: PendantApp, n: int) -> list[Session]:
    wait_until(lambda: len(app.sessions) == n, what=f"{n} sessions")
    return list(app.sessions.values())


def test_accept_language_picks_each_browsers_start_language(app_factory: Any) -> None:
    app = app_factory()
    anna = DrainingClient(app.port, headers={"Accept-Language": "de-DE,de;q=0.9,en;q=0.8"})
    try:
        (s_anna,) = _session(app, 1)
        ben = DrainingClient(app.port, headers={"Accept-Language": "fr-FR,fr;q=0.9"})
        try:
            s_ben = next(s for s in _session(app, 2) if s is not s_anna)
            assert (s_anna.language, s_ben.language) == ("de", "en")
            assert s_anna.views["pendant"].increment.label == "Inkrement"
            assert s_ben.views["pendant"].increment.label == "Increment"
        finally:
            ben.close()
    finally:
        anna.close()


def test_language_option_sets_every_browsers_start_language_and_refuses_an_unknown_one(app_factory: Any) -> None:
    app = app_factory(language="de")
    c = DrainingClient(app.port, headers={"Accept-Language": "en-US"})
    try:
        (s,) = _session(app, 1)
        assert s.language == "de"
        assert s.views["pendant"].settings_folder.label == "Handverfahr-Optionen"
    finally:
        c.close()
    with pytest.raises(ValueError, match="Unknown language 'fr'; use auto or one of en, de"):
        PendantApp(AppConfig(port=0, language="fr"))


def test_the_selector_switches_one_browser_live_keeping_pose_and_wizard(app_factory: Any) -> None:
    app = app_factory()
    anna = InputsClient(app.port)
    try:
        (s_anna,) = _session(app, 1)
        ben = InputsClient(app.port)
        try:
            s_ben = next(s for s in _session(app, 2) if s is not s_anna)
            with s_anna.lock:
                s_anna.motion.jog("Z", -1)
                s_anna.wizard_commands.start("xyz4")
            q_before = s_anna.controller.q_rad.copy()
            wizard_before = s_anna.workflow.wizard
            wait_until(lambda: "Language" in anna.labels(), what="the selector")
            uuid = next(u for u, (_, label, _) in anna.inputs.items() if label == "Language")
            anna.send({"type": "GuiUpdateMessage", "uuid": uuid, "updates": {"value": "Deutsch"}})
            wait_until(lambda: s_anna.language == "de", what="Anna's German")
            panel = s_anna.views["pendant"]
            with s_anna.lock:                            # the change signal ran to its end
                assert panel.hide_distance.label == "Abstand ausblenden"
            assert panel.language.dropdown.label == "Sprache (Language)"
            assert tuple(panel.mode.options) == ("✓ Kartesisch", "Achsen")
            assert "Koordinatensystem WORLD" in panel.settings_md.content
            assert "Achswinkel (Grad)" in panel.joints_md.content
            # the labels the page's script looks for, in German (serve/static/pendant.js, 8.)
            assert panel.keys_md.content.startswith("Tasten: `1`…`6` verfahren")
            assert ('<div hidden data-tcp-pendant-labels data-increment="Inkrement" data-cont="Kont." '
                    'data-shadows="Schatten" data-keys-line="Tasten:" data-tip-views=') in panel.keys_md.content
            np.testing.assert_array_equal(s_anna.controller.q_rad, q_before)
            assert s_anna.workflow.wizard is wizard_before is not None
            # Ben's browser: untouched
            assert s_ben.language == "en"
            assert s_ben.views["pendant"].hide_distance.label == "Hide distance"
            # a click on a German button is read: the Mode switches to joints
            mode_uuid = next(u for u, (_, label, _) in anna.inputs.items() if label == "Mode")
            anna.send({"type": "GuiUpdateMessage", "uuid": mode_uuid, "updates": {"value": "Achsen"}})
            wait_until(lambda: s_anna.jogger.settings.mode.value == "Joint", what="joint mode")
            wait_until(lambda: tuple(panel.mode.options) == ("Kartesisch", "✓ Achsen"), what="the marked mode")
            inc_uuid = next(u for u, (_, label, _) in anna.inputs.items() if label == "Increment")
            anna.send({"type": "GuiUpdateMessage", "uuid": inc_uuid, "updates": {"value": "Kont."}})
            wait_until(lambda: s_anna.jogger.settings.continuous, what="continuous jog")
            # a name that is no language: refused, nothing changes
            anna.send({"type": "GuiUpdateMessage", "uuid": uuid, "updates": {"value": "Klingon"}})
            anna.send({"type": "GuiUpdateMessage", "uuid": uuid, "updates": {"value": "English"}})
            wait_until(lambda: s_anna.language == "en", what="back to English")
            with s_anna.lock:
                assert panel.hide_distance.label == "Hide distance"
                assert tuple(panel.mode.options) == ("Cartesian", "✓ Joint")
        finally:
            ben.ws.close()
    finally:
        anna.ws.close()


def _handles(panel: PendantPanel) -> Iterator[tuple[str, object]]:
    """Every GUI handle of the Jog panel (its own: not the tip views', a view of its own)."""
    for name, value in vars(panel).items():
        items = value.values() if isinstance(value, dict) else value if isinstance(value, list) else (value,)
        for item in items:
            if isinstance(item, viser.GuiMarkdownHandle | viser.GuiButtonHandle | viser.GuiButtonGroupHandle
                          | viser.GuiCheckboxHandle | viser.GuiDropdownHandle | viser.GuiSliderHandle
                          | viser.GuiFolderHandle):
                yield name, item
    yield "language", panel.language.dropdown


def test_with_the_pseudo_locale_every_text_of_the_jog_panel_is_from_the_catalogs(app_factory: Any) -> None:
    """Labels, hints, options and markdown of every handle of the panel, in Cartesian and Joint
    mode, incremental and continuous: outside ``⟦ ⟧`` only names (axes, joints, frames, tool
    names, units, the selector's language names and the English word "Language" it keeps beside
    the translation) and numbers, the offset line of ``pendant.guidance`` under the distance
    included."""
    app = app_factory(language=PSEUDO_LANGUAGE)
    c = DrainingClient(app.port)
    try:
        (s,) = _session(app, 1)
        panel = s.views["pendant"]
        joints = set(s.controller.kinematics.joint_names)
        names = (set("XYZABC") | joints | set(JOG_FRAMES) | {"WORLD", "BASE", "HOME", "mm", "deg", "TOOL",
                 "FLANGE", "TCP", "KR", "Shift", "A5", "Language"}
                 | {w for n in LANGUAGE_NAMES.values() for w in WORD.findall(n)})
        for mode, increment in (("Cartesian", "10"), ("Joint", "10"), ("Joint", "Cont."), ("Cartesian", "Cont.")):
            with s.lock:
                s.motion.set_jog_setting("mode", JogMode(mode))
                s.motion.set_jog_setting("increment", increment)
                panel._show_settings()
                panel.render()
            for name, handle in _handles(panel):
                for text in gui_texts(handle):
                    assert untranslated_words(text, names) == [], (name, text)
        qps = translator(PSEUDO_LANGUAGE)
        far = TouchGeometry(distance_mm=12.0, touching=False, crashed=False, penetration_mm=0.0)
        for touch, hide in ((far, False), (far, True),
                            (TouchGeometry(distance_mm=0.2, touching=True, crashed=False, penetration_mm=0.0), False),
                            (TouchGeometry(distance_mm=0.0, touching=True, crashed=True, penetration_mm=1.5), True)):
            assert untranslated_words(touch_indicator_markdown(touch, hide_distance=hide, tr=qps), set()) == []
        assert untranslated_words(dropped_presses_text(3, qps), set()) == []
    finally:
        c.close()


def _hidden_labels(markdown: str) -> dict[str, str]:
    """The ``data-*`` attributes of the panel's hidden labels div (what the page's script reads)."""
    (div,) = re.findall(r"<div hidden data-tcp-pendant-labels ([^>]*)></div>", markdown)
    return {k: html.unescape(v) for k, v in re.findall(r'data-([a-z-]+)="([^"]*)"', div)}


def test_in_the_pseudo_locale_the_hidden_labels_name_the_wizards_buttons_and_the_scripts_own_words(
        app_factory: Any) -> None:
    """The R, N and B keys (serve/static/pendant.js) find the wizard's buttons by the labels the
    panel hands over: in every language they are the labels the Calibration step folder shows,
    before and after a live switch; the script's own words (the lost-connection notice, its
    button, the keys' tooltips) come the same way."""
    app = app_factory(language=PSEUDO_LANGUAGE)
    c = DrainingClient(app.port)
    try:
        (s,) = _session(app, 1)
        panel, dock = s.views["pendant"], s.views["dock"]
        with s.lock:
            s.wizard_commands.start("xyz4")
        for language in (PSEUDO_LANGUAGE, "de", "en"):
            with s.lock:
                s.set_language(language)
                labels = _hidden_labels(panel.keys_md.content)
                assert labels["record"] == dock.record.label
                assert labels["next"] in dock.nav.options and labels["back"] in dock.nav.options
                assert labels["finish"] == translator(language).gettext("Finish ▶")
                assert labels["key-r"] == translator(language).gettext("Key {key}").format(key="R")
                assert labels["reload"] == translator(language).gettext("Reload the page")
                if language == PSEUDO_LANGUAGE:
                    for key in ("record", "next", "finish", "back", "lost", "reload", "key-r", "key-n", "key-b"):
                        assert labels[key].startswith("⟦"), (key, labels[key])
        english = _hidden_labels(panel.keys_md.content)
        assert english["next"] == "Next ▶" and english["key-b"] == "Key B"
        assert english["lost"] == ("This page cannot reach the pendant server (it is still trying). Your name and "
                                   "your recorded touches are kept on the server: reload the page to join again.")
    finally:
        c.close()
