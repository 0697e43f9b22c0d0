"""robots/README.md: our ``flange`` against ROS-Industrial's ``tool0``.

``tool0`` is built here from the joint origins, axes and the ``tool0`` joint of ROS-Industrial's
macros, copied as numbers (no ROS package is needed): [R] ``kuka_experimental``
``kr6r900sixx_macro.xacro`` and [M] ``motoman`` ``gp12_macro.xacro``. Our URDFs, loaded with
pinocchio, must give ``T_base_flange = T_base_tool0 @ Rz(180 deg)`` on the KR 6 and
``T_base_flange = T_base_tool0`` on the GP12, at any joint angles.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

ROBOTS = Path(__file__).resolve().parents[2] / "robots"

# (joint origin xyz in m, joint axis): every joint origin rpy is (0, 0, 0) in both macros.
KR6_ROS_I = [((0, 0, 0.400), (0, 0, -1)), ((0.025, 0, 0), (0, 1, 0)), ((0.455, 0, 0), (0, 1, 0)),
             ((0, 0, 0.035), (-1, 0, 0)), ((0.420, 0, 0), (0, 1, 0)), ((0.080, 0, 0), (-1, 0, 0))]
KR6_TOOL0 = ((0, 0, 0), (0, np.pi / 2, 0))                 # joint_a6-tool0: xyz, rpy
GP12_ROS_I = [((0, 0, 0.450), (0, 0, 1)), ((0.155, 0, 0), (0, 1, 0)), ((0, 0, 0.614), (0, -1, 0)),
              ((0.640, 0, 0.200), (-1, 0, 0)), ((0, 0, 0), (0, -1, 0)), ((0, 0, 0), (-1, 0, 0))]
GP12_TOOL0 = ((0.100, 0, 0), (3.1415926, -1.570796, 0))     # joint_6_t-tool0 (rounded as in [M])


def _T(xyz, R) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = xyz
    return T


def ros_i_tool0(chain, tool0, q: np.ndarray) -> np.ndarray:
    """``T_base_tool0`` of a ROS-I macro at joint angles ``q`` (rad)."""
    T = np.eye(4)
    for (xyz, axis), qi in zip(chain, q):
        T = T @ _T(xyz, np.eye(3)) @ _T((0, 0, 0), Rotation.from_rotvec(np.array(axis, float) * qi).as_matrix())
    xyz, rpy = tool0
    return T @ _T(xyz, Rotation.from_euler("xyz", rpy).as_matrix())   # URDF rpy: fixed axes x, y, z


def our_flange(urdf: Path, q: np.ndarray) -> np.ndarray:
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    return data.oMf[model.getFrameId("flange")].homogeneous


RZ180 = _T((0, 0, 0), np.diag([-1.0, -1.0, 1.0]))


@pytest.mark.parametrize("robot,urdf,chain,tool0,T_tool0_flange,atol", [
    ("kr6", ROBOTS / "kr6_r900" / "kr6_r900.urdf", KR6_ROS_I, KR6_TOOL0, RZ180, 1e-12),
    ("gp12", ROBOTS / "gp12" / "gp12.urdf", GP12_ROS_I, GP12_TOOL0, np.eye(4), 1e-6),  # [M]'s pi to 7 digits
])
def test_flange_is_tool0_as_stated(robot, urdf, chain, tool0, T_tool0_flange, atol) -> None:
    rng = np.random.default_rng(13)
    for q in [np.zeros(6), *(rng.uniform(-2.5, 2.5, 6) for _ in range(20))]:
        np.testing.assert_allclose(our_flange(urdf, q), ros_i_tool0(chain, tool0, q) @ T_tool0_flange,
                                   atol=atol, rtol=0, err_msg=robot)


def test_kr6_flange_is_not_tool0_itself() -> None:
    """The 180 deg is real: X and Y of the KR 6 flange are opposite to ROS-I tool0's."""
    q = np.radians([0, -90, 90, 0, 0, 0])                       # HOME: forearm and flange forward
    ours = our_flange(ROBOTS / "kr6_r900" / "kr6_r900.urdf", q)
    tool0 = ros_i_tool0(KR6_ROS_I, KR6_TOOL0, q)
    np.testing.assert_allclose(ours[:3, 0], [0, 0, 1], atol=1e-12)     # our flange X up
    np.testing.assert_allclose(tool0[:3, 0], [0, 0, -1], atol=1e-12)   # tool0 X down
    np.testing.assert_allclose(ours[:3, 2], tool0[:3, 2], atol=1e-12)  # same Z, out of the face


def test_readme_states_the_relation_checked_here() -> None:
    """robots/README.md said "ROS tool0 style" for both robots; it must state what is checked above."""
    text = " ".join((ROBOTS / "README.md").read_text(encoding="utf-8").split())
    assert "tool0` style" not in text
    assert "On the **GP12** our `flange` *is* [M]'s `tool0`" in text
    assert "On the **KR 6** it is [R]'s `tool0` **rotated 180° about Z** (X and Y flipped" in text
