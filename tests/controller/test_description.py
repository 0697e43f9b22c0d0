"""Robot descriptions as ROS packages ship them (controller/description.py, kinematics.py):
xacro, package:// and $(find pkg) through --package-path and ROS_PACKAGE_PATH, missing meshes,
mimic joints. The layouts and their sources: tests/support/ros_layouts.py, robots/README.md."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from tcp_pendant.controller import ControllerError, RobotKinematics
from tcp_pendant.controller.description import PackageFinder, load_description, package_search_path

from support.ros_layouts import (
    ACME7_MIMIC,
    IRB6640,
    acme7_T_base_flange,
    acme7_workspace,
    irb6640_xacro,
    kr16_2_T_base_tool0,
    kr16_2_urdf,
)


@pytest.fixture
def acme(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    ws = acme7_workspace(tmp_path)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(ws.ros_package_path))
    return ws


def test_xacro_with_find_and_packages_from_both_paths(acme) -> None:
    """The description package comes from ROS_PACKAGE_PATH ($(find acme_description) in the
    xacro includes), the meshes' package from --package-path."""
    d = load_description(acme.xacro, [acme.package_path])
    assert d.name == "acme7" and not d.missing_meshes
    by_link = {m.link: m.path for m in d.meshes if m.kind == "visual"}
    assert by_link == {link: path.resolve() for link, path in acme.meshes.items()}
    assert all(d.drawing(link) == "visual" for link in acme.meshes)
    assert d.drawing("acme_link_ee") == "none"                     # no geometry: nothing to draw
    assert d.mimic_joints == {ACME7_MIMIC[0]: ACME7_MIMIC[1:]}
    assert d.continuous_joints == (ACME7_MIMIC[0],)


def test_package_path_comes_before_ros_package_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    for root in ("first", "second"):
        pkg = tmp_path / root / "deep" / "er" / "folder_name_differs"
        pkg.mkdir(parents=True)
        (pkg / "package.xml").write_text("<package><name>my_pkg</name></package>")
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"{tmp_path / 'second'}:{tmp_path / 'nowhere'}")
    roots = package_search_path([tmp_path / "first"])
    assert roots[0] == tmp_path / "first" and roots[1] == tmp_path / "second"
    found = PackageFinder(roots).find("my_pkg")             # by package.xml <name>, not folder name
    assert found == tmp_path / "first" / "deep" / "er" / "folder_name_differs"
    assert PackageFinder(package_search_path()).find("my_pkg") == tmp_path / "second" / "deep" / "er" / "folder_name_differs"
    assert PackageFinder(roots).find("other_pkg") is None


