"""TCP origin: the XYZ 4-point method and the XYZ reference method (methods.md sections 2-3).

Unit-agnostic: lengths come out in the unit the positions went in (the CLI uses mm). Angles
are reported in degrees (``*_deg``).

Touch ``i`` is the flange pose ``(R_i, f_i)`` = (``R_world_flange``, ``p_world_flange``)
recorded while the tool tip touches the fixed reference point ``r`` (WORLD). The unknown TCP
``t`` is in FLANGE coordinates::

    R_i t + f_i = r                                                   (4P-1)

A small residual does not prove an accurate TCP: systematic errors (robot calibration, a
reference that moved, a tool that bends) are consistent across touches and hide in ``t``.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import threading
from dataclasses import dataclass
from typing import Any, Literal, NamedTuple

import numpy as np
from scipy.special import chdtrc, fdtrc

from tcpcal import _lapack
from tcpcal._stats import (
    _GRAM_SMALL,
    DEGENERATE_TILT_RAD,
    SAME_ORIENTATION_DEG,
    AngleExtremes,
    Information,
    angle_between,
    angle_extremes,
    ci_radius,
    distinct_orientations,
    fmt_vec,
    information,
    information_from_sum,
    soa,
    sum_over_touches,
)
from tcpcal.errors import DegenerateTouchesError, InvalidInputError
from tcpcal.validation import (
    MAX_ABS_COORDINATE,
    as_positions,
    as_rotation,
    as_vector3,
    read_only_array,
    rotations_and_soa,
)

__all__ = ["METHODS", "TcpResult", "solve_reference", "solve_xyz4"]

Method = Literal["lstsq", "sphere", "pairwise"]
METHODS: tuple[str, ...] = ("lstsq", "sphere", "pairwise")

MIN_TOUCHES = 4
OUTLIER_ALPHA = 0.01
"""Family-wise false-alarm probability of the outlier test on a clean set (Bonferroni over the
touches, at each deletion step)."""
SMALL_TILT_DEG = 20.0
"""Warn when the largest angle between two touch orientations is below this."""
NEAR_DUPLICATE_DEG = 5.0
"""Warn when two touch orientations are closer than this."""
WEAK_AXIS_RATIO = 5.0
"""Warn when the TCP standard deviation along the weakest flange direction exceeds that along
the strongest by this factor."""
COPLANAR_RATIO = 0.2
"""Sphere fit: warn when the flange positions' thickness / extent is below this."""
SIGMA_RANGE: tuple[float, float] = (1e-12, 1e9)
"""Accepted range of a given ``sigma`` (length unit of the positions; the CLI's own range in mm
is narrower, docs/cli.md). Outside it the squares of sigma under- or overflow."""
_EXACT_REL = 1e-9
"""Residual noise below this fraction of the data scale counts as exact data (no outlier test)."""
_EXACT_RESIDUAL_SHARE = 1e-12
"""Outlier test: the other touches fit exactly when ``SSE - Q_i <= this * SSE`` (rounding)."""


@dataclass(frozen=True)
class TcpResult:
    """Result of a TCP origin calibration (methods.md sections 2-3).

    Lengths are in the unit of the input positions; angles in degrees.

    Attributes:
        method: ``"lstsq"`` (4P-3), ``"sphere"`` (2a), ``"pairwise"`` (4P-2) or
            ``"reference"`` (REF-1).
        tcp: (3,) TCP ``t`` in FLANGE coordinates.
        reference: (3,) reference point ``r`` in WORLD coordinates.
        residual_vectors: (N, 3) ``e_i = R_i t + f_i - r`` (WORLD).
        residuals: (N,) ``|e_i|``.
        mean_error: mean of ``|e_i|``.
        max_error: max of ``|e_i|``.
        rms_error: ``sqrt(mean |e_i|^2)`` (root mean square of the residual lengths; not
            the mean).
        noise_sigma: per-axis touch noise: the estimate ``s = sqrt(sum |e_i|^2 / (3N - 6))``,
            or the ``sigma`` given by the caller (NaN for the reference method without sigma).
        covariance: (3, 3) covariance of ``tcp`` (``noise_sigma^2 (A^T A)^-1`` restricted to
            ``t`` for lstsq; the first-order propagation of the touch noise for the others).
        ci95_radius: radius of the sphere about ``tcp`` that contains the true TCP with 95 %
            probability under ``covariance`` (with the 3N - 6 degrees of freedom of ``s``
            when sigma was estimated).
        max_angle_deg: largest rotation angle between two touch orientations; exact unless
            ``max_angle_exact`` is False (possible only above ``EXACT_ANGLES_MAX_N`` = 512
            touches, see ``tcpcal._stats.angle_extremes``): then a lower bound attained by a
            pair of touches (the true largest angle is at most ``max_angle_upper_deg``).
        min_angle_deg: smallest rotation angle between two touch orientations; exact unless
            ``min_angle_exact`` is False (possible only above ``SAMPLED_ANGLES_ABOVE_N`` =
            512 touches): then the angle of an actual pair, an upper bound of the smallest.
        condition_number: of the stacked (4P-3) matrix ``A`` (3N x 6).
        outliers: 0-based indices of touches flagged as outliers.
        without_outliers: the same method on the other touches (indices renumbered in
            order), or None if no touch was flagged.
        warnings: plain-words remarks on the data.
        n_touches: N.
        max_angle_exact: whether ``max_angle_deg`` is exact (always for N <= 512).
        max_angle_upper_deg: upper bound of the largest angle (= ``max_angle_deg`` when
            exact).
        min_angle_exact: whether ``min_angle_deg`` is exact (always for N <= 512).
    """

    method: str
    tcp: np.ndarray
    reference: np.ndarray
    residual_vectors: np.ndarray
    residuals: np.ndarray
    mean_error: float
    max_error: float
    rms_error: float
    noise_sigma: float
    covariance: np.ndarray
    ci95_radius: float
    max_angle_deg: float
    min_angle_deg: float
    condition_number: float
    outliers: tuple[int, ...]
    without_outliers: TcpResult | None
    warnings: tuple[str, ...]
    n_touches: int
    max_angle_exact: bool = True
    max_angle_upper_deg: float = math.nan
    min_angle_exact: bool = True


