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
from typing import NamedTuple

import numpy as np
from scipy.special import chdtri, fdtri

from tcpcal import _lapack

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
_dot = _lapack.dot  # small 2-D products: less Python dispatch than the @ operator (hot path)


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
        total: np.ndarray = np.add.reduce(a, axis=0)
        return total
    total = np.ones(n) @ a.reshape(n, -1)
    return total.reshape(a.shape[1:])


class Information(NamedTuple):
    """The TCP information matrix ``M`` of a set of touches and its eigen-decomposition
    (immutable; a named tuple rather than a frozen dataclass: every solve makes one, and a
    tuple is made in a fraction of the time)."""

    n: int
    rbar: np.ndarray  # (3,3) mean of the R_i (not a rotation)
    m: np.ndarray  # (3,3) M = N I - S^T S / N = sum (R_i - Rbar)^T (R_i - Rbar)
    eigvals: np.ndarray  # (3,) ascending eigenvalues of M (clipped at 0)
    eigvecs: np.ndarray  # (3,3) columns: eigenvectors of M, FLANGE coordinates

    @property
    def weakest_tilt_rad(self) -> float:
        """RMS spread of the orientations about the weakest flange direction,
        ``sqrt(min eig M / N)`` (radians, approximately)."""
        return math.sqrt(self.eigvals.item(0) / self.n)

    @property
    def weakest_axis(self) -> np.ndarray:
        """Unit eigenvector of the smallest eigenvalue of ``M`` (FLANGE coordinates), sign
        chosen so that its largest component is positive."""
        v = self.eigvecs[:, 0].copy()
        if v[np.argmax(np.abs(v))] < 0:
            v = -v
        axis: np.ndarray = v + 0.0  # no negative zeros in messages
        return axis

    @property
    def observable(self) -> bool:
        """Whether the touches determine the TCP (weakest tilt >= ``DEGENERATE_TILT_RAD``)."""
        return self.n >= 2 and self.weakest_tilt_rad >= DEGENERATE_TILT_RAD

    def m_inv(self) -> np.ndarray:
        """``M^-1 = ((A^T A)^-1)_tt`` from the eigen-decomposition (observable sets only)."""
        v = self.eigvecs
        m_inv: np.ndarray = _dot(v / self.eigvals, v.T)
        return m_inv

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


_N_CONSTANTS: dict[int, tuple[np.ndarray, np.ndarray]] = {}
"""``(N I, N)`` for small N: the 3x3 matrix ``N I`` and N as a 0-d float array (dividing by a
0-d array is the same IEEE division as by the number, with less of numpy's scalar handling),
made once (hot path)."""


def _n_constants(n: int) -> tuple[np.ndarray, np.ndarray]:
    found = _N_CONSTANTS.get(n)
    if found is not None:
        return found
    n_eye, n_0d = _EYE3 * n, np.array(float(n))
    if n <= 64:
        n_eye.setflags(write=False)
        n_0d.setflags(write=False)
        _N_CONSTANTS[n] = (n_eye, n_0d)
    return n_eye, n_0d


def information_from_sum(s: np.ndarray, n: int) -> Information:
    """:class:`Information` from ``S = sum_i R_i`` (3x3) and N: ``M = N I - S^T S / N``."""
    n_eye, n_0d = _n_constants(n)
    rbar = s / n_0d
    m = _dot(s.T, rbar)
    np.subtract(n_eye, m, out=m)
    w, v = _lapack.eigh(m)
    if w.item(0) < 0.0:  # rounding of a (numerically) singular M
        w = np.maximum(w, 0.0)
    return Information(n, rbar, m, w, v)  # positional: a third of the time of keywords


def information(rotations: np.ndarray, rotations_soa: np.ndarray | None = None) -> Information:
    """Information matrix ``M`` of the TCP for touches with rotations ``R_i`` (methods.md
    (4P-3), Schur complement of ``A^T A``): ``M = N I - S^T S / N``. O(N), no 3N x 6 matrix.
    ``rotations_soa`` (``soa(rotations)``), if given, makes the sum contiguous."""
    n = rotations.shape[0]
    if rotations_soa is not None:
        s = rotations_soa.reshape(9, n).sum(axis=1).reshape(3, 3)
    elif n <= 64:
        s = np.add.reduce(rotations, axis=0)  # sum_over_touches, inlined (hot path)
    else:
        s = sum_over_touches(rotations)
    return information_from_sum(s, n)


