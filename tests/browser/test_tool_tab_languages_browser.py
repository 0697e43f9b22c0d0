"""The Tool tab with the pseudo-locale in chromium: its folders, buttons and texts show the
catalogs' words (``⟦…⟧``) at 1400x900 and 1024x768, a TCP check's result too, and no button
label of the tab is cut (its text fits its button). Screenshots saved for a look."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from support.app_page import truth_tool
from support.pendant_page import TIMEOUT_MS, assert_not_blank, wait_text

from tcp_pendant.translation import PSEUDO_LANGUAGE, translator

pytestmark = pytest.mark.browser

QPS = translator(PSEUDO_LANGUAGE)

CUT_BUTTONS = """() => [...document.querySelectorAll('[role="tabpanel"]:not([hidden]) button')]
    .filter(b => b.offsetParent !== null && b.innerText.trim())
    .filter(b => b.scrollWidth > b.clientWidth + 1)
    .map(b => b.innerText.trim())"""
"""The visible buttons of the tab on show whose text is wider than the button (cut)."""


def test_the_tool_tab_in_the_pseudo_locale_shows_the_catalogs_words_and_cuts_no_button(
        app_factory, new_page: Callable[..., Any], shot) -> None:
    app = app_factory({1: truth_tool("pointer", "Pointer"), 2: truth_tool("pointer", "Skewed", (0.0, 1.0, 0.0))},
                      language=PSEUDO_LANGUAGE)
    page = new_page(app.url, wait_for=QPS.gettext("Record point"))
    page.get_by_role("tab").nth(1).click()                      # the Tool tab (its title is the tabs' owner's)
    wait_text(page, QPS.gettext("Check active tool"))
    page.get_by_role("button", name=QPS.gettext("Check"), exact=True).click()
    page.get_by_role("columnheader", name=QPS.gettext("Rotation"), exact=True).first.wait_for(
        state="attached", timeout=TIMEOUT_MS)                    # the check's table, headed in the catalogs' words
    for width, height in ((1400, 900), (1024, 768)):
        page.set_viewport_size({"width": width, "height": height})
        page.wait_for_timeout(500)
        assert_not_blank(shot(page, f"tool_tab_qps_{width}x{height}"), min_colors=200)
        assert page.evaluate(CUT_BUTTONS) == [], (width, height)
