"""Cartesian jogging never changes the arm configuration (KUKA's Status: shoulder, elbow, wrist).

A six-axis arm with a spherical wrist reaches most poses in up to eight configurations. Going
from one to another means either a jump (many joints move a lot for a small TCP motion) or a
continuous motion *through* a singularity (wrist: A5 = 0; elbow: arm stretched; shoulder:
wrist centre on the A1 axis). A real controller's Cartesian jog does neither: it stops.

The configuration is computed here from the link positions, independently of the jog code:

* shoulder: the wrist centre in front of (+1) or behind (-1) the first axis, i.e. the sign of
  the wrist centre's x in the frame of link_1 (which turns with axis 1);
* elbow: the sign of ((p_3 - p_2) x (p_wc - p_3)) . a_2 with p_2, p_3 the axis-2 and axis-3
  points, p_wc the wrist centre and a_2 the axis-2 direction (which side of the stretched arm
  the elbow is on);
* wrist: the sign of axis 5 (A5 / B).
"""

from __future__ import annotations

import math
import zlib

import numpy as np
import pytest

from tcp_pendant.controller import JogFrame, VirtualController

from .conftest import angle_deg, make_controller

STRETCHED_A3_DEG = math.degrees(math.atan2(35.0, 420.0))  # KR 6: forearm offset 35, A4..wrist 420


def configuration(ctrl: VirtualController) -> tuple[int, int, int]:
    """(shoulder, elbow, wrist) signs, see the module docstring."""
    poses = ctrl.link_poses()
    p2, p3, pwc = (poses[k][:3, 3] for k in ("link_2", "link_3", "link_5"))
    T1 = poses["link_1"]
    shoulder = (T1[:3, :3].T @ (pwc - T1[:3, 3]))[0]
    a2 = poses["link_2"][:3, 1]
    elbow = np.cross(p3 - p2, pwc - p3) @ a2
    wrist = ctrl.q_rad[4]
    return int(np.sign(shoulder)), int(np.sign(elbow)), int(np.sign(wrist))


@pytest.mark.parametrize("a5_deg", [0.5, 0.2, -0.3, 1.5])
@pytest.mark.parametrize("step_deg", [1.0, 2.0, 0.1])
def test_rotation_jog_never_flips_the_wrist_through_a5_zero(a5_deg, step_deg):
    """Start inside the wrist-singular zone (|A5| < 2 deg) and keep turning towards A5 = 0:
    the jog must stop at the singularity, never come out with A5 of the other sign."""
    ctrl = make_controller("kr6", "pointer", active=False, q_deg=(0.0, -80.0, 100.0, 0.0, a5_deg, 0.0))
    start = configuration(ctrl)
    # With A4 = A6 = 0 the flange Y axis is minus the A5 axis (flange frame: Y = Z x X, Z along
    # the forearm, X up), so +B about FLANGE Y turns the wrist towards smaller A5.
    sign = 1.0 if a5_deg > 0 else -1.0
    res = None
    for _ in range(int(5.0 / step_deg) + 2):
        res = ctrl.jog_cartesian("FLANGE", "B", sign * step_deg)
        assert configuration(ctrl) == start, f"wrist flipped: A5 = {math.degrees(ctrl.q_rad[4]):.4f} deg"
        if not res.ok:
            break
    assert res is not None and not res.ok and res.stopped_by == "singularity"
    assert res.message.startswith("A5 near ") and "wrist singularity" in res.message
    assert abs(math.degrees(ctrl.q_rad[4])) < abs(a5_deg) + 1e-9
    for _ in range(5):  # the trainee keeps pressing: still no flip
        again = ctrl.jog_cartesian("FLANGE", "B", sign * step_deg)
        assert not again.ok and again.stopped_by == "singularity"
        assert configuration(ctrl) == start
    # and can always jog back out of the singular zone
    assert ctrl.jog_cartesian("FLANGE", "B", -sign * step_deg).ok
    assert configuration(ctrl) == start


def test_translation_through_the_wrist_singularity_stops_instead_of_flipping():
    """KR 6 near HOME with A5 = +1 deg and the flange orientation held: moving the TCP down
    tilts the forearm down and drives A5 to 0 (computed: d A5 / d z > 0 there). The jog stops."""
    ctrl = make_controller("kr6", "pointer", active=False, q_deg=(0.0, -90.0, 90.0, 0.0, 1.0, 0.0))
    start = configuration(ctrl)
    T0 = ctrl.T_world_tcp()
    res = None
    for _ in range(30):
        res = ctrl.jog_cartesian("WORLD", "Z", -1.0)
        assert configuration(ctrl) == start
        if not res.ok:
            break
    assert res is not None and res.stopped_by == "singularity" and "A5 near" in res.message
    T = ctrl.T_world_tcp()
    assert angle_deg(T[:3, :3], T0[:3, :3]) < 0.001
    assert np.linalg.norm(T[:2, 3] - T0[:2, 3]) * 1000.0 < 0.01


