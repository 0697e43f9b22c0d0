"""Beam-sensor TCP (BullsEye / TRACC style): methods.md section 9, (BEAM-1)-(BEAM-4).

A through-beam light barrier is the line ``L = {b + s u}`` in WORLD. At a **tip event** the
robot has moved the tool until its tip lies on the beam line; the flange pose ``(R_i, f_i)``
(``R_world_flange``, ``p_world_flange``) is recorded and::

    P (R_i t + f_i - b) = 0,   P = I - u u^T                          (BEAM-1)

two equations per event, linear in the TCP ``t`` (FLANGE). :func:`solve_beam` solves them by
least squares (normal equations (BEAM-2), ``M = sum R_i^T P R_i``). At an **axis event** the
tool's shaft crossed the beam sideways (entry and exit averaged, (BEAM-3)): the tool axis
through the TCP meets the beam line; :func:`solve_beam_axis` gives the tool direction in
FLANGE from several of them (BEAM-4).

Unit-agnostic: lengths come out in the unit they went in (the CLI feeds mm, the app metres).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.special import chdtrc

from tcpcal._stats import DEGENERATE_TILT_RAD, ci_radius, fmt_vec
from tcpcal.errors import DegenerateTouchesError, InvalidInputError
from tcpcal.origin import SIGMA_RANGE
from tcpcal.validation import as_positions, as_rotations, as_vector3, read_only_array

__all__ = [
    "MIN_AXIS_EVENTS",
    "MIN_EVENTS",
    "BeamAxisResult",
    "BeamResult",
    "solve_beam",
    "solve_beam_axis",
]

MIN_EVENTS = 2
"""Fewest tip events: 2 events with different beam directions in FLANGE give 4 equations for
the 3 unknowns (methods.md section 9)."""
CHECKABLE_EVENTS = 4
"""Below this many tip events a warning says a bad event cannot be told from the others."""
MIN_AXIS_EVENTS = 2
"""Fewest axis events (crossings at two tool orientations)."""
WEAK_AXIS_RATIO = 5.0
"""Warn when the TCP deviation along the weakest flange direction exceeds the strongest's by
this factor."""
_AXIS_DEGENERATE_SHARE = DEGENERATE_TILT_RAD ** 2
"""Axis events: the planes through the TCP are 'the same' when the second-smallest eigenvalue
of their normal matrix is below this share of its trace (planes within ~1e-3 rad)."""
_IRLS_STEPS = 4


@dataclass(frozen=True)
class BeamResult:
    """Result of :func:`solve_beam` (methods.md section 9). Lengths in the input unit.

    The keys of the other TCP solves (:class:`tcpcal.origin.TcpResult`) where they apply.

    Attributes:
        tcp: (3,) TCP ``t`` in FLANGE coordinates.
        residual_vectors: (N, 3) ``e_i = P_i (R_i t + f_i - b_i)`` (WORLD): from the beam line
            to the computed tip, across the beam.
        residuals: (N,) ``|e_i|``: the computed tip's distance from the beam line.
        beam_positions: (N,) ``s_i = u_i . (R_i t + f_i - b_i)``: where along the beam (from
            ``b``) the tip crossed it.
        mean_error: mean of ``|e_i|``.
        max_error: max of ``|e_i|``.
        rms_error: ``sqrt(mean |e_i|^2)``.
        noise_sigma: per-axis noise across the beam: the estimate
            ``s = sqrt(sum |e_i|^2 / (2N - 3))`` or the ``sigma`` given.
        covariance: (3, 3) ``noise_sigma^2 M^-1``, ``M = sum R_i^T P_i R_i`` (BEAM-2); with a
            known sigma this is the Cramer-Rao bound of the line-constraint model.
        ci95_radius: radius of the sphere about ``tcp`` holding the true TCP with 95 %
            probability (``2N - 3`` degrees of freedom when sigma was estimated).
        condition_number: ``sqrt(mu_max / mu_min)`` of ``M`` (the whitened 2N x 3 system).
        weakest_axis: (3,) unit flange direction along which ``t`` is least certain.
        outliers: always ``()`` (no outlier test for beam events; the key of the other solves).
        warnings: plain-words remarks.
        n_events: N.
    """

    tcp: np.ndarray
    residual_vectors: np.ndarray
    residuals: np.ndarray
    beam_positions: np.ndarray
    mean_error: float
    max_error: float
    rms_error: float
    noise_sigma: float
    covariance: np.ndarray
    ci95_radius: float
    condition_number: float
    weakest_axis: np.ndarray
    outliers: tuple[int, ...]
    warnings: tuple[str, ...]
    n_events: int

    @property
    def method(self) -> str:
        """``"beam"``."""
        return "beam"

    @property
    def n_touches(self) -> int:
        """``n_events`` (the name the other TCP results use)."""
        return self.n_events


@dataclass(frozen=True)
class BeamAxisResult:
    """Result of :func:`solve_beam_axis` (methods.md section 9, (BEAM-4)).

    Attributes:
        direction: (3,) unit tool direction ``d`` in FLANGE, pointing from the shaft to the tip.
        axis_points: (K, 3) where the tool axis met the beam at each crossing, FLANGE
            coordinates (``t + lambda_k d``).
        axis_distances: (K,) ``lambda_k`` (input length unit; negative: behind the tip).
        residuals: (K,) signed distance between the tool axis and the beam line of each
            crossing (input length unit).
        rms_error: ``sqrt(mean residual^2)``.
        noise_sigma: the estimate ``sqrt(sum residual^2 / (K - 2))`` or the ``sigma`` given
            (NaN when K = 2 and no sigma: no redundancy).
        covariance: (3, 3) covariance of ``direction`` (rad^2, rank 2, in the plane normal to
            it); NaN without a noise figure. The TCP's own error is not included.
        ci95_angle_deg: half-angle of the cone about ``direction`` holding the true direction
            with 95 % probability (deg).
        warnings: plain-words remarks.
        n_events: K.
    """

    direction: np.ndarray
    axis_points: np.ndarray
    axis_distances: np.ndarray
    residuals: np.ndarray
    rms_error: float
    noise_sigma: float
    covariance: np.ndarray
    ci95_angle_deg: float
    warnings: tuple[str, ...]
    n_events: int


# ------------------------------------------------------------------------------ input checks
def _check_sigma(sigma: Any) -> float | None:
    if sigma is None:
        return None
    try:
        s = float(sigma)
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"sigma must be a number (event noise per axis across the beam), got {sigma!r}."
        ) from None
    lo, hi = SIGMA_RANGE
    if not (math.isfinite(s) and lo <= s <= hi):
        raise InvalidInputError(
            f"sigma must be a finite number within {lo:g}..{hi:g} (event noise per axis, length "
            f"unit of the positions), got {sigma!r}; omit it to estimate the noise from the "
            "residuals.")
    return s


def _ndim(x: Any) -> int:
    """Number of dimensions of array-like ``x`` (-1 when it is not rectangular)."""
    try:
        return int(np.ndim(x))
    except ValueError:
        return -1


def _beams(beam_point: Any, beam_dir: Any, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(N, 3) beam points and (N, 3) unit beam directions: one beam for all events, or one per
    event (two crossed beams)."""
    per_event_b, per_event_u = _ndim(beam_point) == 2, _ndim(beam_dir) == 2
    if per_event_b:
        b = as_positions(beam_point, n=n, name="beam_point")
    else:
        b = np.broadcast_to(as_vector3(beam_point, name="beam_point"), (n, 3)).copy()
    if per_event_u:
        u = as_positions(beam_dir, n=n, name="beam_dir")
    else:
        u = np.broadcast_to(as_vector3(beam_dir, name="beam_dir"), (n, 3)).copy()
    norms = np.linalg.norm(u, axis=1)
    bad = ~(norms > 0.0)
    if bad.any():
        i = int(np.argmax(bad))
        where = f"[{i}]" if per_event_u else ""
        raise InvalidInputError(
            f"beam_dir{where} is the zero vector; give the beam's direction in WORLD "
            "(any length, e.g. 1,0,0 for a beam along WORLD X).",
            index=i if per_event_u else None)
    return b, u / norms[:, None]


