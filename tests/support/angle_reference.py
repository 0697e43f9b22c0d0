"""Exact angle figures of many touches, the reference of the tests of ``tcpcal._stats.angle_extremes``.

Above ``EXACT_ANGLES_MAX_N`` touches the library estimates both angles from a sample and one
pass (``tcpcal._stats._angle_extremes_sampled``); :func:`angle_extremes_large` finds them in
O(N log N) time and O(N) memory: the smallest exactly by a KD-tree nearest-pair search over unit
quaternions, the largest by bound and prune (exact unless it says otherwise). Angles in degrees.
"""

from __future__ import annotations

import math
from typing import cast

import numpy as np
from scipy.spatial import cKDTree

from tcpcal._stats import EXACT_ANGLES_MAX_N, AngleExtremes, _pair_angles_deg

_CHUNK_ROWS = 65536
"""Rows per chunk of the O(N m) passes of :func:`angle_extremes_large` (keeps memory O(N))."""
_N_RANDOM_CENTRES = 16
_N_SWEEPS = 4


def quaternions(rotations: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(w, x, y, z)`` of proper rotations (N, 3, 3), folded to ``w >= 0``.

    Shepperd's method, element-wise (no Python loop): the largest of ``4w^2 = 1 + tr R``,
    ``4x^2 = 1 + 2 R_00 - tr R``, ... picks the stable formula per row. ``q`` and ``-q`` are the
    same rotation; the rotation angle between two rotations is ``2 acos |q_a . q_b|`` =
    ``4 asin(|q_a - s q_b| / 2)`` with the sign ``s`` that makes the distance smallest.
    """
    n = rotations.shape[0]
    r = rotations.reshape(n, 9)
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = (r[:, k] for k in range(9))
    tr = r00 + r11 + r22
    cand = np.stack([1.0 + tr, 1.0 + 2.0 * r00 - tr, 1.0 + 2.0 * r11 - tr, 1.0 + 2.0 * r22 - tr], axis=1)
    k = cand.argmax(axis=1)
    q = np.empty((n, 4))
    for case in range(4):
        m = k == case
        if not m.any():
            continue
        s = 2.0 * np.sqrt(np.maximum(cand[m, case], 1e-300))  # = 4 |component|
        if case == 0:
            q[m] = np.stack([s / 4, (r21[m] - r12[m]) / s, (r02[m] - r20[m]) / s, (r10[m] - r01[m]) / s], 1)
        elif case == 1:
            q[m] = np.stack([(r21[m] - r12[m]) / s, s / 4, (r01[m] + r10[m]) / s, (r02[m] + r20[m]) / s], 1)
        elif case == 2:
            q[m] = np.stack([(r02[m] - r20[m]) / s, (r01[m] + r10[m]) / s, s / 4, (r12[m] + r21[m]) / s], 1)
        else:
            q[m] = np.stack([(r10[m] - r01[m]) / s, (r02[m] + r20[m]) / s, (r12[m] + r21[m]) / s, s / 4], 1)
    q /= np.sqrt(np.einsum("ij,ij->i", q, q))[:, None]
    q[q[:, 0] < 0.0] *= -1.0
    return q


def _exact_duplicate_pair(q: np.ndarray) -> tuple[int, int] | None:
    """A pair of touches with bit-identical quaternions (same rotation matrix), or None.
    O(N log N): sort by a random projection, compare neighbours with equal keys."""
    key = q @ np.array([0.5773502691896258, 0.4472135954999579, 0.3779644730092272, 0.5773502691896257])
    order = np.argsort(key, kind="stable")
    ks = key[order]
    same = np.flatnonzero(ks[1:] == ks[:-1])
    if same.size:
        qs0, qs1 = q[order[same]], q[order[same + 1]]
        eq = np.flatnonzero((qs0 == qs1).all(axis=1))
        if eq.size:
            k = same[eq[0]]
            i, j = int(order[k]), int(order[k + 1])
            return (min(i, j), max(i, j))
    return None


def _nearest_pair(q: np.ndarray) -> tuple[int, int]:
    """The two touches whose orientations are closest (exact), for quaternions folded to
    ``w >= 0`` without bit-identical duplicates.

    A KD-tree over the folded quaternions; an upper bound ``delta`` on the smallest chord
    comes from the nearest neighbours of a sample of touches, then every touch's nearest
    neighbour is searched within ``delta`` only (cheap: the search stops at ``delta``). Two
    rotations near ``w = 0`` may be closest through the sign flip: a touch with ``w_i > delta``
    cannot be within ``delta`` of a flipped one (``|-q_i - q_j| >= w_i + w_j``), so only touches
    with ``w_i <= delta`` are searched again as ``-q_i``.
    """
    n = q.shape[0]
    tree = cKDTree(q, leafsize=16, balanced_tree=False, compact_nodes=False)
    rng = np.random.default_rng(0)
    sample = rng.choice(n, size=min(n, 2048), replace=False)
    # A 2-D query gives (m, k) arrays (the stubs also allow the scalars of a 1-D query).
    d, idx = cast("tuple[np.ndarray, np.ndarray]", tree.query(q[sample], k=2))
    own = idx[:, 0] == sample
    nd = np.where(own, d[:, 1], d[:, 0])
    ni = np.where(own, idx[:, 1], idx[:, 0])
    k = int(nd.argmin())
    best_d, best = float(nd[k]), (int(sample[k]), int(ni[k]))
    bound = best_d * (1.0 + 1e-9) + 1e-300
    for start in range(0, n, _CHUNK_ROWS):
        rows = np.arange(start, min(start + _CHUNK_ROWS, n))
        d, idx = cast("tuple[np.ndarray, np.ndarray]", tree.query(q[rows], k=2, distance_upper_bound=bound))
        own = idx[:, 0] == rows
        nd = np.where(own, d[:, 1], d[:, 0])
        ni = np.where(own, idx[:, 1], idx[:, 0])
        k = int(nd.argmin())
        if float(nd[k]) < best_d:
            best_d, best = float(nd[k]), (int(rows[k]), int(ni[k]))
    edge = np.flatnonzero(q[:, 0] <= bound)
    if edge.size:
        d, idx = cast("tuple[np.ndarray, np.ndarray]", tree.query(-q[edge], k=1, distance_upper_bound=bound))
        k = int(d.argmin())
        if float(d[k]) < best_d:
            best_d, best = float(d[k]), (int(edge[k]), int(idx[k]))
    i, j = best
    return (min(i, j), max(i, j))


def _angles_to(q: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Rotation angles (rad) between every row of ``q`` (N, 4) and every row of ``c`` (m, 4)."""
    dots = np.abs(q @ c.T)
    np.minimum(dots, 1.0, out=dots)
    angles: np.ndarray = 2.0 * np.arccos(dots)
    return angles


def angle_extremes_large(rotations: np.ndarray) -> AngleExtremes:
    """``tcpcal._stats.angle_extremes`` for many touches in O(N log N) time and O(N) memory
    (tens of ms at 10^4 touches), the reference of the library's sampled estimates above
    ``EXACT_ANGLES_MAX_N`` touches: the smallest angle exact, the largest exact unless flagged
    (``max_exact``).

    Smallest angle (exact): bit-identical rotations give 0 (found by sorting); otherwise the
    nearest pair of the quaternions with sign folding (:func:`_nearest_pair`).

    Largest angle (bound and prune): the rotation angle is a metric on SO(3). For a few
    centres ``c`` (touch 0, touches found by farthest-point sweeps, random touches, and the
    principal direction of the quaternions, which need not be a touch) one pass computes
    every touch's angle to every centre, ``d(j, c)``, and each touch centre's eccentricity
    ``e(c) = max_j d(c, j)``. ``L = max e(c)`` over the touch centres is attained by a pair.
    By the triangle inequality ``d(i, j) <= d(i, c) + e(c)`` for every ``c``, so a touch can
    belong to a pair farther apart than ``L`` only if ``u_j = min_c (d(j, c) + e(c)) > L``,
    and ``U = max_j u_j`` bounds the largest angle from above. When at most
    ``EXACT_ANGLES_MAX_N`` touches have ``u_j > L`` every pair among them is looked at and the
    result is exact; otherwise ``L`` is returned as an estimate with ``max_upper_deg = U``.
    """
    n = rotations.shape[0]
    x = rotations.reshape(n, 9)
    q = quaternions(rotations)
    dup = _exact_duplicate_pair(q)
    min_pair = dup if dup is not None else _nearest_pair(q)

    # --- largest angle: centres
    rng = np.random.default_rng(1)
    touch_centres = [0]
    c = 0
    for _ in range(_N_SWEEPS):  # farthest-point sweeps (the double-sweep heuristic)
        c = int(np.abs(q @ q[c]).argmin())
        if c in touch_centres:
            break
        touch_centres.append(c)
    touch_centres += [int(i) for i in rng.choice(n, size=min(n, _N_RANDOM_CENTRES), replace=False)]
    touch_centres = list(dict.fromkeys(touch_centres))
    _, vecs = np.linalg.eigh(q.T @ q)  # sign-invariant "mean" orientation
    centres = np.vstack([q[touch_centres], vecs[:, -1]])
    m_touch = len(touch_centres)
    ecc = np.zeros(len(centres))
    far = np.zeros(len(centres), dtype=np.int64)
    for start in range(0, n, _CHUNK_ROWS):
        ang = _angles_to(q[start : start + _CHUNK_ROWS], centres)
        k = ang.argmax(axis=0)
        v = ang[k, np.arange(len(centres))]
        better = v > ecc
        ecc[better] = v[better]
        far[better] = k[better] + start
    slack = 1e-7  # rad: rounding of arccos near 1 (~1e-8) with a margin
    k = int(ecc[:m_touch].argmax())
    lower = float(ecc[k])
    max_pair = (touch_centres[k], int(far[k]))
    upper = 0.0
    cand_parts = []
    for start in range(0, n, _CHUNK_ROWS):
        ang = _angles_to(q[start : start + _CHUNK_ROWS], centres)
        ang += ecc
        u = ang.min(axis=1)
        upper = max(upper, float(u.max()))
        cand_parts.append(np.flatnonzero(u > lower - slack) + start)
    cand = np.concatenate(cand_parts)
    upper = min(upper + slack, math.pi)
    exact = cand.size <= EXACT_ANGLES_MAX_N
    if exact and cand.size >= 2:
        qc = q[cand]
        g = np.abs(qc @ qc.T)
        kk = int(g.argmin())
        a, b = divmod(kk, cand.size)
        if a != b and 2.0 * math.acos(min(float(g.item(kk)), 1.0)) > lower:
            max_pair = (int(cand[a]), int(cand[b]))
    a, b = min(max_pair), max(max_pair)
    if a == b:  # every orientation the same
        a, b = (0, 1)
    min_deg, max_deg = _pair_angles_deg(x, min_pair, (a, b))
    upper_deg = max_deg if exact else max(max_deg, math.degrees(upper))
    return AngleExtremes(min_deg=min_deg, max_deg=max_deg, min_pair=min_pair, max_pair=(a, b),
                         max_exact=exact, max_upper_deg=upper_deg)
