"""Panel logic without a browser: jog settings, jog keys against an independent pose check,
readout formatting, numeric tool entry."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcp_pendant.controller import ControllerError, PoseReadout, TouchGeometry, VirtualController
from tcp_pendant.pendant import (
    JogMode,
    Jogger,
    JogSettings,
    ToolEntry,
    joint_label,
    joint_readout_markdown,
    parse_number,
    parse_tool_entry,
    tcp_readout_markdown,
    touch_indicator_markdown,
    touch_label,
)
from tcp_pendant.pendant.jogging import LINEAR_SPEED_MM_S, MAX_TICK_S

from support.jogging import FakeClock, away_from_singularity

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


# ------------------------------------------------------------------ settings
def test_settings_validate_and_clamp_override() -> None:
    s = JogSettings()
    assert s.mode is JogMode.CARTESIAN and s.frame == "WORLD" and not s.continuous
    assert JogSettings(frame="tool").frame == "TOOL"
    assert JogSettings(override_pct=250).override_pct == 100.0
    assert JogSettings(override_pct=-3).override_pct == 1.0
    for bad in ({"frame": "CAMERA"}, {"increment": "5"}, {"mode": "teach"}, {"override_pct": "fast"},
                {"override_pct": float("nan")}):
        with pytest.raises(ControllerError):
            JogSettings(**bad)  # type: ignore[arg-type]


def test_step_amount_increment_and_continuous_speed() -> None:
    assert JogSettings(increment="0.1").step_amount(rotational=False) == pytest.approx(0.1)
    s = JogSettings(increment="Cont.", override_pct=40)
    # 250 mm/s * 40 % * 0.05 s = 5 mm; 30 deg/s * 40 % * 0.05 s = 0.6 deg
    assert s.step_amount(rotational=False, dt_s=0.05) == pytest.approx(250 * 0.4 * 0.05)
    assert s.step_amount(rotational=True, dt_s=0.05) == pytest.approx(30 * 0.4 * 0.05)
    # a stalled browser (1 s between ticks) moves at most MAX_TICK_S worth
    assert s.step_amount(rotational=False, dt_s=1.0) == pytest.approx(250 * 0.4 * MAX_TICK_S)


# ------------------------------------------------------------------ jog keys
@pytest.mark.parametrize("increment,expected_mm", [("100", 100.0), ("10", 10.0), ("1", 1.0), ("0.1", 0.1)])
def test_cartesian_key_moves_tcp_by_increment_along_world_axis(controller: VirtualController, increment: str,
                                                               expected_mm: float) -> None:
    away_from_singularity(controller)
    jog = Jogger(controller)
    jog.settings = JogSettings(increment=increment, frame="WORLD")
    T0 = controller.T_world_flange()
    res = jog.key("Y", -1)
    assert res is not None and res.ok, res
    d_mm = (controller.T_world_flange()[:3, 3] - T0[:3, 3]) * 1000.0
    np.testing.assert_allclose(d_mm, [0.0, -expected_mm, 0.0], atol=0.01)


def test_tool_frame_key_moves_along_tool_x(controller: VirtualController) -> None:
    from tcpcal.tool import Tool

    away_from_singularity(controller)
    tool = Tool(name="bent", tcp_mm=(20.0, 0.0, 150.0), abc_deg=(0.0, -60.0, 0.0))
    controller.set_active_tool(tool)
    jog = Jogger(controller)
    jog.settings = JogSettings(increment="10", frame="TOOL")
    T_flange_tool_m = np.eye(4)
    T_flange_tool_m[:3, :3] = Rotation.from_euler("ZYX", tool.abc_deg, degrees=True).as_matrix()
    T_flange_tool_m[:3, 3] = np.array(tool.tcp_mm) / 1000.0
    T0 = controller.T_world_flange() @ T_flange_tool_m
    jog.key("X", 1)
    T1 = controller.T_world_flange() @ T_flange_tool_m
    np.testing.assert_allclose((T1[:3, 3] - T0[:3, 3]) * 1000.0, 10.0 * T0[:3, 0], atol=0.01)
    np.testing.assert_allclose(T1[:3, :3], T0[:3, :3], atol=1e-7)


def test_rotation_key_keeps_tcp_and_turns_about_world_z(controller: VirtualController) -> None:
    away_from_singularity(controller)
    jog = Jogger(controller)
    jog.settings = JogSettings(increment="10", frame="WORLD")
    T0 = controller.T_world_tcp()
    jog.key("A", 1)
    T1 = controller.T_world_tcp()
    np.testing.assert_allclose(T1[:3, 3], T0[:3, 3], atol=1e-5)
    rel = Rotation.from_matrix(T1[:3, :3] @ T0[:3, :3].T).as_rotvec(degrees=True)
    np.testing.assert_allclose(rel, [0.0, 0.0, 10.0], atol=1e-3)


def test_joint_key_and_limit(controller: VirtualController) -> None:
    jog = Jogger(controller)
    jog.settings = JogSettings(increment="10", mode="Joint")
    q0 = np.degrees(controller.q_rad)
    jog.key(0, 1)
    np.testing.assert_allclose(np.degrees(controller.q_rad) - q0, [10, 0, 0, 0, 0, 0], atol=1e-9)
    jog.settings = jog.settings.with_(increment="100")
    res = None
    for _ in range(3):
        res = jog.key(0, 1)
    assert res is not None and not res.ok and res.stopped_by == "joint_limit"
    assert "A1" in res.message
    assert math.degrees(controller.q_rad[0]) == pytest.approx(170.0)


def test_click_and_hold_do_not_double_jog(controller: VirtualController) -> None:
    """Incremental: the hold callback does nothing (one press = one increment);
    continuous: the click (release) does nothing, hold ticks move speed * dt."""
    away_from_singularity(controller)
    clock = FakeClock()
    jog = Jogger(controller, clock=clock, tick_s=0.05)
    jog.settings = JogSettings(increment="10")
    assert jog.key("X", 1, hold_tick=True) is None
    jog.settings = JogSettings(increment="Cont.", override_pct=40)
    assert jog.key("X", 1, hold_tick=False) is None
    x0 = controller.T_world_tcp()[0, 3]
    assert jog.key("X", 1, hold_tick=True).ok          # first tick: nominal 0.05 s
    clock.t += 0.04
    assert jog.key("X", 1, hold_tick=True).ok          # second tick: measured 0.04 s
    moved_mm = (controller.T_world_tcp()[0, 3] - x0) * 1000.0
    assert moved_mm == pytest.approx(LINEAR_SPEED_MM_S * 0.4 * (0.05 + 0.04), abs=0.01)


def test_bad_keys_raise(controller: VirtualController) -> None:
    jog = Jogger(controller)
    with pytest.raises(ControllerError):
        jog.key("Q", 1)
    with pytest.raises(ControllerError):
        jog.key("X", 2)
    with pytest.raises(ControllerError):
        jog.key(9, 1)


# ------------------------------------------------------------------ formatting
def test_tcp_readout_text() -> None:
    r = PoseReadout("BASE", 525.004, -0.001, 890.0, 180.0, -90.0, 0.0)
    md = tcp_readout_markdown(r, "Pointer")
    assert "TCP in BASE" in md and "TOOL Pointer" in md
    assert "X 525.00 mm" in md and "Y   0.00 mm" in md and "-0.00" not in md
    assert "B -90.00 deg" in md
    assert "Active tool data: none (FLANGE) · mounted: Straight pointer" in tcp_readout_markdown(r, None, "Straight pointer")
    assert "Active tool data: TOOL Pointer" in md and "no tool" not in tcp_readout_markdown(r, None, "Straight pointer")


def test_joint_texts() -> None:
    md = joint_readout_markdown({"A1": 0.0, "A2": -90.0, "A3": 90.0, "A4": 0.0, "A5": 12.345, "A6": -0.004})
    assert "A2   -90.00" in md and "A5    12.35" in md and "-0.00" not in md
    assert joint_label("A2", -190.0, 45.0) == "A2 [-190, +45]°"
    T = np.eye(4)
    T[:3, 3] = [0.5254, -0.00001, 0.4]
    assert touch_label(1, T) == "P2  X 525.4 Y 0.0 Z 400.0 mm"


def test_touch_indicator_states() -> None:
    far = TouchGeometry(12.345, False, False, 0.0)
    near = TouchGeometry(0.3, True, False, 0.0)
    crash = TouchGeometry(3.0, False, True, 3.0)
    assert "12.35 mm" in touch_indicator_markdown(far, hide_distance=False)
    assert "TOUCHING" in touch_indicator_markdown(near, hide_distance=False)
    hidden = touch_indicator_markdown(near, hide_distance=True)
    assert "TOUCHING" not in hidden and "0.30" not in hidden and "hidden" in hidden
    assert "CRASH" in touch_indicator_markdown(crash, hide_distance=True)      # always shown


# ------------------------------------------------------------------ numeric entry
def _entry(name: str = "Gun", **vals: str) -> ToolEntry:
    base = {"X": "10", "Y": "-2.5", "Z": "150", "A": "0", "B": "90", "C": "0"}
    base.update(vals)
    return ToolEntry(name, base)


def test_valid_entry_makes_tool_with_those_numbers() -> None:
    res = parse_tool_entry(_entry(Y="-2,5"))
    assert res.ok and res.tool is not None
    assert res.tool.tcp_mm == (10.0, -2.5, 150.0)
    # B = 90: tool X along flange -Z (R = Rz(A) Ry(B) Rx(C)); independent: Ry(90) maps x to -z
    np.testing.assert_allclose(res.tool.rotation[:, 0], [0.0, 0.0, -1.0], atol=1e-12)
    assert res.tool.calibration is not None and res.tool.calibration.method == "numeric"


def test_invalid_entry_reports_each_bad_field_and_builds_nothing() -> None:
    res = parse_tool_entry(_entry(name="  ", X="abc", C="nan", Z="1e9"))
    assert not res.ok and res.tool is None
    assert set(res.errors) == {"name", "X", "Z", "C"}
    assert "'abc' is not a number" in res.errors["X"]
    assert "out of range" in res.errors["Z"]
    with pytest.raises(ValueError, match="enter a number"):
        parse_number("", "X (mm)")


def test_touch_feedback_says_how_far_and_which_way_the_tool_tip_was() -> None:
    from tcp_pendant.pendant.touch_feedback import touch_feedback

    # the reference tip 0.72 mm +Z of the tool tip: the tool tip was below it (−Z)
    assert touch_feedback(np.array([-0.3, 0.2, 0.72]), "WORLD") == (
        "0.8 mm off, mostly −Z (WORLD): the tool tip was 0.7 mm −Z of the reference tip")
    assert touch_feedback(np.array([2.0, 0.0, 0.1]), "TOOL").startswith("2.0 mm off, mostly −X (TOOL)")
    assert touch_feedback(np.zeros(3), "WORLD") == "the touch was spot on (0.0 mm off)"


@pytest.mark.parametrize("robot", ["kr6", "gp12"])
def test_no_start_is_a_whole_number_of_millimetres_from_the_reference_tip(robot: str) -> None:
    """Fine positioning must be practised: from the ready pose, and after the 30° tilts the
    wizards suggest, every jog-axis offset to the default reference tip is at least 0.1 mm off
    a whole millimetre, so the 1 mm and 0.1 mm increments are needed (the 10 mm one alone left
    3 of 4 touches at 0.00 mm)."""
    from tcp_pendant.controller import RobotKinematics, builtin_tools
    from tcp_pendant.controller.pose_state import pose_state, pose_state_key
    from tcp_pendant.pendant.guidance import tip_offset_mm
    from tcp_pendant.serve.server import default_reference_tip_mm, ready_configuration, resolve_robot

    kin = RobotKinematics.from_urdf(resolve_robot(robot))
    tip_m = np.asarray(default_reference_tip_mm(kin)) / 1000.0
    ready = ready_configuration(kin, tip_m)
    for tool in builtin_tools():
        for axis, deg in (("", 0.0), ("B", 30.0), ("C", 30.0), ("B", -30.0)):
            c = VirtualController(kin, tool=builtin_tools()[tool], reference_tip_world_m=tip_m)
            c.set_q(ready)
            if axis:
                assert c.jog_cartesian("WORLD", axis, deg).ok
            delta = tip_offset_mm(pose_state(c, pose_state_key(c)), tip_m, "WORLD")
            frac = np.abs(delta - np.round(delta))
            assert frac.min() >= 0.1, (tool, axis, deg, delta)


def test_the_tip_views_draw_a_half_millimetre_as_12_pixels_each_way_and_nothing_when_far() -> None:
    from tcp_pendant.pendant.tip_insets import TOOL_COLOR, insets_key, tip_insets_image, view_pixel

    ref = np.array([0.5, 0.0, 0.4])
    T = np.eye(4)
    T[:3, :3] = np.column_stack([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])   # tool X down
    T[:3, 3] = ref + np.array([0.4, -0.3, 1.6]) / 1000.0

    def apex(img: np.ndarray, half: str) -> tuple[float, float]:
        tool = np.all(img == TOOL_COLOR, axis=2)
        w = img.shape[1] // 2
        part = tool[:, :w] if half == "front" else tool[:, w:]
        rows, cols = np.nonzero(part)
        low = rows.max()
        return float(cols[rows == low].mean()), float(low)

    img0 = tip_insets_image(ref, T)
    assert img0.dtype == np.uint8 and img0.shape == (192, 344, 3)
    for axis, view, index in ((0, "front", 0), (1, "side", 0), (2, "front", 1), (2, "side", 1)):
        moved = T.copy()
        moved[axis, 3] += 0.0005
        before, after = apex(img0, view), apex(tip_insets_image(ref, moved), view)
        shift = after[index] - before[index]
        assert abs(abs(shift) - 12.0) <= 1.0, (axis, view, shift)
    col, row = view_pixel("front", np.zeros(3))
    assert (round(col), round(row)) == (84, 120)              # the spike's point: centre, 5 mm from the top
    far = T.copy()
    far[2, 3] += 0.1                                           # 100 mm above: out of the window
    assert insets_key(ref, far) == ("far",) and not np.all(tip_insets_image(ref, far) == TOOL_COLOR, axis=2).any()
    assert insets_key(ref, T) != insets_key(ref, far)
