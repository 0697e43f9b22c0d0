"""What the pose-diversity meter says before the TCP is determinable (touches 1-3), without viser.

tcpcal names the axis the touches so far cannot resolve as a vector in FLANGE coordinates
("not about flange [0.00, 1.00, 0.00]"); a trainee needs it in words. This module says:

* how far the current orientation is from the nearest recorded one (degrees);
* after one touch: tilt at least ``MIN_TILT_DEG`` from it;
* after two or more touches that all turn about one axis (tcpcal's ``unobservable_axis``):
  that axis in words (the flange axis, i.e. turning the tool about its own length, or a
  horizontal / vertical WORLD direction, seen with the flange's current orientation) and the
  axis still missing, and whether the current orientation adds it;
* from two touches on, the tilt that helps most (:func:`best_tilt`): of the six turns by
  ``MIN_TILT_DEG`` about the TOOL axes from the current orientation (the jog keys A, B, C in
  the TOOL frame), the one after which tcpcal predicts the smallest TCP error. That turn is
  about an axis across the TCP direction the touches determine worst (the least-observed
  direction of the information matrix ``sum (R_i - R_mean)^T (R_i - R_mean)``), which a turn
  about an axis along it cannot observe.

Angles in degrees; rotations are ``R_world_flange`` (3x3), as the wizard records them.
"""

from __future__ import annotations

import math
import re

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from tcp_pendant.translation import ENGLISH, Translator
from tcpcal.pose_quality import assess_touches

__all__ = ["MIN_TILT_DEG", "axis_in_words", "diversity_advice", "failure_in_words", "least_observed",
           "missing_axis_in_words"]

MIN_TILT_DEG = 45.0
"""The least tilt asked for between touches (the step texts ask 45-60 deg about two axes): four
touches tilted so predict a TCP error of about 1 mm at the wizards' 0.5 mm operator error,
where tilts of 30 deg leave about 1.4 mm (test_first_hour_meter)."""
_FLANGE_AXIS_COS = math.cos(math.radians(25.0))   # within 25 deg of flange Z: "the flange axis"
_HORIZONTAL_SIN = math.sin(math.radians(30.0))    # within 30 deg of the floor: "horizontal"
_VERTICAL_COS = math.cos(math.radians(30.0))


def _world_axis(axis_world: np.ndarray) -> str:
    """A horizontal direction: "X", "Y" (a WORLD axis) or "" (between them)."""
    x, y = abs(float(axis_world[0])), abs(float(axis_world[1]))
    if x >= 2.0 * y:
        return "X"
    if y >= 2.0 * x:
        return "Y"
    return ""


def _world_direction(axis_world: np.ndarray, tr: Translator = ENGLISH) -> str:
    """A horizontal direction in words: "WORLD X", "WORLD Y" or between them."""
    axis = _world_axis(axis_world)
    return f"WORLD {axis}" if axis else tr.gettext("the diagonal between WORLD X and Y")


def _kind(axis_flange: ArrayLike, R_world_flange: ArrayLike) -> tuple[str, np.ndarray]:
    a = np.asarray(axis_flange, dtype=float).reshape(3)
    a = a / np.linalg.norm(a)
    w = np.asarray(R_world_flange, dtype=float).reshape(3, 3) @ a
    if abs(a[2]) >= _FLANGE_AXIS_COS:
        return "flange", w
    if abs(w[2]) <= _HORIZONTAL_SIN:
        return "horizontal", w
    if abs(w[2]) >= _VERTICAL_COS:
        return "vertical", w
    return "slanted", w


def axis_in_words(axis_flange: ArrayLike, R_world_flange: ArrayLike, *, tr: Translator = ENGLISH) -> str:
    """The turn the touches share, in words ("a turn about the flange axis (the tool turned
    about its own length)", "a tilt about a horizontal axis along WORLD Y", ...).

    Args:
        axis_flange: the axis, FLANGE coordinates (tcpcal's ``unobservable_axis``).
        R_world_flange: the flange's orientation now, to say where the axis points in WORLD.
    """
    _ = tr.gettext
    kind, w = _kind(axis_flange, R_world_flange)
    if kind == "flange":
        return _("a turn about the flange axis (the tool turned about its own length)")
    if kind == "horizontal":
        return _("a tilt about a horizontal axis along {direction}").format(direction=_world_direction(w, tr))
    if kind == "vertical":
        return _("a turn about the vertical (WORLD Z)")
    return _("a tilt about one slanted axis")


def missing_axis_in_words(axis_flange: ArrayLike, R_world_flange: ArrayLike, *, tr: Translator = ENGLISH) -> str:
    """What the next touch must add: a tilt about an axis at right angles to the shared one."""
    _ = tr.gettext
    kind, w = _kind(axis_flange, R_world_flange)
    if kind == "horizontal":
        along = _world_axis(w)
        if along:
            other = "Y" if along == "X" else "X"
            return _("tilt the tool about a horizontal axis along {direction} (lean it toward +{lean} or -{lean}), "
                     "or turn it about its own length").format(direction=f"WORLD {other}", lean=along)
        return _("tilt the tool about a horizontal axis along the other diagonal (lean it the other way), "
                 "or turn it about its own length")
    if kind == "flange":
        return _("tilt the tool sideways (about a horizontal axis), not only about its own length")
    return _("tilt the tool about a horizontal axis (lean it sideways)")


