"""Robot descriptions written by the tests in the layouts ROS and ROS-Industrial publish
(robots/README.md, "Robot descriptions from ROS packages", gives each source).

Every number here is ours (or, for the KR 16, the joint origins and limits of the cited macro,
small data excerpts); the meshes are boxes and cylinders made with trimesh.

* :func:`acme7_workspace`: a 7-axis arm in the layout of ``IFL-CAMP/iiwa_stack``
  ``iiwa_description/urdf/iiwa14.xacro`` (a xacro macro with ``$(find ...)`` includes, links
  ``<prefix>_link_0..7`` on joints about their own Z, ``package://`` STL meshes in
  ``meshes/<model>/visual`` and ``collision``), with a continuous mimic joint like the balancing
  cylinder of ROS-Industrial's IRB 6640 (``ros-industrial/abb``
  ``abb_irb6640_support/urdf/irb6640_185_280_macro.xacro``). Two packages: the description
  (found through ``ROS_PACKAGE_PATH``) and the meshes (through ``--package-path``).
* :func:`kr16_2_urdf`: the joint chain of ``ros-industrial/kuka_experimental``
  ``kuka_kr16_support/urdf/kr16_2_macro.xacro`` (joint_a1..a6, tool0, base).
* :func:`irb6640_urdf`: the chain of the IRB 6640 macro above, with its ``joint_cylinder`` and
  ``joint_piston`` mimic joints (continuous, multipliers -0.25 and -1.25 of joint_2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

# acme7: (joint origin z from the previous link, axis, limit deg); every joint origin is on the
# previous link's Z, rpy 0, like the iiwa's up to its alternating rpy (ours are plain axes)
ACME7_JOINTS = [
    (0.160, (0, 0, 1), 170), (0.200, (0, 1, 0), 120), (0.200, (0, 0, 1), 170),
    (0.220, (0, -1, 0), 120), (0.180, (0, 0, 1), 170), (0.220, (0, 1, 0), 120),
    (0.080, (0, 0, 1), 175),
]
ACME7_FLANGE_Z = 0.045
ACME7_MIMIC = ("acme_joint_guide", "acme_joint_2", -0.5, 0.1)   # (joint, leader, multiplier, offset)

PACKAGE_XML = """<?xml version="1.0"?>
<package format="2">
  <name>{name}</name>
  <version>0.1.0</version>
  <description>test package</description>
  <maintainer email="test@example.com">test</maintainer>
  <license>MIT</license>
  <buildtool_depend>catkin</buildtool_depend>
