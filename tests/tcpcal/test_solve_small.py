"""The default lstsq solve of up to 64 touches (``tcpcal.origin._solve_lstsq_small``, the
wizard's case) against a straightforward computation written here, and against the general
path of ``tcpcal.origin._solve`` (the same functions one by one), and the clean-path bounds of
the input checks at their limits.

The reference builds the explicit 3N x 6 matrix ``A = [R_i, -I]`` of (4P-3) and solves it with
``numpy.linalg.lstsq`` (SVD); the covariance is ``noise^2 (A^T A)^-1``; the outlier test is the
sequential deletion with explicit refits: the drop of the SSE when touch i is left out is its
deleted statistic ``Q_i`` (methods.md section 2, ``tcpcal.origin._find_outliers``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.poses import random_tcp, stacked_a, tilted_rotations, touch_positions
from scipy import stats
from scipy.spatial.transform import Rotation

from tcpcal import origin
from tcpcal.errors import InvalidInputError
from tcpcal.origin import solve_xyz4

REL = 1e-12
"""Agreement asked of the solve with the reference, relative to the scale of the numbers
(the largest |coordinate| for lengths, the largest entry for the covariance, the number itself
for the noise and the radius)."""


def _touches(seed: int, n: int, tilt: tuple[float, float], sigma: float = 0.5,
             outlier_mm: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    rot = tilted_rotations(rng, n, tilt)
    pos = touch_positions(rot, random_tcp(rng, (100.0, 300.0)), np.array([850.0, -120.0, 310.0]), rng, sigma)
    if outlier_mm:
        pos[n // 2] += outlier_mm * np.array([0.6, -0.8, 0.0])
    return rot, pos


def _ill_conditioned(seed: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The tool turned about its own axis by large angles but tilted only 1.5-3 deg: the TCP
    along flange Z is ~30 times less certain than across (condition number of M ~ 1000)."""
    return _touches(seed, n, (1.5, 3.0))


