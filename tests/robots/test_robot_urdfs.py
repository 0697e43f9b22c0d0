"""The authored robot URDFs: loading, joint names and limits, and forward kinematics.

Expected numbers are written from the specification (robots/README.md), in mm and
degrees, never read from robots/generate.py.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy

ROBOTS = Path(__file__).resolve().parents[2] / "robots"
KR6 = ROBOTS / "kr6_r900" / "kr6_r900.urdf"
GP12 = ROBOTS / "gp12" / "gp12.urdf"
DEG = np.pi / 180.0

# Specification (mm / deg).
KR6_LIMITS_DEG = {
    "A1": (-170, 170), "A2": (-190, 45), "A3": (-120, 156),
    "A4": (-185, 185), "A5": (-120, 120), "A6": (-350, 350),
}
GP12_LIMITS_DEG = {
    "S": (-170, 170), "L": (-90, 155), "U": (-85, 150),
    "R": (-200, 200), "B": (-150, 150), "T": (-455, 455),
}
KR6_HOME_DEG = np.array([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])


def _load_yourdfpy(path: Path) -> yourdfpy.URDF:
    return yourdfpy.URDF.load(str(path))


def _fk_yourdfpy(urdf: yourdfpy.URDF, q_rad: np.ndarray, link: str = "flange") -> np.ndarray:
    urdf.update_cfg(q_rad)
    return urdf.get_transform(link, "base_link")


def _fk_pinocchio(path: Path, q_rad: np.ndarray, link: str = "flange") -> np.ndarray:
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.asarray(q_rad, float))
    return data.oMf[model.getFrameId(link)].homogeneous


@pytest.fixture(scope="module")
def kr6() -> yourdfpy.URDF:
    return _load_yourdfpy(KR6)


@pytest.fixture(scope="module")
def gp12() -> yourdfpy.URDF:
    return _load_yourdfpy(GP12)


@pytest.mark.parametrize("path", [KR6, GP12], ids=["kr6", "gp12"])
def test_meshes_load_from_any_working_directory(
    path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Relative mesh paths resolve against the URDF file, not the working directory."""
    monkeypatch.chdir(tmp_path)
    urdf = yourdfpy.URDF.load(str(path))
    n_visuals = sum(len(link.visuals) for link in urdf.robot.links)
    assert n_visuals >= 8
    assert len(urdf.scene.geometry) == n_visuals
    for name, geom in urdf.scene.geometry.items():
        assert len(geom.faces) > 0, name


@pytest.mark.parametrize(
    ("path", "limits"), [(KR6, KR6_LIMITS_DEG), (GP12, GP12_LIMITS_DEG)], ids=["kr6", "gp12"]
)
def test_joint_names_and_limits(path: Path, limits: dict[str, tuple[int, int]]) -> None:
    urdf = _load_yourdfpy(path)
    assert tuple(urdf.actuated_joint_names) == tuple(limits)
    for name, (lo, hi) in limits.items():
        j = urdf.joint_map[name]
        assert j.type == "revolute"
        assert j.limit.lower == pytest.approx(lo * DEG, abs=1e-12)
        assert j.limit.upper == pytest.approx(hi * DEG, abs=1e-12)
        assert j.limit.velocity > 0
    model = pin.buildModelFromUrdf(str(path))
    assert tuple(model.names[1:]) == tuple(limits)
    np.testing.assert_allclose(model.lowerPositionLimit, [lo * DEG for lo, _ in limits.values()])
    np.testing.assert_allclose(model.upperPositionLimit, [hi * DEG for _, hi in limits.values()])


@pytest.mark.parametrize("path", [KR6, GP12], ids=["kr6", "gp12"])
def test_base_and_flange_links(path: Path) -> None:
    urdf = _load_yourdfpy(path)
    assert urdf.base_link == "base_link"
    assert "flange" in urdf.link_map
    j = next(j for j in urdf.robot.joints if j.child == "flange")
    assert j.type == "fixed"