</package>
"""


@dataclass(frozen=True)
class Acme7:
    """The written tree: the xacro to give ``--robot``, the two package roots, the mesh files."""

    xacro: Path
    ros_package_path: Path
    package_path: Path
    meshes: dict[str, Path]


def _mesh(link: int, length: float) -> trimesh.Trimesh:
    if link == 0:
        return trimesh.creation.cylinder(radius=0.09, height=0.16, transform=_tz(0.08))
    return trimesh.creation.cylinder(radius=0.06, height=max(length, 0.05), sections=16,
                                     transform=_tz(0.5 * max(length, 0.05)))


def _tz(z: float) -> np.ndarray:
    T = np.eye(4)
    T[2, 3] = z
    return T


def _xyz(v) -> str:
    return " ".join(repr(float(x)) for x in v)


def acme7_workspace(root: Path, *, missing_visual: tuple[int, ...] = ()) -> Acme7:
    """Write the acme7 packages under ``root`` (see the module doc).

    Args:
        missing_visual: link numbers whose visual STL is not written (their collision STL is).
    """
    desc = root / "ws" / "src" / "acme_description"
    mesh_pkg = root / "vendor" / "acme_meshes"
    (desc / "urdf").mkdir(parents=True)
    for kind in ("visual", "collision"):
        (mesh_pkg / "meshes" / "acme7" / kind).mkdir(parents=True)
    (desc / "package.xml").write_text(PACKAGE_XML.format(name="acme_description"))
    (mesh_pkg / "package.xml").write_text(PACKAGE_XML.format(name="acme_meshes"))
    lengths = [z for z, _, _ in ACME7_JOINTS[1:]] + [ACME7_FLANGE_Z]
    meshes: dict[str, Path] = {}
    for i in range(8):
        m = _mesh(i, lengths[i - 1] if i else 0.16)
        for kind in ("visual", "collision"):
            path = mesh_pkg / "meshes" / "acme7" / kind / f"link_{i}.stl"
            if kind == "visual" and i in missing_visual:
                continue
            m.export(path)
            if kind == "visual":
                meshes[f"acme_link_{i}"] = path
    guide = trimesh.creation.box(extents=(0.04, 0.03, 0.15), transform=_tz(0.075))
    guide.export(mesh_pkg / "meshes" / "acme7" / "visual" / "guide.stl")
    guide.export(mesh_pkg / "meshes" / "acme7" / "collision" / "guide.stl")
    meshes["acme_link_guide"] = mesh_pkg / "meshes" / "acme7" / "visual" / "guide.stl"

    links = []
    for i in range(8):
        links.append(f"""
    <link name="${{prefix}}_link_{i}">
      <visual>
        <origin xyz="0 0 0" rpy="0 0 0"/>
        <geometry><mesh filename="package://acme_meshes/meshes/acme7/visual/link_{i}.stl"/></geometry>
        <xacro:material_acme_orange/>
      </visual>
      <collision>
        <origin xyz="0 0 0" rpy="0 0 0"/>
        <geometry><mesh filename="package://acme_meshes/meshes/acme7/collision/link_{i}.stl"/></geometry>
      </collision>
    </link>""")
    joints = []
    for i, (z, axis, lim) in enumerate(ACME7_JOINTS, start=1):
        joints.append(f"""
    <joint name="${{prefix}}_joint_{i}" type="revolute">
      <parent link="${{prefix}}_link_{i - 1}"/>
      <child link="${{prefix}}_link_{i}"/>
      <origin xyz="0 0 {z}" rpy="0 0 0"/>
      <axis xyz="{_xyz(axis)}"/>
      <limit lower="${{-{lim} * pi / 180}}" upper="${{{lim} * pi / 180}}" effort="300" velocity="${{max_velocity}}"/>
    </joint>""")
    joint, leader, mult, offset = ACME7_MIMIC
    macro = f"""<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find acme_description)/urdf/materials.xacro"/>
  <xacro:property name="max_velocity" value="1.7"/>
  <xacro:macro name="acme7" params="prefix">
    {''.join(links)}
    <link name="${{prefix}}_link_guide">
      <visual>
        <geometry><mesh filename="package://acme_meshes/meshes/acme7/visual/guide.stl"/></geometry>
        <xacro:material_acme_orange/>
      </visual>
      <collision>
        <geometry><mesh filename="package://acme_meshes/meshes/acme7/collision/guide.stl"/></geometry>
      </collision>
    </link>
    <link name="${{prefix}}_link_ee"/>
    {''.join(joints)}
    <joint name="{joint}" type="continuous">
      <parent link="${{prefix}}_link_1"/>
      <child link="${{prefix}}_link_guide"/>
      <origin xyz="-0.08 0 0.1" rpy="0 0 0"/>
      <axis xyz="0 1 0"/>
      <mimic joint="{leader}" multiplier="{mult}" offset="{offset}"/>
    </joint>
    <joint name="${{prefix}}_joint_ee" type="fixed">
      <parent link="${{prefix}}_link_7"/>
      <child link="${{prefix}}_link_ee"/>
      <origin xyz="0 0 {ACME7_FLANGE_Z}" rpy="0 0 0"/>
    </joint>
  </xacro:macro>
</robot>
"""
    (desc / "urdf" / "acme7_macro.xacro").write_text(macro)
    (desc / "urdf" / "materials.xacro").write_text("""<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="material_acme_orange">
    <material name="acme_orange"><color rgba="1 0.4 0 1"/></material>
  </xacro:macro>
</robot>
""")
    top = desc / "urdf" / "acme7.urdf.xacro"
    top.write_text("""<?xml version="1.0"?>
<robot name="acme7" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find acme_description)/urdf/acme7_macro.xacro"/>
  <link name="world"/>
  <joint name="world_acme_joint" type="fixed">
    <parent link="world"/>
    <child link="acme_link_0"/>
    <origin xyz="0 0 0" rpy="0 0 0"/>
  </joint>
  <xacro:acme7 prefix="acme"/>
