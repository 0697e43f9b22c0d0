"""In the app: systematic-error scenarios as session state (``Session.set_scenario``,
one change signal), played by the controller (physical robot, bent tool, knocked reference tip),
chosen in the Calibrate tab's "Systematic error" panel (training only; the explanation after a
result, escaped), and as the start options ``--scenario`` / ``--scenario-seed``. Item 4: touches
carry their joint values, in the session and its record. In-process server, headless websocket
clients as browsers (``guiclick``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from support.app_page import AppPage

from tcpcal.tool import Tool
from tcp_pendant.calibrate.workflow import AutoTouchRequest
from tcp_pendant.serve.cli import SCENARIO_CHOICES, build_parser
from tcp_pendant.controller import ControllerError, builtin_tools, reference_tip_model
from tcp_pendant.controller.scenarios import SCENARIO_KINDS, explain
from tcp_pendant.serve.server import AppConfig, PendantApp
from tcp_pendant.session import SessionChange
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.scenario_panel import SCENARIO_CHOICES as PANEL_CHOICES
from tcp_pendant.views.scenario_panel import scenario_markdown
from tcp_pendant.wizards.session_record import (
    SessionRecordError,
    check_session_record,
    session_from_controller,
)


class Page(AppPage):
    """One connected browser: its session, views and every change signal it saw."""

    def __init__(self, app: PendantApp) -> None:
        super().__init__(app)
        self.panel = self.session.views["scenario"]
        self.calibrate = self.session.views["calibrate"]
        self.tools = self.session.views["tools"]
        self.touches = self.session.views["touches"]
        self.changes: list[SessionChange] = []
        self.session.subscribe(self.changes.append)


pytestmark = pytest.mark.app_page(cls=Page, seed=5)


def auto_xyz4(p: Page) -> None:
    v = p.calibrate
    p.click(v.start)
    for _ in range(4):
        p.click(v.steps.auto_touch)
    assert v.workflow.result is not None


# ----------------------------------------------------------------------------- session state
def test_robot_accuracy_puts_a_physical_robot_under_the_readouts(page) -> None:
    p = page()
    s, c = p.session, p.session.controller
    readout = c.readout()
    tip_before = c.T_world_tool_true()
    s.set_scenario("robot_accuracy", 4)
    assert c.true_kinematics is not c.kinematics
    assert c.readout() == readout                                    # the controller's belief
    moved_mm = np.linalg.norm(c.T_world_tool_true()[:3, 3] - tip_before[:3, 3]) * 1000.0
    assert 0.05 < moved_mm < 5.0                                     # where the tip really is
    assert p.changes[-1].tool and p.changes[-1].state is not None   # one signal, with the state
    np.testing.assert_allclose(p.changes[-1].state.T_world_tool_true, c.T_world_tool_true(), atol=1e-15)
    s.set_scenario("off")
    assert c.true_kinematics is c.kinematics
    np.testing.assert_allclose(c.T_world_tool_true(), tip_before, atol=1e-15)


def test_bent_tool_is_bolted_on_and_stays_bent_across_mounts_library_untouched(page) -> None:
    p = page()
    s, c = p.session, p.session.controller
    pointer = builtin_tools()["pointer"]
    s.set_scenario("bent_tool", 2)
    bend_mm = np.linalg.norm(c.mounted_tool.T_flange_tool_true[:3, 3] - pointer.T_flange_tool_true[:3, 3]) * 1000
    assert c.mounted_tool.key == "pointer" and 2.0 <= bend_mm <= 5.5
    p.choose(p.tools.mounted, builtin_tools()["torch"].label)       # another tool: bent too
    torch = builtin_tools()["torch"]
    assert c.mounted_tool.key == "torch"
    assert np.linalg.norm(c.mounted_tool.T_flange_tool_true[:3, 3] - torch.T_flange_tool_true[:3, 3]) * 1000 > 2.0
    p.choose(p.tools.mounted, pointer.label)
    first = c.mounted_tool
    p.choose(p.tools.mounted, torch.label)
    p.choose(p.tools.mounted, pointer.label)
    assert c.mounted_tool is first                                   # the same bent pointer
    s.set_scenario("off")
    np.testing.assert_allclose(c.mounted_tool.T_flange_tool_true, pointer.T_flange_tool_true, atol=1e-15)
    assert s.library.tools() == {}


def test_a_bent_tool_calibrated_anew_is_graded_against_the_bent_truth(page) -> None:
    p = page()
    p.session.set_scenario("bent_tool", 1)
    auto_xyz4(p)
    truth = p.calibrate.workflow.truth()
    assert truth is not None and truth.position_error_mm < 0.01      # the new TCP is right
    bent = p.session.controller.mounted_tool.T_flange_tool_true[:3, 3] * 1000.0
    np.testing.assert_allclose(p.calibrate.workflow.result.tcp_mm, bent, atol=0.01)


def test_moved_reference_is_knocked_after_touch_k_and_stays(page) -> None:
    p = page()
    s, c = p.session, p.session.controller
    tip0 = c.reference_tip_world_m
    beam0 = c.beam_sensor
    world = s.set_scenario("moved_reference", 3)
    k = world.reference_move.after_touch
    for n in range(k):
        np.testing.assert_allclose(c.reference_tip_world_m, tip0)
        p.click(p.touches.record)
    shift = np.asarray(world.reference_move.shift_mm) / 1000.0
    np.testing.assert_allclose(c.reference_tip_world_m, tip0 + shift, atol=1e-15)
    assert p.changes[-1].pose and p.changes[-1].state.touch is not None
    scene = s.views["scene"]                                         # the stand is drawn where the tip is
    stand = reference_tip_model().T_world_stand(tip0 + shift)[:3, 3]
    np.testing.assert_allclose(scene._tip_frame.position, stand, atol=1e-9)
    np.testing.assert_array_equal(c.beam_sensor.point, beam0.point)  # the knock leaves the beam device
    s.delete_touch(0)                                                # a knocked tip stays knocked
    np.testing.assert_allclose(c.reference_tip_world_m, tip0 + shift, atol=1e-15)
    s.set_scenario("off")
    np.testing.assert_allclose(c.reference_tip_world_m, tip0)
    assert c.beam_sensor_is_default                                  # and it follows the tip again
    np.testing.assert_array_equal(c.beam_sensor.point, beam0.point)


def test_wizard_touches_count_for_the_moved_reference(page) -> None:
    p = page()
    s, c = p.session, p.session.controller
    tip0 = c.reference_tip_world_m
    world = s.set_scenario("moved_reference", 3)
    v = p.calibrate
    p.click(v.start)
    for n in range(4):
        expected = tip0 if n < world.reference_move.after_touch else tip0 + np.asarray(world.reference_move.shift_mm) / 1000
        np.testing.assert_allclose(c.reference_tip_world_m, expected, atol=1e-15)
        p.click(v.steps.auto_touch)
    res = v.workflow.result
    assert res is not None and res.max_error_mm > 0.5                # the touches disagree


def test_bad_scenarios_are_refused_by_name_and_change_nothing(page) -> None:
    p = page()
    s = p.session
    with pytest.raises(ControllerError, match="Unknown scenario"):
        s.set_scenario("wobbly")
    with pytest.raises(ControllerError, match="seed"):
        s.set_scenario("bent_tool", -1)
    assert s.scenario_player.scenario.kind == "off" and s.scenario_player.world is None


# ----------------------------------------------------------------------------- the panel
def test_panel_chooses_the_scenario_and_explains_it_after_a_result(page) -> None:
    p = page()
    panel, s = p.panel, p.session
    assert tuple(PANEL_CHOICES) == SCENARIO_KINDS
    assert panel.kind.value == "Off" and "No systematic error" in panel.md.content
    p.choose(panel.seed, 7)
    p.choose(panel.kind, "Robot accuracy")
    assert s.scenario_player.scenario.kind == "robot_accuracy" and s.scenario_player.scenario.seed == 7
    assert "Playing **Robot accuracy** (seed 7)" in panel.md.content
    assert "How this result shows it" not in panel.md.content
    auto_xyz4(p)
    expected = escape_markdown(explain(s.scenario_player.world))
    assert expected in panel.md.content and panel.md.content == scenario_markdown(s)
    res = p.calibrate.workflow.result
    assert 0.02 < res.max_error_mm < 1.0                               # the arm's inaccuracy shows
    p.choose(panel.kind, "Off")
    assert s.scenario_player.scenario.kind == "off" and s.controller.true_kinematics is s.controller.kinematics


def test_panel_shows_in_training_mode_only(page) -> None:
    p = page()
    v = p.calibrate
    assert p.panel.folder.visible
    p.choose(v.training, False)
    assert not p.panel.folder.visible
    p.choose(v.training, True)
    assert p.panel.folder.visible


def test_a_bad_seed_from_the_browser_is_one_notification(page) -> None:
    p = page()
    p.choose(p.panel.kind, "Bent tool")
    p.choose(p.panel.seed, -3)
    assert p.session.scenario_player.scenario.kind == "bent_tool" and p.session.scenario_player.scenario.seed == 0
    assert len(p.notes) == 1 and "seed" in p.notes[0][1]
    assert p.panel.seed.value == 0 and p.panel.kind.value == "Bent tool"   # shows what is played


# ----------------------------------------------------------------------------- start options
def test_start_option_scenario_every_session_starts_with_it(page) -> None:
    p = page(scenario="bent_tool", scenario_seed=5)
    assert p.session.scenario_player.scenario.kind == "bent_tool" and p.session.scenario_player.scenario.seed == 5
    assert p.panel.kind.value == "Bent tool"
    pointer = builtin_tools()["pointer"]
    assert not np.allclose(p.session.controller.mounted_tool.T_flange_tool_true, pointer.T_flange_tool_true)


def test_cli_scenario_names_and_a_bad_one(tmp_path: Path) -> None:
    assert tuple(n.replace("-", "_") for n in SCENARIO_CHOICES) == SCENARIO_KINDS
    args = build_parser().parse_args(["--scenario", "robot-accuracy", "--scenario-seed", "9"])
    assert (args.scenario, args.scenario_seed) == ("robot-accuracy", 9)
    with pytest.raises(SystemExit):
        build_parser().parse_args(["--scenario", "wobbly"])
    with pytest.raises(ControllerError, match="seed"):
        PendantApp(AppConfig(port=0, tool_library=tmp_path / "t.json", scenario="bent_tool", scenario_seed=-1))


# ----------------------------------------------------------------------------- joints
def test_touches_carry_their_joint_values_into_the_session_record(page) -> None:
    p = page()
    s, c = p.session, p.session.controller
    p.click(p.touches.record)
    c.jog_joint(0, 5.0)
    s.moved()
    p.click(p.touches.record)
    joints = [tuple(t.joints_deg) for t in s.touches]
    assert len(joints[0]) == 6 and joints[1][0] == pytest.approx(joints[0][0] + 5.0)
    assert joints[1] == pytest.approx(tuple(c.joint_angles_deg().values()))
    s.delete_touch(0)
    assert s.touches[0].joints_deg == joints[1] and s.touches[0].label.startswith("P1")
    record = session_from_controller(c, [], robot="kr6", touches=s.touches)
    assert record["touches"][0]["joints_deg"] == pytest.approx(list(joints[1]))
    check_session_record(record)
    old = dict(record, touches=[{k: v for k, v in t.items() if k != "joints_deg"} for t in record["touches"]])
    check_session_record(old)                                        # older records: no joints
    bad = dict(record, touches=[dict(record["touches"][0], joints_deg=["x"])])
    with pytest.raises(SessionRecordError, match="joints_deg"):
        check_session_record(bad)


def test_wizard_touches_carry_their_joint_values_into_the_session_record(page) -> None:
    from tcp_pendant.wizards.session_record import load_and_replay

    p = page()
    c = p.session.controller
    auto_xyz4(p)
    wf = p.calibrate.workflow
    record = wf.export_record(p.session.touches)
    entry = record["wizards"][0]
    joints = entry["joints_deg"]
    assert sorted(joints) == ["0", "1", "2", "3"]
    for step, q_deg in joints.items():
        q = np.radians(q_deg)
        pose = np.array(entry["state"]["poses"][step]["T_world_flange_m"])
        np.testing.assert_allclose(c.kinematics.T_world_flange(q), pose, atol=1e-12)   # the recorded pose
    check_session_record(record)
    assert load_and_replay(record).checks[0].message                    # still replays
    del entry["joints_deg"]
    check_session_record(record)                                         # older records: no joints
    entry["joints_deg"] = {"0": [float("inf")]}
    with pytest.raises(SessionRecordError, match="joints_deg"):
        check_session_record(record)


def test_reference_wizard_under_a_bent_tool_is_graded_against_the_bent_new_tool(page) -> None:
    """The XYZ reference wizard's truth is the new tool mounted at its tool change: with the
    bent-tool scenario that is the bent torch, not the catalogue's (it was graded against the
    unbent frame, a TCP off by the bend called wrong)."""
    p = page()
    s, c = p.session, p.session.controller
    s.set_scenario("bent_tool", 2)
    pointer = c.mounted_tool                                         # the bent pointer, as bolted on
    T = pointer.T_flange_tool_true
    s.library.save(1, Tool.from_rotation("Pointer", tuple(T[:3, 3] * 1000.0), T[:3, :3]))
    s.tools.reload_library()
    wf = p.calibrate.workflow
    s.wizard_commands.start("reference", slot=1, reference_tool_key="pointer", new_tool_key="torch")
    s.wizard_commands.auto_touch(AutoTouchRequest())
    s.wizard_commands.mount_required_tool()
    torch = c.mounted_tool
    bent_mm = np.linalg.norm(torch.T_flange_tool_true[:3, 3] - builtin_tools()["torch"].T_flange_tool_true[:3, 3])
    assert torch.key == "torch" and bent_mm * 1000.0 > 2.0           # the bent torch is on the flange
    s.wizard_commands.auto_touch(AutoTouchRequest())
    res, truth = wf.result, wf.truth()
    assert res is not None and truth is not None
    np.testing.assert_allclose(res.tcp_mm, torch.T_flange_tool_true[:3, 3] * 1000.0, atol=1e-6)
    assert truth.position_error_mm < 1e-6                            # graded against the bent torch
