"""Issue 10's leftovers on the Calibrate tab, in a real viser server (in-process) with a
headless websocket client as the browser (``guiclick``): the Auto-touch line never goes stale
(item 6), wizard touches keep their distance-at-record for the session record and the result
(item 4), and an XYZ 4-point wizard can start from the free "Record point" touches (item 1)."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from tcp_pendant.server import AppConfig, PendantApp
from tcp_pendant.views.wizard_menu import CalibrateView

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE.parent / "app"))
sys.path.insert(0, str(HERE))
from guiclick import choose, click
from wsclient import DrainingClient, wait_until


class Page:
    """One connected browser: its session, Calibrate view and client."""

    def __init__(self, app: PendantApp) -> None:
        n = len(app.sessions)
        self.ws = DrainingClient(app.port)
        wait_until(lambda: len(app.sessions) > n, what="session built")
        self.session = list(app.sessions.values())[-1]
        self.view: CalibrateView = self.session.views["calibrate"]
        self.client = self.session.client
        self.notes: list[tuple[str, str]] = []
        self.session.notify = lambda title, body, kind="info": self.notes.append((title, body))  # type: ignore[method-assign]

    def click(self, handle: Any) -> None:
        click(handle, self.client)

    def choose(self, handle: Any, value: Any) -> None:
        choose(handle, value, self.client)


@pytest.fixture
def page(tmp_path: Path) -> Iterator[Callable[..., Page]]:
    apps: list[PendantApp] = []
    pages: list[Page] = []

    def make(tool: str = "pointer") -> Page:
        app = PendantApp(AppConfig(port=0, tool=tool, tool_library=tmp_path / "tools.json", library_poll_s=0.1))
        app.start()
        apps.append(app)
        p = Page(app)
        p.view.workflow.rng = np.random.default_rng(5)
        pages.append(p)
        return p

    yield make
    for p in pages:
        p.ws.close()
    for a in apps:
        a.stop()


# ---------------------------------------------------------------- item 6: stale texts
def test_auto_touch_line_goes_when_a_step_is_recorded_by_hand(page) -> None:
    p = page()
    v = p.view
    p.click(v.start)
    p.click(v.steps.auto_touch)                        # step 1 by auto-touch, the wizard is on step 2
    assert v.workflow.wizard.step_index == 1
    assert v.steps.auto_md.content.startswith("Step 1 recorded")
    p.click(v.steps.record)                            # step 2 recorded by hand
    assert v.workflow.wizard.recorded_poses.keys() == {0, 1}
    assert v.steps.auto_md.content == ""               # no "Step 1 recorded" next to step 2's record


def test_auto_touch_line_follows_every_auto_touch_and_the_step(page) -> None:
    p = page()
    v = p.view
    p.click(v.start)
    for _ in range(3):
        p.click(v.steps.auto_touch)
    assert v.steps.auto_md.content.startswith("Step 3 recorded")
    p.click(v.steps.back)                              # back to step 3: the line was about going on
    assert v.steps.auto_md.content == ""


def test_auto_touch_line_does_not_carry_into_another_wizard(page) -> None:
    p = page()
    v = p.view
    p.click(v.start)
    p.click(v.steps.auto_touch)
    assert v.steps.auto_md.content.startswith("Step 1 recorded")
    p.click(v.steps.cancel)
    p.click(v.start)                                   # another wizard: nothing from the first one
    assert len(v.workflow.runs) == 2
    assert v.steps.auto_md.content == ""
