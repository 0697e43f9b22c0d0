"""Private numerics shared by :mod:`tcpcal.origin` and :mod:`tcpcal.pose_quality`.

The joint system (4P-3) of methods.md stacks ``[R_i  -I] x = -f_i`` for ``x = (t, r)``. Its
normal matrix reduces to sums over the touches::

    A^T A = [[N I, -S^T], [-S, N I]],   S = sum_i R_i

Eliminating ``r`` (Schur complement of the ``N I`` block) leaves the 3x3 information matrix of
the TCP ``t``::

    M = N I - S^T S / N = sum_i D_i^T D_i,   D_i = R_i - Rbar,   Rbar = S / N

so ``((A^T A)^-1)_tt = M^-1`` and the Cramer-Rao bound of methods.md section 7 is
``sigma^2 M^-1``. ``M`` depends on the rotations only. The eigenvalues of ``A^T A`` are
``N +- s_k(S)`` (``s_k`` the singular values of ``S``), which gives the condition number of
``A`` without forming it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import chdtri, fdtri

# A set of touches whose orientations spread by less than this RMS angle (radians) about some
# flange direction cannot determine the TCP along that direction (predicted uncertainty
# > 1000 x the touch noise for 1 touch, ~500 x for 4): treated as degenerate, not just weak.
DEGENERATE_TILT_RAD: float = 1e-3
# Two touch orientations closer than this are "the same orientation" (a duplicated pose).
SAME_ORIENTATION_DEG: float = 0.05
CONFIDENCE: float = 0.95


@dataclass(frozen=True)
class Information:
    """The TCP information matrix ``M`` of a set of touches and its eigen-decomposition."""

    n: int
    rbar: np.ndarray  # (3,3) mean of the R_i (not a rotation)
    m: np.ndarray  # (3,3) M = N I - S^T S / N = sum (R_i - Rbar)^T (R_i - Rbar)
    eigvals: np.ndarray  # (3,) ascending eigenvalues of M (clipped at 0)
    eigvecs: np.ndarray  # (3,3) columns: eigenvectors of M, FLANGE coordinates

    @property
    def weakest_tilt_rad(self) -> float:
        """RMS spread of the orientations about the weakest flange direction,
        ``sqrt(min eig M / N)`` (radians, approximately)."""
        return math.sqrt(self.eigvals[0] / self.n)

    @property
    def weakest_axis(self) -> np.ndarray:
        """Unit eigenvector of the smallest eigenvalue of ``M`` (FLANGE coordinates), sign
        chosen so that its largest component is positive."""
        v = self.eigvecs[:, 0].copy()
        if v[np.argmax(np.abs(v))] < 0:
            v = -v
        return v + 0.0  # no negative zeros in messages

    @property
    def observable(self) -> bool:
        """Whether the touches determine the TCP (weakest tilt >= ``DEGENERATE_TILT_RAD``)."""
        return self.n >= 2 and self.weakest_tilt_rad >= DEGENERATE_TILT_RAD

    def m_inv(self) -> np.ndarray:
        """``M^-1 = ((A^T A)^-1)_tt`` from the eigen-decomposition (observable sets only)."""
        v = self.eigvecs
        return (v / self.eigvals) @ v.T

    @property
    def condition_number(self) -> float:
        """Condition number of the stacked (4P-3) matrix ``A`` (3N x 6) without forming it.

        The eigenvalues of ``A^T A`` are ``N +- s_k(S)``; with ``s_max^2 = N (N - mu_min)``
        (``mu_min`` the smallest eigenvalue of ``M``),
        ``cond(A) = sqrt((N + s_max) / (N - s_max)) = (N + s_max) / sqrt(N mu_min)``.
        """
        n = self.n
        mu = float(self.eigvals[0])
        if mu <= 0.0:
            return math.inf
        s_max = math.sqrt(max(n * (n - mu), 0.0))
        return (n + s_max) / math.sqrt(n * mu)


def information(rotations: np.ndarray) -> Information:
    """Information matrix ``M`` of the TCP for touches with rotations ``R_i`` (methods.md
    (4P-3), Schur complement of ``A^T A``): ``M = N I - S^T S / N``. O(N), no 3N x 6 matrix."""
    n = rotations.shape[0]
    rbar = rotations.sum(axis=0) / n
    m = n * (np.eye(3) - rbar.T @ rbar)
    w, v = np.linalg.eigh(m)
    return Information(n=n, rbar=rbar, m=m, eigvals=np.maximum(w, 0.0), eigvecs=v)


def ci_radius(cov_eigvals: np.ndarray, dof: float | None, confidence: float = CONFIDENCE) -> float:
    """Radius of the sphere about the estimate that holds the true TCP with probability
    ``confidence``.

    The squared error ``|t_hat - t|^2 = sum_k lambda_k z_k^2`` (``lambda_k`` the eigenvalues of
    the covariance, ``z_k`` standard normal) is a weighted chi-square sum. It is approximated by
    a scaled chi-square with the same mean and variance (Welch-Satterthwaite):
    ``c chi2_d``, ``c = sum lambda^2 / sum lambda``, ``d = (sum lambda)^2 / sum lambda^2``.
    When the covariance was scaled by an estimated noise ``s^2`` with ``dof = 3N - 6`` degrees
    of freedom (``s^2 / sigma^2 ~ chi2_dof / dof``, independent of ``t_hat``), the ratio is
    ``c d F(d, dof)``. The 95 % quantile of this approximation is within +0.0 .. +1.5 % of the
    exact quantile of the squared radius (checked by Monte Carlo in the tests; slightly
    conservative).

    Args:
        cov_eigvals: eigenvalues of the TCP covariance (length unit squared).
        dof: degrees of freedom of the noise estimate, or None when sigma is known.
        confidence: coverage probability.

    Returns:
        The radius, in the length unit of the input.
    """
    lam = np.maximum(np.asarray(cov_eigvals, dtype=float), 0.0)
    s1 = float(lam.sum())
    if not math.isfinite(s1):
        return math.inf
    if s1 <= 0.0:
        return 0.0
    s2 = float((lam * lam).sum())
    c = s2 / s1
    d = s1 * s1 / s2
    if dof is None or math.isinf(dof):
        q = c * float(chdtri(d, 1.0 - confidence))
    else:
        q = c * d * float(fdtri(d, dof, confidence))
    return math.sqrt(q)


def angle_between(ra: np.ndarray, rb: np.ndarray) -> float:
    """Rotation angle (radians) of ``R_a^T R_b``, accurate for small angles:
    ``2 asin(|R_a - R_b|_F / (2 sqrt 2))``."""
    diff = ra - rb
    fro = math.sqrt(float((diff * diff).sum()))
    return 2.0 * math.asin(min(fro / (2.0 * math.sqrt(2.0)), 1.0))


@dataclass(frozen=True)
class AngleExtremes:
    min_deg: float
    max_deg: float
    min_pair: tuple[int, int]
    max_pair: tuple[int, int]


def angle_extremes(rotations: np.ndarray) -> AngleExtremes:
    """Smallest and largest rotation angle between two of the orientations (degrees).

    Uses ``trace(R_a^T R_b) = 1 + 2 cos(angle)`` on the Gram matrix of the flattened
    rotations (O(N^2)) to find the two pairs, then recomputes their angles with
    :func:`angle_between`.
    """
    n = rotations.shape[0]
    if n < 2:
        return AngleExtremes(math.nan, math.nan, (0, 0), (0, 0))
    x = rotations.reshape(n, 9)
    g = x @ x.T
    k_max = int(np.argmin(g))  # smallest trace = largest angle (diagonal is the maximum 3)
    g.flat[:: n + 1] = -np.inf
    k_min = int(np.argmax(g))
    a, b = divmod(k_max, n)
    c, e = divmod(k_min, n)
    if a == b:  # all orientations equal: argmin hit the diagonal
        a, b = 0, 1
    a, b = min(a, b), max(a, b)
    c, e = min(c, e), max(c, e)
    return AngleExtremes(
        min_deg=math.degrees(angle_between(rotations[c], rotations[e])),
        max_deg=math.degrees(angle_between(rotations[a], rotations[b])),
        min_pair=(c, e),
        max_pair=(a, b),
    )


def duplicate_orientations(rotations: np.ndarray, tol_deg: float = SAME_ORIENTATION_DEG) -> list[tuple[int, int]]:
    """Pairs ``(i, j)``, ``i < j``, where touch ``j`` has (within ``tol_deg``) the orientation
    of an earlier touch ``i`` (the first such ``i``); one pair per duplicated ``j``."""
    n = rotations.shape[0]
    x = rotations.reshape(n, 9)
    g = x @ x.T
    thr = 1.0 + 2.0 * math.cos(math.radians(tol_deg))
    close = np.triu(g > thr, k=1)
    js = np.flatnonzero(close.any(axis=0))
    return [(int(np.argmax(close[:, j])), int(j)) for j in js]


def fmt_vec(v: np.ndarray) -> str:
    """``[0.00, 0.00, 1.00]``."""
    return "[" + ", ".join(f"{float(c) + 0.0:.2f}" for c in v) + "]"