def _lstsq(rot: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(x = (t, r), residual vectors, A, b)`` of (4P-3) by numpy.linalg.lstsq on the explicit A."""
    a = stacked_a(rot)
    b = -pos.reshape(-1)
    x = np.linalg.lstsq(a, b, rcond=None)[0]
    return x, (a @ x - b).reshape(-1, 3), a, b


def _reference_outliers(rot: np.ndarray, pos: np.ndarray) -> list[int]:
    """Sequential deletion: the touch with the largest ``T_i = Q_i / (3 s_(i)^2)``, ``Q_i`` =
    SSE - SSE without touch i, ``s_(i)^2`` = SSE without it / (3N - 9), is flagged when
    ``N p < 0.01`` (``p`` of F(3, 3N - 9)), removed, and the test repeated while more than 4
    touches remain."""
    idx = list(range(rot.shape[0]))
    flagged: list[int] = []
    while len(idx) > 4:
        n = len(idx)
        sse = float(np.sum(_lstsq(rot[idx], pos[idx])[1] ** 2))
        best_t, best_k = -1.0, -1
        for k in range(n):
            rest = idx[:k] + idx[k + 1 :]
            sse_rest = float(np.sum(_lstsq(rot[rest], pos[rest])[1] ** 2))
            t_k = (sse - sse_rest) / (3.0 * sse_rest / (3 * n - 9))
            if t_k > best_t:
                best_t, best_k = t_k, k
        if n * float(stats.f.sf(best_t, 3, 3 * n - 9)) >= origin.OUTLIER_ALPHA:
            break
        flagged.append(idx.pop(best_k))
    return sorted(flagged)


def _reference_ci95(cov: np.ndarray, dof: int | None) -> float:
    """The 95 % radius by the scaled chi-square / F approximation (tcpcal._stats.ci_radius)."""
    lam = np.linalg.eigvalsh(cov)
    c, d = float(np.sum(lam**2) / np.sum(lam)), float(np.sum(lam) ** 2 / np.sum(lam**2))
    q = c * stats.chi2.ppf(0.95, d) if dof is None else c * d * stats.f.ppf(0.95, d, dof)
    return math.sqrt(q)


def _check_against_reference(res: origin.TcpResult, rot: np.ndarray, pos: np.ndarray, sigma: float | None) -> None:
    n = rot.shape[0]
    x, e, a, _ = _lstsq(rot, pos)
    scale = float(np.abs(pos).max())
    np.testing.assert_allclose(res.tcp, x[:3], rtol=0, atol=REL * scale)
    np.testing.assert_allclose(res.reference, x[3:], rtol=0, atol=REL * scale)
    np.testing.assert_allclose(res.residual_vectors, e, rtol=0, atol=REL * scale)
    lengths = np.linalg.norm(e, axis=1)
    np.testing.assert_allclose(res.residuals, lengths, rtol=0, atol=REL * scale)
    sse = float(np.sum(e**2))
    assert res.rms_error == pytest.approx(math.sqrt(sse / n), rel=0, abs=REL * scale)
    assert res.mean_error == pytest.approx(float(lengths.mean()), rel=0, abs=REL * scale)
    assert res.max_error == pytest.approx(float(lengths.max()), rel=0, abs=REL * scale)
    s_est = math.sqrt(sse / (3 * n - 6))
    noise = s_est if sigma is None else sigma
    assert res.noise_sigma == pytest.approx(noise, rel=REL)
    cov = noise**2 * np.linalg.inv(a.T @ a)[:3, :3]
    np.testing.assert_allclose(res.covariance, cov, rtol=0, atol=REL * float(np.abs(cov).max()))
    assert res.ci95_radius == pytest.approx(_reference_ci95(cov, None if sigma is not None else 3 * n - 6),
                                            rel=REL)
    assert res.condition_number == pytest.approx(float(np.linalg.cond(a)), rel=1e-9)  # from N +- s_max(S)
    quats = Rotation.from_matrix(rot)
    angles = [math.degrees((quats[i].inv() * quats[j]).magnitude()) for i in range(n) for j in range(i + 1, n)]
    assert res.max_angle_deg == pytest.approx(max(angles), abs=1e-9)
    assert res.min_angle_deg == pytest.approx(min(angles), abs=1e-9)


CASES = {
    "N=4": (_touches, 4, 11),
    "N=5": (_touches, 5, 12),
    "N=8": (_touches, 8, 13),
    "N=8 ill-conditioned": (_ill_conditioned, 8, 14),
    "N=4 ill-conditioned": (_ill_conditioned, 4, 15),
}


@pytest.mark.parametrize("sigma", [None, 0.4])
@pytest.mark.parametrize("case", CASES)
def test_small_lstsq_solve_matches_the_explicit_3n_x_6_least_squares(case: str, sigma: float | None) -> None:
    make, n, seed = CASES[case]
    rot, pos = make(seed, n) if make is _ill_conditioned else make(seed, n, (20.0, 50.0))
    res = solve_xyz4(rot, pos, sigma=sigma)
    assert res.outliers == () and res.without_outliers is None
    _check_against_reference(res, rot, pos, sigma)
    a = stacked_a(rot)
    cov_eig = np.linalg.eigvalsh(np.linalg.inv(a.T @ a)[:3, :3])  # the reference's, up to noise^2
    ratio = math.sqrt(float(cov_eig[-1] / cov_eig[0]))
    weak = [w for w in res.warnings if "times less certain" in w]
    if "ill" in case:  # the weak-axis remark, with the reference's ratio
        assert ratio > 20.0
        assert len(weak) == 1 and f"is {ratio:.0f} times less certain" in weak[0]
    else:
        assert ratio < origin.WEAK_AXIS_RATIO and not weak
    assert any("only 4 touches" in w for w in res.warnings) == (n == 4)


@pytest.mark.parametrize("n", [5, 8])
def test_small_lstsq_solve_flags_the_outlier_the_explicit_deletion_test_flags(n: int) -> None:
    rot, pos = _touches(21 + n, n, (20.0, 50.0), outlier_mm=6.0)
    res = solve_xyz4(rot, pos)
    expected = _reference_outliers(rot, pos)
    assert expected == [n // 2]  # the touch made 6 mm off (the premise of the case)
    assert list(res.outliers) == expected
    _check_against_reference(res, rot, pos, None)
    keep = [i for i in range(n) if i not in expected]
    assert res.without_outliers is not None
    _check_against_reference(res.without_outliers, rot[keep], pos[keep], None)
    remark = [w for w in res.warnings if "stands out" in w]
    assert len(remark) == 1
    assert f"touch {n // 2} (0-based) stands out (residual {res.residuals[n // 2]:.3g} vs noise estimate " \
           f"{res.without_outliers.noise_sigma:.3g})" in remark[0]


def _fields(res: origin.TcpResult) -> dict[str, object]:
    return {name: getattr(res, name) for name in origin.TcpResult.__dataclass_fields__}


def _assert_identical(a: origin.TcpResult, b: origin.TcpResult) -> None:
    fa, fb = _fields(a), _fields(b)
    for name, va in fa.items():
        vb = fb[name]
        if isinstance(va, np.ndarray):
            assert np.array_equal(va, vb), name
        elif isinstance(va, origin.TcpResult):
            assert isinstance(vb, origin.TcpResult)
            _assert_identical(va, vb)
        elif isinstance(va, float) and math.isnan(va):
            assert isinstance(vb, float) and math.isnan(vb), name
        else:
            assert va == vb, name


@pytest.mark.parametrize("detect_outliers", [True, False])
@pytest.mark.parametrize("n", [4, 5, 7, 8, 12, 64])
def test_small_lstsq_solve_equals_the_general_path_to_the_last_bit(monkeypatch: pytest.MonkeyPatch, n: int,
                                                                   detect_outliers: bool) -> None:
    """The one-function solve does the arithmetic of information, _observability, m_inv and
    _lstsq_core in their order: every figure and remark the same as theirs, bit for bit."""
    rng = np.random.default_rng(40 + n)
    rot = tilted_rotations(rng, n, (5.0, 40.0))
    pos = touch_positions(rot, random_tcp(rng), np.array([700.0, 90.0, 250.0]), rng, 0.3)
    pos[1] += [0.0, 6.0, 0.0]  # an outlier for the test to find (n >= 5)
    if n > 6:  # a repeated orientation: the duplicate pretest fails, the exact check runs (and passes)
        rot[n - 1] = rot[0]
    fast = solve_xyz4(rot, pos, detect_outliers=detect_outliers)
    monkeypatch.setattr(origin, "_SMALL_N", 0)
    general = solve_xyz4(rot, pos, detect_outliers=detect_outliers)
    _assert_identical(fast, general)
    assert (1 in fast.outliers) == (detect_outliers and n >= 5)


def test_small_lstsq_solve_raises_what_the_general_path_raises(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(5)
    rot = tilted_rotations(rng, 5, (20.0, 50.0))
    rot[3] = rot[1]
    rot[4] = rot[2]  # 3 distinct orientations among 5
    pos = touch_positions(rot, random_tcp(rng), np.array([700.0, 90.0, 250.0]))
    spin = Rotation.from_euler("z", [[0.0], [40.0], [90.0], [150.0]], degrees=True).as_matrix()  # one axis
    cases = [(rot, pos), (spin, touch_positions(spin, random_tcp(rng), np.array([700.0, 90.0, 250.0])))]
    for r, p in cases:
        with pytest.raises(origin.DegenerateTouchesError) as fast:
            solve_xyz4(r, p)
        monkeypatch.setattr(origin, "_SMALL_N", 0)
        with pytest.raises(origin.DegenerateTouchesError) as general:
            solve_xyz4(r, p)
        monkeypatch.undo()
        assert str(fast.value) == str(general.value)


def _scaled_column(r: np.ndarray, factor: float) -> np.ndarray:
    out = r.copy()
    out[:, 0] *= factor  # (R^T R)_00 = factor^2: defect factor^2 - 1
    return out


def test_orthonormality_clean_path_bound_keeps_the_entry_limit() -> None:
    """The one-call bound (sum of squares of the defects) only lets clearly good stacks through:
    64 rotations each 0.9 x the tolerance off pass (the sum is 64 x 0.81 tol^2), one 1.1 x off
    fails, named, as the entry-by-entry check decides."""
    rng = np.random.default_rng(8)
    rot = tilted_rotations(rng, 64, (20.0, 50.0))
    pos = touch_positions(rot, random_tcp(rng), np.array([700.0, 90.0, 250.0]))
    tol = 1e-6
    near = np.stack([_scaled_column(r, math.sqrt(1.0 + 0.9 * tol)) for r in rot])
    solve_xyz4(near, pos)  # accepted
    near[37] = _scaled_column(rot[37], math.sqrt(1.0 + 1.1 * tol))
    with pytest.raises(InvalidInputError, match=r"rotations\[37\] is not a rotation matrix") as err:
        solve_xyz4(near, pos)
    assert err.value.index == 37


def test_coordinate_clean_path_bound_keeps_the_entry_limit() -> None:
    """64 touches with coordinates 0.9e9 (sum of squares above 1e18) pass; one at 1.1e9 fails."""
    rng = np.random.default_rng(9)
    rot = tilted_rotations(rng, 64, (20.0, 50.0))
    far = np.full((64, 3), 0.9e9) + touch_positions(rot, random_tcp(rng), np.zeros(3))
    res = solve_xyz4(rot, far)
    assert np.isfinite(res.tcp).all()
    far[20, 1] = 1.1e9
    with pytest.raises(InvalidInputError, match=r"positions\[20\] has a coordinate 1\.1e\+09 beyond") as err:
        solve_xyz4(rot, far)
    assert err.value.index == 20
