"""The words a trainee sees in the first hour, and the library tool the
orientation wizards offer first."""

from __future__ import annotations

import re
from datetime import datetime

import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.calibrate.library_choice import default_library_slot
from tcp_pendant.wizards import wizard_classes
from tcp_pendant.wizards import WizardStateError

from tcpcal.tool import Tool

from support.calib_helpers import library_tool_with_true_tcp
from support.calib_page import Page


def run_auto(wf) -> None:
    for _ in range(wf.wizard.n_steps):
        assert wf.auto_touch(AutoTouchRequest()).ok
    assert wf.result is not None


def test_method_blurbs_point_at_no_file_the_trainee_cannot_open() -> None:
    for cls in wizard_classes():
        assert "methods.md" not in cls.blurb and "section" not in cls.blurb, cls.kind


def test_tool_change_is_asked_for_by_the_tools_labels(workflow, library) -> None:
    library.save(1, library_tool_with_true_tcp("pointer", "Pointer"))
    wf = workflow(tool="pointer")
    wiz = wf.start("reference", slot=1, reference_tool_key="pointer", new_tool_key="torch")
    wf.auto_touch(AutoTouchRequest())
    assert wiz.blocked_reason == "Mount the bent-neck welding torch first: the straight pointer is mounted now."
    assert "'" not in wiz.blocked_reason and "torch'" not in wiz.blocked_reason


def test_auto_touch_reports_a_sentence(workflow) -> None:
    wf = workflow()
    wf.start("xyz4")
    out = wf.auto_touch(AutoTouchRequest())
    assert out.message.startswith("Step 1 recorded: Touch 1 (tilt ") and out.message.endswith("°).")


def test_three_point_auto_touch_message_reads_as_a_sentence(workflow, library) -> None:
    library.save(1, library_tool_with_true_tcp("pointer", "Pointer"))
    wf = workflow()
    wf.start("three-point", slot=1)
    out = wf.auto_touch(AutoTouchRequest())
    assert out.message.startswith("Step 1 recorded: Touch the reference tip (tilt ")
    assert "Recorded touch the" not in out.message


def test_left_half_way_lists_only_runs_still_to_do(workflow) -> None:
    wf = workflow()
    wf.start("xyz4")
    run_auto(wf)
    wf.save("Pen")                                   # run 1: finished and saved
    wf.start("xyz4")
    run_auto(wf)                                     # run 2: finished, not saved
    wf.start("xyz4")
    wf.auto_touch(AutoTouchRequest())                # run 3: half-way
    wf.start("xyz4")                                  # run 4 open: the others are cancelled
    labels = [re.sub(r"started \d\d:\d\d$", "started HH:MM", label) for _, label in wf.resumable()]
    assert labels == ["3: XYZ 4-point, at step 2 of 4 (1 recorded), started HH:MM",
                      "2: XYZ 4-point, result not saved, started HH:MM"]
    started = datetime.fromisoformat(wf.runs[2].wizard.started_at.replace("Z", "+00:00")).astimezone()
    assert wf.resumable()[0][1].endswith(started.strftime("%H:%M"))      # the server's local time
    assert wf.resume().kind == "xyz4" and wf.run is wf.runs[2]          # newest still to do
    wf.resume(1)                                     # the unsaved result can be saved later
    assert wf.result is not None and not wf.result_saved
    wf.save("Pen 2")
    assert wf.result_saved
    wf.cancel()
    assert [i for i, _ in wf.resumable()] == [3, 2]           # the two runs still to do
    with pytest.raises(WizardStateError, match="Calibration 9 is not waiting"):
        wf.resume(8)


def test_a_saved_run_changed_afterwards_is_listed_again(workflow) -> None:
    wf = workflow()
    wf.start("xyz4")
    run_auto(wf)
    wf.save("Pen")
    wf.back()                                        # a step back: the saved result no longer stands
    wf.next()                                        # finished again: a new result, not saved
    wf.cancel()
    assert [label.split(", started")[0] for _, label in wf.resumable()] == ["1: XYZ 4-point, result not saved"]


class _T:
    def __init__(self, name: str) -> None:
        self.name = name


@pytest.mark.parametrize("kwargs,expected", [
    (dict(active_slot=3, active_tool_name="Torch", mounted_label="Straight pointer", mounted_key="pointer"), 3),
    (dict(active_slot=None, active_tool_name="torch", mounted_label="Straight pointer", mounted_key="pointer"), 3),
    (dict(active_slot=None, active_tool_name=None, mounted_label="Bent-neck welding torch", mounted_key="torch"), 3),
    (dict(active_slot=None, active_tool_name=None, mounted_label="Straight pointer", mounted_key="pointer"), 1),
    (dict(active_slot=5, active_tool_name=None, mounted_label="Straight pointer", mounted_key="pointer"), 1),
])
def test_default_library_slot(kwargs, expected) -> None:
    tools = {1: _T("Pen"), 3: _T("Torch"), 4: _T("Gripper")}
    assert default_library_slot(tools, **kwargs) == expected
    assert default_library_slot({}, **kwargs) is None


