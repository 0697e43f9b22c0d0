"""Pose quality before solving (tcpcal.pose_quality) against independent computations."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.poses import crb_tcp, random_rotations, tilted_rotations
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

from tcpcal.errors import InvalidInputError
from tcpcal.pose_quality import assess_touches, candidate_gain


def test_predicted_uncertainty_is_sigma_sqrt_trace_crb() -> None:
    rng = np.random.default_rng(0)
    rot = tilted_rotations(rng, 7)
    q = assess_touches(rot, sigma=0.4)
    assert q.observable and q.unobservable_axis is None and q.n_touches == 7
    assert q.predicted_tcp_rms == pytest.approx(math.sqrt(np.trace(crb_tcp(rot, 0.4))), rel=1e-9)


def test_predicted_ci95_isotropic_is_chi2_quantile() -> None:
    rot = Rotation.from_euler("xyz", [[0, 0, 0], [180, 0, 0], [0, 180, 0], [0, 0, 180]], degrees=True).as_matrix()
    q = assess_touches(rot, sigma=1.0)
    var = np.trace(crb_tcp(rot, 1.0)) / 3
    assert q.predicted_ci95_radius == pytest.approx(math.sqrt(var * chi2.ppf(0.95, 3)), rel=1e-9)


def test_single_axis_reports_the_axis() -> None:
    u = np.array([0.0, 0.6, 0.8])
    base = Rotation.from_rotvec([0.2, 0.1, -0.4])
    rot = (base * Rotation.from_rotvec(np.radians([[0], [50], [100], [150], [220]]) * u)).as_matrix()
    q = assess_touches(rot)
    assert not q.observable
    assert math.isinf(q.predicted_tcp_rms) and math.isinf(q.predicted_ci95_radius)
    assert abs(abs(q.unobservable_axis @ u) - 1) < 1e-9
    assert "second axis" in q.message and "flange [0.00, 0.60, 0.80]" in q.message


@pytest.mark.parametrize("n", [0, 1, 2, 3])
def test_too_few_touches_not_observable(n: int) -> None:
    rot = random_rotations(np.random.default_rng(1), n) if n else np.zeros((0, 3, 3))
    q = assess_touches(rot)
    assert not q.observable and q.n_touches == n
    assert math.isinf(q.predicted_tcp_rms)
    if n >= 2:
        assert f"record {4 - n} more" in q.message


def test_duplicated_orientations_not_observable() -> None:
    rot = random_rotations(np.random.default_rng(2), 3)[[0, 1, 2, 2, 1]]
    q = assess_touches(rot)
    assert not q.observable and q.min_angle_deg < 1e-6


def test_far_candidate_beats_near_duplicate() -> None:
    rng = np.random.default_rng(3)
    rot = tilted_rotations(rng, 5, (25, 45))
    near = rot[2] @ Rotation.from_rotvec(np.radians([2.0, 0, 0])).as_matrix()
    far = Rotation.from_rotvec(np.radians([0, -50.0, 0])).as_matrix() @ rot[0]
    g_near = candidate_gain(rot, near, sigma=0.5)
    g_far = candidate_gain(rot, far, sigma=0.5)
    assert g_far.reduction > g_near.reduction
    assert g_near.too_close and not g_far.too_close
    assert g_near.angle_to_nearest_deg == pytest.approx(2.0, abs=1e-9)
    # independent values: CRB with and without the candidate
    before = math.sqrt(np.trace(crb_tcp(rot, 0.5)))
    after = math.sqrt(np.trace(crb_tcp(np.concatenate([rot, far[None]]), 0.5)))
    assert g_far.predicted_before == pytest.approx(before, rel=1e-9)
    assert g_far.predicted_after == pytest.approx(after, rel=1e-9)
    assert g_far.reduction == pytest.approx(1 - after / before, rel=1e-9)
    angles = np.degrees((Rotation.from_matrix(rot).inv() * Rotation.from_matrix(far)).magnitude())
    assert g_far.angle_to_nearest_deg == pytest.approx(angles.min(), abs=1e-7)


def test_candidate_that_makes_tcp_observable() -> None:
    rng = np.random.default_rng(4)
    rot = tilted_rotations(rng, 4, (25, 45))
    g = candidate_gain(rot[:3], rot[3])
    assert math.isinf(g.predicted_before) and math.isfinite(g.predicted_after)
    assert g.reduction == 1.0 and "determinable" in g.message
    g0 = candidate_gain(np.zeros((0, 3, 3)), rot[0])
    assert math.isinf(g0.angle_to_nearest_deg) and not g0.too_close and g0.reduction == 0.0


def test_bad_input() -> None:
    with pytest.raises(InvalidInputError, match="sigma"):
        assess_touches(np.eye(3)[None], sigma=0)
    with pytest.raises(InvalidInputError, match="candidate_rotation"):
        candidate_gain(np.eye(3)[None], np.ones((3, 3)))
    with pytest.raises(InvalidInputError, match=r"rotations\[1\]"):
        assess_touches([np.eye(3), np.full((3, 3), np.nan)])
