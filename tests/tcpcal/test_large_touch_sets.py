"""solve_xyz4 on recorded tracker data: the O(N log N) angle figures and the
O(N) duplicate check equal the exact O(N^2) ones; 1e5 touches with a repeated orientation
fail or solve cleanly in modest memory; a slow continuous motion is not "one orientation".
"""

from __future__ import annotations

import math
import time
import tracemalloc

import numpy as np
import pytest
from support.angle_reference import angle_extremes_large, quaternions
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tcpcal import _stats
from tcpcal._stats import (
    EXACT_ANGLES_MAX_N,
    SAMPLED_ANGLES_ABOVE_N,
    _angle_extremes_sampled,
    angle_extremes,
    distinct_orientations,
)
from tcpcal.errors import DegenerateTouchesError
from tcpcal.origin import solve_xyz4
from tcpcal.report import format_tcp_report, tcp_result_to_dict


def brute_angles_deg(rot: np.ndarray) -> tuple[float, float]:
    """Smallest and largest angle over every pair, from the relative rotations (scipy)."""
    n = len(rot)
    i, j = np.triu_indices(n, 1)
    ang = np.degrees(Rotation.from_matrix(np.einsum("nki,nkj->nij", rot[i], rot[j])).magnitude())
    return float(ang.min()), float(ang.max())


def brute_distinct(rot: np.ndarray, tol_deg: float) -> tuple[int, tuple[int, int] | None]:
    """The greedy definition of distinct_orientations, touch by touch (O(N^2))."""
    leaders: list[int] = []
    first = None
    for j in range(len(rot)):
        near = [i for i in leaders
                if np.degrees(Rotation.from_matrix(rot[i].T @ rot[j]).magnitude()) < tol_deg]
        if near:
            first = first or (near[0], j)
        else:
            leaders.append(j)
    return len(leaders), first


@st.composite
def touch_sets(draw: st.DrawFn) -> np.ndarray:
    """Random orientations with near-duplicates, exact duplicates and pairs near 180 deg
    (quaternions on both sides of w = 0, where the sign folding matters)."""
    seed = draw(st.integers(0, 2**32 - 1))
    n = draw(st.integers(3, 60))
    rng = np.random.default_rng(seed)
    kind = draw(st.sampled_from(["uniform", "cap", "half-turns"]))
    if kind == "uniform":
        r = Rotation.random(n, random_state=rng)
    elif kind == "cap":
        r = Rotation.from_rotvec(rng.normal(size=(n, 3)) * draw(st.floats(1e-4, 0.5)))
    else:  # rotations of ~180 deg: w ~ 0, q and -q both close to other touches
        axes = rng.normal(size=(n, 3))
        axes /= np.linalg.norm(axes, axis=1)[:, None]
        r = Rotation.from_rotvec(axes * (math.pi - rng.uniform(0, 1e-3, (n, 1))))
    rot = r.as_matrix()
    n_near = draw(st.integers(0, 5))
    for _ in range(n_near):  # near-duplicates, down to 1e-6 deg, and exact duplicates
        a, b = rng.integers(0, n, 2)
        eps = draw(st.sampled_from([0.0, 1e-8, 1e-5, 1e-3]))
        rot[b] = (Rotation.from_matrix(rot[a]) * Rotation.from_rotvec(rng.normal(size=3) * eps)).as_matrix()
    return rot


@settings(max_examples=150, deadline=None)
@given(touch_sets())
def test_large_path_equals_every_pair(rot: np.ndarray) -> None:
    exact = angle_extremes(rot)  # N <= 60: every pair (the Gram path of before)
    fast = angle_extremes_large(rot)  # the exact O(N log N) search (the estimates' reference)
    lo, hi = brute_angles_deg(rot)
    # The every-pair path picks the closest pair by the Gram entry trace(R_a^T R_b) = 3 - angle^2
    # + ..., whose rounding (~6e-15) cannot tell apart pairs closer than ~8e-8 rad (4.4e-6 deg);
    # the nearest-neighbour path can, so below that they may name different near-zero pairs.
    assert fast.min_deg == pytest.approx(exact.min_deg, abs=5e-6)
    assert fast.min_deg == pytest.approx(lo, abs=1e-5)
    assert fast.max_exact  # a small set never needs the estimate
    assert fast.max_deg == pytest.approx(exact.max_deg, abs=1e-6)
    assert fast.max_deg == pytest.approx(hi, abs=1e-5)
    # the pairs reported give the angles reported
    for pair, deg in ((fast.min_pair, fast.min_deg), (fast.max_pair, fast.max_deg)):
        a, b = pair
        assert a < b
        # compared as sin(angle / 2) = |R_a - R_b|_F / sqrt(8): near a half-turn asin amplifies
        # the last bit of the Frobenius norm to ~1e-6 deg, whichever order it was summed in
        half = _stats.angle_between(rot[a], rot[b]) / 2.0
        assert math.sin(math.radians(deg) / 2.0) == pytest.approx(math.sin(half), abs=1e-12)


