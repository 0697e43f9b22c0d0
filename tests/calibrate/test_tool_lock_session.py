"""The exercise's tool stays mounted (``SessionTools.set_exercise_tool``): "Mounted tool" is refused in
words, a calibration may only measure that tool, and the XYZ reference method's tool change is
the one exception, for its own run; free practice swaps freely. A calibration is filed under the
tool it measured: touches of another tool than their step measures do not finish."""

from __future__ import annotations

from pathlib import Path

import pytest
from tcp_pendant.classroom.mystery import draw_mystery_tool
from tcp_pendant.controller import ToolModel, builtin_tools
from tcp_pendant.events import RunStarted
from tcp_pendant.calibrate.pendant_rules import FREE_PRACTICE, TOOL_LOCKED_WORDS, RuleRefusal
from tcp_pendant.classroom.exercise_rules import class_rules
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.wizards import WizardStateError

from support.calib_helpers import library_tool_with_true_tcp, make_session

TOOLS = builtin_tools()


def _exercise(tmp_path: Path) -> tuple[Session, ToolModel]:
    """A session in the mystery exercise, its trainee's mystery tool held mounted (as the
    classroom sets it), the pointer's exact TCP in library slot 1 (the README prints it)."""
    s = make_session(tmp_path / "tools.json", seed=4)
    s.library.save(1, library_tool_with_true_tcp("pointer", "Pointer"))
    s.tools.reload_library()
    mystery = draw_mystery_tool(11, "Mallory", TOOLS["pointer"])
    s.wizard_commands.add_physical_tool(mystery)
    s.tools.set_exercise_tool(mystery)
    s.set_rules(class_rules("mystery"))
    return s, mystery


def _events(s: Session) -> list[object]:
    events: list[object] = []

    def keep(change: SessionChange) -> None:
        events.extend(change.events)
    s.subscribe(keep)
    return events


def test_mounting_another_tool_is_refused_in_words(tmp_path: Path) -> None:
    s, mystery = _exercise(tmp_path)
    assert s.controller.mounted_tool is mystery
    for key in ("torch", "pointer"):
        with pytest.raises(RuleRefusal, match=TOOL_LOCKED_WORDS) as refused:
            s.tools.mount_tool(TOOLS[key])
        assert TOOLS[key].label.lower() in str(refused.value) and "mystery tool" in str(refused.value)
        assert s.controller.mounted_tool is mystery
    s.tools.mount_tool(mystery)                                   # its own tool: no change, no refusal
    with pytest.raises(RuleRefusal, match=TOOL_LOCKED_WORDS):
        s.tools.mount_step_tool(TOOLS["torch"])                   # no wizard step asks for it
    assert s.controller.mounted_tool is mystery


def test_free_practice_swaps_freely_and_the_lock_follows_the_exercise(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json")
    s.tools.mount_tool(TOOLS["torch"])
    s.tools.mount_tool(TOOLS["pointer"])
    assert s.controller.mounted_tool.key == "pointer" and s.tools.exercise_tool is None

    s, mystery = _exercise(tmp_path / "class")
    s.set_rules(FREE_PRACTICE)                              # the trainer switches the exercise off
    assert s.tools.exercise_tool is None
    s.tools.mount_tool(TOOLS["torch"])
    assert s.controller.mounted_tool.key == "torch"
    s.tools.set_exercise_tool(mystery)                            # ... and on again
    assert s.controller.mounted_tool is mystery
    with pytest.raises(RuleRefusal):
        s.tools.mount_tool(TOOLS["torch"])


def test_a_calibration_in_the_exercise_measures_the_trainees_own_tool(tmp_path: Path) -> None:
    s, mystery = _exercise(tmp_path)
    events = _events(s)
    for ref, new in (("pointer", "torch"), (mystery.key, "pointer")):
        with pytest.raises(RuleRefusal, match="calibrates your own tool"):
            s.wizard_commands.start("reference", slot=1, reference_tool_key=ref, new_tool_key=new)
    assert s.workflow.runs == [] and s.controller.mounted_tool is mystery
    s.wizard_commands.start("xyz4")
    (started,) = [e for e in events if isinstance(e, RunStarted)]
    assert started.tool_key == mystery.key


def test_xyz_reference_mounts_its_reference_tool_and_gives_the_mystery_tool_back_at_finish(tmp_path: Path) -> None:
    s, mystery = _exercise(tmp_path)
    events = _events(s)
    s.wizard_commands.start("reference", slot=1, reference_tool_key="pointer", new_tool_key=mystery.key)
    (started,) = [e for e in events if isinstance(e, RunStarted)]
    assert started.tool_key == mystery.key                  # filed under the tool it calibrates
    with pytest.raises(RuleRefusal):
        s.tools.mount_tool(TOOLS["pointer"])                      # not through Mounted tool
    assert s.wizard_commands.mount_required_tool().key == "pointer"         # the wizard's own tool change
    assert s.controller.mounted_tool.key == "pointer"
    s.wizard_commands.record_step()
    s.wizard_commands.next_step()
    assert s.controller.mounted_tool.key == "pointer"       # until the wizard's next tool change
    assert s.wizard_commands.mount_required_tool() is mystery
    s.wizard_commands.record_step()
    s.wizard_commands.back()                                                # the reference tool once more ...
    s.wizard_commands.mount_required_tool()
    s.wizard_commands.next_step()
    assert s.controller.mounted_tool.key == "pointer"
    assert s.wizard_commands.next_step() is not None                        # ... Finish with it on the flange
    assert s.controller.mounted_tool is mystery             # the exercise's tool is back


def test_xyz_reference_cancelled_gives_the_mystery_tool_back(tmp_path: Path) -> None:
    s, mystery = _exercise(tmp_path)
    s.wizard_commands.start("reference", slot=1, reference_tool_key="pointer", new_tool_key=mystery.key)
    s.wizard_commands.mount_required_tool()
    assert s.controller.mounted_tool.key == "pointer"
    s.wizard_commands.cancel()
    assert s.controller.mounted_tool is mystery
    s.wizard_commands.resume()                                       # back at its step: the tool change again
    assert s.controller.mounted_tool is mystery
    s.wizard_commands.mount_required_tool()
    s.wizard_commands.start("xyz4")                                  # another run cancels it
    assert s.controller.mounted_tool is mystery


def test_touches_made_with_another_tool_than_the_calibrated_one_do_not_finish(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json", seed=2)      # free practice: the pointer mounted
    s.wizard_commands.start("xyz4")
    for _ in range(3):
        s.wizard_commands.record_step()
        s.wizard_commands.next_step()
    s.tools.mount_tool(TOOLS["torch"])
    s.wizard_commands.record_step()
    with pytest.raises(WizardStateError, match="Step 4 was recorded with the bent-neck welding torch, but it "
                                               "measures the straight pointer"):
        s.wizard_commands.next_step()
    assert s.workflow.result is None
    s.tools.mount_tool(TOOLS["pointer"])
    s.wizard_commands.record_step()                                         # step 4 again, with the pointer
    with pytest.raises(Exception) as failed:                # four touches at one pose: tcpcal's failure,
        s.wizard_commands.next_step()                                       # not the tool's
    assert "recorded with" not in str(failed.value)
