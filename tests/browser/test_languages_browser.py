"""The pendant in German in chromium: a browser whose language is German starts in German (its
``Accept-Language`` on the websocket handshake), the page's script still finds the Increment
row, continuous mode and the Shadows checkbox by their German labels, and screenshots at
1400x900 and 1024x768 show the Jog tab in German."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from support.app_page import true_tip_at
from support.pendant_page import TIMEOUT_MS, assert_not_blank, wait_text, wait_until

from tcp_pendant.translation import PSEUDO_LANGUAGE, translator

pytestmark = pytest.mark.browser


def test_a_german_browser_gets_the_jog_tab_in_german_and_its_keys_work(app_factory, new_page: Callable[..., Any],
                                                                       shot) -> None:
    app = app_factory()
    page = new_page(app.url, locale="de-DE", wait_for=translator("de").gettext("Record point"))
    page.wait_for_function("document.documentElement.dataset.tcpPendantScript === '1'", timeout=TIMEOUT_MS)
    wait_until(lambda: len(app.sessions) == 1, "the page's session")
    (s,) = app.sessions.values()
    assert s.language == "de"
    wait_text(page, "Tasten:")
    page.get_by_text("Handverfahr-Optionen").first.wait_for(state="attached", timeout=TIMEOUT_MS)
    # the script's keys read the German labels: ] to 100, then to Kont.
    assert s.jogger.settings.increment == "10"
    page.keyboard.press("BracketRight")
    wait_until(lambda: s.jogger.settings.increment == "100", "increment 100")
    wait_text(page, "✓ 100")                  # the page shows it: the next ] steps on from 100
    page.keyboard.press("BracketRight")
    wait_until(lambda: s.jogger.settings.continuous, "continuous mode (Kont.)")
    wait_text(page, "✓ Kont.")
    with s.lock:
        x0 = float(s.controller.T_world_tcp()[0, 3])
    page.keyboard.down("Digit1")                               # held: a continuous jog (the script knows Kont.)
    wait_until(lambda: (float(s.controller.T_world_tcp()[0, 3]) - x0) * 1000.0 > 5.0, "X to move while held")
    page.keyboard.up("Digit1")
    # Shadows: the German checkbox, off in this software-WebGL chromium
    page.wait_for_selector("[data-tcp-pendant-shadows]", state="attached", timeout=TIMEOUT_MS)
    assert page.get_attribute("[data-tcp-pendant-shadows]", "data-tcp-pendant-shadows") == "off"
    wait_until(lambda: s.views["pendant"].shadows.value is False, "the server told: shadows off")
    page.keyboard.press("BracketLeft")                         # back to 100 mm steps for the pictures
    wait_until(lambda: s.jogger.settings.increment == "100", "increment 100")
    for width, height in ((1400, 900), (1024, 768)):
        page.set_viewport_size({"width": width, "height": height})
        page.wait_for_timeout(500)
        assert_not_blank(shot(page, f"jog_tab_de_{width}x{height}"), min_colors=200)
    # the View folder with the language selector, in German and English
    selector = page.get_by_text("Sprache (Language)").first
    selector.scroll_into_view_if_needed(timeout=TIMEOUT_MS)
    page.wait_for_timeout(300)
    assert_not_blank(shot(page, "jog_tab_de_view_folder"), min_colors=200)


def test_in_the_pseudo_locale_the_tabs_follow_a_live_switch_and_the_record_key_finds_record_point(
        app_factory, new_page: Callable[..., Any], shot) -> None:
    """The tabs' titles come from the catalogs and change with the session's language (viser
    cannot retitle a tab by its public API: ``viser_adapter.set_tab_label``), and the R key
    finds "Record point" by its label in the session's language (the panel's hidden labels)."""
    qps = translator(PSEUDO_LANGUAGE)
    app = app_factory(language=PSEUDO_LANGUAGE)
    page = new_page(app.url, wait_for=qps.gettext("Record point"))
    page.wait_for_function("document.documentElement.dataset.tcpPendantScript === '1'", timeout=TIMEOUT_MS)
    wait_until(lambda: len(app.sessions) == 1, "the page's session")
    (s,) = app.sessions.values()
    for title in ("Jog", "Tool", "Calibrate"):
        page.get_by_role("tab", name=qps.pgettext("tab", title)).first.wait_for(timeout=TIMEOUT_MS)
    assert page.get_by_role("tab", name="Calibrate", exact=True).count() == 0
    page.keyboard.press("r")
    wait_until(lambda: len(s.touches) == 1, "a free touch by the R key")
    page.get_by_role("button", name=qps.gettext("Delete P{n}").format(n=1)).first.wait_for(timeout=TIMEOUT_MS)
    assert_not_blank(shot(page, "pseudo_tabs_and_labels"), min_colors=200)   # the tabs and the 3D labels
    with s.lock:
        s.set_language("en")
    for title in ("Jog", "Tool", "Calibrate"):
        page.get_by_role("tab", name=title, exact=True).first.wait_for(timeout=TIMEOUT_MS)
    page.get_by_role("button", name="Record point").first.wait_for(timeout=TIMEOUT_MS)
    page.keyboard.press("r")
    wait_until(lambda: len(s.touches) == 2, "a free touch by the R key, in English")


def test_in_the_pseudo_locale_the_r_n_and_b_keys_drive_a_wizard(app_factory, new_page: Callable[..., Any]) -> None:
    """The page's script finds the wizard's Record, Next and Back buttons by the labels the Jog
    panel hands over in the session's language (views/pendant_panel.py's hidden labels): in the
    pseudo-locale R records step 1, N goes on to step 2, B back to step 1 and N on again; the
    Record button's tooltip names its key in the language too."""
    qps = translator(PSEUDO_LANGUAGE)
    app = app_factory(language=PSEUDO_LANGUAGE)
    page = new_page(app.url, wait_for=qps.gettext("Record point"))
    page.wait_for_function("document.documentElement.dataset.tcpPendantScript === '1'", timeout=TIMEOUT_MS)
    wait_until(lambda: len(app.sessions) == 1, "the page's session")
    (s,) = app.sessions.values()
    with s.lock:
        s.wizard_commands.start("xyz4")
    true_tip_at(s, (0.0, 0.0, 0.2))            # touching: Record asks nothing first
    page.get_by_role("button", name=qps.gettext("Record"), exact=True).first.wait_for(timeout=TIMEOUT_MS)
    wizard = s.workflow.wizard
    assert wizard is not None and wizard.step_index == 0
    record = page.get_by_role("button", name=qps.gettext("Record"), exact=True).first
    page.wait_for_function("b => b.getAttribute('title') === " + repr(qps.gettext("Key {key}").format(key="R")),
                           arg=record.element_handle(), timeout=TIMEOUT_MS)     # its tooltip, in the language too
    page.keyboard.press("r")
    wait_until(lambda: 0 in wizard.recorded_poses, "step 1 recorded by the R key")
    page.keyboard.press("n")
    wait_until(lambda: wizard.step_index == 1, "on to step 2 by the N key")
    page.keyboard.press("b")
    wait_until(lambda: wizard.step_index == 0, "back to step 1 by the B key")
    page.keyboard.press("n")
    wait_until(lambda: wizard.step_index == 1, "on to step 2 again by the N key")
    assert sorted(wizard.recorded_poses) == [0]
