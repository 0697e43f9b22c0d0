"""Attendance and the touches' export in chromium: the issue's class (ana finished, ben stuck
at step 2, chen joined and idle) on the trainer's dashboard at 1024x768 and 1400x900, the idle
row highlighted, the thresholds' inputs in view; a wizard's "Export touches (CSV)" downloads
the POSES.csv ``tcpcal solve`` reads, on a desktop and on a phone (390x844).
Screenshots: ``attendance-1024x768.png``, ``attendance-1400x900.png``,
``export-touches-1024x768.png``, ``export-touches-390x844.png`` in the test's folder."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from support.guiclick import choose, click
from support.pendant_page import TIMEOUT_MS, assert_not_blank, wait_text
from support.wizard_page import open_calibrate, press
from support.wsclient import DrainingClient, wait_until

pytestmark = pytest.mark.browser

TOKEN = "trainer-secret-attend-42"

ROWS_JS = """() => [...document.querySelectorAll('.tcp-dashboard-trainees tbody tr')].map(r => r.className)"""


def _class(app: Any) -> list[DrainingClient]:
    clients = []
    for i, name in enumerate(("ana", "ben", "chen")):
        clients.append(DrainingClient(app.port))
        wait_until(lambda: len(app.sessions) == i + 1 and "identity" in list(app.sessions.values())[-1].views,
                   what=f"{name}'s name prompt")
        s = list(app.sessions.values())[-1]
        p = s.views["identity"]
        choose(p.name_field, name, s.client)
        click(p.start, s.client)
        if name == "chen":
            continue
        cal = s.views["calibrate"]
        click(cal.start, s.client)
        for _ in range(6 if name == "ana" else 1):
            if cal.workflow.result is not None:
                break
            click(cal.steps.auto_touch, s.client)
    with app.gradebook.store.write() as db:            # everything 12 minutes ago
        for table, column in (("run_states", "step_since"), ("touches", "recorded_at"), ("sessions", "started_at")):
            db.execute(f"UPDATE {table} SET {column} = strftime('%Y-%m-%dT%H:%M:%f+00:00', 'now', '-12 minutes')")
    return clients


@pytest.mark.parametrize("width, height", [(1024, 768), (1400, 900)])
def test_the_dashboard_flags_the_stuck_and_the_idle_trainee(app_factory, new_page, shot, tmp_path: Path,
                                                           width: int, height: int) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, seed=11)
    clients = _class(app)
    try:
        page = new_page(app.trainer_url, width=width, height=height, wait_for="")
        wait_text(page, "Trainer dashboard")
        page.locator(".tcp-dashboard-trainees tr.idle").first.wait_for(timeout=TIMEOUT_MS)
        assert page.evaluate(ROWS_JS) == ["trainee", "stuck", "idle"]
        for label in ("Stuck after (min)", "Idle after (min)"):
            box = page.get_by_label(label, exact=True).first.bounding_box()
            assert box is not None and box["y"] + box["height"] <= height, (label, box)   # in view, no scroll
        idle = page.locator(".tcp-dashboard-trainees tr.idle").first
        assert "◔ chen" in idle.inner_text() and "idle" in idle.inner_text()
        assert_not_blank(shot(page, f"attendance-{width}x{height}"), min_colors=50)
    finally:
        for c in clients:
            c.close()


@pytest.mark.parametrize("width, height", [(1024, 768), (390, 844)])
def test_export_touches_downloads_the_poses_csv(pendant_server, new_page, shot, width: int, height: int) -> None:
    server = pendant_server()
    page = new_page(server.url, width=width, height=height)
    open_calibrate(page)
    press(page, "Start")
    assert page.get_by_role("button", name="Export touches (CSV)", exact=True).filter(visible=True).count() == 0
    press(page, "Auto-touch")
    press(page, "Auto-touch")
    button = page.get_by_role("button", name="Export touches (CSV)", exact=True).filter(visible=True).first
    button.wait_for(timeout=TIMEOUT_MS)
    button.scroll_into_view_if_needed()
    assert_not_blank(shot(page, f"export-touches-{width}x{height}"))
    with page.expect_download(timeout=TIMEOUT_MS) as dl:
        button.click()
    assert dl.value.suggested_filename == "xyz4-touches.csv"
    lines = Path(dl.value.path()).read_text().splitlines()
    assert lines[0] == "# tcpcal solve xyz4 xyz4-touches.csv" and lines[1].startswith("name,x,y,z,a,b,c,j1")
    assert [line.split(",")[0] for line in lines[2:]] == ["P1", "P2"]
    assert np.isfinite([float(v) for v in lines[2].split(",")[1:]]).all()