</robot>
""")
    return Acme7(top, root / "ws" / "src", root / "vendor", meshes)


def acme7_T_base_flange(q: np.ndarray) -> np.ndarray:
    """The acme7 flange (``acme_link_ee``) pose by a chain walk written from the table above."""
    from scipy.spatial.transform import Rotation

    T = np.eye(4)
    for (z, axis, _), qi in zip(ACME7_JOINTS, q):
        step = np.eye(4)
        step[:3, :3] = Rotation.from_rotvec(np.array(axis, float) * qi).as_matrix()
        step[2, 3] = z
        T = T @ step
    flange = np.eye(4)
    flange[2, 3] = ACME7_FLANGE_Z
    return T @ flange


# ros-industrial/kuka_experimental kuka_kr16_support/urdf/kr16_2_macro.xacro: joint origins (m),
# axes and limits (deg) of joint_a1..a6, tool0 at x 0.158 rpy (0, 90 deg, 0) from link_6
KR16_2 = [((0, 0, 0.675), (0, 0, -1), (-185, 185)), ((0.26, 0, 0), (0, 1, 0), (-155, 35)),
          ((0.68, 0, 0), (0, 1, 0), (-130, 154)), ((0.67, 0, -0.035), (-1, 0, 0), (-350, 350)),
          ((0, 0, 0), (0, 1, 0), (-130, 130)), ((0, 0, 0), (-1, 0, 0), (-350, 350))]


def kr16_2_urdf(folder: Path, *, meshes: bool = True) -> Path:
    """The KR 16-2 chain as the macro expands it (``prefix=""``), visual meshes named as in the
    macro (``package://kuka_kr16_support/meshes/kr16_2/visual/link_N.dae``; not written here, so
    they are missing unless the caller provides them) and collision STLs (written when
    ``meshes``)."""
    folder.mkdir(parents=True, exist_ok=True)
    pkg = folder / "kuka_kr16_support"
    (pkg / "urdf").mkdir(parents=True, exist_ok=True)
    (pkg / "package.xml").write_text(PACKAGE_XML.format(name="kuka_kr16_support"))
    if meshes:
        (pkg / "meshes" / "kr16_2" / "collision").mkdir(parents=True, exist_ok=True)
    names = ["base_link"] + [f"link_{i}" for i in range(1, 7)]
    links = []
    for n in names:
        if meshes:
            trimesh.creation.box(extents=(0.15, 0.15, 0.15)).export(
                pkg / "meshes" / "kr16_2" / "collision" / f"{n}.stl")
        links.append(f"""  <link name="{n}">
    <visual><origin xyz="0 0 0" rpy="0 0 0"/><geometry>
      <mesh filename="package://kuka_kr16_support/meshes/kr16_2/visual/{n}.dae"/></geometry></visual>
    <collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry>
      <mesh filename="package://kuka_kr16_support/meshes/kr16_2/collision/{n}.stl"/></geometry></collision>
  </link>
""")
    joints = []
    for i, (xyz, axis, (lo, hi)) in enumerate(KR16_2, start=1):
        joints.append(f"""  <joint name="joint_a{i}" type="revolute">
    <origin xyz="{_xyz(xyz)}" rpy="0 0 0"/><parent link="{names[i - 1]}"/><child link="{names[i]}"/>
    <axis xyz="{_xyz(axis)}"/>
    <limit effort="0" lower="{math.radians(lo)!r}" upper="{math.radians(hi)!r}" velocity="{math.radians(156)!r}"/>
  </joint>
""")
    text = f"""<?xml version="1.0"?>
<robot name="kuka_kr16_2">
{''.join(links)}  <link name="tool0"/>
{''.join(joints)}  <joint name="joint_a6-tool0" type="fixed">
    <parent link="link_6"/><child link="tool0"/><origin xyz="0.158 0 0" rpy="0 {math.radians(90)!r} 0"/>
  </joint>
  <link name="base"/>
  <joint name="base_link-base" type="fixed">
    <origin xyz="0 0 0" rpy="0 0 0"/><parent link="base_link"/><child link="base"/>
  </joint>