@pytest.mark.parametrize("offset_deg", [0.3, 1.0, 3.0])
def test_stretching_never_flips_the_elbow(offset_deg):
    """A3 just above the stretched arm (elbow up); push the TCP away from A2 along the arm:
    the jog stops at the elbow singularity and A3 stays above it."""
    ctrl = make_controller("kr6", "pointer", active=False,
                           q_deg=(0.0, -30.0, STRETCHED_A3_DEG + offset_deg, 0.0, 40.0, 0.0))
    start = configuration(ctrl)
    poses = ctrl.link_poses()
    u = poses["link_5"][:3, 3] - poses["link_2"][:3, 3]
    u /= np.linalg.norm(u)
    res = None
    for _ in range(40):
        T = ctrl.T_world_tcp()
        T[:3, 3] += u * 0.5e-3
        res = ctrl.move_tcp_to(T)
        assert configuration(ctrl) == start
        assert math.degrees(ctrl.q_rad[2]) > STRETCHED_A3_DEG
        if not res.ok:
            break
    assert res is not None and not res.ok and res.stopped_by in ("singularity", "unreachable")
    assert res.stopped_by == "singularity" and "elbow singularity" in res.message


@pytest.mark.parametrize("robot, q_deg, axis_name", [
    ("kr6", (0.0, -90.0, 30.0, 0.0, 60.0, 0.0), "A1"),
    ("gp12", (0.0, 10.0, 80.0, 0.0, -60.0, 0.0), "S"),
])
def test_wrist_centre_over_the_first_axis_stops_at_the_shoulder_singularity(robot, q_deg, axis_name):
    """Forearm raised, wrist centre in front of the first axis and high; WORLD -X moves it
    towards that axis: the jog stops near it with the shoulder message, never passing over."""
    ctrl = make_controller(robot, "pointer", active=False, q_deg=q_deg)
    start = configuration(ctrl)
    res = None
    for _ in range(100):
        res = ctrl.jog_cartesian("WORLD", "X", -5.0)
        assert configuration(ctrl) == start
        if not res.ok:
            break
    assert res is not None and res.stopped_by == "singularity"
    assert res.message == f"wrist centre near the {axis_name} axis: shoulder singularity"
    wc = ctrl.link_poses()["link_5"][:3, 3]
    assert 0.0 < wc[0] < 0.05  # stopped in front of the axis, within 50 mm of it
    q_stop = ctrl.q_rad
    assert not ctrl.jog_cartesian("WORLD", "X", -0.1).ok  # pressing again does not pass over
    assert configuration(ctrl) == start
    for amount in (0.1, 1.0, 10.0):  # and the smallest increment backs out of it
        ctrl.set_q(q_stop)
        assert ctrl.jog_cartesian("WORLD", "X", amount).ok


@pytest.mark.parametrize("robot, tool, q_deg", [
    ("kr6", "torch", (10.0, -80.0, 100.0, 20.0, 40.0, 30.0)),
    ("kr6", "pointer", (0.0, -90.0, 90.0, 0.0, 3.0, 0.0)),     # 3 deg from the wrist singularity
    ("kr6", "gripper", (-30.0, -40.0, 20.0, -60.0, -50.0, 0.0)),
    ("gp12", "torch", (10.0, 10.0, 10.0, 20.0, -50.0, 30.0)),
    ("gp12", "pointer", (0.0, 0.0, 0.0, 0.0, -3.0, 0.0)),
])
def test_random_jogging_keeps_the_configuration_and_never_jumps(robot, tool, q_deg):
    """200 random jogs (frame, axis, increment 100/10/1/0.1 mm or deg, either sign): the
    configuration never changes, a completed jog lands exactly on its target, and an increment
    never moves a joint by more than 5 deg per mm (or deg) of flange motion (a rotation by
    theta about a TCP at distance d from the flange swings the flange by theta d)."""
    ctrl = make_controller(robot, tool)
    ctrl.set_q(np.radians(q_deg))
    lever_mm = float(np.linalg.norm(ctrl.T_flange_tool[:3, 3])) * 1000.0
    start = configuration(ctrl)
    rng = np.random.default_rng(zlib.crc32(f"{robot}-{tool}-{q_deg}".encode()))  # str hash is salted
    stops = 0
    for _ in range(200):
        frame = JogFrame(rng.choice(["WORLD", "BASE", "FLANGE", "TOOL"]))
        axis = str(rng.choice(list("XYZABC")))
        amount = float(rng.choice([100.0, 10.0, 1.0, 0.1]) * rng.choice([-1.0, 1.0]))
        q0, T0 = ctrl.q_rad, ctrl.T_world_tcp()
        res = ctrl.jog_cartesian(frame, axis, amount)
        assert configuration(ctrl) == start, (frame, axis, amount, np.degrees(ctrl.q_rad))
        flange_motion = abs(amount) * (1.0 if axis in "XYZ" else 1.0 + math.radians(lever_mm))
        assert np.degrees(np.abs(ctrl.q_rad - q0)).max() <= 5.0 * flange_motion * res.moved + 0.02 + 1e-9
        if res.ok:
            T = ctrl.T_world_tcp()
            if axis in "XYZ":
                assert np.linalg.norm(T[:3, 3] - T0[:3, 3]) * 1000.0 == pytest.approx(abs(amount), abs=1e-6)
                assert angle_deg(T[:3, :3], T0[:3, :3]) < 1e-6
            else:
                assert np.linalg.norm(T[:3, 3] - T0[:3, 3]) * 1000.0 < 1e-6
                assert angle_deg(T[:3, :3], T0[:3, :3]) == pytest.approx(abs(amount), abs=1e-6)
        else:
            stops += 1
            ctrl.set_q(np.radians(q_deg))  # back to the start, as a trainee would re-home
    assert stops < 200