@settings(max_examples=100, deadline=None)
@given(touch_sets(), st.sampled_from([0.05, 1.0, 30.0]))
def test_distinct_orientations_equals_the_touch_by_touch_definition(rot: np.ndarray, tol: float) -> None:
    count, first = brute_distinct(rot, tol)
    got = distinct_orientations(rot, tol, limit=len(rot) + 1)
    assert got.count == count
    assert got.first_repeat == first
    capped = distinct_orientations(rot, tol, limit=4)
    assert capped.count == min(count, 4)


def test_quaternions_give_the_rotation_angle() -> None:
    rot = Rotation.random(500, random_state=3).as_matrix()
    q = quaternions(rot)
    assert (q[:, 0] >= 0).all()
    assert np.allclose(np.abs(np.einsum("ij,ij->i", q, q)), 1.0)
    ref = Rotation.from_matrix(rot).as_quat()[:, [3, 0, 1, 2]]
    assert np.allclose(np.abs(np.einsum("ij,ij->i", q, ref)), 1.0, atol=1e-12)


def test_above_the_threshold_both_angles_are_bracketed_estimates() -> None:
    """N = 1000 uniform orientations (above EXACT_ANGLES_MAX_N, where looking at every pair
    would cost more than the solve): the smallest angle is the angle of an actual pair, at
    least the true one (every pair, blocked Gram), and flagged; the largest within
    [max_deg, max_upper_deg] around the true one."""
    rot = Rotation.random(1000, random_state=5).as_matrix()
    assert len(rot) > EXACT_ANGLES_MAX_N
    fast = angle_extremes(rot)
    x = rot.reshape(len(rot), 9)
    a, b, c, e = _stats._blocked_gram_extremes(x, np.ascontiguousarray(x.T))
    min_deg, max_deg = _stats._pair_angles_deg(x, (c, e), (a, b))
    assert not fast.min_exact and not fast.max_exact
    assert min_deg - 1e-9 <= fast.min_deg < 10.0
    assert fast.max_deg <= max_deg + 1e-9 <= fast.max_upper_deg + 2e-9
    assert max_deg - fast.max_deg < 0.5  # the estimate of a uniform set is close
    (pair_deg,) = _stats._pair_angles_deg(x, fast.min_pair)
    assert pair_deg == fast.min_deg


def test_a_repeated_orientation_above_the_threshold_is_exact_and_still_refused() -> None:
    """600 touches with only 3 distinct orientations: the estimate finds the repeat (0 deg,
    exact), and the solve refuses the set as before (the repeat check does not rely on it)."""
    rng = np.random.default_rng(12)
    three = Rotation.from_rotvec(rng.normal(size=(3, 3)) * 0.6).as_matrix()
    rot = three[np.arange(600) % 3]
    ext = angle_extremes(rot)
    assert ext.min_exact and ext.min_deg == 0.0
    pos = np.array([800.0, 0, 300]) - rot @ np.array([10.0, 20.0, 150.0])
    with pytest.raises(DegenerateTouchesError, match="same orientation"):
        solve_xyz4(rot, pos)


