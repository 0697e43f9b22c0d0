"""Statistical behaviour of the default estimator under isotropic touch noise (methods.md
section 7): efficiency against the Cramer-Rao bound and coverage of the 95 % radius.

The bound is computed here from the explicit 3N x 6 matrix A (``poses.crb_tcp``). Fixed seeds;
a few thousand trials (a few seconds).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.poses import crb_tcp, make_touches, touch_positions
from scipy.spatial.transform import Rotation

from tcpcal._stats import ci_radius
from tcpcal.origin import solve_xyz4

TRIALS = 2000


def _trials(rot: np.ndarray, tcp: np.ndarray, ref: np.ndarray, sigma: float, seed: int, given: bool):
    rng = np.random.default_rng(seed)
    err = np.empty((TRIALS, 3))
    covered = np.empty(TRIALS, dtype=bool)
    for k in range(TRIALS):
        pos = touch_positions(rot, tcp, ref, rng, sigma)
        res = solve_xyz4(rot, pos, sigma=sigma if given else None, detect_outliers=False)
        err[k] = res.tcp - tcp
        covered[k] = np.linalg.norm(err[k]) <= res.ci95_radius
    return err, covered


@pytest.mark.slow
@pytest.mark.parametrize("n, seed", [(4, 1), (8, 2), (20, 3)])
def test_default_estimator_reaches_cramer_rao_bound(n: int, seed: int) -> None:
    sigma = 0.5
    rng = np.random.default_rng(seed)
    rot, _, tcp, ref = make_touches(rng, n, tilt_deg=(20.0, 50.0))
    err, covered = _trials(rot, tcp, ref, sigma, seed + 100, given=False)
    crb = crb_tcp(rot, sigma)
    efficiency = math.sqrt(np.mean(np.sum(err**2, axis=1))) / math.sqrt(np.trace(crb))
    assert abs(efficiency - 1.0) < 0.05, efficiency
    # unbiased: the mean error is within 4 standard errors of 0 on every axis
    se = np.sqrt(np.diag(crb) / TRIALS)
    assert np.all(np.abs(err.mean(axis=0)) < 4 * se)
    assert abs(covered.mean() - 0.95) <= 0.03, covered.mean()


@pytest.mark.slow
@pytest.mark.parametrize("given", [False, True])
def test_ci95_coverage_anisotropic(given: bool) -> None:
    """Touches tilted far about flange X but little about Y: a strongly anisotropic covariance
    (ratio of variances > 15). The 95 % sphere must still hold the true TCP in 95 % of
    trials, with the noise estimated (F-type quantile, 3N - 6 = 12 dof) or given."""
    rotvecs = np.radians([[40, 0, 0], [-40, 0, 0], [0, 0, 0], [0, 3, 0], [20, -3, 10], [-20, 2, -10]])
    rot = Rotation.from_rotvec(rotvecs).as_matrix()
    tcp, ref = np.array([5.0, -3.0, 180.0]), np.array([600.0, 100.0, 50.0])
    ev = np.linalg.eigvalsh(crb_tcp(rot, 1.0))
    assert ev[-1] / ev[0] > 15
    _, covered = _trials(rot, tcp, ref, 0.5, 7 + given, given=given)
    assert abs(covered.mean() - 0.95) <= 0.03, covered.mean()


@pytest.mark.parametrize(
    "lam, dof",
    [((1, 1, 1), None), ((1, 0.3, 0.05), None), ((1, 0.01, 0.0), None),
     ((1, 1, 1), 6), ((1, 0.3, 0.05), 6), ((1, 0.1, 0.1), 12), ((1, 0.5, 0.01), 54)],
)
def test_ci_radius_matches_monte_carlo_quantile(lam: tuple, dof: int | None) -> None:
    """The radius is the 95 % quantile of sqrt(sum lam_k z_k^2 / (chi2_dof / dof)), computed
    here by Monte Carlo (400k samples: quantile standard error ~0.1 %)."""
    rng = np.random.default_rng(42)
    m = 400_000
    q = (rng.standard_normal((m, 3)) ** 2) @ np.asarray(lam, float)
    if dof is not None:
        q = q / (rng.chisquare(dof, m) / dof)
    expected = math.sqrt(np.quantile(q, 0.95))
    got = ci_radius(np.asarray(lam, float), dof)
    assert got == pytest.approx(expected, rel=0.01)