def ci_radius(cov_eigvals: np.ndarray | list[float], dof: float | None, confidence: float = CONFIDENCE) -> float:
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
    """Smallest and largest rotation angle between two touch orientations (degrees) and the
    pairs (0-based touch indices) that give them.

    ``min_deg`` is exact when ``min_exact`` (always up to ``EXACT_ANGLES_MAX_N`` touches);
    otherwise it is the angle of the actual pair ``min_pair``, an upper bound of the smallest.
    ``max_deg`` is exact when ``max_exact`` (always up to ``EXACT_ANGLES_MAX_N`` touches);
    otherwise it is a lower bound attained by the pair ``max_pair`` and the true largest angle
    lies in ``[max_deg, max_upper_deg]``.
    """

    min_deg: float
    max_deg: float
    min_pair: tuple[int, int]
    max_pair: tuple[int, int]
    max_exact: bool = True
    max_upper_deg: float = math.nan  # upper bound of the largest angle (= max_deg when exact)
    min_exact: bool = True


_GRAM_SMALL = 128
"""Up to this many touches :func:`angle_extremes` forms the whole N x N Gram matrix."""
_GRAM_BLOCK_ENTRIES = 16384
"""Entries per Gram block above ``_GRAM_SMALL`` (128 kB: stays in cache; and a product of
``rows x cols x 9`` multiply-adds small enough that OpenBLAS runs it on one thread: measured
on the 2-core machine the benchmark runs on, multi-threaded blocks of 128 x 1000 were up to
40x slower whenever other processes kept the second core busy, and blocks of 16k-32k entries
were the fastest, single- or multi-threaded)."""
EXACT_ANGLES_MAX_N = 512
"""Up to this many touches :func:`angle_extremes` looks at every pair (blocked Gram matrix,
O(N^2) time, O(N) memory; measured at N = 512 about half the time of the solve, at N = 1000
already about twice it). Above, both angles come from a sample and one O(N) pass
(:func:`_angle_extremes_sampled`, less time than the solve at any N): the smallest exact only
when it is 0, the largest exact when its bounds meet; otherwise each is a flagged estimate."""
SAMPLED_ANGLES_ABOVE_N = EXACT_ANGLES_MAX_N
"""Above this many touches the angle figures may be estimates (``min_exact`` / ``max_exact``
False); the same threshold as ``EXACT_ANGLES_MAX_N``, named for what callers of the smallest
angle ask (``TcpResult.min_angle_exact``). The exact reference of both angles for many
touches, an O(N log N) search, lives with the tests (``tests/support/angle_reference.py``)."""
_SAMPLE_PAIRS = 512
"""Most consecutive pairs of touches in the sample of :func:`_angle_extremes_sampled`."""
SAMPLED_PROJECTION_MAX_N = 20_000
"""Up to this many touches :func:`_angle_extremes_sampled` also looks at neighbours along a
projection for the smallest angle (a sort and a gather of every touch: measured 0.3-0.5 x the
solve up to here, but up to ~0.9 x at 10^5 touches on a busy machine, where the arrays leave
the cache)."""
_PROJECTION_NEIGHBOURS = 4
"""Neighbours in the projected order whose pairs :func:`_projected_neighbours_best` looks at."""
_PROJECTION = np.array([0.39, -0.27, 0.21, 0.33, 0.41, -0.19, 0.29, -0.36, 0.45])
_PROJECTION /= math.sqrt(float(_PROJECTION @ _PROJECTION))
_PROJECTION.setflags(write=False)
"""A fixed generic unit direction in the 9-space of flattened rotations."""
_SAMPLE_PAIRS_PER_TOUCH = 1 / 16
"""Sample pairs per touch below ``_SAMPLE_PAIRS`` (the sample's every-pair look costs
O(sample^2): a few percent of the solve at 1000 touches)."""
_PAIR_OFFSETS = np.array([0, 1])
_PASS_ROWS = 8192
"""Rows per block of the one pass of :func:`_angle_extremes_sampled` (a block's product with
the two centres stays single-threaded in OpenBLAS and in cache)."""


