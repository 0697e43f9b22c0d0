"""Reachable guidance, checked against the robot model: every tilt the pendant calls reachable
is one the controller really makes (the rotation key by 45°, then the tip brought back onto the
reference tip, ending clear of the wrist singularity and the joint limits), and every one it
calls unreachable is not, on the KR 6, the GP12 and a ROS-Industrial KR 16 (the joint chain of
``ros-industrial/kuka_experimental`` ``kuka_kr16_support/urdf/kr16_2_macro.xacro``,
tests/support/ros_layouts.py). A key that stops at a limit says which way to go instead."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from support.calib_helpers import make_controller
from support.ros_layouts import kr16_2_urdf

from tcp_pendant.controller import RobotKinematics, VirtualController, builtin_tools
from tcp_pendant.controller.jog import smallest_singular_value
from tcp_pendant.controller.reach import LIMIT_MARGIN_DEG, WRIST_MARGIN_SIGMA, tilt_reach
from tcp_pendant.pendant.jogging import Jogger
from tcp_pendant.pendant.tilts import TiltOptions, reachable_line
from tcp_pendant.serve.server import default_reference_tip_mm, ready_configuration

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _controller(robot: str, tmp: Path) -> VirtualController:
    if robot != "kr16":
        return make_controller(robot)
    kin = RobotKinematics.from_urdf(kr16_2_urdf(tmp, meshes=False))
    c = VirtualController(kin, tool=builtin_tools()["pointer"],
                          reference_tip_world_m=np.asarray(default_reference_tip_mm(kin)) / 1000.0)
    c.set_q(ready_configuration(kin))
    return c


def _onto_tip(c: VirtualController) -> None:
    d_mm = (c.reference_tip_world_m - c.T_world_tool_true()[:3, 3]) * 1000.0
    for i, ax in enumerate("XYZ"):
        assert c.jog_cartesian("WORLD", ax, float(d_mm[i])).ok
    assert c.touch_geometry().distance_mm < 1e-3


def _really(c: VirtualController, frame: str, key: str, sign: int) -> bool:
    """The tilt made on a copy of the controller with its own keys: the rotation key, then the
    TCP moved on a straight line until the tool tip is on the reference tip; clear of the
    margins at the end."""
    q0 = c.q_rad.copy()
    try:
        if not c.jog_cartesian(frame, key, sign * 45.0).ok:
            return False
        T = c.T_world_tcp()
        T[:3, 3] += c.reference_tip_world_m - c.T_world_tool_true()[:3, 3]
        if not c.move_tcp_to(T).ok:
            return False
        kin, q = c.kinematics, c.q_rad
        margin = math.radians(LIMIT_MARGIN_DEG)
        return (smallest_singular_value(kin, q) >= WRIST_MARGIN_SIGMA
                and bool(np.all(q - kin.lower_rad >= margin)) and bool(np.all(kin.upper_rad - q >= margin)))
    finally:
        c.set_q(q0)


@pytest.mark.parametrize("robot", ["kr6", "gp12", "kr16"])
def test_every_tilt_called_reachable_is_made_by_the_robot_and_no_other(robot, tmp_path) -> None:
    c = _controller(robot, tmp_path)
    agree = []
    for where in ("ready", "touching"):
        if where == "touching":
            _onto_tip(c)
        for frame in ("WORLD", "TOOL"):
            for key in "ABC":
                for sign in (1, -1):
                    checked = tilt_reach(c, frame, key, sign, 45.0)
                    agree.append((where, frame, key, sign, checked.reachable, _really(c, frame, key, sign)))
    wrong = [a for a in agree if a[4] != a[5]]
    assert wrong == [], wrong
    assert any(a[4] for a in agree) and len(agree) == 24


def test_the_issues_kr6_case_b_plus_at_the_ready_pose_is_named_unreachable_with_its_limit() -> None:
    c = make_controller("kr6")
    r = tilt_reach(c, "WORLD", "B", 1, 45.0)
    assert not r.reachable and "A5 at its limit +120.0 deg" in r.why
    opts = TiltOptions(c).options("WORLD")
    line = reachable_line(opts, frame="WORLD", joint_mode=False)
    assert "B + (A5 limit)" in line and "A (own axis)" in line       # flange down: A turns it about itself
    assert "B − (wrist singularity)" in line and "**C ±** (6, Shift+6)" in line


def test_a_rotation_key_stopped_at_a_limit_names_the_reachable_tilts_instead() -> None:
    c = make_controller("kr6")
    j = Jogger(c)
    j.settings = j.settings.with_(increment="100")
    res = j.key("B", 1)                                   # 100 deg about WORLD Y: A5 runs into its limit
    assert res is not None and res.stopped_by == "joint_limit"
    assert res.message.startswith("A5 at its limit +120.0 deg. Instead tilt with ")
    assert "B − (Shift+5) turns back" in res.message
    named = res.message.split("Instead tilt with ")[1].split(" (reachable")[0].split(", ")
    assert named
    for words in named:                                   # e.g. "C + (6)": each reachable from the stop
        key, sym = words.split()[:2]
        assert tilt_reach(c, "WORLD", key, 1 if sym == "+" else -1, 45.0).reachable, words


def test_a_translation_stopped_at_the_reach_says_the_key_that_goes_back() -> None:
    c = make_controller("kr6")
    j = Jogger(c)
    j.settings = j.settings.with_(increment="100")
    res = None
    for _ in range(30):                                   # out along +X until the arm cannot follow
        res = j.key("X", 1)
        assert res is not None
        if not res.ok:
            break
    assert res is not None and not res.ok
    assert res.message.endswith("X − (Shift+1) goes back.")


def test_a_joint_key_at_its_limit_says_the_other_key_turns_it_back() -> None:
    from tcp_pendant.pendant.jogging import JogMode

    c = make_controller("kr6")
    j = Jogger(c)
    j.settings = j.settings.with_(mode=JogMode.JOINT, increment="100")
    res = j.key(4, 1)                                     # A5 from +90 by 100 deg: its limit +120
    assert res is not None and res.stopped_by == "joint_limit"
    assert res.message == "A5 at its limit +120.0 deg. The other key of that row (Shift+5) turns it back."


def test_fine_presses_near_the_tip_reuse_the_check_and_a_tilt_checks_again() -> None:
    c = make_controller("kr6")
    _onto_tip(c)
    tilts = TiltOptions(c)
    first = tilts.options("WORLD")
    assert tilts.checks == 1
    for axis in "XYZ":                                    # 0.1 and 1 mm presses: the same answer
        assert c.jog_cartesian("WORLD", axis, 1.0).ok and c.jog_cartesian("WORLD", axis, -0.9).ok
    assert tilts.options("WORLD") is first and tilts.checks == 1
    assert c.jog_cartesian("WORLD", "C", 10.0).ok          # a 10 deg tilt: checked again
    tilts.options("WORLD")
    assert tilts.checks == 2