def test_a_package_is_found_above_the_description_without_any_path(tmp_path: Path, monkeypatch) -> None:
    """A ROS-I URDF inside its own package (pkg/urdf/robot.urdf) finds its package:// files."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    urdf = kr16_2_urdf(tmp_path / "src")
    d = load_description(urdf)
    collision = [m for m in d.meshes if m.kind == "collision"]
    assert len(collision) == 7 and all(m.found for m in collision)
    assert d.drawing("link_3") == "collision"                          # its .dae visual is missing


def test_missing_meshes_are_said_with_what_to_do(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    d = load_description(kr16_2_urdf(tmp_path / "src"))
    lines = d.mesh_warnings()
    assert len(lines) == 7                                         # one per visual mesh
    assert lines[2] == (
        "robot mesh not found: package://kuka_kr16_support/meshes/kr16_2/visual/link_2.dae (link link_2): "
        f"package 'kuka_kr16_support' is {tmp_path / 'src' / 'kuka_kr16_support'}, but it has no "
        "meshes/kr16_2/visual/link_2.dae: check the package's files; link link_2 is drawn from its "
        "collision geometry.")
    # a package that is nowhere: the message names it and the two ways to give it
    d = load_description(irb6640_xacro(tmp_path / "abb"))
    line = next(w for w in d.mesh_warnings() if "(link link_1)" in w)
    assert "package://abb_irb6640_support/meshes/irb6640_185_280/visual/link_1.dae" in line
    assert "drawn as simple link shapes" in line                  # its collision mesh is missing too
    moved = tmp_path / "abb" / "abb_irb6640_support" / "urdf"
    (moved / "irb6640_185_280_macro.xacro").write_text(
        (moved / "irb6640_185_280_macro.xacro").read_text().replace("abb_irb6640_support/meshes", "abb_meshes/meshes"))
    line = next(w for w in load_description(moved / "irb6640_185_280.xacro").mesh_warnings() if "(link link_1)" in w)
    assert "no ROS package 'abb_meshes' was found" in line
    assert "--package-path DIR" in line and "ROS_PACKAGE_PATH" in line


def test_xacro_errors_name_the_package_and_the_options(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    bad = tmp_path / "robot.xacro"
    bad.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                   '<xacro:include filename="$(find nowhere_support)/urdf/m.xacro"/></robot>')
    with pytest.raises(ControllerError, match=r"\$\(find nowhere_support\).*--package-path DIR"):
        load_description(bad)
    broken = tmp_path / "broken.xacro"
    broken.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:nomacro/></robot>')
    with pytest.raises(ControllerError, match="xacro cannot expand"):
        load_description(broken)


def test_seven_axis_xacro_kinematics_and_its_mimic_joint(acme) -> None:
    kin = RobotKinematics.from_urdf(acme.xacro, package_paths=[acme.package_path])
    assert kin.n_joints == 7 and kin.flange_link == "acme_link_ee" and kin.base_link == "world"
    assert ACME7_MIMIC[0] not in kin.joint_names
    rng = np.random.default_rng(4)
    for q in rng.uniform(-1.5, 1.5, (10, 7)):
        np.testing.assert_allclose(kin.T_world_flange(q), acme7_T_base_flange(q), atol=1e-12)
        # the guide follows joint 2: q_guide = -0.5 q2 + 0.1, about link_1's Y
        poses = kin.link_poses(q)
        R_1_guide = poses["acme_link_1"][:3, :3].T @ poses["acme_link_guide"][:3, :3]
        angle = -0.5 * q[1] + 0.1
        np.testing.assert_allclose(R_1_guide, Rotation.from_euler("y", angle).as_matrix(), atol=1e-12)
    J = kin.jacobian_flange(np.zeros(7))
    assert J.shape == (6, 7)


def test_irb6640_with_its_balancing_cylinder_mimic_joints(tmp_path: Path, monkeypatch) -> None:
    """The IRB 6640 layout: continuous mimic joints (cylinder and piston follow joint_2) load;
    pinocchio's internal joint names (JointModelRUBY) are nowhere."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    kin = RobotKinematics.from_urdf(irb6640_xacro(tmp_path))
    assert kin.joint_names == tuple(f"joint_{i}" for i in range(1, 7))
    assert kin.mimic_joints == {"joint_cylinder": ("joint_2", -0.25, 0.0), "joint_piston": ("joint_2", -1.25, 0.0)}
    assert "JointModel" not in repr(kin)
    q = np.radians([20, 30, -40, 10, 50, -60])
    # tool0 by a chain walk of the macro's numbers
    T = np.eye(4)
    for (xyz, axis, _), qi in zip(IRB6640, q):
        step = np.eye(4)
        step[:3, :3] = Rotation.from_rotvec(np.array(axis, float) * qi).as_matrix()
        step[:3, 3] = xyz
        T = T @ step
    T_tool0 = np.eye(4)
    T_tool0[:3, :3] = Rotation.from_euler("y", 1.57079632679).as_matrix()
    np.testing.assert_allclose(kin.T_world_flange(q), T @ T_tool0, atol=1e-12)
    poses = kin.link_poses(q)
    for link, parent, mult in (("link_cylinder", "link_1", -0.25), ("link_piston", "link_2", -1.25)):
        R = poses[parent][:3, :3].T @ poses[link][:3, :3]
        np.testing.assert_allclose(R, Rotation.from_euler("y", mult * q[1]).as_matrix(), atol=1e-12)


