"""Where a foreign robot starts (controller/placement.py, server.default_reference_tip_mm and
ready_configuration) and how a 7-axis arm jogs (jog.py, J-3). Layouts: tests/support/ros_layouts.py."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from support.pseudo_text import english_words

from tcp_pendant.controller import JogFrame, RobotKinematics, VirtualController, builtin_tools
from tcp_pendant.controller.jog import DEFAULT_SETTINGS, JogSettings, smallest_singular_value
from tcp_pendant.controller.placement import (
    LIMIT_MARGIN_RAD,
    MIN_TIP_HEIGHT_M,
    READY_HOVER_M,
    XYZ4_DIRECTIONS,
    unreachable_directions,
)
from tcp_pendant.translation import PSEUDO_LANGUAGE, translator
from tcp_pendant.serve.server import default_reference_tip_mm, ready_configuration, tip_reach_warning

from support.ros_layouts import acme7_workspace, kr16_2_urdf

ROBOTS = Path(__file__).resolve().parents[2] / "robots"
POINTER = np.asarray(builtin_tools()["pointer"].T_flange_tool_true)


def kr6_with_ros_i_names(folder: Path) -> Path:
    """Our KR 6 with ROS-Industrial's joint names (joint_a1..joint_a6, as kuka_experimental's
    kr6r900sixx_macro.xacro names them): no known home, so it is placed from the model."""
    text = (ROBOTS / "kr6_r900" / "kr6_r900.urdf").read_text()
    for i in range(1, 7):
        text = text.replace(f'name="A{i}"', f'name="joint_a{i}"')
    path = folder / "kr6_r900" / "kr6_ros_i_names.urdf"
    path.parent.mkdir(parents=True)
    path.write_text(text)
    return path


@pytest.fixture(params=["kr16_2", "kr6_ros_i_names", "acme7"])
def foreign(request, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> RobotKinematics:
    if request.param == "kr16_2":
        return RobotKinematics.from_urdf(kr16_2_urdf(tmp_path))
    if request.param == "kr6_ros_i_names":
        return RobotKinematics.from_urdf(kr6_with_ros_i_names(tmp_path))
    ws = acme7_workspace(tmp_path)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(ws.ros_package_path))
    return RobotKinematics.from_urdf(ws.xacro, package_paths=[ws.package_path])


def test_foreign_robot_tip_is_reachable_and_ready_pose_is_well_conditioned(foreign: RobotKinematics) -> None:
    kin = foreign
    assert not kin.known_home
    tip = np.asarray(default_reference_tip_mm(kin, POINTER)) / 1000.0
    assert tip[1] == 0.0 and tip[0] > 0.2 and tip[2] >= MIN_TIP_HEIGHT_M
    reach = unreachable_directions(kin, tip, POINTER)                 # the full test, every seed
    assert reach.ok, reach
    q = ready_configuration(kin, tip)
    assert np.abs(q).max() > math.radians(20)                          # not the all-zero stretch
    span = kin.upper_rad - kin.lower_rad
    margin = np.minimum(LIMIT_MARGIN_RAD, 0.1 * span)
    assert np.all(q >= kin.lower_rad + margin - 1e-9) and np.all(q <= kin.upper_rad - margin + 1e-9)
    assert smallest_singular_value(kin, q) >= 2 * DEFAULT_SETTINGS.singular_eps
    T = kin.T_world_flange(q)
    assert T[2, 2] < -1 + 1e-9                                         # flange straight down ...
    np.testing.assert_allclose(T[:3, 3], tip + [0, 0, READY_HOVER_M], atol=1e-9)   # ... above the tip


def test_all_zero_kr16_would_have_been_out_of_reach(tmp_path: Path) -> None:
    """The old default (below the all-zero flange at half its height: 1768, 0, 320 mm) fails the
    reach test; the start says so when it is given."""
    kin = RobotKinematics.from_urdf(kr16_2_urdf(tmp_path))
    old = np.array([1.768, 0.0, 0.320])
    np.testing.assert_allclose(kin.T_world_flange(np.zeros(6))[:3, 3] * [1, 1, 0.5], old, atol=1e-12)
    text = tip_reach_warning(kin, old, POINTER, "kuka_kr16_2", "Straight pointer")
    assert text is not None and text.startswith("the reference tip (1768, 0, 320) mm is out of reach of the kuka_kr16_2")
    failed = re.search(r"cannot touch it from (\d) of 8 test directions", text)
    assert failed is not None and int(failed.group(1)) >= 4, text
    default = ",".join(f"{v:.0f}" for v in default_reference_tip_mm(kin, POINTER))
    assert text.endswith(f"--reference-tip {default} (this robot's default).")
    said = text.text(translator(PSEUDO_LANGUAGE))                    # every pendant's notice, in its language
    assert said.startswith("⟦") and english_words(said, {"kuka", "kr16", "straight", "pointer"}) == [], said
    assert default in said and "(1768, 0, 320)" in said
    assert tip_reach_warning(kin, np.asarray(default_reference_tip_mm(kin, POINTER)) / 1000, POINTER,
                             "kuka_kr16_2", "Straight pointer") is None


def test_builtin_robots_keep_their_hand_chosen_placement() -> None:
    kr6 = RobotKinematics.from_urdf(ROBOTS / "kr6_r900" / "kr6_r900.urdf")
    gp12 = RobotKinematics.from_urdf(ROBOTS / "gp12" / "gp12.urdf")
    # below the home flange at half its height, off the round numbers by TIP_PLACEMENT_MM
    np.testing.assert_allclose(default_reference_tip_mm(kr6), (528.81, 1.28, 444.63), atol=1e-9)
    np.testing.assert_allclose(default_reference_tip_mm(gp12), (798.81, 1.28, 581.63), atol=1e-9)
    tip = np.array([0.525, 0.0, 0.445])
    np.testing.assert_array_equal(ready_configuration(kr6, tip), np.radians([0, -90, 90, 0, 90, 0]))
    np.testing.assert_array_equal(ready_configuration(gp12, tip), np.radians([0, 0, 0, 0, -90, 0]))
    for kin in (kr6, gp12):                     # and their defaults pass the reach test
        t = np.asarray(default_reference_tip_mm(kin)) / 1000.0
        assert unreachable_directions(kin, t, POINTER).ok


def test_reach_test_directions_are_the_auto_touch_spread() -> None:
    tilts = sorted({t for t, _ in XYZ4_DIRECTIONS})
    assert tilts == [20.0, 35.0] and len({a for _, a in XYZ4_DIRECTIONS}) == 8


@pytest.fixture
def acme7(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[RobotKinematics, np.ndarray, np.ndarray]:
    ws = acme7_workspace(tmp_path)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(ws.ros_package_path))
    kin = RobotKinematics.from_urdf(ws.xacro, package_paths=[ws.package_path])
    tip = np.asarray(default_reference_tip_mm(kin, POINTER)) / 1000.0
    return kin, tip, ready_configuration(kin, tip)


def _controller(kin: RobotKinematics, tip: np.ndarray, q: np.ndarray, settings: JogSettings = DEFAULT_SETTINGS):
    c = VirtualController(kin, tool=builtin_tools()["pointer"], reference_tip_world_m=tip, settings=settings)
    c.set_q(q)
    c.set_rest_configuration(q)
    return c


def test_seven_axes_jog_along_x_y_z_and_keep_the_elbow(acme7) -> None:
    kin, tip, q_ready = acme7
    c = _controller(kin, tip, q_ready)
    for axis, i in (("X", 0), ("Y", 1), ("Z", 2)):
        for d in (40.0, -40.0):
            T0 = c.T_world_tcp()
            r = c.jog_cartesian(JogFrame.WORLD, axis, d)
            assert r.ok, (axis, r.message)
            T1 = c.T_world_tcp()
            expected = T0[:3, 3].copy()
            expected[i] += d / 1000.0
            np.testing.assert_allclose(T1[:3, 3], expected, atol=1e-9)
            np.testing.assert_allclose(T1[:3, :3], T0[:3, :3], atol=1e-9)

    def square(ctrl: VirtualController) -> None:
        for _ in range(10):
            for axis, d in (("X", 20.0), ("Y", 20.0), ("X", -20.0), ("Y", -20.0)):
                assert ctrl.jog_cartesian(JogFrame.WORLD, axis, d).ok

    # a closed loop of jogs: with the null-space step the arm comes back to its ready pose;
    # without it (minimum-norm steps only) the self-motion drifts
    kept = _controller(kin, tip, q_ready)
    square(kept)
    drifted = _controller(kin, tip, q_ready, JogSettings(null_space_gain=0.0))
    square(drifted)
    np.testing.assert_allclose(kept.T_world_tcp(), drifted.T_world_tcp(), atol=1e-9)
    kept_deg = float(np.degrees(np.abs(kept.q_rad - q_ready)).max())
    drift_deg = float(np.degrees(np.abs(drifted.q_rad - q_ready)).max())
    assert kept_deg < 0.1 and drift_deg > 5 * kept_deg, (kept_deg, drift_deg)


def test_null_space_step_moves_only_the_self_motion(acme7) -> None:
    kin, tip, q_ready = acme7
    c = _controller(kin, tip, q_ready)
    J = kin.jacobian_flange(q_ready)
    N = np.eye(7) - np.linalg.pinv(J) @ J
    v = N @ np.ones(7)
    c.set_rest_configuration(q_ready + 0.3 * v / np.abs(v).max())
    T0 = c.T_world_tcp()
    before = float(np.linalg.norm(c.q_rad - c.rest_q_rad))
    assert c.jog_cartesian(JogFrame.WORLD, "Z", 30.0).ok
    T1 = c.T_world_tcp()
    np.testing.assert_allclose(T1[:3, 3], T0[:3, 3] + [0, 0, 0.03], atol=1e-9)
    np.testing.assert_allclose(T1[:3, :3], T0[:3, :3], atol=1e-9)
    assert float(np.linalg.norm(c.q_rad - c.rest_q_rad)) < 0.8 * before     # the elbow went towards rest


def test_six_axis_jogs_ignore_the_rest_configuration() -> None:
    kr6 = RobotKinematics.from_urdf(ROBOTS / "kr6_r900" / "kr6_r900.urdf")
    tip = np.array([0.525, 0.0, 0.445])
    q = ready_configuration(kr6, tip)
    a, b = _controller(kr6, tip, q), _controller(kr6, tip, q)
    b.set_rest_configuration(q + 0.2)
    for ctrl in (a, b):
        assert ctrl.jog_cartesian(JogFrame.WORLD, "Y", 25.0).ok
    np.testing.assert_array_equal(a.q_rad, b.q_rad)