def _check_sigma(sigma: float | None) -> float | None:
    if sigma is None:
        return None
    try:
        s = float(sigma)
    except (TypeError, ValueError):
        raise InvalidInputError(f"sigma must be a number (touch noise per axis), got {sigma!r}.") from None
    if not (math.isfinite(s) and s > 0.0):
        raise InvalidInputError(
            f"sigma must be a finite positive number (touch noise per axis), got {sigma!r}; "
            "omit it to estimate the noise from the residuals."
        )
    lo, hi = SIGMA_RANGE
    if not lo <= s <= hi:
        raise InvalidInputError(
            f"sigma {sigma!r} is outside {lo:g}..{hi:g} (touch noise per axis, length unit of the "
            "positions): no touch is that precise or that poor; give a realistic value, or omit "
            "it to estimate the noise from the residuals."
        )
    return s


def _check_observable(rotations: np.ndarray, info: Information, ext: AngleExtremes) -> None:
    """Raise DegenerateTouchesError when the touches cannot determine the TCP."""
    n = rotations.shape[0]
    if ext.max_upper_deg < SAME_ORIENTATION_DEG:  # = max_deg unless it is an estimate
        raise DegenerateTouchesError(
            f"all {n} touches have the same orientation (at most {ext.max_deg:.2f} deg apart), so "
            "the TCP cannot be determined; the 4-point method needs clearly different "
            "orientations: tilt the tool 30-60 deg between touches, about two different axes.",
            unobservable_axis=None,
        )
    if not info.observable:
        axis = info.weakest_axis
        raise DegenerateTouchesError(
            f"all touches rotate about nearly the same axis (flange {fmt_vec(axis)}), so the TCP "
            "along that axis cannot be determined; tilt the tool about a second axis "
            f"(spread about it: {math.degrees(info.weakest_tilt_rad):.3f} deg).",
            unobservable_axis=axis,
        )
    if ext.min_deg < SAME_ORIENTATION_DEG or not ext.min_exact:  # an estimate may miss the repeat
        found = distinct_orientations(rotations, limit=MIN_TOUCHES)
        distinct = found.count
        if distinct < MIN_TOUCHES and found.first_repeat is not None:
            i, j = found.first_repeat
            raise DegenerateTouchesError(
                f"touches {i} and {j} (0-based) have the same orientation "
                f"({math.degrees(angle_between(rotations[i], rotations[j])):.2f} deg apart): "
                f"only {distinct} clearly different orientations among {n} touches, the "
                f"4-point method needs at least {MIN_TOUCHES}; re-record touch {j} from a "
                "different orientation.",
                index=j,
                indices=(i, j),
            )


class _LstsqFit(NamedTuple):
    """Joint least squares (4P-3) of one set of touches (see :func:`_lstsq_core`)."""

    t: np.ndarray  # (3,) TCP
    r: np.ndarray  # (3,) reference point
    e: np.ndarray  # (N, 3) residual vectors e_i = R_i t + f_i - r
    sse: float  # sum |e_i|^2
    neg_d: np.ndarray  # (N, 3) fbar - f_i


def _lstsq_core(info: Information, m_inv: np.ndarray, rotations: np.ndarray, f: np.ndarray) -> _LstsqFit:
    """Joint least squares (4P-3) through the reduced normal equations.

    With ``d_i = f_i - fbar``: ``M t = -sum_i (R_i - Rbar)^T d_i = -sum_i R_i^T d_i`` (as
    ``sum d_i = 0``), ``r = Rbar t + fbar`` (second block row), ``e_i = R_i t + f_i - r
    = R_i t + d_i - Rbar t``. The sums are single BLAS products over the (3N, 3) stack of
    rotation rows.
    """
    n = rotations.shape[0]
    fbar, neg_d = _centred(f)  # neg_d = -d_i (the sign spares a negation below)
    rows = rotations.reshape(3 * n, 3)
    t = _dot(m_inv, _dot(neg_d.reshape(3 * n), rows))
    rbar_t = _dot(info.rbar, t)
    e = _dot(rows, t).reshape(n, 3)
    e -= neg_d
    e -= rbar_t
    return _LstsqFit(t, rbar_t + fbar, e, float(_vdot(e, e)), neg_d)


