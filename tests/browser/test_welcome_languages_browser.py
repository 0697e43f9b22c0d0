"""The welcome window in another language than English, in chromium: the page's script still
finds its fields and buttons (their labels handed over by ``views.identity``'s hidden element),
so the remembered name joins again by itself after a reload, and the trainer address opens the
dashboard. The pseudo-locale stands for every language (each label differs from the English)."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

import pytest

from support.pendant_page import TIMEOUT_MS, assert_not_blank, type_text, wait_text, wait_until

from tcp_pendant.serve.server import PendantApp
from tcp_pendant.translation import PSEUDO_LANGUAGE, translator
from tcp_pendant.views.identity import BANNER, JOIN_LABEL, NAME_LABEL

pytestmark = pytest.mark.browser

TOKEN = "trainer-secret-4242"


def _open(app: PendantApp, new_page: Callable[..., Any], url: str | None = None, **kw: Any) -> tuple[Any, Any]:
    n = len(app.sessions)
    page = new_page(url or app.url, **kw)
    page.wait_for_function("document.documentElement.dataset.tcpPendantScript === '1'", timeout=TIMEOUT_MS)
    wait_until(lambda: len(app.sessions) > n, "the page's session")
    return page, list(app.sessions.values())[-1]


def test_in_another_language_the_name_joins_again_after_a_reload_and_the_trainer_address_opens_the_dashboard(
        app_factory: Any, new_page: Callable[..., Any], shot: Callable[[Any, str], Path], tmp_path: Path) -> None:
    qps = translator(PSEUDO_LANGUAGE)
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, language=PSEUDO_LANGUAGE)
    page, s = _open(app, new_page, wait_for=qps.gettext(JOIN_LABEL))
    assert qps.gettext(NAME_LABEL) != NAME_LABEL
    type_text(page, qps.gettext(NAME_LABEL), "Anna")
    wait_until(lambda: s.views["identity"].name_field.value == "Anna", "the typed name on the server")
    page.get_by_role("button", name=qps.gettext(JOIN_LABEL), exact=True).click()
    banner = qps.gettext(BANNER).split("**", 1)[0].strip()
    wait_text(page, f"{banner} Anna")
    page.wait_for_function("localStorage.getItem('tcpPendant.traineeName') === 'Anna'", timeout=TIMEOUT_MS)
    # a reload: the script types the name into the pseudo-locale's field and presses its button
    page.reload()
    wait_until(lambda: s not in app.sessions.values(), "the old session closed")
    wait_until(lambda: [t.name for t in app.classroom.trainee_statuses() if t.connected] == ["Anna"],
               "the reloaded page joined by itself")
    wait_text(page, f"{banner} Anna")
    # the trainer address: the token typed into the pseudo-locale's field, the dashboard opens
    dash_page, trainer = _open(app, new_page, app.trainer_url, width=1024, height=768,
                               wait_for=qps.gettext("Download grades (CSV)"))
    wait_until(lambda: "trainer" in trainer.views, "the dashboard")
    assert trainer.language == PSEUDO_LANGUAGE
    wait_text(dash_page, qps.gettext("Push language to all trainees"))
    assert_not_blank(shot(dash_page, "dashboard_pseudo_1024x768"), min_colors=50)