def test_tracker_like_cone_exact_search_gets_an_exact_largest_angle() -> None:
    """Pivoting inside a 30 deg cone (spin about the tool axis within +-20 deg): the exact
    O(N log N) search (angle_extremes_large) prunes to few candidates, so its largest angle
    is exact, equal to the blocked Gram result; the solver's estimate brackets it."""
    rng = np.random.default_rng(11)
    n = 4000
    tilt = np.radians(30.0) * np.sqrt(rng.uniform(0, 1, n))
    az = rng.uniform(0, 2 * np.pi, n)
    spin = np.radians(rng.uniform(-20, 20, n))
    r = (Rotation.from_rotvec(np.c_[np.cos(az) * tilt, np.sin(az) * tilt, np.zeros(n)])
         * Rotation.from_rotvec(np.c_[np.zeros((n, 2)), spin]))
    rot = r.as_matrix()
    exact = angle_extremes_large(rot)
    x = rot.reshape(n, 9)
    a, b, _, _ = _stats._blocked_gram_extremes(x, np.ascontiguousarray(x.T))
    (max_deg,) = _stats._pair_angles_deg(x, (a, b))
    assert exact.max_exact
    assert exact.max_deg == pytest.approx(max_deg, abs=1e-7)
    fast = angle_extremes(rot)
    assert fast.max_deg <= max_deg + 1e-7 <= fast.max_upper_deg + 2e-7


def test_estimated_largest_angle_is_flagged_in_result_json_and_report() -> None:
    rng = np.random.default_rng(2)
    rot = Rotation.random(3000, random_state=rng).as_matrix()
    pos = np.array([800.0, 0, 300]) - rot @ np.array([10.0, 20.0, 150.0]) + 0.1 * rng.normal(size=(3000, 3))
    res = solve_xyz4(rot, pos)
    assert not res.max_angle_exact
    assert res.max_angle_deg <= res.max_angle_upper_deg <= 180.0
    d = tcp_result_to_dict(res)
    assert d["max_angle_exact"] is False and d["max_angle_upper_deg"] == res.max_angle_upper_deg
    assert "largest angle >= " in format_tcp_report(res, None, command="solve xyz4")
    assert "(estimate, at most" in format_tcp_report(res, None, command="solve xyz4")
    assert np.allclose(res.tcp, [10.0, 20.0, 150.0], atol=0.05)


def _continuous_sweep(n: int) -> np.ndarray:
    """A slow continuous motion recorded at a high rate: tilt 0 -> 40 deg about X, then
    about Y, 2 * n poses, consecutive poses ~0.02 deg apart."""
    t = np.linspace(0.0, np.radians(40.0), n)
    first = Rotation.from_rotvec(np.c_[t, np.zeros(n), np.zeros(n)])
    second = Rotation.from_rotvec(np.c_[np.zeros(n), t, np.zeros(n)]) * first[-1]
    return np.concatenate([first.as_matrix(), second.as_matrix()])


def test_continuous_motion_counts_as_many_orientations() -> None:
    """Before: every pose within 0.05 deg of the previous one was a duplicate, so a continuous
    recording had "1 distinct orientation" and was refused as degenerate."""
    rot = _continuous_sweep(2000)
    tcp, ref = np.array([5.0, -3.0, 120.0]), np.array([700.0, 50.0, 200.0])
    pos = ref - rot @ tcp
    res = solve_xyz4(rot, pos)
    assert np.allclose(res.tcp, tcp, atol=1e-6)
    assert res.min_angle_deg < 0.05
    assert distinct_orientations(rot, limit=4).count == 4


@pytest.mark.slow
def test_1e5_touches_one_orientation_fail_cleanly_in_modest_memory() -> None:
    """All touches one orientation (the case that asked for a 74.5 GiB matrix before)."""
    n = 100_000
    rot = np.broadcast_to(Rotation.from_euler("ZYX", [10, 20, 170], degrees=True).as_matrix(), (n, 3, 3)).copy()
    pos = np.tile([800.0, 0.0, 300.0], (n, 1))
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(DegenerateTouchesError, match="same orientation"):
            solve_xyz4(rot, pos)
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    assert time.perf_counter() - t0 < 20.0  # generous: a shared CI machine
    assert peak < 300e6, peak  # O(N): the input is 7 MB, an N x N matrix 80 GB


@pytest.mark.slow
def test_1e5_touches_with_a_repeated_orientation_solve() -> None:
    """Half of 1e5 touches repeat one orientation, the rest are diverse: solved, smallest
    angle 0 (the repeated pair), no N x N matrix."""
    n = 100_000
    rng = np.random.default_rng(4)
    rot = Rotation.from_rotvec(rng.normal(size=(n, 3)) * 0.5).as_matrix()
    rot[::2] = rot[0]
    tcp, ref = np.array([5.0, -3.0, 120.0]), np.array([700.0, 50.0, 200.0])
    pos = ref - rot @ tcp + 0.05 * rng.normal(size=(n, 3))
    tracemalloc.start()
    try:
        res = solve_xyz4(rot, pos)
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    assert res.min_angle_deg == 0.0
    assert np.allclose(res.tcp, tcp, atol=0.01)
    assert peak < 600e6, peak


