"""The robot URDFs against an independent forward kinematics written here by hand.

Each robot's flange pose is the product of elementary translations and rotations built from
the published figures (robots/README.md: mm, degrees) and the makers' rotation
directions, written out below in words. Nothing is read from robots/generate.py or the URDF
files; pinocchio and yourdfpy load the URDFs and must agree with the hand product to 1e-12 m
over random configurations, so a wrong length, axis, sign or zero in the URDF fails here.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy

ROBOTS = Path(__file__).resolve().parents[2] / "robots"
KR6 = ROBOTS / "kr6_r900" / "kr6_r900.urdf"
GP12 = ROBOTS / "gp12" / "gp12.urdf"


def Rx(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return _h(np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]))


def Ry(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return _h(np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]))


def Rz(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return _h(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]))


def Tr(x_mm: float = 0.0, y_mm: float = 0.0, z_mm: float = 0.0) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = (x_mm / 1000.0, y_mm / 1000.0, z_mm / 1000.0)
    return T


def _h(R: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    return T


# FLANGE in the last link's frame (the last axis runs along that frame's +X, away from the
# wrist): Z out of the flange face = +X, X = +Z (up when the wrist is straight and the forearm
# horizontal), Y = Z x X. Columns are the flange X, Y, Z axes.
FLANGE_IN_LAST_LINK = _h(np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]]))


def kr6_by_hand(q_deg) -> np.ndarray:
    """KUKA KR 6 R900 sixx, ``T_base_flange`` (metres) at axis angles A1..A6 in degrees.

    Zero pose (KUKA): arm stretched forward horizontally. KUKA rotation directions:
    * A1 turns about the vertical, positive = clockwise seen from above (about -Z);
    * A2, A3, A5 turn about horizontal axes pointing to the robot's left (+Y at A1 = 0),
      positive = right-handed about them: A2 > 0 lowers the upper arm forward, A3 > 0 lowers
      the forearm, A5 > 0 tilts the flange down (forearm horizontal);
    * A4, A6 turn about the forearm / flange axis, positive = right-handed about the axis
      pointing back towards the robot (about -X): clockwise seen looking at the flange face.
    Figures (mm): A2 400 above the floor and 25 forward of A1; upper arm 455; forearm offset 35;
    A3 to the wrist centre along A4 420; wrist centre to flange 80.
    """
    a1, a2, a3, a4, a5, a6 = q_deg
    return (Tr(z_mm=400.0) @ Rz(-a1) @ Tr(x_mm=25.0) @ Ry(a2) @ Tr(x_mm=455.0) @ Ry(a3)
            @ Tr(z_mm=35.0) @ Rx(-a4) @ Tr(x_mm=420.0) @ Ry(a5) @ Tr(x_mm=80.0) @ Rx(-a6)
            @ FLANGE_IN_LAST_LINK)


def gp12_by_hand(q_deg) -> np.ndarray:
    """Yaskawa GP12 class, ``T_base_flange`` (metres) at S, L, U, R, B, T in degrees.

    Zero pose (Yaskawa): upper arm vertical, forearm and flange forward horizontally.
    Yaskawa rotation directions: S > 0 counter-clockwise seen from above (about +Z); L > 0
    leans the upper arm forward (about +Y); U > 0 raises the forearm (about -Y); R, T about
    the forearm / flange axis, right-handed about -X; B > 0 raises the flange (about -Y).
    Figures (mm): L axis 450 above the floor and 155 forward of S; upper arm 614; forearm axis
    200 above U; U to B (wrist centre) 640 along it; B to flange 100.
    """
    s, l, u, r, b, t = q_deg
    return (Tr(z_mm=450.0) @ Rz(s) @ Tr(x_mm=155.0) @ Ry(l) @ Tr(z_mm=614.0) @ Ry(-u)
            @ Tr(x_mm=640.0, z_mm=200.0) @ Rx(-r) @ Ry(-b) @ Tr(x_mm=100.0) @ Rx(-t)
            @ FLANGE_IN_LAST_LINK)


LIMITS_DEG = {
    "kr6": [(-170, 170), (-190, 45), (-120, 156), (-185, 185), (-120, 120), (-350, 350)],
    "gp12": [(-170, 170), (-90, 155), (-85, 150), (-200, 200), (-150, 150), (-455, 455)],
}
CASES = {"kr6": (KR6, kr6_by_hand), "gp12": (GP12, gp12_by_hand)}


@pytest.mark.parametrize("robot", ["kr6", "gp12"])
def test_urdf_flange_pose_equals_the_hand_product(robot: str) -> None:
    path, by_hand = CASES[robot]
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    fid = model.getFrameId("flange")
    urdf = yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False,
                              load_collision_meshes=False)
    lo, hi = np.array(LIMITS_DEG[robot], dtype=float).T
    rng = np.random.default_rng(11)
    samples = [np.zeros(6), *(rng.uniform(lo, hi) for _ in range(50))]
    for q_deg in samples:
        expected = by_hand(q_deg)
        q = np.radians(q_deg)
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(data.oMf[fid].homogeneous, expected, atol=1e-12, rtol=0)
        urdf.update_cfg(q)
        np.testing.assert_allclose(urdf.get_transform("flange", "base_link"), expected, atol=1e-12, rtol=0)


def test_the_hand_product_is_not_trivially_satisfied() -> None:
    """Flipping any one KUKA axis direction, or moving any figure by 1 mm, changes the pose:
    the comparison above would fail for a URDF with that mistake."""
    q = np.array([23.0, -71.0, 64.0, 37.0, 52.0, -48.0])
    reference = kr6_by_hand(q)
    for i in range(6):
        flipped = q.copy()
        flipped[i] = -flipped[i]
        assert np.abs(kr6_by_hand(flipped) - reference).max() > 1e-3
    assert np.abs((Tr(x_mm=1.0) @ reference) - reference).max() == pytest.approx(1e-3)


def test_kr6_home_upper_arm_vertical_forearm_and_flange_forward() -> None:
    """KUKA HOME {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}, checked on the URDF's links."""
    urdf = yourdfpy.URDF.load(str(KR6), load_meshes=False, build_collision_scene_graph=False,
                              load_collision_meshes=False)
    urdf.update_cfg(np.radians([0.0, -90.0, 90.0, 0.0, 0.0, 0.0]))

    def p(link: str) -> np.ndarray:
        return urdf.get_transform(link, "base_link")[:3, 3] * 1000.0

    np.testing.assert_allclose(p("link_3") - p("link_2"), [0.0, 0.0, 455.0], atol=1e-9)  # upper arm up
    np.testing.assert_allclose(p("link_5") - p("link_4"), [420.0, 0.0, 0.0], atol=1e-9)  # forearm forward
    np.testing.assert_allclose(p("flange") - p("link_5"), [80.0, 0.0, 0.0], atol=1e-9)
    T = urdf.get_transform("flange", "base_link")
    np.testing.assert_allclose(T[:3, 2], [1.0, 0.0, 0.0], atol=1e-12)  # flange looks forward