@pytest.mark.parametrize(
    ("q_deg", "expected_mm"),
    [
        # All zero: stretched forward, flange at x = 25 + 455 + 420 + 80, z = 400 + 35.
        ([0, 0, 0, 0, 0, 0], (980.0, 0.0, 435.0)),
        # HOME: upper arm vertical (z = 400 + 455 + 35), forearm forward (x = 25 + 420 + 80).
        ([0, -90, 90, 0, 0, 0], (525.0, 0.0, 890.0)),
        # HOME with A1 = +30: KUKA's A1 turns clockwise seen from above (axis points down).
        ([30, -90, 90, 0, 0, 0], (525.0 * np.cos(np.pi / 6), -525.0 * 0.5, 890.0)),
        # HOME with A5 = +90: the flange points straight down, 80 mm below the wrist centre.
        ([0, -90, 90, 0, 90, 0], (445.0, 0.0, 810.0)),
        # A2 = 0, A3 = -90: upper arm forward, forearm pointing up. A3 is at x = 25 + 455;
        # the 35 mm offset now points backwards (-x), the 420 + 80 up.
        ([0, 0, -90, 0, 0, 0], (480.0 - 35.0, 0.0, 400.0 + 500.0)),
    ],
)
def test_kr6_flange_position(kr6: yourdfpy.URDF, q_deg: list[float],
                             expected_mm: tuple[float, float, float]) -> None:
    q = np.array(q_deg, float) * DEG
    expected_m = np.array(expected_mm) / 1000.0
    np.testing.assert_allclose(_fk_yourdfpy(kr6, q)[:3, 3], expected_m, atol=1e-9)
    np.testing.assert_allclose(_fk_pinocchio(KR6, q)[:3, 3], expected_m, atol=1e-9)


def test_kr6_flange_axes_at_home(kr6: yourdfpy.URDF) -> None:
    """At HOME the flange Z (out of the face) is +WORLD X and flange X points up."""
    for T in (_fk_yourdfpy(kr6, KR6_HOME_DEG * DEG), _fk_pinocchio(KR6, KR6_HOME_DEG * DEG)):
        R = T[:3, :3]
        np.testing.assert_allclose(R[:, 2], [1, 0, 0], atol=1e-12)
        np.testing.assert_allclose(R[:, 0], [0, 0, 1], atol=1e-12)
        np.testing.assert_allclose(R[:, 1], [0, -1, 0], atol=1e-12)


def test_kr6_flange_z_points_away_from_wrist(kr6: yourdfpy.URDF) -> None:
    """For random configurations the flange Z axis runs from the wrist centre (A5 axis) to the
    flange centre, 80 mm long."""
    rng = np.random.default_rng(3)
    lo = np.array([v[0] for v in KR6_LIMITS_DEG.values()]) * DEG
    hi = np.array([v[1] for v in KR6_LIMITS_DEG.values()]) * DEG
    for _ in range(20):
        q = rng.uniform(lo, hi)
        T_flange = _fk_yourdfpy(kr6, q)
        T_wrist = _fk_yourdfpy(kr6, q, "link_5")
        d = T_flange[:3, 3] - T_wrist[:3, 3]
        assert np.linalg.norm(d) == pytest.approx(0.080, abs=1e-12)
        np.testing.assert_allclose(d / 0.080, T_flange[:3, 2], atol=1e-12)


