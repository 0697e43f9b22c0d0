"""RobotKinematics: hand-computed KR 6 poses, pinocchio == yourdfpy, Jacobian vs finite
differences, default flange link, homes, and clear errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yourdfpy
from scipy.spatial.transform import Rotation

from tcp_pendant.controller import ControllerError, RobotKinematics, builtin_robots, example_robot_urdf
from tcp_pendant.controller.assets import robots_dir

from .conftest import kinematics


def flange_mm(robot: str, q_deg) -> np.ndarray:
    return kinematics(robot).T_world_flange(np.radians(q_deg))[:3, 3] * 1000.0


# KR 6 R900 sixx figures: A2 400 mm up and 25 mm forward of A1, upper arm 455,
# forearm offset 35, A4..wrist centre 420, wrist centre..flange 80.
@pytest.mark.parametrize("q_deg, expected_mm", [
    # all zero: everything forward and horizontal: x = 25 + 455 + 420 + 80, z = 400 + 35
    ((0, 0, 0, 0, 0, 0), (980.0, 0.0, 435.0)),
    # HOME: upper arm vertical (z = 400 + 455 + 35), forearm forward (x = 25 + 420 + 80)
    ((0, -90, 90, 0, 0, 0), (525.0, 0.0, 890.0)),
    # arm straight up: the 35 mm offset points backwards, z = 400 + 455 + 420 + 80
    ((0, -90, 0, 0, 0, 0), (-10.0, 0.0, 1355.0)),
    # HOME with the wrist bent 90 deg: flange 80 mm below the wrist centre (x = 25 + 420)
    ((0, -90, 90, 0, 90, 0), (445.0, 0.0, 810.0)),
    ((0, -90, 90, 0, -90, 0), (445.0, 0.0, 970.0)),
])
def test_kr6_flange_at_documented_poses(q_deg, expected_mm):
    np.testing.assert_allclose(flange_mm("kr6", q_deg), expected_mm, atol=1e-9)


def test_kr6_a1_turns_about_the_vertical_and_flange_z_points_out_of_the_face():
    # A1 only rotates the zero pose about the vertical axis: radius 980 mm, height 435 mm
    for a1 in (-150.0, -30.0, 45.0, 120.0):
        p = flange_mm("kr6", (a1, 0, 0, 0, 0, 0))
        assert math.hypot(p[0], p[1]) == pytest.approx(980.0, abs=1e-9)
        assert p[2] == pytest.approx(435.0, abs=1e-9)
        assert abs(math.degrees(math.atan2(p[1], p[0]))) == pytest.approx(abs(a1), abs=1e-9)
    # flange Z out of the face: at HOME the flange looks forward (+X)
    kin = kinematics("kr6")
    np.testing.assert_allclose(kin.T_world_flange(kin.home_rad)[:3, 2], [1.0, 0.0, 0.0], atol=1e-12)


def test_gp12_zero_pose_from_its_urdf_dimensions():
    # gp12.urdf joint origins: S 450 up, L 155 forward, U 614 up, R 640 forward 200 up, T 100
    np.testing.assert_allclose(flange_mm("gp12", (0,) * 6), (155 + 640 + 100, 0.0, 450 + 614 + 200), atol=1e-9)


def test_joint_names_limits_and_homes():
    kr6, gp12 = kinematics("kr6"), kinematics("gp12")
    assert kr6.joint_names == ("A1", "A2", "A3", "A4", "A5", "A6")
    assert gp12.joint_names == ("S", "L", "U", "R", "B", "T")
    np.testing.assert_allclose(np.degrees(kr6.lower_rad), (-170, -190, -120, -185, -120, -350), atol=1e-9)
    np.testing.assert_allclose(np.degrees(kr6.upper_rad), (170, 45, 156, 185, 120, 350), atol=1e-9)
    np.testing.assert_allclose(np.degrees(kr6.home_rad), (0, -90, 90, 0, 0, 0), atol=1e-12)
    # GP12 home: flange straight down, inside the limits
    T = gp12.T_world_flange(gp12.home_rad)
    np.testing.assert_allclose(T[:3, 2], [0.0, 0.0, -1.0], atol=1e-12)
    assert np.all(gp12.home_rad >= gp12.lower_rad) and np.all(gp12.home_rad <= gp12.upper_rad)
    assert kr6.flange_link == "flange" and gp12.flange_link == "flange"


@pytest.mark.parametrize("robot", ["kr6", "gp12", "ur5"])
def test_pinocchio_matches_yourdfpy_for_random_configurations(robot):
    kin = kinematics(robot)
    urdf = yourdfpy.URDF.load(str(kin.urdf_path), load_meshes=False, build_collision_scene_graph=False,
                              load_collision_meshes=False)
    assert tuple(urdf.actuated_joint_names) == kin.joint_names
    rng = np.random.default_rng(3)
    for _ in range(25):
        q = rng.uniform(kin.lower_rad, kin.upper_rad)
        urdf.update_cfg(q)
        T_yourdfpy = urdf.get_transform(frame_to=kin.flange_link, frame_from=urdf.base_link)
        np.testing.assert_allclose(kin.T_world_flange(q), T_yourdfpy, atol=1e-9, rtol=0)
        poses = kin.link_poses(q)
        assert set(poses) == set(urdf.link_map)
        for link, T in poses.items():
            np.testing.assert_allclose(T, urdf.get_transform(frame_to=link, frame_from=urdf.base_link),
                                       atol=1e-9, rtol=0)


@pytest.mark.parametrize("robot", ["kr6", "gp12", "ur5"])
def test_jacobian_matches_finite_differences_of_fk(robot):
    kin = kinematics(robot)
    rng = np.random.default_rng(4)
    h = 1e-6
    for _ in range(5):
        q = rng.uniform(kin.lower_rad, kin.upper_rad)
        J = kin.jacobian_flange(q)
        T0 = kin.T_world_flange(q)
        for j in range(kin.n_joints):
            dq = np.zeros(kin.n_joints)
            dq[j] = h
            Tp, Tm = kin.T_world_flange(q + dq), kin.T_world_flange(q - dq)
            v = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
            w = Rotation.from_matrix(Tp[:3, :3] @ Tm[:3, :3].T).as_rotvec() / (2 * h)
            np.testing.assert_allclose(J[:3, j], v, atol=1e-7)
            np.testing.assert_allclose(J[3:, j], w, atol=1e-7)
        np.testing.assert_allclose(kin.T_world_flange(q), T0)  # no state leaks between calls


def test_ur5_from_example_robot_data_default_and_named_flange():
    path = example_robot_urdf()
    kin = RobotKinematics.from_urdf(path)
    # longest chain: world - base_link - ... - wrist_3_link - {ee_link, tool0}: tie goes to tool0
    assert kin.flange_link == "tool0"
    assert kin.n_joints == 6 and kin.joint_names[0] == "shoulder_pan_joint"
    np.testing.assert_allclose(kin.home_rad, np.zeros(6))
    urdf = yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False,
                              load_collision_meshes=False)
    q = np.array([0.3, -1.0, 1.2, -0.4, 0.8, 0.1])
    urdf.update_cfg(q)
    named = RobotKinematics.from_urdf(path, flange_link="ee_link")
    assert named.flange_link == "ee_link"
    np.testing.assert_allclose(named.T_world_flange(q), urdf.get_transform("ee_link", urdf.base_link), atol=1e-9)
    with pytest.raises(ControllerError, match="no link 'nope'.*tool0"):
        RobotKinematics.from_urdf(path, flange_link="nope")


CHAIN = """<robot name="toy">
  <link name="root"/><link name="a"/><link name="b"/><link name="tip"/><link name="side"/>
  <joint name="j1" type="revolute"><parent link="root"/><child link="a"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/><limit lower="0.5" upper="1.5" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.2 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="-0.2" effort="1" velocity="1"/></joint>
  <joint name="f" type="fixed"><parent link="b"/><child link="tip"/><origin xyz="0.1 0 0"/></joint>
  <joint name="s" type="fixed"><parent link="root"/><child link="side"/></joint>
