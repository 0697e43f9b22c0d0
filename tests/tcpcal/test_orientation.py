"""Orientation methods (methods.md sections 4-5) against poses built independently here.

Every flange pose is built from the *true* tool (R_true, t_true) and the reference tip r by the
forward model: choose R_world_tool, then R_world_flange = R_world_tool R_true^T and
f = r - R_world_flange (t_true + R_true tip_tool), so that the reference tip sits at
``tip_tool`` in TOOL coordinates. The solvers never see R_true.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tcpcal.errors import DegenerateTouchesError, InvalidInputError
from tcpcal.orientation import (
    solve_abc_world,
    solve_three_point,
    solve_three_point_lstsq,
)

PA1 = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
R_REF = np.array([812.0, -140.0, 355.0])  # reference tip in WORLD, mm


def rand_rot(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    return Rotation.from_quat(q / np.linalg.norm(q)).as_matrix()


def flange_pose(
    R_true: np.ndarray, t_true: np.ndarray, tip_tool, R_world_tool: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Flange pose putting the reference tip at ``tip_tool`` (TOOL coordinates)."""
    R_world_flange = R_world_tool @ R_true.T
    f = R_REF - R_world_flange @ (t_true + R_true @ np.asarray(tip_tool, dtype=float))
    return R_world_flange, f


def make_poses(rng, R_true, t_true, tips):
    poses = [flange_pose(R_true, t_true, tip, rand_rot(rng)) for tip in tips]
    return np.array([p[0] for p in poses]), np.array([p[1] for p in poses])


def random_tool(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    direction = rng.normal(size=3)
    t = direction / np.linalg.norm(direction) * rng.uniform(10.0, 500.0)
    return rand_rot(rng), t


def angle_deg(a, b) -> float:
    a, b = np.asarray(a), np.asarray(b)
    return math.degrees(math.atan2(np.linalg.norm(np.cross(a, b)), np.dot(a, b)))


seeds = st.integers(min_value=0, max_value=2**32 - 1)


# --------------------------------------------------------------------------- ABC world
@settings(max_examples=60, deadline=None)
@given(seeds)
def test_abc_world_6d_recovers_the_tool_exactly(seed):
    rng = np.random.default_rng(seed)
    R_true = rand_rot(rng)
    R_world_flange = PA1 @ R_true.T  # operator aligned tool X down, Y along Y, Z along X
    res = solve_abc_world(R_world_flange)
    assert res.method == "abc-world-6d"
    np.testing.assert_allclose(res.rotation, R_true, atol=1e-9)
    # property: the tool X then points along WORLD -Z
    np.testing.assert_allclose(R_world_flange @ res.rotation[:, 0], [0, 0, -1], atol=1e-12)
    assert np.linalg.det(res.rotation) == pytest.approx(1.0, abs=1e-12)
    assert res.displacements == () and res.orthogonality_defect_deg == 0.0


@settings(max_examples=60, deadline=None)
@given(seeds, st.floats(-180.0, 180.0))
def test_abc_world_5d_recovers_tool_x_exactly_whatever_the_spin(seed, spin_deg):
    rng = np.random.default_rng(seed)
    R_true = rand_rot(rng)
    # only X is aligned: the tool may be spun by any angle about its own X axis
    spin = Rotation.from_euler("x", spin_deg, degrees=True).as_matrix()
    R_world_flange = PA1 @ spin @ R_true.T
    res = solve_abc_world(R_world_flange, variant="5d")
    R = res.rotation
    np.testing.assert_allclose(R[:, 0], R_true[:, 0], atol=1e-9)
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-12)
    # documented choice: Y is flange Y projected normal to X (in the plane of X and e_y,
    # on e_y's side), unless flange Y is nearly parallel to X
    e_y = np.array([0.0, 1.0, 0.0])
    if np.linalg.norm(np.cross(R_true[:, 0], e_y)) > 1e-2:
        assert abs(np.dot(np.cross(R[:, 0], e_y), R[:, 1])) < 1e-9
        assert np.dot(R[:, 1], e_y) > 0
    # with the true rotation as current one, its Y is kept, so the whole tool comes back
    res_cur = solve_abc_world(R_world_flange, variant="5d", current_rotation=R_true)
    np.testing.assert_allclose(res_cur.rotation, R_true, atol=1e-9)
    assert any("5D" in w for w in res_cur.warnings)