def test_kr6_wrist_axes_directions(kr6: yourdfpy.URDF) -> None:
    """A4 and A6 positive turn the flange the same way (both axes point back along the
    forearm at HOME): +10 deg on each equals +20 deg on one."""
    home = KR6_HOME_DEG * DEG
    a = _fk_yourdfpy(kr6, home + np.array([0, 0, 0, 10, 0, 10]) * DEG)
    b = _fk_yourdfpy(kr6, home + np.array([0, 0, 0, 0, 0, 20]) * DEG)
    np.testing.assert_allclose(a, b, atol=1e-12)
    # A6 = +90 at HOME: turning about -X (right-handed), flange X (up) goes to +WORLD Y.
    T = _fk_yourdfpy(kr6, home + np.array([0, 0, 0, 0, 0, 90]) * DEG)
    np.testing.assert_allclose(T[:3, 0], [0, 1, 0], atol=1e-12)


@pytest.mark.parametrize(
    ("q_deg", "expected_mm"),
    [
        # All zero: upper arm vertical, forearm forward. x = 155 + 640 + 100,
        # z = 450 + 614 + 200.
        ([0, 0, 0, 0, 0, 0], (895.0, 0.0, 1264.0)),
        # L = +90: upper arm forward horizontal, so the forearm points down: the R axis lies
        # 200 mm forward of U, the flange 640 + 100 below it.
        ([0, 90, 0, 0, 0, 0], (155.0 + 614.0 + 200.0, 0.0, 450.0 - 740.0)),
        # U = +90: forearm points up (Yaskawa's U+ raises the forearm).
        ([0, 0, 90, 0, 0, 0], (155.0 - 200.0, 0.0, 450.0 + 614.0 + 740.0)),
        # S = +90: Yaskawa's S turns counter-clockwise seen from above.
        ([90, 0, 0, 0, 0, 0], (0.0, 895.0, 1264.0)),
    ],
)
def test_gp12_flange_position(gp12: yourdfpy.URDF, q_deg: list[float],
                              expected_mm: tuple[float, float, float]) -> None:
    q = np.array(q_deg, float) * DEG
    expected_m = np.array(expected_mm) / 1000.0
    np.testing.assert_allclose(_fk_yourdfpy(gp12, q)[:3, 3], expected_m, atol=1e-9)
    np.testing.assert_allclose(_fk_pinocchio(GP12, q)[:3, 3], expected_m, atol=1e-9)


def test_gp12_flange_axes_at_zero(gp12: yourdfpy.URDF) -> None:
    R = _fk_pinocchio(GP12, np.zeros(6))[:3, :3]
    np.testing.assert_allclose(R[:, 2], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(R[:, 0], [0, 0, 1], atol=1e-12)


def test_gp12_reach_is_1440_mm() -> None:
    """Data sheet reach: the wrist centre (B axis) at most 1440 mm (+-1) from the S axis."""
    # Stretched horizontally, B is 155 + 614 + hypot(640, 200) from the S axis.
    reach = 155.0 + 614.0 + np.hypot(640.0, 200.0)
    assert reach == pytest.approx(1440.0, abs=1.0)
    # L = 90 deg turns the arm forward; the U-to-B vector (640, 0, 200) is horizontal when the
    # total pitch 90 deg - U equals atan2(200, 640).
    q = np.array([0.0, np.pi / 2, np.pi / 2 - np.arctan2(200.0, 640.0), 0.0, 0.0, 0.0])
    T_b = _fk_pinocchio(GP12, q, "link_5")
    assert np.hypot(T_b[0, 3], T_b[1, 3]) * 1000.0 == pytest.approx(reach, abs=1e-6)
    assert T_b[2, 3] * 1000.0 == pytest.approx(450.0, abs=1e-6)


@pytest.mark.parametrize("path", [KR6, GP12], ids=["kr6", "gp12"])
def test_yourdfpy_and_pinocchio_agree(path: Path) -> None:
    urdf = _load_yourdfpy(path)
    model = pin.buildModelFromUrdf(str(path))
    rng = np.random.default_rng(7)
    for _ in range(10):
        q = rng.uniform(model.lowerPositionLimit, model.upperPositionLimit)
        np.testing.assert_allclose(_fk_yourdfpy(urdf, q), _fk_pinocchio(path, q), atol=1e-12)