def _centred(f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(fbar, fbar - f_i)`` of the (N, 3) positions: their mean and negated deviations.

    Up to ``_MEAN_ROWS_MAX_N`` touches one product gives the mean in every row (two numpy
    calls rather than three, no broadcast: hot path). BLAS sums such short columns in order,
    so every row is the same and, for N = 4 and 8 (1/N exact), equal to ``sum f_i / N`` bit
    for bit; for N = 5 to 7 within an ulp of it."""
    n = f.shape[0]
    if n <= _MEAN_ROWS_MAX_N:
        fbar_rows = _dot(_mean_rows(n), f)
        return fbar_rows[0], fbar_rows - f
    fbar = (_add(f, axis=0) if n <= 64 else sum_over_touches(f)) / n  # sum_over_touches, inlined
    return fbar, fbar - f


_MEAN_ROWS_MAX_N = 8


@functools.lru_cache(maxsize=_MEAN_ROWS_MAX_N)
def _mean_rows(n: int) -> np.ndarray:
    """The (n, n) matrix with every entry ``1/n`` (read-only): its product with the (n, 3)
    positions has their mean in every row."""
    mean_rows = np.full((n, n), 1.0 / n)
    mean_rows.setflags(write=False)
    return mean_rows


def _pairwise_core(rotations: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairwise differences (4P-2) over the N - 1 consecutive pairs ``(a, a+1)``.

    Stacks ``(R_a - R_{a+1}) t = -(f_a - f_{a+1})`` and solves with the pseudo-inverse
    (``numpy.linalg.lstsq``). Returns ``(t, cov_unit)`` with ``cov_unit`` the covariance of
    ``t`` per unit touch variance: ``t - t_true = -G^-1 sum_i K_i^T eps_i`` with
    ``G = sum D_a^T D_a`` and ``K_i = D_i - D_{i-1}`` (pairs that contain touch i).
    """
    n = rotations.shape[0]
    dr = rotations[:-1] - rotations[1:]
    y = -(f[:-1] - f[1:])
    t, *_ = np.linalg.lstsq(dr.reshape(3 * (n - 1), 3), y.reshape(-1), rcond=None)
    g_inv = np.linalg.inv(np.einsum("aki,akj->ij", dr, dr))
    k = np.zeros_like(rotations)
    k[:-1] += dr
    k[1:] -= dr
    inner = np.einsum("nki,nkj->ij", k, k)
    return t, g_inv @ inner @ g_inv


def _sphere_core(rotations: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Best-fit sphere (methods.md 2a).

    ``|d_i|^2 = 2 d_i . r' + k`` (``d_i = f_i - fbar``, ``r = fbar + r'``) by linear least
    squares, then ``t = mean_i R_i^T (r - f_i)``. The covariance per unit touch variance is the
    first-order propagation: ``dr = P_r [2 (f_i - r) . df_i]_i`` (``P_r`` the first three rows of
    the pseudo-inverse of ``[2 d_i, 1]``), ``dt = Rbar^T dr - (1/N) sum R_i^T df_i``. It ignores
    the sphere fit's bias (methods.md section 7). Returns ``(t, cov_unit, flatness)`` with
    ``flatness`` = smallest / largest singular value of the centred flange positions.
    """
    n = rotations.shape[0]
    fbar = f.mean(axis=0)
    dd = f - fbar
    sv = np.linalg.svd(dd, compute_uv=False)
    flatness = float(sv[-1] / sv[0]) if sv[0] > 0 else 0.0
    if flatness < 1e-6:
        raise DegenerateTouchesError(
            "the flange positions are coplanar, so the sphere fit cannot locate the reference "
            f"(thickness / extent = {flatness:.2g}); use method 'lstsq', or touch from "
            "orientations that move the flange out of that plane.",
            unobservable_axis=None,
        )
    h = np.empty((n, 4))
    h[:, :3] = 2.0 * dd
    h[:, 3] = 1.0
    h_pinv = np.linalg.pinv(h)
    z = h_pinv @ np.einsum("ni,ni->n", dd, dd)
    r = fbar + z[:3]
    t = np.einsum("nki,nk->i", rotations, r - f) / n
    rbar = rotations.mean(axis=0)
    # J_i = Rbar^T outer(P_r[:, i], 2 (f_i - r)) - R_i^T / N
    jac = np.einsum("ki,kn,nj->nij", rbar, h_pinv[:3], 2.0 * (f - r)) - rotations.transpose(0, 2, 1) / n
    cov_unit = np.einsum("nij,nkj->ik", jac, jac)
    return t, cov_unit, flatness


_CYCLIC = np.array([0, 1, 2, 0, 1])
_EYE_COLUMN = np.eye(3)[:, :, None]


_STATS_CHUNK = 16384
"""Touches per chunk of :func:`_deleted_residual_statistics` for large N (its 3x3-per-touch
temporaries: 25 rows of N numbers; chunked they stay in cache, memory O(chunk))."""


def _deleted_residual_statistics(y: np.ndarray, info: Information, e: np.ndarray,
                                 n_all: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``Q_i = e_i^T (I - H_ii)^-1 e_i`` and ``det(I - H_ii)`` of every touch (see
    :func:`_find_outliers`), without a Python loop over touches.

    ``H_ii = I/N + D_i M^-1 D_i^T = I/N + W_i W_i^T`` with ``W_i = D_i L``,
    ``L = V diag(eig^-1/2)`` (``M = V diag(eig) V^T``). The symmetric 3x3 blocks
    ``B_i = I - H_ii`` are inverted through their cofactor matrices (cyclic-index formula
    ``C_jk = B_{j+1,k+1} B_{j+2,k+2} - B_{j+1,k+2} B_{j+2,k+1}``): ``Q_i = e_i^T C_i e_i / det B_i``.
    Everything is element-wise on the (3, 3, N) layout ``y`` (entry rows of length N): a
    dozen numpy calls at any N. (Hand-written rather than ``np.linalg.solve`` on the (N, 3, 3)
    stack, which costs ~0.3 us per touch plus a determinant pass; measured 4x faster at
    N = 1000.) ``n_all``: the number of touches of the fit when ``y`` and ``e`` are one chunk
    of them.
    """
    n = e.shape[0]
    if n > _STATS_CHUNK:  # same element-wise algebra chunk by chunk: temporaries stay in cache
        parts = [_deleted_residual_statistics(y[:, :, k : k + _STATS_CHUNK], info, e[k : k + _STATS_CHUNK], n)
                 for k in range(0, n, _STATS_CHUNK)]
        return np.concatenate([q for q, _ in parts]), np.concatenate([d for _, d in parts])
    a = 1.0 - 1.0 / (n if n_all is None else n_all)
    d = y - info.rbar[:, :, None]  # d[j, k] = (R_i - Rbar)_jk
    w = np.matmul((info.eigvecs / np.sqrt(info.eigvals)).T, d)  # w[j] = (D_i L)_j. rows
    b = _EYE_COLUMN * a - np.einsum("jkn,lkn->jln", w, w)  # a I - W_i W_i^T
    bx = b[_CYCLIC[:, None], _CYCLIC]
    cof = bx[1:4, 1:4] * bx[2:5, 2:5] - bx[1:4, 2:5] * bx[2:5, 1:4]
    det = np.einsum("jn,jn->n", b[0], cof[0])
    et = np.ascontiguousarray(e.T)  # contiguous rows: the einsum below is 7x faster
    quad = np.einsum("jkn,jn,kn->n", cof, et, et)
    return quad, det


def _find_outliers(rotations: np.ndarray, y: np.ndarray, f: np.ndarray,
                   first: tuple[Information, _LstsqFit]) -> list[int]:
    """Touches whose residual stands out, by sequential deletion.

    For the linear model (4P-3) the hat-matrix block of touch i is
    ``H_ii = I/N + D_i M^-1 D_i^T``; the deleted (leave-one-out) statistic
    ``Q_i = e_i^T (I - H_ii)^-1 e_i`` and ``s_(i)^2 = (SSE - Q_i) / (3N - 9)`` give
    ``T_i = Q_i / (3 s_(i)^2) ~ F(3, 3N - 9)`` for a clean touch under Gaussian noise
    (externally studentised residual of a 3-row block). The touch with the largest ``T_i`` is
    flagged if its p-value is below ``OUTLIER_ALPHA / N`` (Bonferroni), removed, and the test
    repeated, as long as at least 4 touches would remain. Touches with ``det(I - H_ii) ~ 0``
    (without them the rest is degenerate) cannot be tested.

    All ``Q_i`` come in closed form from the full fit (:func:`_deleted_residual_statistics`),
    none by refitting; ``first`` is the (information, fit) of all touches, which the solver
    has already computed; ``y`` is ``soa(rotations)``. Only after a deletion is the rest
    refitted (O(N) each). As ``SSE`` is common to all touches, ``T_i`` increases with ``Q_i``:
    the largest ``T_i`` is at the largest ``Q_i`` (the clean path computes ``T`` for that touch
    only; the general expression handles untestable touches).
    """
    n_all = rotations.shape[0]
    idx = np.arange(n_all)
    flagged: list[int] = []
    info, fit = first
    while n_all - len(flagged) > MIN_TOUCHES:
        n = n_all - len(flagged)
        if flagged:
            rot = rotations[idx]
            info = information(rot)
            if not info.observable:
                break
            fit = _lstsq_core(info, info.m_inv(), rot, f[idx])
            y_now = y[:, :, idx]
        else:
            y_now = y
        sse = fit.sse
        scale = max(float(np.abs(fit.neg_d).max()), math.hypot(*fit.t.tolist()), 1e-300)
        if sse <= (_EXACT_REL * scale) ** 2 * (3 * n - 6):
            break
        quad, det = _deleted_residual_statistics(y_now, info, fit.e)
        dof = 3 * n - 9
        k = -1
        # The other touches fit exactly when SSE - Q_i vanishes (to rounding): then T_i is
        # infinite, touch i alone carries all the error and is flagged (e.g. one careless touch
        # among exact ones, as a training robot's auto-touches are).
        exact_rest = _EXACT_RESIDUAL_SHARE * sse
        if float(det.min()) > 1e-9:  # every touch testable (the usual case)
            q = quad / det
            k = int(q.argmax())
            q_k = float(q[k])
            t_k = q_k / (3.0 * ((sse - q_k) / dof)) if sse - q_k > exact_rest else math.inf
        else:
            testable = det > 1e-9
            q = np.where(testable, quad / np.where(testable, det, 1.0), 0.0)
            rest = sse - q
            tstat = np.where(testable & (rest > exact_rest), q / (3.0 * np.maximum(rest, 1e-300) / dof),
                             np.where(testable & (q > 0.0), math.inf, 0.0))
            k = int(np.argmax(tstat))
            t_k = float(tstat[k])
        p = float(fdtrc(3, dof, t_k))
        if p * n >= OUTLIER_ALPHA:
            break
        flagged.append(int(idx[k]))
        idx = np.delete(idx, k)
    return sorted(flagged)


def _check_finite_result(t: np.ndarray, r: np.ndarray, sse: float) -> None:
    """Raise InvalidInputError rather than return a TCP holding NaN or inf (an overflow of the
    arithmetic on extreme numbers that the input bounds did not prevent)."""
    if not math.isfinite(sum(t.tolist()) + sum(r.tolist()) + sse):
        raise InvalidInputError(
            "the TCP could not be computed in floating point (overflow: the result is not finite); "
            "check the positions' unit and magnitude (they must be within "
            f"+-{MAX_ABS_COORDINATE:g} length units)."
        )


def _fmt_idx(indices: list[int] | tuple[int, ...]) -> str:
    return ", ".join(str(i) for i in indices)


def solve_xyz4(
    rotations: np.ndarray,
    positions: np.ndarray,
    *,
    method: Method = "lstsq",
    sigma: float | None = None,
    detect_outliers: bool = True,
) -> TcpResult:
    """XYZ 4-point method: the TCP from N >= 4 touches of one reference point (4P-1).

    Estimators (methods.md section 2):

    - ``"lstsq"`` (default, (4P-3)): joint linear least squares for ``x = (t, r)``, solved
      through the normal equations reduced to sums over the touches
      (``A^T A = [[N I, -S^T], [-S, N I]]``, ``S = sum R_i``; eliminating ``r`` leaves the 3x3
      system ``M t = -sum D_i^T d_i``, ``M = sum D_i^T D_i``, ``D_i = R_i - Rbar``,
      ``d_i = f_i - fbar``). O(N), the 3N x 6 matrix is never formed. It is the
      maximum-likelihood estimate under isotropic Gaussian touch noise and reaches the
      Cramer-Rao bound ``sigma^2 M^-1`` (methods.md section 7).
    - ``"pairwise"`` ((4P-2)): the N - 1 **consecutive** pairs ``(a, a+1)`` stacked and solved
      with the pseudo-inverse (the lecture's idea, generalised from pairs (1,2), (3,4)).
      Consecutive rather than all pairs because stacking *all* pairs with equal weights gives
      exactly the ``"lstsq"`` estimate (``sum_{a<b} D_ab^T D_ab = N M``), so it would not be a
      different method; consecutive pairs discard information, as methods.md section 7 says.
    - ``"sphere"`` (2a): best-fit sphere through the flange positions, centre = reference;
      ``t = mean_i R_i^T (r - f_i)``. Biased for small tilts, poor when the flange positions
      are nearly coplanar (typical of N = 4).

    Quality figures: residuals ``e_i = R_i t + f_i - r``; noise ``s^2 = sum |e_i|^2 / (3N - 6)``
    (or the given ``sigma``); covariance ``noise^2 M^-1`` for lstsq (first-order propagation
    for the others); 95 % confidence radius from the eigenvalues of the covariance (see
    ``tcpcal._stats.ci_radius``); condition number of ``A`` from ``N +- s_max(S)``.

    Outliers (``detect_outliers``, N >= 5): leave-one-out F test on the linear model
    (``_find_outliers``), independent of ``method``; flagged touches are listed in ``outliers``
    and the same method is re-run without them (``without_outliers``), keeping at least 4.

    Args:
        rotations: (N, 3, 3) ``R_world_flange`` of each touch.
        positions: (N, 3) ``p_world_flange`` of each touch (any length unit).
        method: ``"lstsq"``, ``"pairwise"`` or ``"sphere"``.
        sigma: known per-axis touch noise (length unit); if given it replaces the estimate
            ``s`` in the covariance and confidence radius.
        detect_outliers: run the outlier test.

    Returns:
        A frozen :class:`TcpResult`; TCP in FLANGE coordinates, reference in WORLD.

    Raises:
        InvalidInputError: wrong shapes, NaN/inf, non-rotations, fewer than 4 touches, unknown
            method, bad sigma.
        DegenerateTouchesError: the touches cannot determine the TCP (all the same orientation,
            rotations about one common axis (``unobservable_axis`` in FLANGE coordinates),
            fewer than 4 different orientations, coplanar flange positions for the sphere fit).
    """
    if method not in METHODS:
        raise InvalidInputError(
            f"unknown method {method!r}; choose one of {', '.join(METHODS)} (lstsq is the default)."
        )
    try:
        n_given = len(rotations)
    except TypeError:
        n_given = MIN_TOUCHES  # let as_rotations report the problem
    if n_given < MIN_TOUCHES:
        raise InvalidInputError(
            f"the 4-point method needs at least {MIN_TOUCHES} touches, got {n_given}; record "
            f"{MIN_TOUCHES - n_given} more from clearly different orientations."
        )
    rot, y = rotations_and_soa(rotations, name="rotations")
    f = as_positions(positions, n=rot.shape[0], name="positions")
    s_given = _check_sigma(sigma)
    return _solve(rot, y, f, method, s_given, detect_outliers)


_add = np.add.reduce  # ufunc reductions without the Python wrapper of ndarray.sum (hot path)
_max = np.maximum.reduce
_dot = _lapack.dot  # small 2-D products: less Python dispatch than the @ operator (hot path)
_vdot = _lapack.vdot  # a whole array's sum of squares
try:  # numpy.einsum without its Python dispatch (optimize=False calls this very function)
    from numpy._core.multiarray import c_einsum as _einsum
except ImportError:  # pragma: no cover - another numpy
    _einsum = np.einsum

_DUPLICATE_PRETEST_TRACE = 1.0 + 2.0 * math.cos(math.radians(0.5))
"""Largest ``trace(R_a^T R_b)`` of two touches below which no pair can be "the same
orientation" (``SAME_ORIENTATION_DEG`` = 0.05 deg): ``|R_a - R_b|_F^2 = |R_a|_F^2 + |R_b|_F^2 -
2 trace(R_a^T R_b)`` with ``|R|_F^2 = 3 +- 3e-6`` (orthonormal within ``ORTHONORMAL_TOL``) puts
such a pair at least 0.49 deg apart."""


@functools.lru_cache(maxsize=16)
def _three_eye(n: int) -> np.ndarray:
    """``3 I`` (n x n, read-only): ``|R|_F^2`` of a rotation on the diagonal."""
    three_eye = 3.0 * np.eye(n)
    three_eye.setflags(write=False)
    return three_eye


def _observability(rot: np.ndarray, y: np.ndarray | None, info: Information) -> AngleExtremes | None:
    """Raise :class:`DegenerateTouchesError` exactly when :func:`_check_observable` does, and
    compute the angle extremes only when they can decide it (returned then, else None).

    Observable touches (``info.observable``) cannot all have one orientation (that would leave
    ``min eig M / N <= 2/3 (0.05 deg)^2``, below ``DEGENERATE_TILT_RAD^2``), so only the repeated
    orientation check remains, which needs two touches closer than ``SAME_ORIENTATION_DEG`` and
    fewer than 4 distinct orientations: ruled out by the largest off-diagonal Gram entry of the
    flattened rotations (N <= ``_GRAM_SMALL``, ``_DUPLICATE_PRETEST_TRACE``) or by finding 4
    distinct orientations (:func:`distinct_orientations`, a few rows at any N)."""
    n = rot.shape[0]
    if info.observable:
        if n <= _GRAM_SMALL:
            x = rot.reshape(n, 9)
            g = _dot(x, x.T)
            g -= _three_eye(n)  # the diagonal |R_i|_F^2 - 3 = +-3e-6: far below the pretest's bound
            if float(_max(g, axis=None)) < _DUPLICATE_PRETEST_TRACE:
                return None
        elif distinct_orientations(rot, limit=MIN_TOUCHES).count >= MIN_TOUCHES:
            return None
    ext = angle_extremes(rot, y)
    _check_observable(rot, info, ext)
    return ext


class _Deferred(NamedTuple):
    """What the deferred quality figures of one solve are computed from (:class:`_LazyTcpResult`)."""

    rot: np.ndarray
    y: np.ndarray | None
    info: Information
    ext: AngleExtremes | None  # None: not computed yet
    lstsq_noise: float | None  # lstsq: ``cov = noise^2 M^-1``, eigenvalues noise^2 / eig M; None: of ``cov``
    cov: np.ndarray | None  # the covariance (None for lstsq, whose eigenvalues need it not)
    ci_dof: int | None
    early_warnings: list[str]
    sigma: float | None
    sse: float
    s_est: float
    dof: int
    detect_outliers: bool


class _Figures(NamedTuple):
    mean_error: float
    max_error: float
    ci95_radius: float
    ext: AngleExtremes
    condition_number: float
    warnings: tuple[str, ...]


def _late_figures(d: _Deferred, res: np.ndarray) -> _Figures:
    """The mean and largest residual (of ``res``, the residual lengths), the 95 % radius, the
    angle figures, the condition number and the warnings of a solve (the same numbers and
    words as if computed in :func:`_solve`)."""
    info, n = d.info, d.rot.shape[0]
    ext = d.ext if d.ext is not None else angle_extremes(d.rot, d.y)
    cov_eig: list[float] | np.ndarray
    if d.lstsq_noise is not None:
        noise2 = d.lstsq_noise * d.lstsq_noise
        cov_eig = [noise2 / v for v in info.eigvals.tolist()]  # > 0: the touches are observable
    else:
        assert d.cov is not None  # given for every estimator but lstsq
        cov_eig = np.linalg.eigvalsh(d.cov)
    ci95 = ci_radius(cov_eig, d.ci_dof)
    warnings = d.early_warnings
    eig = info.eigvals.tolist()
    if ext.max_deg < SMALL_TILT_DEG and ext.max_upper_deg < SMALL_TILT_DEG:
        warnings.append(
            f"the touch orientations differ by at most {ext.max_deg:.1f} deg: tilt the tool 30-60 deg "
            "between touches, about two different axes, for a precise TCP."
        )
    ratio = math.sqrt(eig[2] / eig[0])
    if ratio > WEAK_AXIS_RATIO:
        warnings.append(
            f"the TCP along flange {fmt_vec(info.weakest_axis)} is {ratio:.0f} times less certain "
            "than across it: the touches tilt little about a second axis; add a touch tilted "
            "about another axis."
        )
    if ext.min_deg < NEAR_DUPLICATE_DEG:
        i, j = ext.min_pair
        warnings.append(
            f"touches {i} and {j} (0-based) are only {ext.min_deg:.1f} deg apart in orientation, so "
            "one of them adds little: re-record it from a clearly different orientation."
        )
    sigma = d.sigma
    if sigma is not None and float(chdtrc(d.dof, d.sse / sigma**2)) < 1e-3:
        warnings.append(
            f"the residuals (noise estimate {d.s_est:.3g}) are larger than the given sigma {sigma:.3g} "
            "explains: the touches are less precise than assumed, or something is not rigid or not "
            "calibrated (tool, reference point, robot)."
        )
    if d.detect_outliers and n == MIN_TOUCHES:
        warnings.append(
            "with only 4 touches a careless touch cannot be detected; record 5 to 8 touches for a "
            "checkable result."
        )
    return _Figures(float(_add(res)) / n, float(_max(res)), ci95, ext, info.condition_number, tuple(warnings))


_LATE_FIGURES_LOCK = threading.Lock()


class _LazyTcpResult(TcpResult):
    """The :class:`TcpResult` of :func:`solve_xyz4`: the figures that cost more than the solve
    needs (``mean_error``, ``max_error``, ``ci95_radius``, the angle figures,
    ``condition_number``, ``warnings``) are computed
    together on the first read of any of them (:func:`_late_figures`, from the solve's own
    arrays; the same values as computed eagerly), then kept; so is the lstsq ``covariance``
    of up to ``_SMALL_N`` touches, ``noise^2 M^-1``, on its own first read (one product). Frozen
    like its base; a copy or a pickle is a plain :class:`TcpResult` with every figure."""

    @functools.cached_property
    def covariance(self) -> np.ndarray:
        scale, m_inv = self.__dict__["_covariance_of"]  # (noise^2, M^-1): kept, never written
        cov: np.ndarray = scale * m_inv
        cov.setflags(write=False)
        return cov

    @property
    def _figures(self) -> _Figures:
        figures: _Figures | None = self.__dict__.get("_late")
        if figures is None:
            with _LATE_FIGURES_LOCK:  # once, whichever thread asks first
                figures = self.__dict__.get("_late")
                if figures is None:
                    figures = _late_figures(self.__dict__["_deferred"], self.residuals)
                    ext = figures.ext
                    self.__dict__.update(  # read from now on as plain attributes
                        mean_error=figures.mean_error, max_error=figures.max_error,
                        ci95_radius=figures.ci95_radius, max_angle_deg=ext.max_deg, min_angle_deg=ext.min_deg,
                        condition_number=figures.condition_number, warnings=figures.warnings,
                        max_angle_exact=ext.max_exact, max_angle_upper_deg=ext.max_upper_deg,
                        min_angle_exact=ext.min_exact, _late=figures)
                    del self.__dict__["_deferred"]  # the solve's arrays are no longer needed
        return figures

    @functools.cached_property
    def mean_error(self) -> float:
        return self._figures.mean_error

    @functools.cached_property
    def max_error(self) -> float:
        return self._figures.max_error

    @functools.cached_property
    def ci95_radius(self) -> float:
        return self._figures.ci95_radius

    @functools.cached_property
    def max_angle_deg(self) -> float:
        return self._figures.ext.max_deg

    @functools.cached_property
    def min_angle_deg(self) -> float:
        return self._figures.ext.min_deg

    @functools.cached_property
    def condition_number(self) -> float:
        return self._figures.condition_number

    @functools.cached_property
    def warnings(self) -> tuple[str, ...]:
        return self._figures.warnings

    @functools.cached_property
    def max_angle_exact(self) -> bool:
        return self._figures.ext.max_exact

    @functools.cached_property
    def max_angle_upper_deg(self) -> float:
        return self._figures.ext.max_upper_deg

    @functools.cached_property
    def min_angle_exact(self) -> bool:
        return self._figures.ext.min_exact

    def _plain(self) -> TcpResult:
        return TcpResult(*(getattr(self, f.name) for f in dataclasses.fields(TcpResult)))

    def __reduce__(self) -> tuple[Any, ...]:
        return (TcpResult, tuple(getattr(self, f.name) for f in dataclasses.fields(TcpResult)))

    def __repr__(self) -> str:
        return repr(self._plain())

    def __setattr__(self, name: str, value: Any) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")


def _solve(rot: np.ndarray, y: np.ndarray | None, f: np.ndarray, method: str, sigma: float | None,
           detect_outliers: bool) -> TcpResult:
    """Solve validated touches: ``rot`` (N, 3, 3), ``f`` (N, 3); ``y`` = ``soa(rot)`` or None
    (then made here if needed)."""
    n = rot.shape[0]
    if method == "lstsq" and n <= _SMALL_N:
        return _solve_lstsq_small(rot, f, sigma, detect_outliers)
    test_outliers = detect_outliers and n > MIN_TOUCHES
    if y is None and (test_outliers or n > 64):
        y = soa(rot)
    info = information(rot, y)
    ext = _observability(rot, y, info)
    m_inv = info.m_inv()
    warnings: list[str] = []

    fit = _lstsq_core(info, m_inv, rot, f) if method == "lstsq" or test_outliers else None
    if method == "lstsq":
        assert fit is not None  # made above for "lstsq"
        t, r, e = fit.t, fit.r, fit.e
        cov_unit = None
    else:
        if method == "pairwise":
            t, cov_unit = _pairwise_core(rot, f)
        else:
            t, cov_unit, flatness = _sphere_core(rot, f)
            if flatness < COPLANAR_RATIO:
                warnings.append(
                    f"the flange positions are nearly coplanar (thickness / extent = {flatness:.2f}): "
                    "the sphere fit is very sensitive to touch noise here; prefer method 'lstsq'."
                )
        r = info.rbar @ t + sum_over_touches(f) / n  # = mean_i (R_i t + f_i)
        e = rot @ t + (f - r)

    res = _einsum("ni,ni->n", e, e)
    if method == "lstsq" and fit is not None:
        sse = fit.sse
        # a finite SSE = sum |R_i t + d_i - Rbar t|^2 (finite d_i) needs every |R_i t| = |t| and
        # Rbar t finite, so t and r = Rbar t + fbar are finite too: one check for all three
        finite = math.isfinite(sse)
    else:
        sse = float(_add(res))
        finite = math.isfinite(sum(t.tolist()) + sum(r.tolist()) + sse)
    if not finite:
        _check_finite_result(t, r, sse)
    np.sqrt(res, out=res)
    dof = 3 * n - 6
    s_est = math.sqrt(sse / dof)
    noise = s_est if sigma is None else sigma
    if cov_unit is None:
        cov = (noise * noise) * m_inv
    else:
        cov = noise**2 * cov_unit

    outliers: list[int] = (_find_outliers(rot, y, f, (info, fit))
                           if test_outliers and y is not None and fit is not None else [])  # both made above
    without = _without_outliers(rot, f, outliers, method, sigma, res, warnings) if outliers else None
    return _lazy_result(method, t, r, e, res, sse, noise, cov, outliers, without,
                        _Deferred(rot, y, info, ext, noise if cov_unit is None else None, cov,
                                  None if sigma is not None else dof, warnings, sigma, sse, s_est, dof,
                                  detect_outliers))


def _without_outliers(rot: np.ndarray, f: np.ndarray, outliers: list[int], method: str, sigma: float | None,
                      res: np.ndarray, warnings: list[str]) -> TcpResult | None:
    """The same method on the touches not in ``outliers`` (None if they are degenerate), and
    the remarks on the outliers appended to ``warnings`` (``res``: the residual lengths)."""
    keep = np.setdiff1d(np.arange(rot.shape[0]), outliers)
    without: TcpResult | None = None
    try:
        without = _solve(rot[keep], None, f[keep], method, sigma, False)
    except DegenerateTouchesError as exc:
        warnings.append(f"without the outliers the touches are degenerate: {exc}")
    scale = f"noise estimate {without.noise_sigma:.3g}" if without is not None else "the others"
    plural = len(outliers) > 1
    warnings.append(
        f"touch{'es' if plural else ''} {_fmt_idx(outliers)} (0-based) stand{'' if plural else 's'} out "
        f"(residual {', '.join(f'{res[i]:.3g}' for i in outliers)} vs {scale}): probably a careless "
        f"touch; see the result without {'them' if plural else 'it'} (without_outliers), or re-record "
        f"{'them' if plural else 'it'}."
    )
    return without


def _lazy_result(method: str, t: np.ndarray, r: np.ndarray, e: np.ndarray, res: np.ndarray, sse: float,
                 noise: float, cov: np.ndarray | tuple[float, np.ndarray], outliers: list[int],
                 without: TcpResult | None, deferred: _Deferred) -> TcpResult:
    """The :class:`_LazyTcpResult` of a solve; its arrays become read-only (made by the solve
    and shared with nobody: no copy). ``cov``: the covariance, or ``(noise^2, M^-1)`` to make
    it from on its first read."""
    for a in (t, r, e, res):
        a.setflags(write=False)
    n = e.shape[0]
    result = object.__new__(_LazyTcpResult)  # its fields as TcpResult's __init__ sets them, the rest deferred
    fields = {
        "method": method, "tcp": t, "reference": r, "residual_vectors": e, "residuals": res,
        "rms_error": math.sqrt(sse / n), "noise_sigma": float(noise),
        "outliers": tuple(outliers), "without_outliers": without, "n_touches": n, "_deferred": deferred}
    if isinstance(cov, tuple):
        fields["_covariance_of"] = cov
    else:
        cov.setflags(write=False)
        fields["covariance"] = cov
    object.__setattr__(result, "__dict__", fields)
    return result


_SMALL_N = 64
"""Up to this many touches the default estimator's solve is :func:`_solve_lstsq_small`."""


def _solve_lstsq_small(rot: np.ndarray, f: np.ndarray, sigma: float | None, detect_outliers: bool) -> TcpResult:
    """:func:`_solve` with ``method="lstsq"`` for up to ``_SMALL_N`` touches (the wizard's
    case), written as one function: the same arithmetic, in the same order, as
    :func:`tcpcal._stats.information`, :func:`_observability`, ``Information.m_inv`` and
    :func:`_lstsq_core` (a test checks them equal to the last bit), without their calls and
    intermediate tuples; the covariance ``noise^2 M^-1`` is left to its first read
    (:class:`_LazyTcpResult`). At a few touches every numpy call costs more in overhead than in
    arithmetic (~1 us against a few ns), so the count of calls is the cost
    (``tests/bench/bench_solver.py``, tables 2 and 2b)."""
    n = rot.shape[0]
    y = soa(rot) if detect_outliers and n > MIN_TOUCHES else None
    # information(rot, y)
    s = _add(rot, 0) if y is None else y.reshape(9, n).sum(axis=1).reshape(3, 3)
    info = information_from_sum(s, n)
    w, v = info.eigvals, info.eigvecs
    # _observability(rot, y, info): the pretest of the largest off-diagonal Gram entry
    ext: AngleExtremes | None = None
    if math.sqrt(w.item(0) / n) >= DEGENERATE_TILT_RAD:  # info.observable
        x = rot.reshape(n, 9)
        g = _dot(x, x.T)
        g -= _three_eye(n)
        if not float(_max(g, None)) < _DUPLICATE_PRETEST_TRACE:
            ext = angle_extremes(rot, y)
            _check_observable(rot, info, ext)
    else:
        ext = angle_extremes(rot, y)
        _check_observable(rot, info, ext)  # raises
    m_inv = _dot(v / w, v.T)  # info.m_inv()
    fit = _lstsq_core(info, m_inv, rot, f)
    t, r, e, sse, _ = fit
    # the rest of _solve for lstsq
    res = _einsum("ni,ni->n", e, e)
    if not math.isfinite(sse):  # see _solve: one check for t, r and the SSE
        _check_finite_result(t, r, sse)
    np.sqrt(res, out=res)
    dof = 3 * n - 6
    s_est = math.sqrt(sse / dof)
    noise = s_est if sigma is None else sigma
    warnings: list[str] = []
    outliers = _find_outliers(rot, y, f, (info, fit)) if y is not None else []
    without = _without_outliers(rot, f, outliers, "lstsq", sigma, res, warnings) if outliers else None
    return _lazy_result("lstsq", t, r, e, res, sse, noise, (noise * noise, m_inv), outliers, without,
                        _Deferred(rot, y, info, ext, noise, None, None if sigma is not None else dof, warnings,
                                  sigma, sse, s_est, dof, detect_outliers))


def solve_reference(
    known_tcp: np.ndarray,
    rotation_known: np.ndarray,
    position_known: np.ndarray,
    rotation_new: np.ndarray,
    position_new: np.ndarray,
    *,
    sigma: float | None = None,
) -> TcpResult:
    """XYZ reference method (methods.md section 3, (REF-1)).

    A tool with known TCP ``t_1`` touches a reference point at flange pose
    ``(R_1, f_1)``: ``r = R_1 t_1 + f_1``. The new tool touches the same point at ``(R_2, f_2)``:
    ``t_2 = R_2^T (r - f_2)``.

    There is no redundancy: residuals are zero by construction and the noise cannot be
    estimated. With a given ``sigma`` (per-axis noise of each touch) the covariance is
    ``2 sigma^2 I`` (``t_2`` error ``= R_2^T (eps_1 - eps_2)``), not counting ``t_1``'s own error.

    Args:
        known_tcp: (3,) TCP of the calibrated tool, FLANGE coordinates.
        rotation_known: (3, 3) ``R_world_flange`` of the calibrated tool's touch.
        position_known: (3,) ``p_world_flange`` of that touch.
        rotation_new: (3, 3) ``R_world_flange`` of the new tool's touch.
        position_new: (3,) ``p_world_flange`` of that touch.
        sigma: per-axis touch noise (length unit), optional.

    Returns:
        :class:`TcpResult` with ``method="reference"``, ``n_touches=2``; ``noise_sigma``,
        ``covariance`` and ``ci95_radius`` are NaN when ``sigma`` is None.
    """
    t1 = as_vector3(known_tcp, name="known_tcp")
    r1 = as_rotation(rotation_known, name="rotation_known")
    f1 = as_vector3(position_known, name="position_known")
    r2 = as_rotation(rotation_new, name="rotation_new")
    f2 = as_vector3(position_new, name="position_new")
    s_given = _check_sigma(sigma)
    ref = r1 @ t1 + f1
    t2 = r2.T @ (ref - f2)
    angle = math.degrees(angle_between(r1, r2))
    warnings = [
        (
            "reference method: one touch per tool and no redundancy, so the residuals are zero by "
            "construction; the TCP error is the sum of both touches' errors and of the known "
            "TCP's own error. Check the result, e.g. with a 4-point calibration."
        )
    ]
    if s_given is None:
        cov = np.full((3, 3), math.nan)
        ci95 = math.nan
        noise = math.nan
        warnings.append("no sigma given: the uncertainty of the TCP cannot be estimated from one touch per tool.")
    else:
        cov = 2.0 * s_given**2 * np.eye(3)
        ci95 = ci_radius(np.full(3, 2.0 * s_given**2), None)
        noise = s_given
    zeros = np.zeros((2, 3))
    return TcpResult(
        method="reference",
        tcp=read_only_array(t2),
        reference=read_only_array(ref),
        residual_vectors=read_only_array(zeros),
        residuals=read_only_array(np.zeros(2)),
        mean_error=0.0,
        max_error=0.0,
        rms_error=0.0,
        noise_sigma=noise,
        covariance=read_only_array(cov),
        ci95_radius=ci95,
        max_angle_deg=angle,
        min_angle_deg=angle,
        condition_number=1.0,
        outliers=(),
        without_outliers=None,
        warnings=tuple(warnings),
        n_touches=2,
        max_angle_upper_deg=angle,
    )
