"""The trainer's dashboard in chromium at 1024x768 (a projector): three trainees joined over
raw websockets, the trainer address opened in a page. The table fits the window without a
horizontal scroll bar, one line per trainee, the stuck trainee highlighted; no pendant and no
robot on the trainer's page; a calibration replayed in the dashboard's own 3D scene.
Screenshots: ``dashboard-table.png``, ``dashboard-replay.png`` in the test's folder."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from support.guiclick import choose, click
from support.pendant_page import TIMEOUT_MS, assert_not_blank, wait_text
from support.wsclient import DrainingClient, wait_until

pytestmark = pytest.mark.browser

TOKEN = "trainer-secret-4242"
NAMES = ("Anna", "Ben <b>B</b>", "Chiara Maria Long-Surname")


def _class_of_three(app: Any) -> list[DrainingClient]:
    """Three trainees over raw websockets: Anna finishes a 4-point, Ben stops after one touch,
    Chiara after two."""
    clients = []
    for i, name in enumerate(NAMES):
        clients.append(DrainingClient(app.port))
        wait_until(lambda: len(app.sessions) == i + 1 and "identity" in list(app.sessions.values())[-1].views,
                   what=f"{name}'s name prompt")
        s = list(app.sessions.values())[-1]
        p = s.views["identity"]
        choose(p.name_field, name, s.client)
        click(p.start, s.client)
        cal = s.views["calibrate"]
        click(cal.start, s.client)
        for _ in range((6, 1, 2)[i]):
            if cal.workflow.result is not None:
                break
            click(cal.steps.auto_touch, s.client)
    return clients


FITS_JS = """() => {
  const doc = document.scrollingElement || document.documentElement;
  const box = document.querySelector('.tcp-dashboard-trainees');
  const rows = [...document.querySelectorAll('.tcp-dashboard-trainees tbody tr')];
  const td = rows.length ? rows[0].querySelector('td') : null;
  return {pageScroll: doc.scrollWidth - window.innerWidth, tableScroll: box.scrollWidth - box.clientWidth,
          tableWidth: box.getBoundingClientRect().width, rowHeights: rows.map(r => r.getBoundingClientRect().height),
          lineHeight: td ? parseFloat(getComputedStyle(td).lineHeight) : 0,
          stuck: rows.map(r => r.classList.contains('stuck'))};
}"""


def test_the_trainer_address_opens_a_projector_dashboard(app_factory, new_page, shot, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, seed=11)
    clients = _class_of_three(app)
    try:
        with app.gradebook.store.write() as db:     # Ben has been on his step for 12 minutes, no touch since
            db.execute("UPDATE run_states SET step_since = strftime('%Y-%m-%dT%H:%M:%f+00:00', 'now', '-12 minutes') "
                       "WHERE calibration_id = 2")
            db.execute("UPDATE touches SET recorded_at = strftime('%Y-%m-%dT%H:%M:%f+00:00', 'now', '-12 minutes') "
                       "WHERE calibration_id = 2")
        page = new_page(app.trainer_url, width=1024, height=768, wait_for="")
        wait_text(page, "Trainer dashboard")
        wait_text(page, "Chiara Maria")
        page.locator(".tcp-dashboard-trainees tr.stuck").first.wait_for(timeout=TIMEOUT_MS)
        page.wait_for_timeout(500)
        fit = page.evaluate(FITS_JS)
        assert fit["pageScroll"] <= 0 and fit["tableScroll"] <= 0, fit          # no horizontal scroll
        assert fit["tableWidth"] >= 700, fit                                     # the panel is wide
        assert len(fit["rowHeights"]) == 3 and max(fit["rowHeights"]) < 1.8 * fit["lineHeight"], fit   # one line each
        assert fit["stuck"] == [False, True, False], fit
        # the pendant and the robot are gone from this page
        for label in ("X +", "Record point", "Record"):
            assert page.get_by_role("button", name=label, exact=True).count() == 0, label
        assert page.get_by_role("tab", name="Jog", exact=True).count() == 0
        trainer = next(s for s in app.sessions.values() if "trainer" in s.views)
        assert set(trainer.views) == {"trainer", "tools"}          # the dashboard and its tool library folder
        assert page.get_by_text("Ben <b>B</b>", exact=False).count() >= 1      # shown literally, not as HTML
        assert page.locator(".tcp-dashboard-trainees b, .tcp-dashboard-runs b").count() == 0
        assert_not_blank(shot(page, "dashboard-table"), min_colors=50)
        # Anna's calibration in 3D, in the dashboard's own scene beside the narrowed panel
        page.get_by_label("Trainee", exact=True).first.click()
        page.get_by_role("option", name="Anna", exact=True).click()
        page.wait_for_timeout(300)
        page.get_by_role("button", name="Replay in 3D", exact=True).click()
        page.get_by_role("button", name="Close replay", exact=True).wait_for(timeout=TIMEOUT_MS)
        wait_text(page, "Replay of Anna")
        page.wait_for_timeout(1500)                 # software WebGL draws the frames
        assert trainer.views["trainer"].replay_scene.shown.trainee == "Anna"
        assert_not_blank(shot(page, "dashboard-replay"), min_colors=50)
    finally:
        for c in clients:
            c.close()
