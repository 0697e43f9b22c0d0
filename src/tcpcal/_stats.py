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

Speed (the wizard calls this live; ``tests/bench/bench_solver.py`` prints the figures): per-touch
quantities are computed as whole arrays, never in Python loops over touches, and with as few
numpy calls as possible, because for N = 4..20 the cost is the per-call overhead, not the
arithmetic. Per-touch 3x3 algebra (outlier test) uses the "one row per matrix entry" layout
``(3, 3, N)`` (``soa``), whose element-wise operations run over contiguous length-N rows.
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

_EYE3 = np.eye(3)
_EYE3.setflags(write=False)
_SQRT8 = 2.0 * math.sqrt(2.0)


def soa(rotations: np.ndarray) -> np.ndarray:
    """``(3, 3, N)`` contiguous copy of an ``(N, 3, 3)`` stack: ``soa(R)[j, k]`` holds entry
    ``(j, k)`` of every ``R_i``, so per-touch 3x3 algebra becomes element-wise operations on
    contiguous length-N rows (measured 3-4x faster than batched ``(N, 3, 3)`` matmul/einsum
    at N = 1000, and fewer numpy calls at N = 8)."""
    n = rotations.shape[0]
    return np.ascontiguousarray(rotations.reshape(n, 9).T).reshape(3, 3, n)


def sum_over_touches(a: np.ndarray) -> np.ndarray:
    """``sum_i a[i]`` of an (N, ...) array: ``a.sum(axis=0)`` for small N; for large N a
    matrix-vector product with ones (contiguous BLAS; ``sum(axis=0)`` over rows of 3 or 9
    numbers was measured 4x slower at N = 1000)."""
    n = a.shape[0]
    if n <= 64:
        return np.add.reduce(a, axis=0)
    return (np.ones(n) @ a.reshape(n, -1)).reshape(a.shape[1:])


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


def information_from_sum(s: np.ndarray, n: int) -> Information:
    """:class:`Information` from ``S = sum_i R_i`` (3x3) and N: ``M = N I - S^T S / N``."""
    rbar = s / n
    m = s.T @ rbar
    np.subtract(_EYE3 * n, m, out=m)
    w, v = np.linalg.eigh(m)
    if w[0] < 0.0:  # rounding of a (numerically) singular M
        w = np.maximum(w, 0.0)
    return Information(n=n, rbar=rbar, m=m, eigvals=w, eigvecs=v)


def information(rotations: np.ndarray, rotations_soa: np.ndarray | None = None) -> Information:
    """Information matrix ``M`` of the TCP for touches with rotations ``R_i`` (methods.md
    (4P-3), Schur complement of ``A^T A``): ``M = N I - S^T S / N``. O(N), no 3N x 6 matrix.
    ``rotations_soa`` (``soa(rotations)``), if given, makes the sum contiguous."""
    n = rotations.shape[0]
    if rotations_soa is not None:
        s = rotations_soa.reshape(9, n).sum(axis=1).reshape(3, 3)
    else:
        s = sum_over_touches(rotations)
    return information_from_sum(s, n)


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
    # Three numbers: plain Python floats are several times faster than numpy calls here.
    vals = cov_eigvals if isinstance(cov_eigvals, list) else np.ravel(cov_eigvals).tolist()
    lam = [max(float(v), 0.0) for v in vals]  # max(nan, 0) stays nan
    s1 = sum(lam)
    if not math.isfinite(s1):
        return math.inf
    if s1 <= 0.0:
        return 0.0
    s2 = sum(v * v for v in lam)
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
    return 2.0 * math.asin(min(fro / _SQRT8, 1.0))


@dataclass(frozen=True)
class AngleExtremes:
    min_deg: float
    max_deg: float
    min_pair: tuple[int, int]
    max_pair: tuple[int, int]


_GRAM_SMALL = 128
"""Up to this many touches :func:`angle_extremes` forms the whole N x N Gram matrix."""
_GRAM_BLOCK_ENTRIES = 16384
"""Entries per Gram block above ``_GRAM_SMALL`` (128 kB: stays in cache; and a product of
``rows x cols x 9`` multiply-adds small enough that OpenBLAS runs it on one thread: measured
on the 2-core machine the benchmark runs on, multi-threaded blocks of 128 x 1000 were up to
40x slower whenever other processes kept the second core busy, and blocks of 16k-32k entries
were the fastest, single- or multi-threaded)."""