def test_kr16_chain_matches_the_macro(tmp_path: Path) -> None:
    kin = RobotKinematics.from_urdf(kr16_2_urdf(tmp_path))
    assert kin.flange_link == "tool0" and not kin.known_home
    for q in np.random.default_rng(16).uniform(-2, 2, (10, 6)):
        np.testing.assert_allclose(kin.T_world_flange(q), kr16_2_T_base_tool0(q), atol=1e-12)


def test_mimic_of_a_mimic_is_refused_clearly(tmp_path: Path) -> None:
    p = tmp_path / "m.urdf"
    p.write_text("""<robot name="m"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
      <joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="j2" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="j1"/></joint>
      <joint name="j3" type="revolute"><parent link="c"/><child link="d"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="j2"/></joint></robot>""")
    with pytest.raises(ControllerError, match="'j3'.*follows 'j2', itself a mimic joint"):
        RobotKinematics.from_urdf(p)


def test_builtin_descriptions_are_unchanged_by_loading(tmp_path: Path) -> None:
    """Our URDFs load through the same path with the same kinematics as pinocchio's own file loader."""
    from tcp_pendant.controller import builtin_robots

    for path in builtin_robots().values():
        kin = RobotKinematics.from_urdf(path)
        model = pin.buildModelFromUrdf(str(path))
        data = model.createData()
        q = np.radians([10, -80, 70, 20, 60, -30])
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(kin.T_world_flange(q), data.oMf[model.getFrameId("flange")].homogeneous,
                                   atol=1e-15)
        assert kin.known_home and not kin.description.missing_meshes
        assert math.isclose(float(np.abs(kin.lower_rad - model.lowerPositionLimit).max()), 0.0)


def test_pinocchio_errors_reach_the_user_in_urdf_words() -> None:
    """pinocchio's own text (here its refusal of a continuous joint mimicking a revolute one, as
    pinocchio 4.1 words it) loses the C++ location and its joint model names."""
    from tcp_pendant.controller.kinematics import _pinocchio_words

    text = ("From file: /project/include/pinocchio/src/multibody/joint/joint-mimic.hxx\n"
            "in function: pinocchio::JointModelMimicTpl<Scalar, Options, JointCollectionTpl>::JointModelMimicTpl("
            "...) [with JointModelMimicking = pinocchio::JointModelRevoluteUnboundedTpl<double, 0, 1>]\n"
            "at line: 589\nmessage:\nwrong argument size: expected 1, got 2\n"
            "hint: Mimicking and mimicked configuration spaces have different sizes\n")
    assert _pinocchio_words(text) == ("wrong argument size: expected 1, got 2 (Mimicking and mimicked "
                                      "configuration spaces have different sizes)")
    assert _pinocchio_words("a JointModelRUBY and a JointModelPZ") == "a continuous joint and a prismatic joint"


def test_find_in_a_plain_urdf_mesh_filename(acme, tmp_path: Path) -> None:
    """A URDF (not xacro) that kept ``$(find pkg)/...`` in a mesh filename, as some exported
    descriptions do, finds the file through the same package path."""
    urdf = tmp_path / "plain.urdf"
    urdf.write_text("""<robot name="plain"><link name="a"><visual><geometry>
      <mesh filename="$(find acme_meshes)/meshes/acme7/visual/link_0.stl"/></geometry></visual></link>
      <link name="b"/><joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
      <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>""")
    (mesh,) = load_description(urdf, [acme.package_path]).meshes
    assert mesh.path == acme.meshes["acme_link_0"].resolve()
    (mesh,) = load_description(urdf).meshes                     # without the path: said, not found
    assert mesh.path is None and "no ROS package 'acme_meshes' was found" in mesh.reason