def _flange(path: Path, q_deg) -> np.ndarray:
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.radians(np.asarray(q_deg, dtype=float)))
    return data.oMf[model.getFrameId("flange")].homogeneous


def test_kr6_rotation_directions_in_words() -> None:
    """Each KUKA axis turned positive from HOME moves the arm the way KUKA defines it."""
    home = np.array([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])

    def flange(delta) -> np.ndarray:
        return _flange(KR6, home + np.asarray(delta, dtype=float))

    h = flange([0] * 6)
    # A1 +10: clockwise seen from above, the flange (in front, on +X) swings to the right (-Y)
    assert flange([10, 0, 0, 0, 0, 0])[1, 3] < -0.05
    # A2 +10: the upper arm leans forward, everything goes forward and down
    d = flange([0, 10, 0, 0, 0, 0])[:3, 3] - h[:3, 3]
    assert d[0] > 0.05 and d[2] < -0.01
    # A3 +10: the forearm tips down: the flange goes down, its Z axis points below horizontal
    t = flange([0, 0, 10, 0, 0, 0])
    assert t[2, 3] < h[2, 3] - 0.05 and t[2, 2] < -0.1
    # A5 +10: the flange tilts down about the wrist centre
    assert flange([0, 0, 0, 0, 10, 0])[2, 2] == pytest.approx(-math.sin(math.radians(10.0)))
    # A4 +90 with the wrist bent down (A5 +30): the flange swings to the robot's right (-Y)
    assert flange([0, 0, 0, 90, 30, 0])[1, 2] == pytest.approx(-math.sin(math.radians(30.0)))
    # A6 +90: flange X (up at HOME) turns to the robot's left (+Y): clockwise seen from the front
    np.testing.assert_allclose(flange([0, 0, 0, 0, 0, 90])[:3, 0], [0.0, 1.0, 0.0], atol=1e-12)


def test_gp12_rotation_directions_in_words() -> None:
    zero = _flange(GP12, [0] * 6)
    assert _flange(GP12, [10, 0, 0, 0, 0, 0])[1, 3] > 0.05  # S+: counter-clockwise from above
    assert _flange(GP12, [0, 10, 0, 0, 0, 0])[0, 3] > zero[0, 3] + 0.05  # L+: leans forward
    assert _flange(GP12, [0, 0, 10, 0, 0, 0])[2, 3] > zero[2, 3] + 0.05  # U+: forearm up
    assert _flange(GP12, [0, 0, 0, 0, 10, 0])[2, 2] == pytest.approx(math.sin(math.radians(10.0)))  # B+: up
    np.testing.assert_allclose(_flange(GP12, [0, 0, 0, 0, 0, 90])[:3, 0], [0.0, 1.0, 0.0], atol=1e-12)