</robot>"""


def test_other_urdf_home_is_zero_clipped_to_limits_and_flange_is_deepest_leaf(tmp_path: Path):
    p = tmp_path / "toy.urdf"
    p.write_text(CHAIN)
    kin = RobotKinematics.from_urdf(p)
    assert kin.flange_link == "tip" and kin.base_link == "root"
    np.testing.assert_allclose(kin.home_rad, [0.5, -0.2])
    # hand FK: j1 turns about z at height 0.1, j2 about y 0.2 further; tip 0.1 beyond
    q = np.array([1.0, -0.5])
    r = 0.2 + 0.1 * math.cos(-0.5)
    expected = [r * math.cos(1.0), r * math.sin(1.0), 0.1 - 0.1 * math.sin(-0.5)]
    np.testing.assert_allclose(kin.T_world_flange(q)[:3, 3], expected, atol=1e-12)


def test_bad_urdfs_give_clear_errors(tmp_path: Path):
    with pytest.raises(ControllerError, match="URDF not found"):
        RobotKinematics.from_urdf(tmp_path / "missing.urdf")
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot><link name='a'>")
    with pytest.raises(ControllerError, match="Cannot read the URDF"):
        RobotKinematics.from_urdf(bad)
    floating = tmp_path / "floating.urdf"
    floating.write_text(CHAIN.replace('<joint name="s" type="fixed">', '<joint name="s" type="floating">'))
    with pytest.raises(ControllerError, match="'s'.*floating joint") as err:
        RobotKinematics.from_urdf(floating)
    assert "JointModel" not in str(err.value)                    # pinocchio's names stay inside


def test_continuous_joint_is_revolute_with_one_turn_either_way(tmp_path: Path):
    cont = tmp_path / "cont.urdf"
    cont.write_text(CHAIN.replace('type="revolute"><parent link="a"', 'type="continuous"><parent link="a"'))
    kin = RobotKinematics.from_urdf(cont)
    assert kin.joint_names == ("j1", "j2") and kin.n_joints == 2
    np.testing.assert_allclose(kin.lower_rad, [0.5, -2 * math.pi])
    np.testing.assert_allclose(kin.upper_rad, [1.5, 2 * math.pi])
    assert kin.description.continuous_joints == ("j2",)


def test_builtin_robots_are_in_robots_dir():
    robots = builtin_robots()
    assert set(robots) == {"kr6", "gp12"}
    for path in robots.values():
        assert path.is_file() and robots_dir() in path.parents
