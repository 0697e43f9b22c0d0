"""tcpcal.beam: the beam-sensor TCP (methods.md section 9, (BEAM-1)-(BEAM-4)).

Events are built from the forward model: pick the flange rotation ``R_i`` and where along the
beam the tip crosses it (``s_i``), then ``f_i = b + s_i u - R_i t (+ noise)``. Lengths in mm.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

import tcpcal
from tcpcal.beam import BeamAxisResult, BeamResult, solve_beam, solve_beam_axis
from tcpcal.errors import DegenerateTouchesError, InvalidInputError

T_TRUE = np.array([12.0, -8.0, 180.0])  # a straight tool ~ along flange Z
B = np.array([900.0, 150.0, 400.0])  # beam point, WORLD
U = np.array([0.0, 1.0, 0.0])  # beam along WORLD Y
DOWN = Rotation.from_euler("y", 180.0, degrees=True)  # flange Z along WORLD -Z


def scan_rotations(spins_deg=(0.0, 90.0, 180.0, 270.0), tilts_deg=(0.0, 25.0, -25.0)) -> np.ndarray:
    """The tool pointing down, turned about its own axis and tilted about WORLD X (across the
    beam): a typical scan pattern."""
    out = []
    for spin in spins_deg:
        for tilt in tilts_deg:
            out.append((Rotation.from_euler("x", tilt, degrees=True) * DOWN
                        * Rotation.from_euler("z", spin, degrees=True)).as_matrix())
    return np.array(out)


def tip_events(rot: np.ndarray, t: np.ndarray = T_TRUE, b: np.ndarray = B, u: np.ndarray = U,
               rng: np.random.Generator | None = None, sigma: float = 0.0) -> np.ndarray:
    """Flange positions with the tip on the beam line (plus isotropic noise sigma per axis)."""
    n = rot.shape[0]
    gen = rng if rng is not None else np.random.default_rng(0)
    s = gen.uniform(-15.0, 15.0, n)
    f = b + s[:, None] * u - rot @ t
    if sigma:
        f = f + gen.normal(0.0, sigma, (n, 3))
    return f


def crb(rot: np.ndarray, u: np.ndarray, sigma: float) -> np.ndarray:
    """sigma^2 (sum R_i^T P R_i)^-1, computed the plain way (per event, no shortcut)."""
    p = np.eye(3) - np.outer(u, u)
    m = sum(r.T @ p @ r for r in rot)
    return sigma**2 * np.linalg.inv(m)


# ---------------------------------------------------------------------------- exact data
def test_exact_events_give_the_exact_tcp():
    rot = scan_rotations()
    f = tip_events(rot)
    res = solve_beam(rot, f, B, U)
    assert isinstance(res, BeamResult)
    np.testing.assert_allclose(res.tcp, T_TRUE, atol=1e-9)
    assert res.max_error < 1e-9 and res.rms_error < 1e-9 and res.ci95_radius < 1e-8
    assert res.n_events == res.n_touches == 12 and res.method == "beam"
    assert res.outliers == () and res.warnings == ()
    # where along the beam the tip crossed: s_i of the forward model
    s = (rot @ T_TRUE + f - B) @ U
    np.testing.assert_allclose(res.beam_positions, s, atol=1e-9)


def test_beam_direction_is_normalised_and_its_sign_does_not_matter():
    rot = scan_rotations()
    f = tip_events(rot)
    a = solve_beam(rot, f, B, 7.0 * U)
    b = solve_beam(rot, f, B + 123.0 * U, -U)  # another point of the same line
    np.testing.assert_allclose(a.tcp, T_TRUE, atol=1e-9)
    np.testing.assert_allclose(b.tcp, T_TRUE, atol=1e-9)


def test_two_events_with_different_beam_directions_in_flange_suffice():
    rot = scan_rotations(spins_deg=(0.0, 90.0), tilts_deg=(0.0,))
    res = solve_beam(rot, tip_events(rot), B, U)
    np.testing.assert_allclose(res.tcp, T_TRUE, atol=1e-9)
    assert any("only 2 tip events" in w for w in res.warnings)


def test_crossed_beams_one_beam_per_event():
    rot = scan_rotations(spins_deg=(0.0,), tilts_deg=(0.0, 20.0, -20.0, 35.0))
    u2 = np.array([1.0, 0.0, 0.0])
    beams_u = np.array([U, u2, U, u2])
    beams_b = np.array([B, B, B, B + 5.0 * u2])
    f = np.array([tip_events(rot[i:i + 1], b=beams_b[i], u=beams_u[i])[0] for i in range(4)])
    res = solve_beam(rot, f, beams_b, beams_u)
    np.testing.assert_allclose(res.tcp, T_TRUE, atol=1e-9)
    # the same events against one beam do not fit
    with pytest.raises(AssertionError):
        np.testing.assert_allclose(solve_beam(rot, f, B, U).tcp, T_TRUE, atol=1e-3)


# ---------------------------------------------------------------- independent computation
def test_agrees_with_scipy_least_squares_on_the_perpendicular_distances():
    rng = np.random.default_rng(7)
    rot = scan_rotations()
    f = tip_events(rot, rng=rng, sigma=0.05)
    res = solve_beam(rot, f, B, U)

    def distances(t: np.ndarray) -> np.ndarray:
        tip = rot @ t + f - B  # perpendicular offset of each computed tip from the line
        return (tip - np.outer(tip @ U, U)).ravel()

    ref = least_squares(distances, x0=np.zeros(3), xtol=1e-15, ftol=1e-15, gtol=1e-15)
    np.testing.assert_allclose(res.tcp, ref.x, atol=1e-8)
    d = distances(ref.x).reshape(-1, 3)
    np.testing.assert_allclose(res.residuals, np.linalg.norm(d, axis=1), atol=1e-8)
    n = rot.shape[0]
    s = math.sqrt(float((d**2).sum()) / (2 * n - 3))
    assert res.noise_sigma == pytest.approx(s, rel=1e-9)
    # covariance: s^2 (J^T J)^-1 of the whitened problem; J = the stacked P R_i (3N x 3), the
    # analytic Jacobian of the distances (checked against least_squares' finite differences)
    j = np.concatenate([(np.eye(3) - np.outer(U, U)) @ r for r in rot])
    np.testing.assert_allclose(j, ref.jac, atol=1e-6)
    cov_ls = s**2 * np.linalg.inv(j.T @ j)
    np.testing.assert_allclose(res.covariance, cov_ls, rtol=1e-9, atol=1e-12 * np.abs(cov_ls).max())
    bound = crb(rot, U, s)
    np.testing.assert_allclose(res.covariance, bound, rtol=1e-9, atol=1e-12 * np.abs(bound).max())
    assert res.mean_error == pytest.approx(float(np.mean(res.residuals)))
    assert res.max_error == pytest.approx(float(np.max(res.residuals)))
    assert res.rms_error == pytest.approx(math.sqrt(float(np.mean(res.residuals**2))))
    ev = np.linalg.eigvalsh(j.T @ j)
    assert res.condition_number == pytest.approx(math.sqrt(ev[-1] / ev[0]), rel=1e-9)


def test_known_sigma_gives_the_cramer_rao_covariance():
    rot = scan_rotations()
    f = tip_events(rot, rng=np.random.default_rng(3), sigma=0.02)
    res = solve_beam(rot, f, B, U, sigma=0.02)
    bound = crb(rot, U, 0.02)
    np.testing.assert_allclose(res.covariance, bound, rtol=1e-9, atol=1e-12 * np.abs(bound).max())
    assert res.noise_sigma == 0.02
    lam = np.linalg.eigvalsh(res.covariance)
    # 95 % radius of a nearly isotropic 3-D Gaussian: about 2.8 standard deviations
    assert 2.3 * math.sqrt(lam.max()) < res.ci95_radius < 2.9 * math.sqrt(lam.sum())


def test_residuals_larger_than_the_given_sigma_are_flagged():
    rot = scan_rotations()
    f = tip_events(rot, rng=np.random.default_rng(3), sigma=0.5)
    res = solve_beam(rot, f, B, U, sigma=0.02)
    assert any("larger than the given sigma" in w for w in res.warnings)
    assert not any("larger than the given sigma" in w
                   for w in solve_beam(rot, f, B, U, sigma=0.5).warnings)


# ------------------------------------------------------------------------ noise vs theory
def _monte_carlo(trials: int, seed: int) -> tuple[np.ndarray, np.ndarray, float]:
    rng = np.random.default_rng(seed)
    rot = scan_rotations(spins_deg=(0.0, 120.0, 240.0), tilts_deg=(0.0, 30.0))
    sigma = 0.02
    errs = np.empty((trials, 3))
    inside = 0
    for k in range(trials):
        f = tip_events(rot, rng=rng, sigma=sigma)
        res = solve_beam(rot, f, B, U)
        errs[k] = res.tcp - T_TRUE
        inside += float(np.linalg.norm(errs[k])) <= res.ci95_radius
    return errs, crb(rot, U, sigma), inside / trials


def test_covariance_matches_monte_carlo_fast():
    errs, bound, coverage = _monte_carlo(1500, 11)
    emp = errs.T @ errs / len(errs)
    # each variance from 1500 samples has a relative deviation of sqrt(2/1500) = 3.7 %
    np.testing.assert_allclose(np.diag(emp), np.diag(bound), rtol=0.15)
    assert np.trace(emp) == pytest.approx(np.trace(bound), rel=0.1)
    assert abs(errs.mean(axis=0)).max() < 4 * math.sqrt(np.diag(bound).max() / len(errs))
    assert 0.93 <= coverage <= 0.97  # 95 % radius with the estimated noise (binomial sd 0.6 %)


@pytest.mark.slow
def test_covariance_matches_monte_carlo_slow():
    errs, bound, coverage = _monte_carlo(20000, 12)
    emp = errs.T @ errs / len(errs)
    np.testing.assert_allclose(emp, bound, atol=0.04 * np.abs(bound).max())
    np.testing.assert_allclose(np.diag(emp), np.diag(bound), rtol=0.04)
    assert 0.944 <= coverage <= 0.962  # binomial sd 0.15 %; ci_radius is at most 1.5 % wide


# -------------------------------------------------------------------------- degenerate sets
def test_turns_about_the_beam_leave_the_tcp_unobservable_along_the_beam_in_flange():
    base = (DOWN * Rotation.from_euler("z", 30.0, degrees=True)).as_matrix()
    turns = Rotation.from_rotvec(np.outer(np.radians([0.0, 20.0, -35.0, 50.0, 170.0]), U))
    rot = turns.as_matrix() @ base  # differ only by turns about the beam axis (WORLD)
    f = tip_events(rot)
    with pytest.raises(DegenerateTouchesError) as info:
        solve_beam(rot, f, B, U)
    w = base.T @ U  # the beam seen in FLANGE, the same at every event
    axis = info.value.unobservable_axis
    assert abs(abs(float(axis @ w)) - 1.0) < 1e-9
    assert "same flange direction" in str(info.value) and "Turn the tool" in str(info.value)


def test_same_orientation_everywhere_is_degenerate_with_the_beam_axis():
    rot = np.repeat(scan_rotations()[1:2], 5, axis=0)
    with pytest.raises(DegenerateTouchesError) as info:
        solve_beam(rot, tip_events(rot), B, U)
    assert abs(abs(float(info.value.unobservable_axis @ (rot[0].T @ U))) - 1.0) < 1e-9


def test_half_turn_reversing_the_beam_is_still_degenerate():
    base = DOWN.as_matrix()
    flip = Rotation.from_rotvec(np.pi * np.array([0.0, 0.0, 1.0])).as_matrix()  # u -> -u
    rot = np.array([base, flip @ base, base])
    with pytest.raises(DegenerateTouchesError):
        solve_beam(rot, tip_events(rot), B, U)


def test_tilting_only_a_little_warns_about_the_weak_axis():
    rot = scan_rotations(spins_deg=(0.0, 3.0), tilts_deg=(0.0, 2.0))
    res = solve_beam(rot, tip_events(rot), B, U)
    assert any("less certain" in w for w in res.warnings)
    w = rot[0].T @ U
    assert abs(float(res.weakest_axis @ w)) > 0.99
    assert res.condition_number > 5


# ------------------------------------------------------------------------------ bad input
@pytest.mark.parametrize("beam_dir", [(0.0, 0.0, 0.0), (0.0, 0.0), (np.nan, 0.0, 1.0)])
def test_bad_beam_direction_is_refused(beam_dir):
    rot = scan_rotations()
    with pytest.raises(InvalidInputError, match="beam_dir"):
        solve_beam(rot, tip_events(rot), B, beam_dir)


def test_too_few_events_and_bad_shapes_are_refused():
    rot = scan_rotations()
    f = tip_events(rot)
    with pytest.raises(InvalidInputError, match="at least 2 tip events, got 1"):
        solve_beam(rot[:1], f[:1], B, U)
    with pytest.raises(InvalidInputError, match="positions"):
        solve_beam(rot, f[:-1], B, U)
    with pytest.raises(InvalidInputError, match="beam_point"):
        solve_beam(rot, f, (1.0, 2.0), U)
    with pytest.raises(InvalidInputError, match="sigma"):
        solve_beam(rot, f, B, U, sigma=-1.0)
    bad = rot.copy()
    bad[2, 0, 0] = 2.0
    with pytest.raises(InvalidInputError) as info:
        solve_beam(bad, f, B, U)
    assert info.value.index == 2


def test_exported_from_the_package():
    assert tcpcal.solve_beam is solve_beam and tcpcal.solve_beam_axis is solve_beam_axis
    assert tcpcal.BeamResult is BeamResult and tcpcal.BeamAxisResult is BeamAxisResult


# ------------------------------------------------------------------------------ axis events
D_TRUE = np.array([0.1, -0.05, 1.0]) / np.linalg.norm([0.1, -0.05, 1.0])  # tip direction


def axis_events(rot: np.ndarray, heights: np.ndarray, t: np.ndarray = T_TRUE,
                d: np.ndarray = D_TRUE, rng: np.random.Generator | None = None,
                sigma: float = 0.0) -> np.ndarray:
    """Flange positions at which the axis point ``t - h d`` (h behind the tip) is on the beam."""
    gen = rng if rng is not None else np.random.default_rng(1)
    p = t - heights[:, None] * d
    s = gen.uniform(-10.0, 10.0, len(heights))
    f = B + s[:, None] * U - np.einsum("kij,kj->ki", rot, p)
    if sigma:
        f = f + gen.normal(0.0, sigma, f.shape)
    return f


def test_axis_events_give_the_exact_direction():
    rot = np.repeat(scan_rotations(spins_deg=(0.0, 90.0, 200.0), tilts_deg=(0.0,)), 2, axis=0)
    heights = np.array([20.0, 60.0] * 3)
    res = solve_beam_axis(rot, axis_events(rot, heights), B, U, T_TRUE)
    assert isinstance(res, BeamAxisResult)
    np.testing.assert_allclose(res.direction, D_TRUE, atol=1e-12)
    np.testing.assert_allclose(res.axis_distances, -heights, atol=1e-9)
    np.testing.assert_allclose(res.axis_points, T_TRUE - heights[:, None] * D_TRUE, atol=1e-9)
    assert np.abs(res.residuals).max() < 1e-9 and res.warnings == ()


def test_axis_two_heights_at_one_orientation_are_degenerate():
    rot = np.repeat(scan_rotations(spins_deg=(0.0,), tilts_deg=(0.0,)), 2, axis=0)
    with pytest.raises(DegenerateTouchesError) as info:
        solve_beam_axis(rot, axis_events(rot, np.array([20.0, 60.0])), B, U, T_TRUE)
    normal = info.value.unobservable_axis  # d may turn about it, within the common plane
    assert abs(float(normal @ D_TRUE)) < 1e-9 and abs(float(normal @ (rot[0].T @ U))) < 1e-9
    assert "same plane" in str(info.value)


def test_axis_noise_matches_its_predicted_cone():
    rng = np.random.default_rng(5)
    rot = np.repeat(scan_rotations(spins_deg=(0.0, 90.0, 180.0, 270.0), tilts_deg=(0.0,)), 2,
                    axis=0)
    heights = np.array([25.0, 70.0] * 4)
    sigma = 0.02
    angles, cones, inside = [], [], 0
    trials = 800
    for _ in range(trials):
        res = solve_beam_axis(rot, axis_events(rot, heights, rng=rng, sigma=sigma), B, U,
                              T_TRUE, sigma=sigma)
        ang = math.degrees(math.acos(min(1.0, float(res.direction @ D_TRUE))))
        angles.append(ang)
        cones.append(res.ci95_angle_deg)
        inside += ang <= res.ci95_angle_deg
    predicted = math.degrees(math.sqrt(np.trace(res.covariance)))  # RMS angle
    assert math.sqrt(np.mean(np.square(np.radians(angles)))) == pytest.approx(
        math.radians(predicted), rel=0.12)
    assert 0.92 <= inside / trials <= 0.98


def test_axis_with_two_events_has_no_noise_estimate_without_sigma():
    rot = scan_rotations(spins_deg=(0.0, 90.0), tilts_deg=(0.0,))
    res = solve_beam_axis(rot, axis_events(rot, np.array([30.0, 30.0])), B, U, T_TRUE)
    np.testing.assert_allclose(res.direction, D_TRUE, atol=1e-12)
    assert math.isnan(res.noise_sigma) and math.isnan(res.ci95_angle_deg)
    assert any("without redundancy" in w for w in res.warnings)


def test_axis_refuses_one_event_and_a_crossing_at_the_tcp():
    rot = scan_rotations(spins_deg=(0.0, 90.0), tilts_deg=(0.0,))
    with pytest.raises(InvalidInputError, match="at least 2 axis events"):
        solve_beam_axis(rot[:1], axis_events(rot[:1], np.array([30.0])), B, U, T_TRUE)
    with pytest.raises(InvalidInputError, match="through the TCP") as info:
        solve_beam_axis(rot, axis_events(rot, np.array([30.0, 0.0])), B, U, T_TRUE)
    assert info.value.index == 1


# ------------------------------------------------------------------------ benchmark table 5
def test_bench_solver_beam_table_runs_and_reaches_the_bound():
    """tests/bench/bench_solver.py table 5: a small run of its beam rows."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "bench" / "bench_solver.py"
    spec = importlib.util.spec_from_file_location("bench_solver_beam", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    rows = bench.beam_efficiency_table(n_sets=60, draws=5)
    assert [(r["pattern"], r["n"]) for r in rows] == [
        (p, n) for p in bench.BEAM_PATTERNS for n in bench.BEAM_NS]
    for r in rows:  # 300 draws: the RMS ratio's 2 SE is about 8 %
        assert 0.8 < r["efficiency"] < 1.2 and r["refused"] == 0
        assert 0.88 < r["coverage"] <= 1.0