def test_abc_world_5d_falls_back_when_current_y_is_parallel_to_new_x():
    # true tool X = flange Y; the "current" tool has its Y along flange Y as well
    R_true = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])  # cols X=e_y, Y=e_z
    res = solve_abc_world(PA1 @ R_true.T, variant="5d", current_rotation=np.eye(3))
    np.testing.assert_allclose(res.rotation[:, 0], [0.0, 1.0, 0.0], atol=1e-12)
    # flange Y is parallel to X too, so the flange Z axis is used: Y = e_z, Z = X x Y = e_x
    np.testing.assert_allclose(res.rotation[:, 1], [0.0, 0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(res.rotation[:, 2], [1.0, 0.0, 0.0], atol=1e-12)
    assert any("parallel" in w for w in res.warnings)
    assert any("flange Z axis" in w for w in res.warnings)


def test_abc_world_kuka_abc_of_a_known_tool():
    # tool pointing along flange Z (X = e_z): KUKA writes this as A=0, B=-90, C=0
    R_true = Rotation.from_euler("ZYX", [0.0, -90.0, 0.0], degrees=True).as_matrix()
    np.testing.assert_allclose(R_true[:, 0], [0, 0, 1], atol=1e-15)
    res = solve_abc_world(PA1 @ R_true.T)
    np.testing.assert_allclose(res.kuka_abc_deg, [0.0, -90.0, 0.0], atol=1e-9)
    A, B, C = 30.0, 20.0, -40.0
    R2 = Rotation.from_euler("ZYX", [A, B, C], degrees=True).as_matrix()
    np.testing.assert_allclose(solve_abc_world(PA1 @ R2.T).kuka_abc_deg, [A, B, C], atol=1e-9)


def test_abc_world_rejects_bad_input():
    with pytest.raises(InvalidInputError, match="not orthonormal"):
        solve_abc_world(np.eye(3) * 1.01)
    with pytest.raises(InvalidInputError, match="reflection"):
        solve_abc_world(np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(InvalidInputError, match="NaN"):
        solve_abc_world(np.full((3, 3), np.nan))
    with pytest.raises(InvalidInputError, match="variant"):
        solve_abc_world(np.eye(3), variant="4d")
    with pytest.raises(InvalidInputError, match="5D"):
        solve_abc_world(np.eye(3), current_rotation=np.eye(3))


# --------------------------------------------------------------------------- three-point
@settings(max_examples=80, deadline=None)
@given(seeds, st.floats(25.0, 300.0), st.floats(25.0, 300.0))
def test_three_point_variant_1_exact(seed, d1, d2):
    rng = np.random.default_rng(seed)
    R_true, t_true = random_tool(rng)
    R, f = make_poses(rng, R_true, t_true, [(0, 0, 0), (-d1, 0, 0), (0, d2, 0)])
    res = solve_three_point(R, f, t_true, variant=1)
    assert res.method == "three-point-1"
    np.testing.assert_allclose(res.rotation, R_true, atol=1e-9)
    assert res.displacements == pytest.approx((d1, d2), abs=1e-9)
    assert res.orthogonality_defect_deg < 1e-9


@settings(max_examples=80, deadline=None)
@given(seeds, st.floats(25.0, 300.0), st.floats(-200.0, 200.0), st.floats(25.0, 300.0))
def test_three_point_variant_2_exact(seed, d1, d3, d4):
    rng = np.random.default_rng(seed)
    R_true, t_true = random_tool(rng)
    R, f = make_poses(rng, R_true, t_true, [(0, 0, 0), (-d1, 0, 0), (d3, d4, 0)])
    res = solve_three_point(R, f, t_true, variant=2)
    np.testing.assert_allclose(res.rotation, R_true, atol=1e-9)
    assert res.displacements == pytest.approx((d1, d4), abs=1e-9)
    assert res.orthogonality_defect_deg == 0.0


@settings(max_examples=60, deadline=None)
@given(seeds, st.integers(1, 4), st.integers(1, 4))
def test_three_point_lstsq_exact(seed, n_minus_x, n_plus_y):
    rng = np.random.default_rng(seed)
    R_true, t_true = random_tool(rng)
    tips = [(-rng.uniform(20, 250), 0, 0) for _ in range(n_minus_x)]
    tips += [(rng.uniform(-150, 150), rng.uniform(20, 250), 0) for _ in range(n_plus_y)]
    roles = ["minus_x"] * n_minus_x + ["plus_y"] * n_plus_y
    # put the touch somewhere in the middle: the order of the rows must not matter
    k = int(rng.integers(0, len(tips) + 1))
    tips.insert(k, (0, 0, 0))
    roles.insert(k, "touch")
    R, f = make_poses(rng, R_true, t_true, tips)
    res = solve_three_point_lstsq(R, f, t_true, roles)
    assert res.method == "three-point-lstsq"
    np.testing.assert_allclose(res.rotation, R_true, atol=1e-9)
    expected = [abs(tip[0]) if role == "minus_x" else tip[1]
                for tip, role in zip(tips, roles) if role != "touch"]
    assert res.displacements == pytest.approx(expected, abs=1e-9)
    assert res.orthogonality_defect_deg < 1e-7


def test_lstsq_with_one_point_each_equals_variant_2():
    rng = np.random.default_rng(7)
    R_true, t_true = random_tool(rng)
    R, f = make_poses(rng, R_true, t_true, [(0, 0, 0), (-90, 0, 0), (30, 70, 0)])
    f = f + rng.normal(scale=0.3, size=f.shape)  # noisy: both must agree anyway
    a = solve_three_point(R, f, t_true, variant=2)
    b = solve_three_point_lstsq(R, f, t_true, ["touch", "minus_x", "plus_y"])
    np.testing.assert_allclose(b.rotation, a.rotation, atol=1e-12)


def test_noisy_variant_1_small_positive_defect_and_c1_kept():
    rng = np.random.default_rng(11)
    sigma = 0.2  # mm, per axis, on the flange positions
    defects = []
    for _ in range(50):
        R_true, t_true = random_tool(rng)
        R, f = make_poses(rng, R_true, t_true, [(0, 0, 0), (-100, 0, 0), (0, 100, 0)])
        f = f + rng.normal(scale=sigma, size=f.shape)
        res = solve_three_point(R, f, t_true, variant=1)
        defects.append(res.orthogonality_defect_deg)
        # independent recomputation of the measured tool X (8-17) and of the raw c2 (18-24)
        r = R[0] @ t_true + f[0]
        v1 = R[1].T @ (r - f[1])
        v2 = R[2].T @ (r - f[2])
        c1 = -(v1 - t_true) / np.linalg.norm(v1 - t_true)
        c2 = (v2 - t_true) / np.linalg.norm(v2 - t_true)
        np.testing.assert_allclose(res.rotation[:, 0], c1, atol=1e-12)  # Gram-Schmidt keeps c1
        assert res.orthogonality_defect_deg == pytest.approx(abs(90 - angle_deg(c1, c2)), abs=1e-9)
        np.testing.assert_allclose(res.rotation.T @ res.rotation, np.eye(3), atol=1e-12)
        assert np.linalg.det(res.rotation) == pytest.approx(1.0, abs=1e-12)
        # the orientation is still close: noise ~0.2 mm over 100 mm levers is ~0.1-0.5 deg
        err = Rotation.from_matrix(res.rotation @ R_true.T).magnitude()
        assert math.degrees(err) < 1.5
    defects = np.array(defects)
    assert np.all(defects > 0.0)
    assert 0.01 < np.median(defects) < 1.0


def test_defect_of_an_off_axis_y_point_is_its_angle():
    rng = np.random.default_rng(3)
    R_true, t_true = random_tool(rng)
    # the "+Y" tip was actually placed 10 mm along X: c2 is tilted by atan(10/60)
    R, f = make_poses(rng, R_true, t_true, [(0, 0, 0), (-80, 0, 0), (10, 60, 0)])
    res = solve_three_point(R, f, t_true, variant=1)
    assert res.orthogonality_defect_deg == pytest.approx(math.degrees(math.atan2(10, 60)), abs=1e-9)
    assert any("orthogonality defect" in w for w in res.warnings)
    # Gram-Schmidt keeping c1 still gives the true frame here (the error lies along X only)
    np.testing.assert_allclose(res.rotation, R_true, atol=1e-9)
    # variant 2 accepts the point as a half-plane point without any defect
    res2 = solve_three_point(R, f, t_true, variant=2)
    assert res2.orthogonality_defect_deg == 0.0
    assert not any("orthogonality defect" in w for w in res2.warnings)


def test_short_displacements_warn_and_long_ones_do_not():
    rng = np.random.default_rng(5)
    R_true = np.eye(3)
    t_true = np.array([0.0, 0.0, 150.0])  # tool X = flange X; t . c1 = 0: no direction warning
    R, f = make_poses(rng, R_true, t_true, [(0, 0, 0), (-12, 0, 0), (0, 60, 0)])
    res = solve_three_point(R, f, t_true, variant=1)
    assert res.displacements == pytest.approx((12.0, 60.0), abs=1e-9)
    short = [w for w in res.warnings if "shorter than 20" in w]
    assert len(short) == 1 and "touch 1" in short[0] and "12" in short[0]
    R, f = make_poses(rng, R_true, t_true, [(0, 0, 0), (-50, 0, 0), (0, 60, 0)])
    assert solve_three_point(R, f, t_true, variant=1).warnings == ()
    # the threshold follows the length unit the caller uses
    res_m = solve_three_point(R, f, t_true, variant=1, min_displacement=100.0)
    assert len([w for w in res_m.warnings if "shorter than 100" in w]) == 2


def test_tool_x_pointing_back_to_the_flange_is_flagged():
    rng = np.random.default_rng(9)
    R_true = np.eye(3)
    t_true = np.array([150.0, 0.0, 0.0])
    # operator placed the tip on +X instead of -X: the solver then finds X = -e_x
    R, f = make_poses(rng, R_true, t_true, [(0, 0, 0), (60, 0, 0), (0, 60, 0)])
    res = solve_three_point(R, f, t_true, variant=1)
    np.testing.assert_allclose(res.rotation[:, 0], [-1, 0, 0], atol=1e-9)
    assert any("Delta1 > 0" in w for w in res.warnings)


def test_lstsq_flags_a_minus_x_point_on_the_wrong_side():
    rng = np.random.default_rng(12)
    R_true, t_true = random_tool(rng)
    tips = [(0, 0, 0), (-120, 0, 0), (-80, 0, 0), (40, 0, 0), (0, 90, 0)]
    R, f = make_poses(rng, R_true, t_true, tips)
    roles = ["touch", "minus_x", "minus_x", "minus_x", "plus_y"]
    res = solve_three_point_lstsq(R, f, t_true, roles)
    np.testing.assert_allclose(res.rotation, R_true, atol=1e-9)  # the line is still right
    assert any("touch 3" in w and "Delta1 not negative" in w for w in res.warnings)


def test_lstsq_several_points_beat_one_point():
    """Least squares over 4 -X points at the same lever halves the angular error of X."""
    rng = np.random.default_rng(21)
    sigma = 0.5
    err_one, err_four = [], []
    for _ in range(300):
        R_true, t_true = random_tool(rng)
        tips = [(0, 0, 0)] + [(-100, 0, 0)] * 4 + [(0, 100, 0)]
        R, f = make_poses(rng, R_true, t_true, tips)
        f[1:] += rng.normal(scale=sigma, size=f[1:].shape)  # the touch row stays exact
        four = solve_three_point_lstsq(R, f, t_true, ["touch"] + ["minus_x"] * 4 + ["plus_y"])
        one = solve_three_point(R[[0, 1, 5]], f[[0, 1, 5]], t_true, variant=2)
        err_four.append(angle_deg(four.rotation[:, 0], R_true[:, 0]))
        err_one.append(angle_deg(one.rotation[:, 0], R_true[:, 0]))
    ratio = np.sqrt(np.mean(np.square(err_four)) / np.mean(np.square(err_one)))
    assert 0.35 < ratio < 0.7  # ideal 1/sqrt(4) = 0.5


def test_lstsq_defect_measures_x_out_of_the_y_plane():
    rng = np.random.default_rng(4)
    R_true, t_true = random_tool(rng)
    tips = [(0, 0, 0), (-100, 0, 0), (0, 80, 0), (60, 80, 0)]
    R, f = make_poses(rng, R_true, t_true, tips)
    # corrupt the -X measurement: tip 5 mm off the X axis along tool Z
    R_bad, f_bad = flange_pose(R_true, t_true, (-100, 0, 5), rand_rot(rng))
    R[1], f[1] = R_bad, f_bad
    res = solve_three_point_lstsq(R, f, t_true, ["touch", "minus_x", "plus_y", "plus_y"])
    # measured X leaves the (exact) XY plane by atan(5/100)
    assert res.orthogonality_defect_deg == pytest.approx(math.degrees(math.atan2(5, 100)), abs=1e-9)


# --------------------------------------------------------------------------- errors
def _good_three(rng):
    R_true, t_true = random_tool(rng)
    R, f = make_poses(rng, R_true, t_true, [(0, 0, 0), (-80, 0, 0), (0, 80, 0)])
    return R_true, t_true, R, f


def test_three_point_tip_not_displaced():
    rng = np.random.default_rng(1)
    R_true, t_true, R, f = _good_three(rng)
    R[1], f[1] = flange_pose(R_true, t_true, (0, 0, 0), rand_rot(rng))
    with pytest.raises(DegenerateTouchesError, match="still at the TCP") as exc:
        solve_three_point(R, f, t_true, variant=1)
    assert exc.value.index == 1
    R_true, t_true, R, f = _good_three(rng)
    R[2], f[2] = flange_pose(R_true, t_true, (0, 0, 0), rand_rot(rng))
    with pytest.raises(DegenerateTouchesError) as exc:
        solve_three_point(R, f, t_true, variant=2)
    assert exc.value.index == 2


@pytest.mark.parametrize("variant", [1, 2])
def test_three_point_y_point_on_the_x_axis(variant):
    rng = np.random.default_rng(2)
    R_true, t_true, R, f = _good_three(rng)
    R[2], f[2] = flange_pose(R_true, t_true, (-50, 0, 0), rand_rot(rng))
    with pytest.raises(DegenerateTouchesError, match="X axis") as exc:
        solve_three_point(R, f, t_true, variant=variant)
    assert exc.value.index == 2
    with pytest.raises(DegenerateTouchesError, match="X axis"):
        solve_three_point_lstsq(R, f, t_true, ["touch", "minus_x", "plus_y"])


def test_three_point_input_errors():
    rng = np.random.default_rng(3)
    _, t_true, R, f = _good_three(rng)
    with pytest.raises(InvalidInputError, match="exactly 3"):
        solve_three_point(R[:2], f[:2], t_true, variant=1)
    with pytest.raises(InvalidInputError, match="variant"):
        solve_three_point(R, f, t_true, variant=3)
    f_nan = f.copy()
    f_nan[1, 0] = np.nan
    with pytest.raises(InvalidInputError, match="NaN") as exc:
        solve_three_point(R, f_nan, t_true, variant=1)
    assert exc.value.index == 1
    with pytest.raises(InvalidInputError, match="tcp"):
        solve_three_point(R, f, [1.0, 2.0], variant=1)
    R_bad = R.copy()
    R_bad[2] *= 1.1
    with pytest.raises(InvalidInputError, match="orthonormal"):
        solve_three_point(R_bad, f, t_true, variant=1)


def test_lstsq_role_errors():
    rng = np.random.default_rng(4)
    _, t_true, R, f = _good_three(rng)
    with pytest.raises(InvalidInputError, match="one role per"):
        solve_three_point_lstsq(R, f, t_true, ["touch", "minus_x"])
    with pytest.raises(InvalidInputError, match="not a role") as exc:
        solve_three_point_lstsq(R, f, t_true, ["touch", "minus_x", "plus_z"])
    assert exc.value.index == 2
    with pytest.raises(InvalidInputError, match="exactly one 'touch'"):
        solve_three_point_lstsq(R, f, t_true, ["touch", "touch", "plus_y"])
    with pytest.raises(InvalidInputError, match="at least one 'minus_x'"):
        solve_three_point_lstsq(R, f, t_true, ["touch", "plus_y", "plus_y"])


def test_result_is_frozen_and_read_only():
    res = solve_abc_world(np.eye(3))
    with pytest.raises(AttributeError):
        res.method = "x"  # type: ignore[misc]
    with pytest.raises(ValueError):
        res.rotation[0, 0] = 2.0
