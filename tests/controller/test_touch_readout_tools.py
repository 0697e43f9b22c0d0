"""Touch/crash geometry, the pose readout and its KUKA A, B, C, and the tool models read from
their URDFs (checked against the URDF joint origins composed by hand)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from tcpcal.tool import Tool
from tcp_pendant.controller import ControllerError, builtin_tools, load_tool, reference_tip_model
from tcp_pendant.controller.touch import touch_geometry

from .conftest import make_controller


def Rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def Ry(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def Rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def origin_chain(urdf_path, leaf: str) -> np.ndarray:
    """Compose the fixed-joint origins from the root to ``leaf`` by hand (URDF rpy = Rz Ry Rx)."""
    root = ET.parse(urdf_path).getroot()
    by_child = {j.find("child").get("link"): j for j in root.findall("joint")}
    T = np.eye(4)
    link = leaf
    while link in by_child:
        j = by_child[link]
        o = j.find("origin")
        xyz = [float(v) for v in o.get("xyz", "0 0 0").split()]
        r, p, y = (float(v) for v in o.get("rpy", "0 0 0").split())
        M = np.eye(4)
        M[:3, :3] = Rz(y) @ Ry(p) @ Rx(r)
        M[:3, 3] = xyz
        T = M @ T
        link = j.find("parent").get("link")
    return T


def test_tools_read_their_true_tcp_from_the_urdf():
    tools = builtin_tools()
    assert set(tools) == {"pointer", "torch", "gripper"}
    for key, model in tools.items():
        np.testing.assert_allclose(model.T_flange_tool_true, origin_chain(model.urdf_path, "tcp"), atol=1e-12)
        assert not model.T_flange_tool_true.flags.writeable
        assert model.key == key and model.label
    # the pointer's TCP is on the flange axis; the torch's is off-axis and turned about two axes
    assert np.linalg.norm(tools["pointer"].T_flange_tool_true[:2, 3]) < 1e-12
    torch = tools["torch"].T_flange_tool_true
    assert np.linalg.norm(torch[:2, 3]) > 0.01
    assert np.count_nonzero(np.abs(torch[:3, :3] - np.eye(3)).max(axis=0) > 1e-6) == 3


@pytest.mark.parametrize("key", sorted(builtin_tools()))
def test_every_builtin_tool_name_is_a_name_a_controller_takes(key):
    """A calibration of a built-in tool is saved under its label (the default save name): the
    label must pass tcpcal's tool name check (1..24 printable characters, no double quote), or
    every Save of that tool is refused."""
    label = builtin_tools()[key].label
    assert Tool(name=label, tcp_mm=(0.0, 0.0, 100.0)).name == label


def test_reference_tip_model_puts_the_spike_where_asked():
    ref = reference_tip_model()
    np.testing.assert_allclose(ref.T_stand_tip, origin_chain(ref.urdf_path, "tip"), atol=1e-12)
    tip = np.array([0.55, 0.05, 0.25])
    np.testing.assert_allclose((ref.T_world_stand(tip) @ ref.T_stand_tip)[:3, 3], tip, atol=1e-12)


def test_load_tool_errors(tmp_path):
    with pytest.raises(ControllerError, match="not found"):
        load_tool(tmp_path / "none.urdf")
    p = tmp_path / "t.urdf"
    p.write_text('<robot name="t"><link name="tool_mount"/><link name="tip"/><joint name="j" '
                 'type="fixed"><parent link="tool_mount"/><child link="tip"/></joint></robot>')
    with pytest.raises(ControllerError, match="no link 'tcp'"):
        load_tool(p)
    assert load_tool(p, tcp_link="tip").key == "t"


def _pose(R, p_m) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p_m
    return T


def test_touch_geometry_definitions():
    R = Ry(0.4) @ Rz(0.3)
    p = np.array([0.5, 0.1, 0.3])
    x, y = R[:, 0], R[:, 1]
    T = _pose(R, p)
    g = touch_geometry(T, p + 0.0003 * y)  # 0.3 mm beside the tip
    assert g.touching and not g.crashed and g.distance_mm == pytest.approx(0.3)
    assert g.penetration_mm == pytest.approx(0.0, abs=1e-9)
    g = touch_geometry(T, p + 0.005 * x)  # 5 mm in front of the tip: not touching yet
    assert not g.touching and not g.crashed and g.penetration_mm == 0.0
    g = touch_geometry(T, p - 0.004 * x + 0.001 * y)  # tip driven 4 mm through, 1 mm off-axis
    assert g.crashed and g.penetration_mm == pytest.approx(4.0) and not g.touching
    g = touch_geometry(T, p - 0.0004 * x)  # 0.4 mm: still a touch
    assert g.touching and not g.crashed
    g = touch_geometry(T, p - 0.004 * x + 0.003 * y)  # 3 mm off-axis: beside the tip, no crash
    assert not g.crashed and g.penetration_mm == 0.0
    g = touch_geometry(T, p - 0.060 * x)  # on the -X axis 60 mm back (three-point step 2)
    assert not g.crashed and g.distance_mm == pytest.approx(60.0)


def test_jogging_through_the_tip_is_reported_as_a_crash():
    ctrl = make_controller("kr6", "pointer")
    assert ctrl.auto_approach(tilt_deg=20.0, azimuth_deg=30.0).ok
    assert ctrl.jog_cartesian("TOOL", "X", -3.0).ok  # back off along the working direction
    g = ctrl.touch_geometry()
    assert g.distance_mm == pytest.approx(3.0, abs=1e-6) and not g.touching and not g.crashed
    assert ctrl.jog_cartesian("TOOL", "X", 5.0).ok  # and push 2 mm through
    g = ctrl.touch_geometry()
    assert g.crashed and g.penetration_mm == pytest.approx(2.0, abs=1e-6)


def test_readout_abc_against_a_hand_built_rotation():
    ctrl = make_controller("kr6", "torch")
    for a, b, c in ((30.0, -20.0, 10.0), (-150.0, 60.0, 170.0), (0.0, 0.0, 0.0), (95.0, -5.0, -120.0),
                    (10.0, 90.0, 0.0)):
        T_base_tcp = _pose(Rz(math.radians(a)) @ Ry(math.radians(b)) @ Rx(math.radians(c)), [0.55, 0.02, 0.45])
        # choose BASE so that the TCP sits at the hand-built pose in BASE
        ctrl.set_T_world_base(ctrl.T_world_tcp() @ np.linalg.inv(T_base_tcp))
        r = ctrl.readout("BASE")
        assert r.frame == "BASE"
        np.testing.assert_allclose([r.x_mm, r.y_mm, r.z_mm], [550.0, 20.0, 450.0], atol=1e-9)
        np.testing.assert_allclose([r.a_deg, r.b_deg, r.c_deg], [a, b, c], atol=1e-6)
    # a reachable pose in WORLD, by IK, reads back the same way
    # (tool X = (cos A cos B, sin A cos B, -sin B): B = 60 deg points the tool down, reachable)
    R = Rz(math.radians(20.0)) @ Ry(math.radians(60.0)) @ Rx(math.radians(170.0))
    assert ctrl.move_true_tool_to(_pose(R, [0.55, 0.02, 0.45])).ok  # active data == truth
    r = ctrl.readout("WORLD")
    np.testing.assert_allclose([r.x_mm, r.y_mm, r.z_mm, r.a_deg, r.b_deg, r.c_deg],
                               [550.0, 20.0, 450.0, 20.0, 60.0, 170.0], atol=1e-6)


def test_readout_in_base_and_text_format():
    base = _pose(Rz(math.radians(90.0)), [0.1, 0.2, 0.0])
    ctrl = make_controller("kr6", "pointer", active=False, q_deg=(0, -90, 90, 0, 0, 0))
    ctrl.set_T_world_base(base)
    world = ctrl.readout()
    np.testing.assert_allclose([world.x_mm, world.y_mm, world.z_mm], [525.0, 0.0, 890.0], atol=1e-9)
    b = ctrl.readout("BASE")
    # BASE turned +90 deg about Z at (100, 200): p_base = Rz(-90) (p - o) = (y - 200, -(x - 100))
    np.testing.assert_allclose([b.x_mm, b.y_mm, b.z_mm], [-200.0, -425.0, 890.0], atol=1e-9)
    R_base_tcp = Rz(math.radians(-90.0)) @ ctrl.T_world_flange()[:3, :3]
    rebuilt = Rz(math.radians(b.a_deg)) @ Ry(math.radians(b.b_deg)) @ Rx(math.radians(b.c_deg))
    np.testing.assert_allclose(rebuilt, R_base_tcp, atol=1e-9)
    from tcp_pendant.pendant.formatting import readout_rows, readout_text   # the one place of the text

    assert readout_rows(world)[0] == ("X", "525.00", "mm") and readout_rows(world)[1] == ("Y", "0.00", "mm")
    assert readout_text(world).startswith("WORLD X 525.00 Y 0.00 Z 890.00 mm  A ")
    assert readout_text(world).endswith(" deg") and "-0.00" not in readout_text(world)
    assert not hasattr(world, "rows") and not hasattr(world, "text")       # numbers only
    with pytest.raises(ControllerError, match="WORLD or BASE"):
        ctrl.readout("TOOL")


def test_active_tool_data_defines_the_jogged_tcp():
    ctrl = make_controller("kr6", "torch", active=False)
    believed = Tool("guess", (10.0, -5.0, 250.0), (0.0, -90.0, 0.0))
    ctrl.set_active_tool(believed)
    T = ctrl.T_world_flange() @ _pose(Ry(math.radians(-90.0)), [0.010, -0.005, 0.250])
    np.testing.assert_allclose(ctrl.T_world_tcp(), T, atol=1e-12)
    joints = ctrl.joint_angles_deg()
    assert list(joints) == ["A1", "A2", "A3", "A4", "A5", "A6"]
    np.testing.assert_allclose(list(joints.values()), (10.0, -80.0, 100.0, 20.0, 40.0, 30.0), atol=1e-9)


def test_tool_data_as_the_apps_flange_tool_transform_in_metres():
    from scipy.spatial.transform import Rotation

    from tcp_pendant.controller import T_flange_tool_m

    tool = Tool("T", (12.5, -3.0, 180.0), (30.0, -20.0, 10.0))
    T = T_flange_tool_m(tool)
    np.testing.assert_allclose(T[:3, 3], [0.0125, -0.003, 0.18], atol=1e-15)
    np.testing.assert_allclose(T[:3, :3], Rotation.from_euler("ZYX", [30.0, -20.0, 10.0], degrees=True).as_matrix(),
                               atol=1e-15)
    np.testing.assert_array_equal(T[3], [0.0, 0.0, 0.0, 1.0])
    T[0, 3] = 9.0                                                    # a new array each time
    assert T_flange_tool_m(tool)[0, 3] == 0.0125


def test_one_pose_check_for_the_controller_spin_and_beam():
    """controller, spin check and beam sensor refuse a bad pose with the same words."""
    from tcp_pendant.controller.beam import BeamSensor, ToolShape, tip_on_beam
    from tcp_pendant.controller.checks import check_pose
    from tcp_pendant.controller.spin import spin_check

    bad_row = np.eye(4)
    bad_row[3, 0] = 0.5
    for T, words in ((np.eye(3), "must be a finite 4x4 homogeneous matrix"),
                     (np.diag([1.0, 1.0, -1.0, 1.0]), "has no proper rotation"),
                     (bad_row, r"must have \[0, 0, 0, 1\] as its last row")):
        with pytest.raises(ControllerError, match="T_x " + words):
            check_pose(T, "T_x")
        with pytest.raises(ControllerError, match="T_world_flange_start " + words):
            tip_on_beam(T, (0.0, 0.0, -1.0), BeamSensor((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
                        ToolShape(np.eye(4)))
        c = make_controller("kr6")
        with pytest.raises(ControllerError, match="T_flange_tool_true " + words):
            spin_check(c.kinematics, c.q_rad, np.eye(4), T)
        with pytest.raises(ControllerError, match="T_world_base " + words):
            c.set_T_world_base(T)
    T = np.eye(4)
    out = check_pose(T, "T")
    out[0, 3] = 1.0                                                   # a copy
    assert T[0, 3] == 0.0
