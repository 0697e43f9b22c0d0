"""A Finish that cannot compute says why in the step panels, with the steps to redo and how to
get there (it used to say it in a toast at most: the calibration stayed open with nothing on
the panel)."""

from __future__ import annotations

from pathlib import Path

import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.views.wizard_dock import FINISH
from tcp_pendant.wizards import CalibrationFailedError

from support.calib_helpers import make_session
from support.calib_page import Page

pytestmark = pytest.mark.app_page(cls=Page, seed=5)


def three_touches_then_a_repeat(s) -> None:
    """XYZ 4-point: three touches by Auto-touch, then touch 4 recorded by hand where touch 3
    was (the robot stands there: the same orientation)."""
    s.wizard_commands.start("xyz4")
    for _ in range(3):
        assert s.wizard_commands.auto_touch(AutoTouchRequest()).ok
    s.wizard_commands.record_step()


def test_the_workflow_says_which_touches_and_what_to_do(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json", seed=1)
    three_touches_then_a_repeat(s)
    with pytest.raises(CalibrationFailedError) as err:
        s.wizard_commands.next_step()
    text = s.workflow.finish_failure
    assert text == str(err.value)
    assert text.startswith("Touches 3 and 4 have the same orientation (0.00° apart)")
    assert "record step 4 again" in text and "0-based" not in text
    s.wizard_commands.back()                                            # the failure belongs to where it happened
    assert s.workflow.finish_failure is None


def test_an_earlier_repeat_sends_the_trainee_back_to_its_step(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json", seed=2)
    s.wizard_commands.start("xyz4")
    assert s.wizard_commands.auto_touch(AutoTouchRequest()).ok          # touch 1; the wizard is on step 2
    s.wizard_commands.record_step()                                     # touch 2 where touch 1 was
    s.wizard_commands.next_step()
    assert s.wizard_commands.auto_touch(AutoTouchRequest()).ok          # touch 3
    with pytest.raises(CalibrationFailedError, match="Touches 1 and 2 have the same orientation"):
        s.wizard_commands.auto_touch(AutoTouchRequest())                # touch 4, and Finish
    assert "go Back to step 2 and record it again" in s.workflow.finish_failure


def test_a_failed_finish_in_the_dock_and_the_steps_view_is_said_in_the_panel(page) -> None:
    p = page()
    s = p.session
    three_touches_then_a_repeat(s)
    dock, steps = s.views["dock"], p.view.steps
    p.choose(dock.nav, FINISH)
    assert s.workflow.result is None and s.workflow.wizard.status == "in_progress"
    assert dock.note_md.visible and "Finish not possible: Touches 3 and 4 have the same orientation" in \
        dock.note_md.content
    assert steps.blocked_md.visible and "record step 4 again" in steps.blocked_md.content
    s.wizard_commands.back()                                            # gone once the trainee acts on it
    assert not dock.note_md.visible and not steps.blocked_md.visible