# ------------------------------------------------------------------------------ tip events
def solve_beam(rotations: Any, positions: Any, beam_point: Any, beam_dir: Any, *,
               sigma: float | None = None) -> BeamResult:
    """TCP from beam tip events (methods.md section 9, (BEAM-1), (BEAM-2)).

    Closed-form linear least squares: ``M t = -sum_i R_i^T P_i (f_i - b_i)`` with
    ``M = sum_i R_i^T P_i R_i``, ``P_i = I - u_i u_i^T`` (rank 2: the two equations across the
    beam). Noise model: the recorded event misses the true one by isotropic Gaussian noise of
    deviation ``sigma`` per axis; only its 2 components across the beam enter, so the estimate
    is maximum-likelihood and its covariance ``sigma^2 M^-1`` is the Cramer-Rao bound.

    Args:
        rotations: (N, 3, 3) ``R_world_flange`` at each event.
        positions: (N, 3) ``p_world_flange`` at each event (any length unit).
        beam_point: (3,) a point ``b`` of the beam line in WORLD, or (N, 3) one per event (two
            crossed beams).
        beam_dir: (3,) the beam direction ``u`` in WORLD (any nonzero length; normalised), or
            (N, 3) one per event.
        sigma: known event noise per axis across the beam (length unit); replaces the
            estimate in the covariance and the 95 % radius.

    Returns:
        A frozen :class:`BeamResult`.

    Raises:
        InvalidInputError: wrong shapes, NaN/inf, non-rotations, a zero beam direction, fewer
            than 2 events, bad sigma.
        DegenerateTouchesError: every event sees the beam along (nearly) the same flange
            direction (the orientations differ only by turns about the beam), so the TCP along
            it is unobservable; ``unobservable_axis`` is that direction in FLANGE.
    """
    try:
        n_given = len(rotations)
    except TypeError:
        n_given = MIN_EVENTS  # let as_rotations report the problem
    if n_given < MIN_EVENTS:
        raise InvalidInputError(
            f"the beam method needs at least {MIN_EVENTS} tip events, got {n_given}; record "
            f"{MIN_EVENTS - n_given} more with the tool turned about its own axis or tilted "
            "across the beam.")
    rot = as_rotations(rotations)
    f = as_positions(positions, n=rot.shape[0])
    n = rot.shape[0]
    b, u = _beams(beam_point, beam_dir, n)
    s_given = _check_sigma(sigma)

    w = np.einsum("nji,nj->ni", rot, u)  # w_i = R_i^T u_i, the beam direction in FLANGE
    m = n * np.eye(3) - w.T @ w  # sum R_i^T P_i R_i = sum (I - w_i w_i^T)
    mu, vecs = np.linalg.eigh(m)
    mu = np.maximum(mu, 0.0)
    weakest = vecs[:, 0].copy()
    if weakest[np.argmax(np.abs(weakest))] < 0:
        weakest = -weakest
    weakest = weakest + 0.0
    spread = math.sqrt(mu[0] / n)
    if spread < DEGENERATE_TILT_RAD:
        raise DegenerateTouchesError(
            f"all {n} events see the beam along nearly the same flange direction "
            f"({fmt_vec(weakest)}; spread {math.degrees(spread):.3f} deg): the tool "
            "orientations differ only by turns about the beam, so the TCP along that direction "
            "cannot be determined. Turn the tool about its own axis (e.g. 90 deg) or tilt it "
            "across the beam between events.",
            unobservable_axis=weakest)

    d = f - b
    pd = d - np.einsum("ni,ni->n", d, u)[:, None] * u  # P_i (f_i - b_i)
    rhs = -np.einsum("nji,nj->i", rot, pd)  # -sum R_i^T P_i (f_i - b_i)
    m_inv = (vecs / mu) @ vecs.T
    t = m_inv @ rhs
    tip = rot @ t + d  # R_i t + f_i - b_i
    along = np.einsum("ni,ni->n", tip, u)
    e = tip - along[:, None] * u
    res = np.linalg.norm(e, axis=1)
    sse = float(res @ res)
    if not (np.isfinite(t).all() and math.isfinite(sse)):
        raise InvalidInputError(
            "the beam solve did not give finite numbers (coordinates too large for double "
            "precision); check the unit and the column order.")
    dof = 2 * n - 3
    s_est = math.sqrt(sse / dof)
    noise = s_est if s_given is None else s_given
    cov = noise * noise * m_inv
    ci95 = ci_radius([noise * noise / v for v in mu.tolist()], None if s_given is not None else dof)

    warnings: list[str] = []
    ratio = math.sqrt(mu[2] / mu[0])
    if ratio > WEAK_AXIS_RATIO:
        warnings.append(
            f"the TCP along flange {fmt_vec(weakest)} is {ratio:.0f} times less certain than "
            "across it: the events see the beam along similar flange directions; add events "
            "with the tool turned about its own axis or tilted across the beam (tilting about "
            "the beam itself adds nothing).")
    if n < CHECKABLE_EVENTS:
        warnings.append(
            f"with only {n} tip events a bad event cannot be told from the others and the "
            "noise estimate is poor; record 4 to 8 events.")
    if s_given is not None and float(chdtrc(dof, sse / s_given**2)) < 1e-3:
        warnings.append(
            f"the residuals (noise estimate {s_est:.3g}) are larger than the given sigma "
            f"{s_given:.3g} explains: the events are less precise than assumed, or the beam "
            "position or direction, the tool or the robot is not what the model says.")

    return BeamResult(
        tcp=read_only_array(t), residual_vectors=read_only_array(e), residuals=read_only_array(res),
        beam_positions=read_only_array(along), mean_error=float(res.mean()),
        max_error=float(res.max()), rms_error=math.sqrt(sse / n), noise_sigma=float(noise),
        covariance=read_only_array(cov), ci95_radius=ci95,
        condition_number=math.sqrt(mu[2] / mu[0]), weakest_axis=read_only_array(weakest),
        outliers=(), warnings=tuple(warnings), n_events=n)