def angle_extremes(rotations: np.ndarray, rotations_soa: np.ndarray | None = None, *,
                   gram: np.ndarray | None = None) -> AngleExtremes:
    """Smallest and largest rotation angle between two of the orientations (degrees).

    Up to ``EXACT_ANGLES_MAX_N`` touches every pair is looked at: ``trace(R_a^T R_b) = 1 + 2
    cos(angle)`` = the dot product of the flattened rotations finds the two pairs (largest
    trace = smallest angle and vice versa), whose angles are then recomputed as ``2 asin(|R_a -
    R_b|_F / (2 sqrt 2))`` (:func:`angle_between`, accurate for small angles). Up to
    ``_GRAM_SMALL`` touches the whole N x N Gram matrix is formed; above, its upper triangle in
    blocks of rows (``_GRAM_BLOCK_ENTRIES``), each reduced to its minimum and maximum. Ties
    resolve to the first pair in row-major order in both cases.

    Above ``EXACT_ANGLES_MAX_N`` touches (many touches, recorded tracker data) both come from
    a sample and O(N) passes in at most the time of the solve's least squares
    (:func:`_angle_extremes_sampled`), each flagged when it is an estimate: ``min_exact`` False
    (the angle of an actual pair, an upper bound of the smallest) unless it is 0, ``max_exact`` False (a lower bound attained by a pair, with the upper bound
    ``max_upper_deg``) unless the bounds meet.

    Args:
        rotations: (N, 3, 3).
        rotations_soa: ``soa(rotations)`` if the caller has it (saves a transposed copy).
        gram: the N x N Gram matrix of the flattened rotations if the caller has it (small N
            only; it is overwritten).
    """
    n = rotations.shape[0]
    if n < 2:
        return AngleExtremes(math.nan, math.nan, (0, 0), (0, 0))
    if n > EXACT_ANGLES_MAX_N and gram is None:
        return _angle_extremes_sampled(rotations)
    x = rotations.reshape(n, 9)
    if n <= _GRAM_SMALL:
        g = _dot(x, x.T) if gram is None else gram
        k_max = int(g.argmin())  # smallest trace = largest angle (diagonal is the maximum 3)
        g.ravel()[:: n + 1] = -np.inf
        k_min = int(g.argmax())
        a, b = divmod(k_max, n)
        c, e = divmod(k_min, n)
        if a == b:  # all orientations equal: argmin hit the diagonal
            a, b = 0, 1
    else:
        xt = rotations_soa.reshape(9, n) if rotations_soa is not None else np.ascontiguousarray(x.T)
        a, b, c, e = _blocked_gram_extremes(x, xt)
    a, b = min(a, b), max(a, b)
    c, e = min(c, e), max(c, e)
    min_deg, max_deg = _pair_angles_deg(x, (c, e), (a, b))
    return AngleExtremes(min_deg=min_deg, max_deg=max_deg, min_pair=(c, e), max_pair=(a, b),
                         max_upper_deg=max_deg)


def _pair_angles_deg(x: np.ndarray, *pairs: tuple[int, int]) -> list[float]:
    """Angles (deg) of index pairs of flattened rotations ``x`` (N, 9), accurate for small angles."""
    v = x.take([p[0] for p in pairs] + [p[1] for p in pairs], axis=0)
    k = len(pairs)
    d = v[:k] - v[k:]
    fro2 = np.einsum("ij,ij->i", d, d).tolist()
    return [math.degrees(2.0 * math.asin(min(math.sqrt(f) / _SQRT8, 1.0))) for f in fro2]


