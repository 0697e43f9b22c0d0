"""TCP origin solvers (methods.md sections 2-3) against poses built from the forward model.

Expected values come from the true tool the poses were generated with, or from independent
computations here (explicit 3N x 6 matrix, scipy rotations), never from the solver's output.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from support.poses import crb_tcp, make_touches, random_rotations, stacked_a, touch_positions
from scipy.spatial.transform import Rotation

from tcpcal.errors import DegenerateTouchesError, InvalidInputError, TcpcalError
from tcpcal.origin import METHODS, TcpResult, solve_reference, solve_xyz4

TOL = 1e-9


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("seed", range(10))
def test_exact_recovery_every_method(method: str, seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 12))
    rot, pos, tcp, ref = make_touches(rng, n, tilt_deg=(25.0, 60.0))
    res = solve_xyz4(rot, pos, method=method)
    assert res.method == method
    np.testing.assert_allclose(res.tcp, tcp, atol=TOL, rtol=0)
    np.testing.assert_allclose(res.reference, ref, atol=TOL, rtol=0)
    assert res.max_error < TOL
    assert res.outliers == () and res.without_outliers is None
    assert res.n_touches == n


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(4, 50),
    length=st.floats(10.0, 500.0),
    method=st.sampled_from(METHODS),
)
def test_exact_recovery_property(seed: int, n: int, length: float, method: str) -> None:
    """Uniformly random rotations (any orientation), TCP 10-500 long, N 4-50."""
    rng = np.random.default_rng(seed)
    rot = random_rotations(rng, n)
    # Keep to sets that are well determined (the degeneracy tests cover the rest).
    a = stacked_a(rot)
    assume(np.linalg.cond(a) < 1e3)
    d = rot - rot.mean(axis=0)
    tcp = rng.standard_normal(3)
    tcp *= length / np.linalg.norm(tcp)
    ref = rng.uniform(-1000, 1000, 3)
    pos = touch_positions(rot, tcp, ref)
    if method == "sphere":
        sv = np.linalg.svd(pos - pos.mean(axis=0), compute_uv=False)
        assume(sv[-1] / sv[0] > 1e-2)
    res = solve_xyz4(rot, pos, method=method)
    np.testing.assert_allclose(res.tcp, tcp, atol=TOL, rtol=0)
    np.testing.assert_allclose(res.reference, ref, atol=TOL, rtol=0)
    del d


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), length=st.floats(10.0, 500.0))
def test_reference_method_exact(seed: int, length: float) -> None:
    rng = np.random.default_rng(seed)
    r1, r2 = random_rotations(rng, 2)
    t1 = rng.standard_normal(3)
    t1 *= rng.uniform(10, 500) / np.linalg.norm(t1)
    t2 = rng.standard_normal(3)
    t2 *= length / np.linalg.norm(t2)
    ref = rng.uniform(-1000, 1000, 3)
    f1 = ref - r1 @ t1
    f2 = ref - r2 @ t2
    res = solve_reference(t1, r1, f1, r2, f2)
    np.testing.assert_allclose(res.tcp, t2, atol=TOL, rtol=0)
    np.testing.assert_allclose(res.reference, ref, atol=TOL, rtol=0)
    assert res.method == "reference" and res.n_touches == 2
    assert math.isnan(res.ci95_radius)
    expected_angle = np.degrees((Rotation.from_matrix(r1).inv() * Rotation.from_matrix(r2)).magnitude())
    assert res.max_angle_deg == pytest.approx(expected_angle, abs=1e-7)


def test_reference_method_with_sigma() -> None:
    rng = np.random.default_rng(3)
    r1, r2 = random_rotations(rng, 2)
    t1, t2, ref = np.array([0, 0, 100.0]), np.array([5.0, 0, 200.0]), np.array([500.0, 0, 300])
    res = solve_reference(t1, r1, ref - r1 @ t1, r2, ref - r2 @ t2, sigma=0.5)
    # t2 error = R2^T (eps1 - eps2): covariance 2 sigma^2 I; radius^2 = 2 sigma^2 chi2_3(0.95)
    np.testing.assert_allclose(res.covariance, 2 * 0.25 * np.eye(3), atol=1e-15)
    assert res.ci95_radius == pytest.approx(math.sqrt(2 * 0.25 * 7.814727903251178), rel=1e-9)
    assert any("no redundancy" in w for w in res.warnings)


def test_quality_figures_match_independent_computation() -> None:
    rng = np.random.default_rng(11)
    rot, pos, _tcp, _ref = make_touches(rng, 9, sigma=0.3)
    res = solve_xyz4(rot, pos, detect_outliers=False)
    # Independent: explicit 3N x 6 least squares (4P-3).
    a = stacked_a(rot)
    b = -pos.reshape(-1)
    x, *_ = np.linalg.lstsq(a, b, rcond=None)
    np.testing.assert_allclose(res.tcp, x[:3], atol=1e-9)
    np.testing.assert_allclose(res.reference, x[3:], atol=1e-9)
    e = np.einsum("nij,j->ni", rot, x[:3]) + pos - x[3:]
    np.testing.assert_allclose(res.residual_vectors, e, atol=1e-9)
    r = np.linalg.norm(e, axis=1)
    np.testing.assert_allclose(res.residuals, r, atol=1e-9)
    assert res.mean_error == pytest.approx(r.mean(), rel=1e-9)
    assert res.max_error == pytest.approx(r.max(), rel=1e-9)
    assert res.rms_error == pytest.approx(np.sqrt(np.mean(r**2)), rel=1e-9)
    assert res.rms_error > res.mean_error  # RMS is not the mean
    s2 = (r**2).sum() / (3 * 9 - 6)
    assert res.noise_sigma == pytest.approx(math.sqrt(s2), rel=1e-9)
    np.testing.assert_allclose(res.covariance, s2 * np.linalg.inv(a.T @ a)[:3, :3], rtol=1e-8)
    assert res.condition_number == pytest.approx(np.linalg.cond(a), rel=1e-8)
    angles = [
        np.degrees((Rotation.from_matrix(rot[i]).inv() * Rotation.from_matrix(rot[j])).magnitude())
        for i, j in itertools.combinations(range(9), 2)
    ]
    assert res.max_angle_deg == pytest.approx(max(angles), abs=1e-7)
    assert res.min_angle_deg == pytest.approx(min(angles), abs=1e-7)


def test_given_sigma_replaces_estimate() -> None:
    rng = np.random.default_rng(5)
    rot, pos, *_ = make_touches(rng, 6, sigma=0.2)
    res = solve_xyz4(rot, pos, sigma=0.7)
    assert res.noise_sigma == 0.7
    np.testing.assert_allclose(res.covariance, crb_tcp(rot, 0.7), rtol=1e-8)


def test_isotropic_ci_radius_is_the_f_quantile() -> None:
    """Isotropic covariance c I with estimated s: |t_hat - t|^2 / c ~ 3 F(3, 3N - 6) exactly."""
    from scipy.stats import f as f_dist

    # Touches whose information matrix is isotropic: the 4 rotations of a tetrahedral set.
    rot = Rotation.from_euler("xyz", [[0, 0, 0], [180, 0, 0], [0, 180, 0], [0, 0, 180]], degrees=True).as_matrix()
    m = 4 * np.eye(3) - rot.sum(0).T @ rot.sum(0) / 4
    assert np.allclose(m, m[0, 0] * np.eye(3))
    rng = np.random.default_rng(0)
    pos = touch_positions(rot, np.array([1.0, 2, 100]), np.zeros(3), rng, 0.4)
    res = solve_xyz4(rot, pos)
    c = res.covariance[0, 0]
    assert res.ci95_radius == pytest.approx(math.sqrt(c * 3 * f_dist.ppf(0.95, 3, 6)), rel=1e-9)


def test_pairwise_differs_from_lstsq_with_noise() -> None:
    """Consecutive pairs are a different (less efficient) estimator than lstsq."""
    rng = np.random.default_rng(2)
    rot, pos, *_ = make_touches(rng, 8, sigma=0.5)
    a = solve_xyz4(rot, pos, method="lstsq").tcp
    b = solve_xyz4(rot, pos, method="pairwise").tcp
    assert np.linalg.norm(a - b) > 1e-6
    # Independent: consecutive-pair stack solved by lstsq here.
    dr = (rot[:-1] - rot[1:]).reshape(-1, 3)
    y = -(pos[:-1] - pos[1:]).reshape(-1)
    np.testing.assert_allclose(b, np.linalg.lstsq(dr, y, rcond=None)[0], atol=1e-9)


def test_sphere_fit_matches_independent_fit() -> None:
    rng = np.random.default_rng(4)
    rot, pos, *_ = make_touches(rng, 10, tilt_deg=(30, 70), sigma=0.3)
    res = solve_xyz4(rot, pos, method="sphere")
    h = np.c_[2 * pos, np.ones(len(pos))]
    z = np.linalg.lstsq(h, (pos**2).sum(1), rcond=None)[0]
    t = np.mean([rot[i].T @ (z[:3] - pos[i]) for i in range(10)], axis=0)
    np.testing.assert_allclose(res.tcp, t, atol=1e-8)


def test_result_is_frozen() -> None:
    rng = np.random.default_rng(1)
    rot, pos, *_ = make_touches(rng, 5)
    res = solve_xyz4(rot, pos)
    assert isinstance(res, TcpResult)
    with pytest.raises(AttributeError):
        res.tcp = np.zeros(3)  # type: ignore[misc]
    with pytest.raises(ValueError):
        res.tcp[0] = 1.0


# ---------------------------------------------------------------- degenerate and bad input


def test_rotations_about_one_axis_name_the_flange_axis() -> None:
    rng = np.random.default_rng(0)
    u_flange = np.array([1.0, 2.0, 2.0]) / 3.0
    base = Rotation.from_rotvec([0.3, -1.0, 0.5])
    rot = (base * Rotation.from_rotvec(np.radians([[0], [40], [80], [130], [200]]) * u_flange)).as_matrix()
    pos = touch_positions(rot, np.array([10.0, 0, 150]), np.array([700.0, 0, 200]), rng, 0.1)
    with pytest.raises(DegenerateTouchesError) as ei:
        solve_xyz4(rot, pos)
    err = ei.value
    assert isinstance(err, TcpcalError) and isinstance(err, ValueError)
    assert abs(abs(err.unobservable_axis @ u_flange) - 1) < 1e-9
    msg = str(err)
    assert "nearly the same axis" in msg and "flange [0.33, 0.67, 0.67]" in msg
    assert "tilt the tool about a second axis" in msg
    for m in ("sphere", "pairwise"):
        with pytest.raises(DegenerateTouchesError):
            solve_xyz4(rot, pos, method=m)


def test_flange_z_only_rotations() -> None:
    rot = Rotation.from_euler("z", [[0], [90], [180], [270]], degrees=True).as_matrix()
    pos = touch_positions(rot, np.array([0.0, 0, 100]), np.zeros(3))
    with pytest.raises(DegenerateTouchesError, match=r"flange \[0\.00, 0\.00, 1\.00\]") as ei:
        solve_xyz4(rot, pos)
    np.testing.assert_allclose(ei.value.unobservable_axis, [0, 0, 1], atol=1e-12)


def test_all_same_orientation() -> None:
    rot = np.repeat(Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix()[None], 5, axis=0)
    pos = np.random.default_rng(0).normal(size=(5, 3))
    with pytest.raises(DegenerateTouchesError, match="same orientation") as ei:
        solve_xyz4(rot, pos)
    assert ei.value.unobservable_axis is None


def test_duplicated_poses() -> None:
    """5 touches but only 3 different orientations (two recorded twice)."""
    rng = np.random.default_rng(8)
    rot, pos, *_ = make_touches(rng, 3, tilt_deg=(30, 50))
    rot = rot[[0, 1, 2, 1, 0]]
    pos = pos[[0, 1, 2, 1, 0]]
    with pytest.raises(DegenerateTouchesError, match=r"same orientation.*at least 4") as ei:
        solve_xyz4(rot, pos)
    assert ei.value.index == 3


def test_near_duplicate_is_warned_not_fatal() -> None:
    rng = np.random.default_rng(9)
    rot, pos, tcp, _ref = make_touches(rng, 5, tilt_deg=(30, 50))
    rot = np.concatenate([rot, rot[2:3]])
    pos = np.concatenate([pos, pos[2:3]])
    res = solve_xyz4(rot, pos)
    np.testing.assert_allclose(res.tcp, tcp, atol=1e-9)
    assert res.min_angle_deg < 1e-6
    assert any("touches 2 and 5" in w for w in res.warnings)


@pytest.mark.parametrize("n", [0, 1, 3])
def test_too_few_touches(n: int) -> None:
    rng = np.random.default_rng(0)
    rot, pos, *_ = make_touches(rng, max(n, 1))
    with pytest.raises(InvalidInputError, match="at least 4 touches"):
        solve_xyz4(rot[:n], pos[:n])


def test_nan_position_names_the_touch() -> None:
    rng = np.random.default_rng(0)
    rot, pos, *_ = make_touches(rng, 6)
    pos[4, 1] = np.nan
    with pytest.raises(InvalidInputError, match=r"positions\[4\].*NaN") as ei:
        solve_xyz4(rot, pos)
    assert ei.value.index == 4


def test_nan_rotation_names_the_touch() -> None:
    rng = np.random.default_rng(0)
    rot, pos, *_ = make_touches(rng, 6)
    rot[2, 0, 0] = np.inf
    with pytest.raises(InvalidInputError, match=r"rotations\[2\]") as ei:
        solve_xyz4(rot, pos)
    assert ei.value.index == 2


def test_non_orthonormal_rotation() -> None:
    rng = np.random.default_rng(0)
    rot, pos, *_ = make_touches(rng, 6)
    rot[1] *= 1.001
    with pytest.raises(InvalidInputError, match=r"rotations\[1\] is not a rotation.*orthonormal within 1e-06") as ei:
        solve_xyz4(rot, pos)
    assert ei.value.index == 1
    # within tolerance is accepted
    rot2, pos2, *_ = make_touches(np.random.default_rng(0), 6)
    rot2[1] *= 1 + 4e-7
    solve_xyz4(rot2, pos2)


def test_reflection_rejected() -> None:
    rng = np.random.default_rng(0)
    rot, pos, *_ = make_touches(rng, 6)
    rot[5][:, 2] *= -1
    with pytest.raises(InvalidInputError, match=r"rotations\[5\] is a reflection"):
        solve_xyz4(rot, pos)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"method": "ransac"}, "unknown method"),
        ({"sigma": -1.0}, "sigma must be a finite positive"),
        ({"sigma": float("nan")}, "sigma must be a finite positive"),
    ],
)
def test_bad_options(kwargs: dict, match: str) -> None:
    rng = np.random.default_rng(0)
    rot, pos, *_ = make_touches(rng, 6)
    with pytest.raises(InvalidInputError, match=match):
        solve_xyz4(rot, pos, **kwargs)


def test_shape_mismatch() -> None:
    rng = np.random.default_rng(0)
    rot, pos, *_ = make_touches(rng, 6)
    with pytest.raises(InvalidInputError, match="5 rows but there are 6 rotations"):
        solve_xyz4(rot, pos[:5])
    with pytest.raises(InvalidInputError, match=r"shape \(N, 3, 3\)"):
        solve_xyz4(rot[:, :2], pos)
    with pytest.raises(InvalidInputError, match="could not read"):
        solve_xyz4([["a"]] * 4, pos)


def test_reference_bad_input() -> None:
    r = np.eye(3)
    with pytest.raises(InvalidInputError, match="known_tcp"):
        solve_reference([1, 2], r, [0, 0, 0], r, [0, 0, 0])
    with pytest.raises(InvalidInputError, match="rotation_new is not a rotation"):
        solve_reference([1, 2, 3], r, [0, 0, 0], 2 * r, [0, 0, 0])


def test_sphere_fit_coplanar_positions() -> None:
    """Rotations about two axes whose flange positions happen to be coplanar: lstsq works,
    the sphere fit reports the coplanarity."""
    # TCP along flange Z; rotations about flange X and Y by +-a keep |z| equal -> coplanar.
    tcp = np.array([0.0, 0.0, 100.0])
    rot = Rotation.from_rotvec(np.radians([[30, 0, 0], [-30, 0, 0], [0, 30, 0], [0, -30, 0]])).as_matrix()
    pos = touch_positions(rot, tcp, np.zeros(3))
    np.testing.assert_allclose(solve_xyz4(rot, pos).tcp, tcp, atol=1e-9)
    with pytest.raises(DegenerateTouchesError, match="coplanar"):
        solve_xyz4(rot, pos, method="sphere")


def test_small_tilt_warning() -> None:
    rng = np.random.default_rng(1)
    rotvecs = np.radians([[4, 0, 0], [0, 4, 0], [-4, 0, 0], [0, -4, 0], [0, 0, 4]])
    rot = Rotation.from_rotvec(rotvecs).as_matrix()
    pos = touch_positions(rot, np.array([0, 0, 120.0]), np.zeros(3), rng, 0.1)
    res = solve_xyz4(rot, pos)
    assert res.max_angle_deg < 10
    assert any("differ by at most" in w for w in res.warnings)


def test_weak_axis_warning() -> None:
    """Large tilts about flange X, only 2 deg about flange Y: TCP poorly determined along ..."""
    rng = np.random.default_rng(1)
    rotvecs = np.radians([[40, 0, 0], [-40, 0, 0], [0, 0, 0], [0, 2, 0], [20, -2, 0]])
    rot = Rotation.from_rotvec(rotvecs).as_matrix()
    pos = touch_positions(rot, np.array([0, 0, 120.0]), np.zeros(3), rng, 0.1)
    res = solve_xyz4(rot, pos)
    assert any("times less certain" in w for w in res.warnings)
    # the weak direction is the eigenvector of the largest covariance eigenvalue (independent)
    _w, v = np.linalg.eigh(crb_tcp(rot, 1.0))
    weak = v[:, -1]
    assert abs(weak[0]) > 0.9


def test_the_figures_computed_on_first_read_are_frozen_and_travel_whole() -> None:
    """The 95 % radius, angle figures, warnings ... are computed when first read: the result is
    still frozen, a copy, a pickle or dataclasses.replace carries every figure, and threads
    that read at once get the same values."""
    import copy
    import dataclasses
    import pickle
    import threading

    rng = np.random.default_rng(8)
    rot, pos, _, _ = make_touches(rng, 6, tilt_deg=(3.0, 8.0))    # small tilts: warnings
    fields = [f.name for f in dataclasses.fields(TcpResult)]

    def values(res: TcpResult) -> list:
        return [getattr(res, k).tolist() if isinstance(getattr(res, k), np.ndarray) else getattr(res, k)
                for k in fields if k != "without_outliers"]

    first = solve_xyz4(rot, pos)
    expected = values(first)
    assert first.warnings                                          # a weak axis: one warning
    # the angle figures against scipy: the largest relative rotation of the six touches
    rel = [(Rotation.from_matrix(a).inv() * Rotation.from_matrix(b)).magnitude()
           for a, b in itertools.combinations(rot, 2)]
    assert first.max_angle_deg == pytest.approx(math.degrees(max(rel)), abs=1e-9)
    assert first.min_angle_deg == pytest.approx(math.degrees(min(rel)), abs=1e-9)
    for name in ("tcp", "ci95_radius", "warnings", "max_angle_deg", "new_attribute"):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(first, name, 1)
    for fresh in (lambda: pickle.loads(pickle.dumps(solve_xyz4(rot, pos))),
                  lambda: copy.deepcopy(solve_xyz4(rot, pos)),
                  lambda: dataclasses.replace(solve_xyz4(rot, pos), method="lstsq")):
        got = fresh()
        assert isinstance(got, TcpResult) and values(got) == expected
    shared = solve_xyz4(rot, pos)
    seen: list[list] = []
    threads = [threading.Thread(target=lambda: seen.append(values(shared))) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert seen == [expected] * 4
    assert repr(shared).startswith("TcpResult(method='lstsq'")
