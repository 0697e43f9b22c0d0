"""The scene's words in the session's language (issue 47): the 3D labels, the tabs' titles, the
touch list and the tip views' caption come from the catalogs (the pseudo-locale shows every one
wrapped), and a live switch relabels them; in English they stay as they were."""

from __future__ import annotations

from typing import Any

import pytest
import viser

from support.pseudo_text import english_words, gui_texts, untranslated_words
from support.wsclient import DrainingClient, wait_until

from tcp_pendant.controller.tools import builtin_tools
from tcp_pendant.serve.server import PendantApp
from tcp_pendant.session import Session
from tcp_pendant.translation import PSEUDO_LANGUAGE, translator
from tcp_pendant.views.scene import tool_label_text
from tcp_pendant.views.tip_insets import CAPTION, CAPTION_ZOOMED, caption_text
from tcpcal.tool import Tool

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

NAMES = {"P1", "P2", "X", "Y", "Z", "mm", "TOOL", "WORLD", "FLANGE", "TCP", "CSV", "POSES", "R",
         "tcpcal", "xyz4"}
"""Names the texts keep in every language: touch names, axes, units, frames, a file and a command."""


def _session(app: PendantApp) -> Session:
    wait_until(lambda: len(app.sessions) == 1, what="the session")
    (s,) = app.sessions.values()
    return s


def _tab_titles(s: Session) -> list[str]:
    tabs = s.views["tabs"]
    assert isinstance(tabs, viser.GuiTabGroupHandle)
    return list(tabs._tab_labels)          # what viser sends the browser (the tab handles' titles)


def _scene_texts(s: Session) -> dict[str, str]:
    labels = s.views.labels
    wizard_scene = s.views["calibrate"].scene
    return {"tip": labels.tip.text, "tool": labels.tool.text, "flange": labels.flange.text,
            "world": labels.world.text, "computed": wizard_scene.computed_label.text,
            "true": wizard_scene.true_label.text, "target": wizard_scene.abc_label.text}


def _touch_list_texts(s: Session) -> list[str]:
    view = s.views["touches"]
    handles = [view.record, view.folder, view.export_csv, *view._rows]
    return [t for h in handles for t in gui_texts(h)]


def test_with_the_pseudo_locale_the_scene_tabs_touch_list_and_tip_views_are_from_the_catalogs(
        app_factory: Any) -> None:
    app = app_factory(language=PSEUDO_LANGUAGE)
    c = DrainingClient(app.port)
    try:
        s = _session(app)
        with s.lock:
            s.record_touch()
            s.record_touch()
            s.changed(touches=True)
            titles = _tab_titles(s)
            scene = _scene_texts(s)
            touch_texts = _touch_list_texts(s)
            caption = s.views["pendant"].insets.image.label
        assert len(titles) == 3 and all(t.startswith("⟦") and t.endswith("⟧") for t in titles), titles
        assert scene["world"] == "WORLD" and scene["flange"] == "FLANGE"      # frame names: as they are
        for name, text in scene.items():
            assert untranslated_words(text, NAMES) == [], (name, text)
        assert scene["tip"].startswith("⟦") and scene["computed"].startswith("⟦")
        qps = translator(PSEUDO_LANGUAGE)
        assert [qps.gettext("Delete P{n}").format(n=n) in touch_texts for n in (1, 2, 3)] == [True, True, False]
        for text in touch_texts:
            assert untranslated_words(text, NAMES | {"A", "B", "C", "deg"}) == [], text
        assert caption.startswith("⟦") and untranslated_words(caption, NAMES) == [], caption
    finally:
        c.close()


def test_a_language_switch_relabels_the_tabs_and_the_3d_labels_live_and_english_comes_back_unchanged(
        app_factory: Any) -> None:
    app = app_factory()
    c = DrainingClient(app.port)
    try:
        s = _session(app)
        with s.lock:
            s.record_touch()
            s.changed(touches=True)
            english = (_tab_titles(s), _scene_texts(s), _touch_list_texts(s))
        assert english[0] == ["Jog", "Tool", "Calibrate"]
        assert english[1]["tip"] == "reference tip" and english[1]["computed"] == "COMPUTED"
        assert english[1]["target"] == "TARGET (X down)" and english[1]["true"] == "TRUE"
        assert "Record point" in english[2] and "Delete P1" in english[2]
        with s.lock:
            s.set_language(PSEUDO_LANGUAGE)
            titles, scene, touches = _tab_titles(s), _scene_texts(s), _touch_list_texts(s)
        qps = translator(PSEUDO_LANGUAGE)
        assert titles == [qps.pgettext("tab", t) for t in ("Jog", "Tool", "Calibrate")] != english[0]
        assert scene["tip"] == qps.gettext("reference tip") != "reference tip"
        assert scene["computed"] == qps.gettext("COMPUTED") and scene["target"] == qps.gettext("TARGET (X down)")
        assert qps.gettext("Record point") in touches and qps.gettext("Delete P{n}").format(n=1) in touches
        with s.lock:
            s.set_language("en")
            assert (_tab_titles(s), _scene_texts(s), _touch_list_texts(s)) == english
    finally:
        c.close()


def test_the_tool_triads_label_and_the_tip_views_caption_in_english_and_the_pseudo_locale() -> None:
    qps = translator(PSEUDO_LANGUAGE)
    assert CAPTION.startswith("Tip close-up · left: front (X→, Z↑)") and CAPTION_ZOOMED.startswith(
        "Tip close-up, zoomed out ")
    for zoomed in (False, True):
        said = caption_text(zoomed, qps)
        assert qps.gettext("Tip close-up") in said and untranslated_words(said, NAMES) == [], said
    tools = builtin_tools()
    data_on, now_on = tools["pointer"], next(t for k, t in tools.items() if k != "pointer")
    tool = Tool(name="T7", tcp_mm=(0.0, 0.0, 100.0))
    assert tool_label_text(tool, now_on, data_on) == f"TOOL T7 · on {now_on.label}"
    assert tool_label_text(tool, data_on, data_on, tr=qps) == "TOOL T7"          # a name and a frame
    said = tool_label_text(tool, now_on, data_on, tr=qps)
    assert said != f"TOOL T7 · on {now_on.label}" and qps.gettext(now_on.label) in said   # the model's label too
    assert now_on.label not in said and english_words(said, NAMES | {"T7"}) == [], said


def test_with_the_pseudo_locale_the_touch_lists_empty_line_is_from_the_catalogs(app_factory: Any) -> None:
    """"No touch recorded" (and, while a wizard has its touches, where they are) in the session's
    language, and again in English after a switch back."""
    app = app_factory(language=PSEUDO_LANGUAGE)
    c = DrainingClient(app.port)
    try:
        s = _session(app)
        qps = translator(PSEUDO_LANGUAGE)
        view = s.views["touches"]
        with s.lock:
            assert view.empty_md.content == qps.gettext("*No touch recorded.*")
            s.set_language("en")
            assert view.empty_md.content == "*No touch recorded.*"
    finally:
        c.close()