def _blocked_gram_extremes(x: np.ndarray, xt: np.ndarray) -> tuple[int, int, int, int]:
    """Pairs ``(a, b)`` of the smallest and ``(c, e)`` of the largest Gram entry off the
    diagonal, the upper triangle reduced block by block (O(N^2) time, O(N) memory).

    A float32 screen of the blocks (with a rigorous rounding margin, float64 only for the
    entries within it) was measured no faster on the benchmark's sets: near 180 deg the trace
    ``-1 + (pi - angle)^2`` puts hundreds of pairs within the float32 margin of the smallest,
    and the extra comparison pass per block cost what the cheaper products saved."""
    n = x.shape[0]
    lo, hi = math.inf, -math.inf
    a = b = c = e = 0
    i = 0
    while i < n:
        cols = n - i  # columns i.. of rows i..: the upper triangle and the diagonal block
        rows = min(max(_GRAM_BLOCK_ENTRIES // cols, 1), cols)
        blk = _dot(x[i : i + rows], xt[:, i:])
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
    return a, b, c, e


def _angle_extremes_sampled(rotations: np.ndarray) -> AngleExtremes:
    """:func:`angle_extremes` for many touches: estimates in O(N) time, flagged as such.

    The sample: consecutive pairs ``(i, i + 1)``, ``i`` spread evenly (a fixed stride) over the touches (a
    recording's closest orientations are usually consecutive ones; ``N / 16`` pairs, at least
    16, at most ``_SAMPLE_PAIRS``); every pair of the sample is looked at
    (:func:`_blocked_gram_extremes`). Smallest angle: the sample's, or up to
    ``SAMPLED_PROJECTION_MAX_N`` touches the better pair of neighbours along a projection
    (:func:`_projected_neighbours_best`); the angle of an actual pair, so an upper bound of the
    true smallest (exact when it is 0: two identical orientations).
    Largest angle: with ``a, b`` the sample's farthest pair, one pass over every touch finds the
    touch farthest from ``a`` and from ``b`` (smallest trace ``x_j . x_a`` of the flattened
    rotations), so their eccentricities ``e(a), e(b)`` are exact; ``L`` = the largest of the
    three pairs' angles is attained by a pair, and by the triangle inequality every pair is at
    most ``U = 2 min(e(a), e(b))`` apart (capped at 180 deg). Exact when ``L`` reaches ``U``,
    else an estimate in ``[L, U]``.
    """
    n = rotations.shape[0]
    x = rotations.reshape(n, 9)
    n_pairs = min(_SAMPLE_PAIRS, max(int(n * _SAMPLE_PAIRS_PER_TOUCH), 16))
    step = (n - 2) // (n_pairs - 1)  # the starts 0, step, ..., <= n - 2
    if step >= 2:  # disjoint pairs: the touches in ascending order, each once
        idx = (np.arange(0, n_pairs * step, step)[:, None] + _PAIR_OFFSETS).ravel()
    else:  # few touches: pairs overlap
        starts = np.linspace(0, n - 2, n_pairs).round().astype(np.intp)
        idx = np.unique(np.concatenate([starts, starts + 1]))
    xs = x.take(idx, axis=0)
    a, b, c, e = (int(idx[k]) for k in _blocked_gram_extremes(xs, np.ascontiguousarray(xs.T)))
    centres = np.ascontiguousarray(x[[a, b]].T)  # (9, 2)
    lowest = [math.inf, math.inf]
    far = [a, b]
    for start in range(0, n, _PASS_ROWS):
        tr = _dot(x[start : start + _PASS_ROWS], centres)
        k = tr.argmin(axis=0)
        for col in (0, 1):
            v = float(tr[k[col], col])
            if v < lowest[col]:
                lowest[col] = v
                far[col] = int(k[col]) + start
    min_pair = (min(c, e), max(c, e))
    if n <= SAMPLED_PROJECTION_MAX_N:
        min_pair = _projected_neighbours_best(x, min_pair)
    pairs = [(min(a, b), max(a, b)), (min(a, far[0]), max(a, far[0])), (min(b, far[1]), max(b, far[1]))]
    min_deg, *max_degs = _pair_angles_deg(x, min_pair, *pairs)
    k = max(range(3), key=max_degs.__getitem__)  # the first of the largest (np.argmax)
    max_deg, max_pair = float(max_degs[k]), pairs[k]
    if max_pair[0] == max_pair[1]:  # every orientation the same
        max_pair = (0, 1)
    slack_deg = math.degrees(1e-7)  # rounding of the traces and angles, with a margin
    upper_deg = min(2.0 * min(max_degs[1], max_degs[2]) + slack_deg, 180.0)
    max_exact = max_deg >= upper_deg - slack_deg
    return AngleExtremes(min_deg=min_deg, max_deg=max_deg, min_pair=min_pair, max_pair=max_pair,
                         max_exact=max_exact, max_upper_deg=max_deg if max_exact else upper_deg,
                         min_exact=min_deg == 0.0)


def _projected_neighbours_best(x: np.ndarray, pair: tuple[int, int]) -> tuple[int, int]:
    """``pair`` or the better (larger trace ``x_a . x_b``) of the pairs of touches up to
    ``_PROJECTION_NEIGHBOURS`` apart when the touches are sorted by their projection on the
    fixed direction ``_PROJECTION`` (close orientations have close projections: a cheap way to
    find close pairs a sample misses; O(N log N), no N x N matrix). Returned as ``(a, b)``,
    ``a < b``."""
    n = x.shape[0]
    # BLAS gemv while OpenBLAS runs it on one thread (below 9216 entries), else einsum (one
    # thread whatever N: threads are slow when the other core is busy)
    p = _dot(x, _PROJECTION) if 9 * n < 9216 else np.einsum("ij,j->i", x, _PROJECTION)
    order = np.argsort(p)
    xs = x.take(order, axis=0)
    best = float(_dot(x[pair[0]], x[pair[1]]))
    m = _PROJECTION_NEIGHBOURS
    if n <= 2 * m:  # (not reached above EXACT_ANGLES_MAX_N: kept simple)
        return pair
    # one product for the pairs (i, i + k), k = 1..m, i + m < n: rows i + 1 .. i + m of a window
    win = np.lib.stride_tricks.sliding_window_view(xs[1:], m, axis=0)  # (n - m, 9, m)
    tr: np.ndarray = np.einsum("ij,ijk->ik", xs[: n - m], win)
    tail = _dot(xs[n - m :], xs[n - m :].T)  # the pairs among the last m touches
    tail[_LOWER_OR_DIAGONAL[m]] = -math.inf
    i, k = divmod(int(tr.argmax()), m)
    cands = [(float(tr[i, k]), i, i + k + 1)]
    ti, tj = divmod(int(tail.argmax()), m)
    cands.append((float(tail[ti, tj]), n - m + ti, n - m + tj))
    for v, i, j in cands:
        if v > best:
            best = v
            pa, pb = int(order[i]), int(order[j])
            pair = (min(pa, pb), max(pa, pb))
    return pair


_LOWER_OR_DIAGONAL = {4: ~np.triu(np.ones((4, 4), dtype=bool), 1)}
"""Masks of the entries of an m x m block that are not a pair (i < j), for
``_PROJECTION_NEIGHBOURS``."""


@dataclass(frozen=True)
class DistinctOrientations:
    """Result of :func:`distinct_orientations`."""

    count: int  # number of distinct orientations, capped at the ``limit`` asked for
    first_repeat: tuple[int, int] | None  # (i, j): touch j repeats the orientation of touch i


def distinct_orientations(rotations: np.ndarray, tol_deg: float = SAME_ORIENTATION_DEG, *,
                          limit: int = 4) -> DistinctOrientations:
    """How many clearly different orientations the touches have (up to ``limit``).

    Greedy, in recording order: touch 0 is the first distinct orientation; a later touch is a
    new one when it is more than ``tol_deg`` from every distinct orientation found before it,
    otherwise it repeats (the first) one of them. So the distinct orientations are pairwise
    more than ``tol_deg`` apart and every touch is within ``tol_deg`` of one of them (a slow
    continuous motion recorded at a high rate, each pose within ``tol_deg`` of the previous
    one, counts as many orientations, not one). O(N) time at most (``limit`` distinct
    orientations are usually found among the first touches), never an N x N matrix.

    Args:
        rotations: (N, 3, 3), N >= 1.
        tol_deg: two orientations closer than this (degrees) are the same.
        limit: stop counting here (``count`` is exact when below ``limit``).

    Returns:
        The count and the first touch ``j`` (lowest index) that repeats an orientation, with the
        first distinct orientation ``i`` it repeats (None if no touch repeats one before the
        count reached ``limit``).
    """
    n = rotations.shape[0]
    x = rotations.reshape(n, 9)
    thr = 1.0 + 2.0 * math.cos(math.radians(tol_deg))  # trace(R_a^T R_b) above it: same
    leaders = [0]
    first_repeat: tuple[int, int] | None = None
    start = 1
    window = 64  # rows looked at per step, doubled while no new orientation turns up
    while start < n and len(leaders) < limit:
        stop = min(start + window, n)
        close = (x[start:stop] @ x[leaders].T) > thr  # (rows, k <= limit)
        new = np.flatnonzero(~close.any(axis=1))
        if first_repeat is None and (new.size == 0 or new[0] > 0):  # row `start` repeats
            first_repeat = (leaders[int(np.argmax(close[0]))], start)
        if new.size == 0:
            start = stop
            window *= 2
            continue
        leaders.append(start + int(new[0]))
        start = leaders[-1] + 1
    return DistinctOrientations(count=len(leaders), first_repeat=first_repeat)


def fmt_vec(v: np.ndarray) -> str:
    """``[0.00, 0.00, 1.00]`` (a component that rounds to zero prints as ``0.00``, never
    ``-0.00``)."""
    parts = (f"{float(c):.2f}" for c in v)
    return "[" + ", ".join("0.00" if p == "-0.00" else p for p in parts) + "]"