def angle_extremes(rotations: np.ndarray, rotations_soa: np.ndarray | None = None, *,
                   gram: np.ndarray | None = None) -> AngleExtremes:
    """Smallest and largest rotation angle between two of the orientations (degrees).

    Uses ``trace(R_a^T R_b) = 1 + 2 cos(angle)`` = the dot product of the flattened rotations
    to find the two pairs (largest trace = smallest angle and vice versa), then recomputes
    their angles as ``2 asin(|R_a - R_b|_F / (2 sqrt 2))`` (:func:`angle_between`, accurate for
    small angles).

    This is the only O(N^2) figure of the 4-point method: every pair must be looked at (the
    largest angle is the diameter of the set in SO(3); typical touch sets have hundreds of
    pairs within 0.1 deg of the largest angle, so pruning schemes do not pay). Up to
    ``_GRAM_SMALL`` touches the whole N x N Gram matrix is formed; above, its upper triangle in
    blocks of rows (``_GRAM_BLOCK_ENTRIES``), each reduced to its minimum and maximum. Ties
    resolve to the first pair in row-major order in both cases.

    Args:
        rotations: (N, 3, 3).
        rotations_soa: ``soa(rotations)`` if the caller has it (saves a transposed copy).
        gram: the N x N Gram matrix of the flattened rotations if the caller has it (small N
            only; it is overwritten).
    """
    n = rotations.shape[0]
    if n < 2:
        return AngleExtremes(math.nan, math.nan, (0, 0), (0, 0))
    x = rotations.reshape(n, 9)
    if n <= _GRAM_SMALL:
        g = x @ x.T if gram is None else gram
        k_max = int(g.argmin())  # smallest trace = largest angle (diagonal is the maximum 3)
        g.ravel()[:: n + 1] = -np.inf
        k_min = int(g.argmax())
        a, b = divmod(k_max, n)
        c, e = divmod(k_min, n)
        if a == b:  # all orientations equal: argmin hit the diagonal
            a, b = 0, 1
    else:
        xt = rotations_soa.reshape(9, n) if rotations_soa is not None else np.ascontiguousarray(x.T)
        lo, hi = math.inf, -math.inf
        a = b = c = e = 0
        i = 0
        while i < n:
            cols = n - i  # columns i.. of rows i..: the upper triangle and the diagonal block
            rows = min(max(_GRAM_BLOCK_ENTRIES // cols, 1), cols)
            blk = x[i : i + rows] @ xt[:, i:]
            diag = blk.ravel()[: rows * (cols + 1) : cols + 1]  # the pairs (i + k, i + k)
            k = int(blk.argmin())  # the diagonal (trace 3, the largest) only wins a tie
            if k % (cols + 1) == 0:  # ... of identical orientations: look again without it
                diag[:] = np.inf
                k = int(blk.argmin())
            v = blk.item(k)
            if v < lo:
                lo = v
                a, b = divmod(k, cols)
                a, b = a + i, b + i
            diag[:] = -np.inf
            k = int(blk.argmax())
            v = blk.item(k)
            if v > hi:
                hi = v
                c, e = divmod(k, cols)
                c, e = c + i, e + i
            i += rows
    a, b = min(a, b), max(a, b)
    c, e = min(c, e), max(c, e)
    v = x.take((c, a, e, b), axis=0)
    d = v[:2] - v[2:]
    fro2_min, fro2_max = np.einsum("ij,ij->i", d, d).tolist()
    return AngleExtremes(
        min_deg=math.degrees(2.0 * math.asin(min(math.sqrt(fro2_min) / _SQRT8, 1.0))),
        max_deg=math.degrees(2.0 * math.asin(min(math.sqrt(fro2_max) / _SQRT8, 1.0))),
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
    """``[0.00, 0.00, 1.00]`` (a component that rounds to zero prints as ``0.00``, never
    ``-0.00``)."""
    parts = (f"{float(c):.2f}" for c in v)
    return "[" + ", ".join("0.00" if p == "-0.00" else p for p in parts) + "]"