</robot>
"""
    path = pkg / "urdf" / "kr16_2.urdf"
    path.write_text(text)
    return path


def kr16_2_T_base_tool0(q: np.ndarray) -> np.ndarray:
    """tool0 of the KR 16-2 by a chain walk of :data:`KR16_2` (every joint origin rpy 0)."""
    from scipy.spatial.transform import Rotation

    T = np.eye(4)
    for (xyz, axis, _), qi in zip(KR16_2, q):
        step = np.eye(4)
        step[:3, :3] = Rotation.from_rotvec(np.array(axis, float) * qi).as_matrix()
        step[:3, 3] = xyz
        T = T @ step
    tool0 = np.eye(4)
    tool0[:3, :3] = Rotation.from_euler("xyz", [0, math.pi / 2, 0]).as_matrix()
    tool0[0, 3] = 0.158
    return T @ tool0


# ros-industrial/abb abb_irb6640_support/urdf/irb6640_185_280_macro.xacro: joint_1..6 origins
# (m), axes, limits (rad); tool0 rpy (0, pi/2, 0) on link_6; the cylinder and piston mimic joint_2
IRB6640 = [((0, 0, 0.780), (0, 0, 1), (-2.967, 2.967)), ((0.320, 0, 0), (0, 1, 0), (-1.134, 1.4855)),
           ((0, 0, 1.075), (0, 1, 0), (-3.142, 1.222)), ((0, 0, 0.2), (1, 0, 0), (-5.236, 5.236)),
           ((1.392, 0, 0), (0, 1, 0), (-2.094, 2.094)), ((0.2, 0, 0), (1, 0, 0), (-6.283, 6.283))]
IRB6640_MIMIC = {"joint_cylinder": ("link_1", (-0.3647, 0, -0.1455), -0.25),
                 "joint_piston": ("link_2", (-0.22, 0, -0.0672), -1.25)}


def irb6640_xacro(folder: Path) -> Path:
    """The IRB 6640-185/2.80 as its support package lays it out: ``urdf/irb6640_185_280.xacro``
    including the macro by ``$(find abb_irb6640_support)``, no meshes written (all missing)."""
    pkg = folder / "abb_irb6640_support"
    (pkg / "urdf").mkdir(parents=True, exist_ok=True)
    (pkg / "package.xml").write_text(PACKAGE_XML.format(name="abb_irb6640_support"))
    names = ["base_link"] + [f"link_{i}" for i in range(1, 7)] + ["link_cylinder", "link_piston"]
    links = "".join(f"""    <link name="${{prefix}}{n}">
      <collision name="collision"><geometry>
        <mesh filename="package://abb_irb6640_support/meshes/irb6640_185_280/collision/{n}.stl"/></geometry></collision>
      <visual name="visual"><geometry>
        <mesh filename="package://abb_irb6640_support/meshes/irb6640_185_280/visual/{n}.dae"/></geometry></visual>
    </link>
""" for n in names)
    joints = "".join(f"""    <joint type="revolute" name="${{prefix}}joint_{i}">
      <origin xyz="{_xyz(xyz)}" rpy="0 0 0"/><axis xyz="{_xyz(axis)}"/>
      <parent link="${{prefix}}{names[i - 1]}"/><child link="${{prefix}}{names[i]}"/>
      <limit effort="0" lower="{lo}" upper="{hi}" velocity="1.5707"/>
    </joint>
""" for i, (xyz, axis, (lo, hi)) in enumerate(IRB6640, start=1))
    mimic = "".join(f"""    <joint type="continuous" name="${{prefix}}{j}">
      <origin xyz="{_xyz(xyz)}" rpy="0 0 0"/><axis xyz="0 1 0"/>
      <parent link="${{prefix}}{parent}"/><child link="${{prefix}}{child}"/>
      <mimic joint="${{prefix}}joint_2" multiplier="{m}"/>
    </joint>
""" for (j, (parent, xyz, m)), child in zip(IRB6640_MIMIC.items(), ("link_cylinder", "link_piston")))
    (pkg / "urdf" / "irb6640_185_280_macro.xacro").write_text(f"""<?xml version="1.0"?>
<robot xmlns:xacro="http://ros.org/wiki/xacro">
  <xacro:macro name="abb_irb6640_185_280" params="prefix">
{links}    <link name="${{prefix}}tool0"/>
{joints}    <joint type="fixed" name="${{prefix}}joint_6-tool0">
      <parent link="${{prefix}}link_6"/><child link="${{prefix}}tool0"/>
      <origin xyz="0 0 0" rpy="0 1.57079632679 0"/>
    </joint>
{mimic}    <link name="${{prefix}}base"/>
    <joint name="${{prefix}}base_link-base" type="fixed">
      <origin xyz="0 0 0" rpy="0 0 0"/><parent link="${{prefix}}base_link"/><child link="${{prefix}}base"/>
    </joint>
  </xacro:macro>
</robot>
""")
    top = pkg / "urdf" / "irb6640_185_280.xacro"
    top.write_text("""<?xml version="1.0" ?>
<robot name="abb_irb6640_185_280" xmlns:xacro="http://ros.org/wiki/xacro">
  <xacro:include filename="$(find abb_irb6640_support)/urdf/irb6640_185_280_macro.xacro"/>
  <xacro:abb_irb6640_185_280 prefix=""/>
</robot>
""")
    return top