# ------------------------------------------------------------------------------ axis events
def solve_beam_axis(rotations: Any, positions: Any, beam_point: Any, beam_dir: Any, tcp: Any,
                    *, sigma: float | None = None) -> BeamAxisResult:
    """The tool direction in FLANGE from axis events (methods.md section 9, (BEAM-3), (BEAM-4)).

    Each axis event is the flange pose ``(R_k, f_k)`` midway between the beam's entry and exit
    while the tool's shaft crossed it sideways (BEAM-3): there the tool axis
    ``{t + lambda d}`` meets the beam line, which in FLANGE is ``{c_k + s w_k}``,
    ``c_k = R_k^T (b - f_k)``, ``w_k = R_k^T u``. Meeting means ``d . n_k = 0`` with
    ``n_k = (c_k - t) x w_k`` (BEAM-4); ``d`` minimises the sum of squared distances between
    the axis and the beam lines (eigenvector of ``sum omega_k n_k n_k^T``, reweighted by
    ``omega_k = 1 / |d x w_k|^2``). The axis is taken through the TCP (a straight tool or a
    welding wire); the TCP's own error is not propagated.

    Args:
        rotations: (K, 3, 3) ``R_world_flange`` at each axis event.
        positions: (K, 3) ``p_world_flange`` at each (entry and exit averaged).
        beam_point: (3,) or (K, 3) a point of the beam line, WORLD.
        beam_dir: (3,) or (K, 3) the beam direction, WORLD (normalised).
        tcp: (3,) the TCP in FLANGE (e.g. :func:`solve_beam`'s), same length unit.
        sigma: known noise per axis of the averaged crossing position (length unit).

    Returns:
        A frozen :class:`BeamAxisResult`; ``direction`` points from the shaft to the tip.

    Raises:
        InvalidInputError: bad shapes or values, fewer than 2 events, a crossing at the TCP
            itself or with the beam along the tool (no plane), bad sigma.
        DegenerateTouchesError: all crossings define the same plane through the TCP (one tool
            orientation, or orientations turned about the beam): ``d`` can turn in it;
            ``unobservable_axis`` is the plane's normal, the axis it can turn about (FLANGE).
    """
    try:
        k_given = len(rotations)
    except TypeError:
        k_given = MIN_AXIS_EVENTS
    if k_given < MIN_AXIS_EVENTS:
        raise InvalidInputError(
            f"the tool direction needs at least {MIN_AXIS_EVENTS} axis events (sideways "
            f"crossings at two tool orientations), got {k_given}.")
    rot = as_rotations(rotations)
    f = as_positions(positions, n=rot.shape[0])
    k = rot.shape[0]
    b, u = _beams(beam_point, beam_dir, k)
    t = as_vector3(tcp, name="tcp")
    s_given = _check_sigma(sigma)

    w = np.einsum("kji,kj->ki", rot, u)
    c = np.einsum("kji,kj->ki", rot, b - f)
    nrm = np.cross(c - t, w)  # normals of the planes through t containing the beam lines
    lengths = np.linalg.norm(nrm, axis=1)
    scale = max(1.0, float(np.abs(c).max()), float(np.abs(t).max()))
    tiny = lengths <= 1e-12 * scale
    if tiny.any():
        i = int(np.argmax(tiny))
        raise InvalidInputError(
            f"axis event {i}: the beam passes through the TCP (or along the tool), so the "
            "crossing says nothing about the tool's direction; cross the shaft higher up, with "
            "the tool across the beam.", index=i)

    omega = np.ones(k)
    for _ in range(_IRLS_STEPS):
        nmat = (nrm * omega[:, None]).T @ nrm
        nu, vecs = np.linalg.eigh(nmat)
        d = vecs[:, 0]
        sin2 = np.einsum("ki,ki->k", *(np.cross(d, w),) * 2)
        if (sin2 <= 1e-12).any():
            break
        omega = 1.0 / sin2
    nmat = (nrm * omega[:, None]).T @ nrm
    nu, vecs = np.linalg.eigh(nmat)
    nu = np.maximum(nu, 0.0)
    d = vecs[:, 0]
    trace = float(nu.sum())
    if nu[1] < _AXIS_DEGENERATE_SHARE * trace:
        normal = vecs[:, 2].copy()  # the common plane's normal: d may turn about it
        if normal[np.argmax(np.abs(normal))] < 0:
            normal = -normal
        raise DegenerateTouchesError(
            "all axis events put the tool axis in the same plane through the TCP (one tool "
            "orientation, or orientations that differ only by turns about the beam), so the "
            "tool direction can turn freely in that plane (about flange "
            f"{fmt_vec(normal + 0.0)}); turn the tool about its own axis (e.g. 90 deg) and "
            "cross the beam again.",
            unobservable_axis=normal)

    # closest points: axis t + lambda d and beam line c_k + s w_k
    dw = w @ d
    denom = 1.0 - dw * dw
    if (denom <= 1e-12).any():
        i = int(np.argmax(denom <= 1e-12))
        raise InvalidInputError(
            f"axis event {i}: the beam runs along the tool axis; cross the beam with the tool "
            "across it.", index=i)
    g = c - t
    lam = (g @ d - dw * np.einsum("ki,ki->k", g, w)) / denom
    if lam.sum() > 0:
        d, lam = -d, -lam
    points = t + lam[:, None] * d
    resid = (nrm @ d) / np.sqrt(denom)  # signed line-to-line distances
    sse = float(resid @ resid)
    dof = k - 2
    if s_given is not None:
        noise = s_given
    elif dof > 0:
        noise = math.sqrt(sse / dof)
    else:
        noise = math.nan
    basis = vecs[:, 1:]  # orthonormal, normal to d
    info2 = basis.T @ nmat @ basis
    warnings: list[str] = []
    if math.isfinite(noise):
        cov2 = noise * noise * np.linalg.inv(info2)
        cov = basis @ cov2 @ basis.T
        ci = ci_radius(np.linalg.eigvalsh(cov2), None if s_given is not None else dof)
        ci_deg = math.degrees(ci)
    else:
        cov = np.full((3, 3), math.nan)
        ci_deg = math.nan
        warnings.append(
            f"{k} axis events determine the direction exactly, without redundancy: its "
            "uncertainty cannot be estimated; cross the beam at a third orientation or give "
            "sigma.")
    if (lam >= 0).any():
        i = int(np.argmax(lam >= 0))
        warnings.append(
            f"axis event {i}: the beam met the tool axis {lam[i]:.3g} ahead of the TCP, beyond "
            "the tip; the crossings should be on the shaft behind the tip.")
    return BeamAxisResult(
        direction=read_only_array(d + 0.0), axis_points=read_only_array(points), axis_distances=read_only_array(lam),
        residuals=read_only_array(resid), rms_error=math.sqrt(sse / k), noise_sigma=float(noise),
        covariance=read_only_array(cov), ci95_angle_deg=ci_deg, warnings=tuple(warnings), n_events=k)