def test_default_library_slot_matches_the_mounted_tools_label() -> None:
    tools = {1: _T("Pen"), 2: _T("Bent-neck welding torch")}
    assert default_library_slot(tools, active_slot=None, active_tool_name=None,
                                mounted_label="Bent-neck welding torch", mounted_key="torch") == 2


@pytest.mark.app_page(cls=Page)
def test_tool_data_defaults_to_the_active_slot_not_slot_1(page) -> None:
    """In a running app: with the torch's data active in slot 3, the orientation wizards
    offer slot 3; a pick by the user holds until the active tool data changes."""
    p = page({1: Tool(name="Pen", tcp_mm=(0.0, 0.0, 150.0)), 3: Tool(name="Torch", tcp_mm=(0.0, 0.0, 200.0)),
              4: Tool(name="Gripper", tcp_mm=(0.0, 0.0, 120.0))}, tool="torch")
    v, s = p.view, p.session
    tools = s.views["tools"]                     # the trainee activates slot 3 on the Tool tab
    p.choose(tools.slots, "3: Torch")
    p.click(tools.activate)
    p.choose(v.method, "ABC world (parallel axes)")
    assert s.tools.active_slot == 3, "the session's active tool should be offered"
    assert v.library_tool.value == "3: Torch"
    p.choose(v.library_tool, "4: Gripper")       # the user's pick holds ...
    p.choose(v.method, "Three-point orientation")
    assert v.library_tool.value == "4: Gripper"
    p.click(v.start)                             # ... and Start makes it active
    assert s.tools.active_slot == 4 and v.workflow.wizard.tool.name == "Gripper"


def test_the_4_point_steps_ask_for_what_the_meter_can_reward() -> None:
    """Touch 2 is the first tilt (no 'different axis than before' when nothing was tilted),
    touch 3 asks for another axis, and every tilt asked for is the least the meter calls far
    enough (``MIN_TILT_DEG``)."""
    from tcp_pendant.calibrate.diversity import MIN_TILT_DEG
    from tcp_pendant.wizards import Xyz4Wizard

    steps = Xyz4Wizard(n_points=4).steps
    assert "about A, B or C" in steps[1].instruction and "before" not in steps[1].instruction
    assert "another axis than for touch 2" in steps[2].instruction
    for step in steps[1:]:
        assert f"{MIN_TILT_DEG:.0f} to 60°" in step.instruction, step.index


def test_the_touch_list_points_at_the_wizards_touches(tmp_path) -> None:
    """With no free touch but four wizard touches the Jog tab's Touches list does not say
    'No touch recorded' (it did): it says where they are."""
    from support.calib_helpers import make_session
    from tcp_pendant.calibrate.text import empty_touches_markdown

    s = make_session(tmp_path / "tools.json", seed=4)
    assert empty_touches_markdown(s.workflow.wizard) == "*No touch recorded.*"
    s.wizard_commands.start("xyz4")
    for _ in range(4):
        s.wizard_commands.auto_touch(AutoTouchRequest())
    text = empty_touches_markdown(s.workflow.wizard)
    assert "No touch recorded with Record point" in text and "has 4 touches of its own" in text
    s.wizard_commands.cancel()
    assert empty_touches_markdown(s.workflow.wizard) == "*No touch recorded.*"


def test_exact_touches_are_not_called_outside_the_95_percent_radius(tmp_path) -> None:
    """sigma 0: an error of ~1e-12 mm next to a radius of ~1e-13 mm was 'outside the 95 %
    radius' beside '0.000 mm, good'."""
    from support.calib_helpers import make_session
    from tcp_pendant.calibrate.text import truth_markdown

    s = make_session(tmp_path / "tools.json", seed=6)
    s.wizard_commands.start("xyz4")
    while s.workflow.result is None:
        s.wizard_commands.auto_touch(AutoTouchRequest(sigma_mm=0.0))
    truth = s.workflow.truth()
    assert truth.position_error_mm < 1e-6 and truth.inside_ci95 is True and truth.grade == "good"
    md = truth_markdown(truth)
    assert "outside" not in md and "the computed TCP is the true one" in md
    s.wizard_commands.back()                                     # a touch 2 mm off: a real error, judged as before
    s.wizard_commands.auto_touch(AutoTouchRequest(sigma_mm=2.0))
    noisy = s.workflow.truth()
    assert noisy.position_error_mm > 1e-3
    assert ("inside" if noisy.inside_ci95 else "**outside**") in truth_markdown(noisy)
