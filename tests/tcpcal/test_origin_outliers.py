"""Outlier flagging of the 4-point solver (methods.md section 2, "Robustness")."""

from __future__ import annotations

import numpy as np
import pytest
from support.poses import make_touches

from tcpcal.origin import solve_xyz4


def _offset(rng: np.random.Generator, length: float) -> np.ndarray:
    d = rng.standard_normal(3)
    return length * d / np.linalg.norm(d)


@pytest.mark.parametrize("method", ["lstsq", "sphere", "pairwise"])
def test_one_touch_5mm_off_among_8_is_flagged_and_excluded(method: str) -> None:
    rng = np.random.default_rng(12)
    rot, pos, tcp, _ref = make_touches(rng, 8, tilt_deg=(30, 60), sigma=0.2)
    pos[5] += _offset(rng, 5.0)
    res = solve_xyz4(rot, pos, method=method)
    assert res.outliers == (5,)
    assert any("touch 5 (0-based) stands out" in w for w in res.warnings)
    clean = res.without_outliers
    assert clean is not None and clean.n_touches == 7 and clean.outliers == ()
    # the result without it is close to the truth (well inside what noise 0.2 allows), and
    # closer than the result with it
    assert np.linalg.norm(clean.tcp - tcp) < 0.5
    assert np.linalg.norm(clean.tcp - tcp) < np.linalg.norm(res.tcp - tcp)
    # independent: solving the 7 good touches directly gives the same TCP
    keep = [i for i in range(8) if i != 5]
    np.testing.assert_allclose(clean.tcp, solve_xyz4(rot[keep], pos[keep], method=method).tcp, atol=1e-12)


def test_detection_rate_at_operator_noise() -> None:
    """sigma 0.5 mm, one touch 5 mm off among 8, random directions: flagged (and only it) in
    at least 95 % of 100 sets (measured ~98 %)."""
    hits = 0
    for seed in range(100):
        rng = np.random.default_rng(1000 + seed)
        rot, pos, *_ = make_touches(rng, 8, sigma=0.5)
        k = int(rng.integers(8))
        pos[k] += _offset(rng, 5.0)
        hits += solve_xyz4(rot, pos).outliers == (k,)
    assert hits >= 95


def test_clean_sets_flag_rarely() -> None:
    """The test's nominal family-wise false-alarm rate is 1 %; allow up to 3 % in 300 sets."""
    flagged = 0
    for seed in range(300):
        rng = np.random.default_rng(seed)
        rot, pos, *_ = make_touches(rng, int(rng.integers(5, 21)), sigma=0.5)
        flagged += len(solve_xyz4(rot, pos).outliers) > 0
    assert flagged <= 9


def test_exact_data_flags_nothing() -> None:
    rng = np.random.default_rng(3)
    rot, pos, *_ = make_touches(rng, 12)
    assert solve_xyz4(rot, pos).outliers == ()


def test_two_outliers_and_minimum_remaining() -> None:
    rng = np.random.default_rng(21)
    rot, pos, tcp, _ = make_touches(rng, 10, tilt_deg=(30, 60), sigma=0.2)
    pos[2] += _offset(rng, 6.0)
    pos[7] += _offset(rng, 6.0)
    res = solve_xyz4(rot, pos)
    assert res.outliers == (2, 7)
    assert np.linalg.norm(res.without_outliers.tcp - tcp) < 0.5


def test_four_touches_are_never_trimmed() -> None:
    rng = np.random.default_rng(5)
    rot, pos, *_ = make_touches(rng, 4, sigma=0.2)
    pos[1] += _offset(rng, 10.0)
    res = solve_xyz4(rot, pos)
    assert res.outliers == () and res.without_outliers is None
    assert any("only 4 touches" in w for w in res.warnings)


def test_detect_outliers_off() -> None:
    rng = np.random.default_rng(12)
    rot, pos, *_ = make_touches(rng, 8, sigma=0.2)
    pos[5] += 5.0
    assert solve_xyz4(rot, pos, detect_outliers=False).outliers == ()


@pytest.mark.parametrize("method", ["lstsq", "sphere", "pairwise"])
@pytest.mark.parametrize("n", [5, 8, 12])
def test_one_careless_touch_among_exact_ones_is_flagged(method: str, n: int) -> None:
    """Noise-free touches (a training robot's auto-touches) and one touch 5 mm off: the others
    fit exactly, so the deleted statistic of the bad touch is infinite - it must be flagged, and
    the result without it is the exact TCP."""
    rng = np.random.default_rng(40 + n)
    rot, pos, tcp, _ref = make_touches(rng, n, tilt_deg=(30, 60), sigma=0.0)
    bad = n - 1
    pos[bad] += _offset(rng, 5.0)
    res = solve_xyz4(rot, pos, method=method)
    assert res.outliers == (bad,)
    np.testing.assert_allclose(res.without_outliers.tcp, tcp, atol=1e-9)


def test_exact_touches_flag_nothing() -> None:
    rot, pos, _tcp, _ref = make_touches(np.random.default_rng(3), 8, tilt_deg=(30, 60), sigma=0.0)
    assert solve_xyz4(rot, pos).outliers == ()