_FLANGE_VECTOR = re.compile(r"\s*\((?:not about )?flange \[[^\]]*\]\)")


def failure_in_words(message: str, axis_flange: ArrayLike, R_world_flange: ArrayLike, *,
                     tr: Translator = ENGLISH) -> str:
    """tcpcal's "all touches rotate about nearly the same axis (flange [..])" for a trainee:
    the FLANGE vector dropped, the axis and the tilt still missing said in words (``tr``'s
    language; tcpcal's own sentence stays English: the solver has no catalogs)."""
    text = _FLANGE_VECTOR.sub("", str(message)).strip()
    text = text[:1].upper() + text[1:]
    if not text.endswith("."):
        text += "."
    return tr.gettext("{failure} In words: the touches differ only by {shared}. Still missing: {missing}.").format(
        failure=text, shared=axis_in_words(axis_flange, R_world_flange, tr=tr),
        missing=missing_axis_in_words(axis_flange, R_world_flange, tr=tr))


def _max_angle_deg(rots: np.ndarray) -> float:
    """Largest angle between two of the orientations (degrees)."""
    r = Rotation.from_matrix(rots)
    return max((float(np.degrees((r[i].inv() * r[j]).magnitude())) for i in range(len(r))
                for j in range(i + 1, len(r))), default=0.0)


def diversity_advice(recorded: ArrayLike, candidate: ArrayLike, angle_to_nearest_deg: float, *,
                     tr: Translator = ENGLISH) -> str:
    """The meter's words while the TCP is not determinable yet (markdown, no user text), in
    ``tr``'s language.

    Args:
        recorded: (N, 3, 3) ``R_world_flange`` of the touches recorded so far (N may be 0).
        candidate: (3, 3) ``R_world_flange`` now.
        angle_to_nearest_deg: angle from ``candidate`` to the nearest recorded orientation
            (``CandidateGain.angle_to_nearest_deg``; inf when nothing is recorded).
    """
    rots = np.asarray(recorded, dtype=float).reshape(-1, 3, 3)
    cand = np.asarray(candidate, dtype=float).reshape(3, 3)
    n = rots.shape[0]
    _ = tr.gettext
    least = f"{MIN_TILT_DEG:.0f}"
    if n == 0:
        return _("Touch 1 can have any orientation; each next one must be tilted at least {angle}° from the "
                 "others, about two different axes.").format(angle=least)
    angle = float(angle_to_nearest_deg)
    near = (_("This orientation is **{angle}°** from touch 1") if n == 1 else
            _("This orientation is **{angle}°** from the nearest touch")).format(angle=f"{angle:.0f}")
    quality = assess_touches(rots)
    if n == 1 or _max_angle_deg(rots) < 1.0:
        # one orientation so far (one touch, or all recorded ones alike): only the tilt counts
        if angle >= MIN_TILT_DEG:
            return _("{near}: ✔ far enough. Tilt about another axis for the touch after.").format(near=near)
        return _("{near}: tilt at least {angle}° from it before recording.").format(near=near, angle=least)
    axis = quality.unobservable_axis
    if axis is None:            # two axes already: only more touches are missing
        more = max(4 - n, 1)
        return tr.ngettext("{near}. The touches so far are tilted about two different axes: record {n} more, "
                           "each at least {angle}° from the others.",
                           "{near}. The touches so far are tilted about two different axes: record {n} more, "
                           "each at least {angle}° from the others.", more).format(near=near, n=more, angle=least)
    shared = axis_in_words(axis, cand, tr=tr)
    with_candidate = assess_touches(np.concatenate([rots, cand[None]]))
    if with_candidate.unobservable_axis is None and angle >= 1.0:
        return tr.ngettext("{near}. The {n} touch so far differs only by {shared}; ✔ this orientation adds "
                           "the axis still missing.",
                           "{near}. The {n} touches so far differ only by {shared}; ✔ this orientation adds "
                           "the axis still missing.", n).format(near=near, n=n, shared=shared)
    return tr.ngettext("{near}. The {n} touch so far differs only by {shared}. Still missing: {missing}.",
                       "{near}. The {n} touches so far differ only by {shared}. Still missing: {missing}.",
                       n).format(near=near, n=n, shared=shared, missing=missing_axis_in_words(axis, cand, tr=tr))


def least_observed(rots: np.ndarray) -> float:
    """Smallest eigenvalue of the touches' information matrix for the TCP, ``sum (R_i -
    R_mean)^T (R_i - R_mean)`` (the reference point eliminated): how well the worst-determined
    TCP direction is seen (0: not at all)."""
    d = rots - rots.mean(axis=0)
    M = np.einsum("nji,njk->ik", d, d)
    return float(np.linalg.eigvalsh(M)[0])