@settings(max_examples=150, deadline=None)
@given(touch_sets())
def test_sampled_estimates_bracket_the_true_angles(rot: np.ndarray) -> None:
    """The estimates used above SAMPLED_ANGLES_ABOVE_N touches, against every pair: the smallest
    is the angle of its (actual) pair and at least the true smallest, exact when it says so;
    the largest is the angle of its pair, in [true largest - ..., max_upper_deg]."""
    est = _angle_extremes_sampled(rot)
    lo, hi = brute_angles_deg(rot)
    assert est.min_deg >= lo - 1e-5
    assert est.max_deg <= hi + 1e-5 and hi <= est.max_upper_deg + 1e-5
    if est.min_exact:
        assert est.min_deg == 0.0 and lo == pytest.approx(0.0, abs=1e-5)
    if est.max_exact:
        assert est.max_deg == pytest.approx(hi, abs=1e-5) and est.max_upper_deg == est.max_deg
    for pair, deg in ((est.min_pair, est.min_deg), (est.max_pair, est.max_deg)):
        a, b = pair
        assert a < b
        half = _stats.angle_between(rot[a], rot[b]) / 2.0
        assert math.sin(math.radians(deg) / 2.0) == pytest.approx(math.sin(half), abs=1e-12)


def test_above_the_sampling_threshold_both_angles_are_flagged_estimates() -> None:
    """120,000 uniform orientations: both figures estimated (the smallest an upper bound of the
    true one, said so in the result, the JSON and the report), the TCP as without them."""
    n = SAMPLED_ANGLES_ABOVE_N + 20_000
    rng = np.random.default_rng(8)
    rot = Rotation.random(n, random_state=rng).as_matrix()
    tcp = np.array([10.0, 20.0, 150.0])
    pos = np.array([800.0, 0, 300]) - rot @ tcp + 0.1 * rng.normal(size=(n, 3))
    res = solve_xyz4(rot, pos)
    assert not res.min_angle_exact and not res.max_angle_exact
    exact = angle_extremes_large(rot)                   # the exact search of up to 1e5 touches
    assert exact.min_deg <= res.min_angle_deg < 5.0      # uniform: the sample's closest pair is close
    assert res.max_angle_deg <= exact.max_upper_deg and res.max_angle_deg > 170.0
    assert res.max_angle_deg <= res.max_angle_upper_deg <= 180.0
    d = tcp_result_to_dict(res)
    assert d["min_angle_exact"] is False and d["max_angle_exact"] is False
    text = format_tcp_report(res, None, command="solve xyz4")
    assert "smallest <= " in text and "deg (estimate)" in text
    assert np.allclose(res.tcp, tcp, atol=0.01)


def test_above_the_sampling_threshold_a_repeated_orientation_is_exact() -> None:
    """Half the touches one orientation: the sample holds the repeated pair, so the smallest
    angle is 0 and exact."""
    n = SAMPLED_ANGLES_ABOVE_N + 20_000
    rng = np.random.default_rng(9)
    rot = Rotation.from_rotvec(rng.normal(size=(n, 3)) * 0.5).as_matrix()
    rot[::2] = rot[0]
    ext = angle_extremes(rot)
    assert ext.min_exact and ext.min_deg == 0.0
    assert ext.max_deg <= ext.max_upper_deg


def test_above_the_threshold_a_close_pair_far_apart_in_recording_order_is_found() -> None:
    """600 uniform orientations with touch 450 re-recorded 0.2 deg from touch 17: the sample of
    consecutive pairs cannot hold that pair, the neighbours along the projection do, so the
    estimate names it (still flagged: nothing proves it the smallest)."""
    rng = np.random.default_rng(21)
    r = Rotation.random(600, random_state=rng)
    rot = r.as_matrix()
    rot[450] = (r[17] * Rotation.from_rotvec([0.0, math.radians(0.2), 0.0])).as_matrix()
    lo, _ = brute_angles_deg(rot)
    ext = angle_extremes(rot)
    assert lo == pytest.approx(0.2, abs=1e-9)
    assert ext.min_pair == (17, 450) and ext.min_deg == pytest.approx(0.2, abs=1e-9)
    assert not ext.min_exact
