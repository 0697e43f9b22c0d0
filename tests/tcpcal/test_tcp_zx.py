"""ABB TCP & Z, X (methods.md section 8): the solver against independent computations."""

from __future__ import annotations

import numpy as np
import pytest
from support.poses import tilted_rotations
from scipy.optimize import minimize
from scipy.spatial.transform import Rotation

from tcpcal import InvalidInputError, solve_three_point, solve_tcp_zx, solve_xyz4

T_TRUE = np.array([12.0, -8.0, 180.0])
R_TRUE = Rotation.from_euler("ZYX", [20.0, -35.0, 10.0], degrees=True).as_matrix()
REF = np.array([900.0, -150.0, 350.0])


def make_rows(rng: np.random.Generator, *, n_touch: int = 6, z_d: tuple[float, ...] = (60.0,),
              x_d: tuple[float, ...] = (50.0,), sigma: float = 0.0,
              tcp: np.ndarray = T_TRUE, rot_tool: np.ndarray = R_TRUE,
              ) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Flange poses from the forward model: touches (4P-1), z rows (ZX-1), x rows (ZX-2)."""
    rots, pos, roles = [], [], []
    R = tilted_rotations(rng, n_touch + len(z_d) + len(x_d))
    for i in range(n_touch):
        rots.append(R[i])
        pos.append(REF - R[i] @ tcp + rng.normal(0.0, sigma, 3) if sigma else REF - R[i] @ tcp)
        roles.append("touch")
    k = n_touch
    for role, dists, col in (("z", z_d, 2), ("x", x_d, 0)):
        for d in dists:
            point = tcp + d * rot_tool[:, col]   # the reference in FLANGE coordinates
            noise = rng.normal(0.0, sigma, 3) if sigma else 0.0
            rots.append(R[k])
            pos.append(REF - R[k] @ point + noise)
            roles.append(role)
            k += 1
    return np.array(rots), np.array(pos), roles


def test_noise_free_rows_give_the_true_tcp_and_tool_frame() -> None:
    rng = np.random.default_rng(1)
    rots, pos, roles = make_rows(rng, z_d=(60.0, 120.0), x_d=(40.0, 90.0))
    res = solve_tcp_zx(rots, pos, roles)
    np.testing.assert_allclose(res.tcp, T_TRUE, atol=1e-9)
    np.testing.assert_allclose(res.reference, REF, atol=1e-9)
    np.testing.assert_allclose(res.rotation, R_TRUE, atol=1e-12)
    np.testing.assert_allclose(res.z_distances, (60.0, 120.0), atol=1e-9)
    np.testing.assert_allclose(res.x_distances, (40.0, 90.0), atol=1e-9)
    assert res.orthogonality_defect_deg == pytest.approx(0.0, abs=1e-9)
    assert res.touch_rows == (0, 1, 2, 3, 4, 5) and res.z_rows == (6, 7) and res.x_rows == (8, 9)
    np.testing.assert_allclose(res.kuka_abc_deg, [20.0, -35.0, 10.0], atol=1e-9)
    assert res.warnings == ()
    assert res.method == "tcp-zx"


def test_the_tcp_is_the_4_point_result_of_the_touch_rows_alone() -> None:
    rng = np.random.default_rng(2)
    rots, pos, roles = make_rows(rng, sigma=0.1)
    res = solve_tcp_zx(rots, pos, roles)
    ref = solve_xyz4(rots[:6], pos[:6])
    np.testing.assert_array_equal(res.tcp, ref.tcp)
    assert res.origin.ci95_radius == ref.ci95_radius


def test_one_z_and_one_x_row_match_the_three_point_method_with_renamed_axes() -> None:
    """methods.md section 8: with one row per axis (ZX-3) is eq. (8-17) with c1 -> -z, and
    the +X row plays the three-point +Y row (variant 1); Z kept there means c1 kept there."""
    rng = np.random.default_rng(3)
    rot_tool = Rotation.from_euler("ZYX", [-60.0, 15.0, 100.0], degrees=True).as_matrix()
    rots, pos, roles = make_rows(rng, tcp=T_TRUE, rot_tool=rot_tool, z_d=(70.0,), x_d=(55.0,))
    # perturb the x row off the tool X axis a little, so both orthogonalise
    pos[-1] = pos[-1] + rots[-1] @ (3.0 * rot_tool[:, 2])
    res = solve_tcp_zx(rots, pos, roles)
    tp = solve_three_point(rots[[0, 6, 7]], pos[[0, 6, 7]], res.tcp, variant=1)
    c1, c2, c3 = tp.rotation.T
    np.testing.assert_allclose(res.rotation[:, 2], -c1, atol=1e-12)      # z = -c1
    np.testing.assert_allclose(res.rotation[:, 0], c2, atol=1e-12)       # x = c2
    np.testing.assert_allclose(res.rotation[:, 1], -c3, atol=1e-12)      # y = z x x = -c1 x c2
    assert res.orthogonality_defect_deg == pytest.approx(tp.orthogonality_defect_deg, abs=1e-9)
    assert res.orthogonality_defect_deg > 1.0
    assert any("from perpendicular" in w for w in res.warnings)


def test_several_z_rows_give_the_maximum_likelihood_direction() -> None:
    """(ZX-3) against a direct numerical minimisation of sum |v_k - (v_k . z) z|^2."""
    rng = np.random.default_rng(4)
    rots, pos, roles = make_rows(rng, z_d=(30.0, 80.0, 150.0), x_d=(60.0,), sigma=0.3)
    res = solve_tcp_zx(rots, pos, roles)
    t, r = res.tcp, res.reference
    v = np.array([rots[k].T @ (r - pos[k]) - t for k in res.z_rows])

    def cost(p: np.ndarray) -> float:
        z = p / np.linalg.norm(p)
        return float(np.sum((v - np.outer(v @ z, z)) ** 2))

    best = minimize(cost, v[-1], method="Nelder-Mead", options={"xatol": 1e-12, "fatol": 1e-14,
                                                              "maxiter": 20000})
    z_num = best.x / np.linalg.norm(best.x)
    np.testing.assert_allclose(res.rotation[:, 2], z_num, atol=1e-6)
    np.testing.assert_allclose(res.z_distances, v @ z_num, atol=1e-4)


def test_the_angular_error_shrinks_with_the_distance() -> None:
    """Angular error of Z ~ sigma / d: ten times the distance, about a tenth of the error."""
    def mean_error(d: float) -> float:
        rng = np.random.default_rng(5)
        errs = []
        for _ in range(200):
            rots, pos, roles = make_rows(rng, z_d=(d,), x_d=(d,), sigma=0.1, n_touch=8)
            res = solve_tcp_zx(rots, pos, roles, detect_outliers=False)
            errs.append(np.degrees(np.arccos(np.clip(res.rotation[:, 2] @ R_TRUE[:, 2], -1, 1))))
        return float(np.mean(errs))

    near, far = mean_error(20.0), mean_error(200.0)
    assert far < 0.25 * near


def test_roles_are_case_insensitive() -> None:
    rng = np.random.default_rng(6)
    rots, pos, roles = make_rows(rng)
    res = solve_tcp_zx(rots, pos, [" Touch", "TOUCH", "touch", "touch", "touch", "touch", "Z ", "X"])
    np.testing.assert_allclose(res.rotation, R_TRUE, atol=1e-12)
    assert roles[-2:] == ["z", "x"]


@pytest.mark.parametrize(("n_touch", "z_d", "x_d", "needle"), [
    (3, (60.0,), (50.0,), "at least 4 touch rows"),
    (5, (), (50.0,), "at least one z row"),
    (5, (60.0,), (), "at least one x row"),
])
def test_missing_rows_are_named(n_touch: int, z_d: tuple[float, ...], x_d: tuple[float, ...],
                                needle: str) -> None:
    rots, pos, roles = make_rows(np.random.default_rng(7), n_touch=n_touch, z_d=z_d, x_d=x_d)
    with pytest.raises(InvalidInputError, match=needle):
        solve_tcp_zx(rots, pos, roles)


def test_a_z_row_behind_the_tcp_is_an_error_naming_the_row() -> None:
    rots, pos, roles = make_rows(np.random.default_rng(8), z_d=(80.0, 120.0, -40.0))
    with pytest.raises(InvalidInputError, match=r"z row 9: the reference point lies behind the "
                       r"TCP .*moved the wrong way") as info:
        solve_tcp_zx(rots, pos, roles)
    assert info.value.index == 8


def test_an_x_row_behind_the_tcp_is_an_error() -> None:
    rots, pos, roles = make_rows(np.random.default_rng(9), x_d=(-30.0, 70.0))
    with pytest.raises(InvalidInputError, match=r"x row 8: .*behind the TCP"):
        solve_tcp_zx(rots, pos, roles)


def test_a_single_z_row_behind_the_tcp_gives_a_warning() -> None:
    """With one z row the sign cannot be checked against others; a tool Z pointing back at the
    flange (against the TCP direction) is what a reversed move gives for a straight tool."""
    rot_tool = Rotation.align_vectors([T_TRUE / np.linalg.norm(T_TRUE)], [[0, 0, 1.0]])[0]
    rots, pos, roles = make_rows(np.random.default_rng(10), rot_tool=rot_tool.as_matrix(),
                                 z_d=(-60.0,))
    res = solve_tcp_zx(rots, pos, roles)
    assert any("behind the TCP" in w for w in res.warnings)
    ok = solve_tcp_zx(*make_rows(np.random.default_rng(10), rot_tool=rot_tool.as_matrix()))
    assert not any("behind the TCP" in w for w in ok.warnings)


def test_a_z_row_on_the_tcp_is_an_error() -> None:
    rots, pos, roles = make_rows(np.random.default_rng(11), z_d=(0.0,))
    with pytest.raises(InvalidInputError, match=r"z row 7: the reference point is only"):
        solve_tcp_zx(rots, pos, roles)


def test_x_parallel_to_z_is_an_error() -> None:
    rng = np.random.default_rng(12)
    rots, pos, roles = make_rows(rng)
    # x row on the Z axis (5 deg off): the x pose repeats the z one
    tilt = Rotation.from_rotvec(np.radians(5.0) * R_TRUE[:, 0]).as_matrix()
    point = T_TRUE + 50.0 * tilt @ R_TRUE[:, 2]
    pos[-1] = REF - rots[-1] @ point
    with pytest.raises(InvalidInputError, match=r"measured tool X is 5\.0 deg from the tool Z"):
        solve_tcp_zx(rots, pos, roles)


def test_bad_roles_and_counts() -> None:
    rots, pos, roles = make_rows(np.random.default_rng(13))
    with pytest.raises(InvalidInputError, match="role 'y' is not one of touch, z, x") as info:
        solve_tcp_zx(rots, pos, roles[:-1] + ["y"])
    assert info.value.index == 7
    with pytest.raises(InvalidInputError, match="7 roles for 8 poses"):
        solve_tcp_zx(rots, pos, roles[:-1])


def test_short_distances_warn() -> None:
    rots, pos, roles = make_rows(np.random.default_rng(14), z_d=(10.0,))
    res = solve_tcp_zx(rots, pos, roles)
    assert any(w.startswith("z row 7: the reference is only 10.0") for w in res.warnings)


def test_a_nan_row_is_named_by_its_input_row() -> None:
    rng = np.random.default_rng(15)
    rots, pos, roles = make_rows(rng)
    rots2 = np.concatenate([rots[6:], rots[:6]])
    pos2 = np.concatenate([pos[6:], pos[:6]])
    pos2[5] = np.nan
    with pytest.raises(InvalidInputError) as info:
        solve_tcp_zx(rots2, pos2, roles[6:] + roles[:6])
    assert info.value.index == 5
