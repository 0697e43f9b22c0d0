"""Pose quality before solving: can the touches determine the TCP, and would a candidate pose help?

The wizard calls this live while the user jogs (well under 1 ms for N <= 20). It needs the
rotations only: the information matrix of the TCP in (4P-3),
``M = ((A^T A)^-1)_tt^-1 = N I - S^T S / N`` (``S = sum R_i``), does not depend on the
positions (methods.md section 2, "predicted uncertainty from poses alone").

For an assumed per-axis touch noise ``sigma`` (length unit, default 0.5, i.e. mm for the
pendant) the Cramer-Rao bound of the TCP is ``sigma^2 M^-1`` (methods.md section 7); the
predicted RMS error is ``sigma sqrt(trace M^-1)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from tcpcal._stats import (
    SAME_ORIENTATION_DEG,
    AngleExtremes,
    Information,
    angle_extremes,
    ci_radius,
    distinct_orientations,
    fmt_vec,
    information,
    information_from_sum,
)
from tcpcal.errors import InvalidInputError
from tcpcal.validation import as_rotation, as_rotations

__all__ = ["CandidateGain", "PoseQuality", "assess_touches", "candidate_gain"]

MIN_TOUCHES = 4
WEAK_AXIS_RATIO = 5.0


@dataclass(frozen=True)
class PoseQuality:
    """What the touches so far can tell about the TCP.

    Attributes:
        n_touches: number of touches.
        observable: whether :func:`tcpcal.origin.solve_xyz4` can determine the TCP from them
            (at least 4 touches, at least 4 different orientations, not all about one axis).
        unobservable_axis: unit vector (FLANGE coordinates) along which the TCP cannot be
            determined because all touches rotate about it; None otherwise.
        predicted_tcp_rms: ``sigma sqrt(trace M^-1)``, the Cramer-Rao RMS error of the TCP
            (length unit of sigma); inf if not observable.
        predicted_ci95_radius: 95 % radius of the TCP for known ``sigma``; inf if not
            observable.
        min_angle_deg: smallest angle between two touch orientations (NaN for N < 2).
        message: plain-words advice for the wizard.
    """

    n_touches: int
    observable: bool
    unobservable_axis: np.ndarray | None
    predicted_tcp_rms: float
    predicted_ci95_radius: float
    min_angle_deg: float
    message: str


@dataclass(frozen=True)
class CandidateGain:
    """Effect of adding one candidate orientation to the touches.

    Attributes:
        predicted_before: ``predicted_tcp_rms`` now (inf if not yet observable).
        predicted_after: with the candidate added.
        reduction: ``1 - after / before``; 1.0 when the candidate makes the TCP observable,
            0.0 when it stays unobservable.
        angle_to_nearest_deg: angle between the candidate and the nearest recorded
            orientation (inf when nothing is recorded yet).
        too_close: ``angle_to_nearest_deg < min_angle_deg``.
        message: plain-words advice for the wizard.
    """

    predicted_before: float
    predicted_after: float
    reduction: float
    angle_to_nearest_deg: float
    too_close: bool
    message: str


def _check_sigma(sigma: Any) -> float:
    try:
        s = float(sigma)
    except (TypeError, ValueError):
        s = math.nan
    if not (math.isfinite(s) and s > 0.0):
        raise InvalidInputError(
            f"sigma must be a finite positive number (assumed touch noise per axis), got {sigma!r}."
        )
    return s


def _rotations_and_candidate(rotations: Any, candidate_rotation: Any) -> np.ndarray:
    """The (N + 1, 3, 3) stack of the validated rotations and candidate, checked in one go;
    on any problem the two are checked separately, for the same errors as
    ``as_rotations(rotations)`` then ``as_rotation(candidate_rotation)``."""
    try:
        rot = np.asarray(rotations, dtype=float)
        cand = np.asarray(candidate_rotation, dtype=float)
        if rot.ndim == 3 and rot.shape[1:] == (3, 3) and cand.shape == (3, 3):
            return as_rotations(np.concatenate([rot, cand[None]]), name="rotations")
    except (TypeError, ValueError):
        pass
    rot = _as_rotations_or_empty(rotations)
    cand = as_rotation(candidate_rotation, name="candidate_rotation")
    return np.concatenate([rot, cand[None]])


def _as_rotations_or_empty(rotations: Any) -> np.ndarray:
    if isinstance(rotations, (list, tuple)) and len(rotations) == 0:
        return np.zeros((0, 3, 3))
    shape = np.shape(rotations)
    if len(shape) >= 1 and shape[0] == 0:
        return np.zeros((0, 3, 3))
    return as_rotations(rotations, name="rotations")


def _assess(rot: np.ndarray, sigma: float, info: Information | None = None,
            ext: AngleExtremes | None = None) -> PoseQuality:
    """Pose quality of validated rotations; ``info`` and ``ext`` if the caller has them."""
    n = rot.shape[0]
    if n == 0:
        return PoseQuality(0, False, None, math.inf, math.inf, math.nan,
                           "No touches yet: touch the reference point from 4 or more clearly "
                           "different orientations (tilted 30-60 deg about two axes).")
    if n == 1:
        return PoseQuality(1, False, None, math.inf, math.inf, math.nan,
                           "1 touch recorded: tilt the tool 30-60 deg and touch again "
                           "(at least 4 touches).")
    if info is None:
        info = information(rot)
    if ext is None:
        ext = angle_extremes(rot)
    inf = math.inf
    if ext.max_deg < SAME_ORIENTATION_DEG:
        return PoseQuality(n, False, None, inf, inf, ext.min_deg,
                           f"All {n} touches have the same orientation: tilt the tool 30-60 deg "
                           "before the next touch.")
    if not info.observable:
        axis = info.weakest_axis
        axis.setflags(write=False)
        if n == 2:  # two orientations always differ by a rotation about one axis
            msg = (f"2 touches recorded: record 2 more, tilted about another axis than the first "
                   f"two (not about flange {fmt_vec(axis)}).")
        else:
            msg = (f"All touches rotate about nearly the same axis (flange {fmt_vec(axis)}): "
                   "tilt the tool about a second axis.")
        return PoseQuality(n, False, axis, inf, inf, ext.min_deg, msg)
    distinct = n
    if ext.min_deg < SAME_ORIENTATION_DEG:
        distinct = distinct_orientations(rot, limit=MIN_TOUCHES).count
    if n < MIN_TOUCHES or distinct < MIN_TOUCHES:
        more = MIN_TOUCHES - distinct
        dup = f" ({n - distinct} of them repeat an orientation)" if distinct < n else ""
        return PoseQuality(n, False, None, inf, inf, ext.min_deg,
                           f"{n} touches recorded{dup}: record {more} more from clearly different "
                           "orientations.")
    eig = info.eigvals.tolist()
    cov_eig = [sigma**2 / v for v in eig]
    rms = math.sqrt(sum(cov_eig))
    ci95 = ci_radius(cov_eig, None)
    msg = (f"TCP determined: predicted uncertainty {rms:.2f} RMS, 95 % radius {ci95:.2f} "
           f"(for touch noise {sigma:g}).")
    ratio = math.sqrt(eig[2] / eig[0])
    if ratio > WEAK_AXIS_RATIO:
        msg += (f" The TCP along flange {fmt_vec(info.weakest_axis)} is {ratio:.0f} times less "
                "certain: add a touch tilted about another axis.")
    elif ext.max_deg < 20.0:
        msg += " Tilt further (30-60 deg) for a more precise TCP."
    return PoseQuality(n, True, None, rms, ci95, ext.min_deg, msg)


def assess_touches(rotations: Any, *, sigma: float = 0.5) -> PoseQuality:
    """Whether the touches recorded so far determine the TCP, and how well (no positions needed).

    Uses the TCP information matrix of (4P-3), ``M = N I - S^T S / N``: the TCP is observable
    when its smallest eigenvalue is not ~0 (the eigenvector of a ~0 eigenvalue is the
    unobservable axis, FLANGE coordinates); the predicted RMS error is
    ``sigma sqrt(trace M^-1)`` (Cramer-Rao bound, methods.md section 7) and the 95 % radius the
    quantile of the weighted chi-square sum with weights ``sigma^2 / eig(M)``.

    Args:
        rotations: (N, 3, 3) ``R_world_flange`` of the touches so far (N may be 0).
        sigma: assumed per-axis touch noise (length unit, e.g. mm).

    Returns:
        :class:`PoseQuality`.

    Raises:
        InvalidInputError: malformed rotations or sigma.
    """
    s = _check_sigma(sigma)
    return _assess(_as_rotations_or_empty(rotations), s)


def candidate_gain(
    rotations: Any,
    candidate_rotation: Any,
    *,
    sigma: float = 0.5,
    min_angle_deg: float = 15.0,
) -> CandidateGain:
    """How much a candidate next touch orientation would reduce the predicted TCP error.

    Compares ``predicted_tcp_rms`` of :func:`assess_touches` without and with the candidate;
    the angle to the nearest recorded orientation is ``2 asin(|R_c - R_i|_F / (2 sqrt 2))``.

    Args:
        rotations: (N, 3, 3) ``R_world_flange`` of the touches so far (N may be 0).
        candidate_rotation: (3, 3) ``R_world_flange`` of the candidate pose.
        sigma: assumed per-axis touch noise (length unit).
        min_angle_deg: a candidate closer than this to a recorded orientation is ``too_close``.

    Returns:
        :class:`CandidateGain`.
    """
    s = _check_sigma(sigma)
    both = _rotations_and_candidate(rotations, candidate_rotation)
    rot, cand = both[:-1], both[-1]
    n = rot.shape[0]
    # One Gram matrix of the N + 1 flattened rotations serves the angle extremes before and
    # after; both information matrices come from one sum (M depends on sum R_i only). Same
    # figures as assess_touches without and with the candidate, in about half the time.
    x = both.reshape(n + 1, 9)
    gram = x @ x.T
    if n >= 2:
        s_before = rot.sum(axis=0)
        before = _assess(rot, s, information_from_sum(s_before, n), angle_extremes(rot, gram=gram[:n, :n].copy()))
        s_after = s_before + cand
    else:
        before = _assess(rot, s)
        s_after = both.sum(axis=0)
    after = _assess(both, s, information_from_sum(s_after, n + 1), angle_extremes(both, gram=gram))
    b, a = before.predicted_tcp_rms, after.predicted_tcp_rms
    if math.isinf(b):
        reduction = 1.0 if math.isfinite(a) else 0.0
    else:
        reduction = 1.0 - a / b
    if n:
        diff = rot - cand
        fro = np.sqrt(np.einsum("nij,nij->n", diff, diff))
        k = int(np.argmin(fro))
        nearest = math.degrees(2.0 * math.asin(min(float(fro[k]) / (2.0 * math.sqrt(2.0)), 1.0)))
    else:
        k = -1
        nearest = math.inf
    too_close = nearest < min_angle_deg
    if too_close:
        msg = (f"Too close to touch {k} (0-based; {nearest:.1f} deg apart, want >= {min_angle_deg:g}): "
               "tilt further before recording.")
    elif math.isinf(b) and math.isfinite(a):
        msg = f"Recording here makes the TCP determinable (predicted RMS {a:.2f})."
    elif math.isinf(a):
        msg = "Still not enough: " + after.message
    elif reduction >= 0.1:
        msg = f"Good pose: predicted RMS {b:.2f} -> {a:.2f} ({-100 * reduction:.0f} %)."
    else:
        msg = (f"This pose adds little: predicted RMS {b:.2f} -> {a:.2f} ({-100 * reduction:.0f} %); "
               "tilt about another axis.")
    return CandidateGain(b, a, reduction, nearest, too_close, msg)
