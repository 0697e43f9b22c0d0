"""A class exercise explains itself (issue 44): with no instructions typed by the trainer the
trainee's panel shows the default brief (what to calibrate, how it is graded, what is hidden),
and a Record far from the tip with the distance hidden is recorded with the same neutral words
as one on the tip (no ✔, no distance). Real class server, one websocket browser."""

from __future__ import annotations

import pytest

from support.app_page import join_as_the_only_trainee, true_tip_at
from support.guiclick import choose, click
from support.wsclient import DrainingClient

from tcp_pendant.calibrate.record_words import EXERCISE_RECORDED
from tcp_pendant.views.wizard_dock import NEXT

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def test_an_exercise_without_instructions_shows_the_default_brief_and_records_neutrally(app_factory, tmp_path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="trainer-token-tok-1", exercise="mystery")
    c = DrainingClient(app.port)
    try:
        s = join_as_the_only_trainee(app, "Anna Trainee")
        banner = s.views["notices"].banner
        text = banner.content
        assert banner.visible and s.rules.instructions == ""
        assert "**What to do:** calibrate the TCP of the tool mounted on the robot" in text
        assert "good under 0.5 mm, fair under 2 mm" in text                  # how it is graded
        assert "**What is hidden:** the distance to the reference tip" in text and "Auto-touch (off)" in text
        calibrate, dock = s.views["calibrate"], s.views["dock"]
        click(calibrate.start, s.client)
        assert s.hide_distance
        true_tip_at(s, (0.0, 0.0, 200.0))                                      # 200 mm above the tip
        click(dock.record, s.client)
        wiz = calibrate.workflow.wizard
        far = dock.note_md.content
        assert wiz.steps[0].recorded                                           # still recorded
        assert far == EXERCISE_RECORDED.format(n=1) and "✔" not in far and "mm from" not in far
        choose(dock.nav, NEXT, s.client)
        true_tip_at(s, (0.0, 0.0, 0.0))                                        # on the tip: the same words
        click(dock.record, s.client)
        assert dock.note_md.content == EXERCISE_RECORDED.format(n=2)
    finally:
        c.close()
