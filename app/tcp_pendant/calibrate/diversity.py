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
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from tcpcal.pose_quality import assess_touches, candidate_gain

__all__ = ["MIN_TILT_DEG", "BestTilt", "axis_in_words", "best_tilt", "best_tilt_words", "diversity_advice",
           "failure_in_words", "missing_axis_in_words"]

MIN_TILT_DEG = 45.0
"""The least tilt asked for between touches (the step texts ask 45-60 deg about two axes): four
touches tilted so predict a TCP error of about 1 mm at the wizards' 0.5 mm operator error,
where tilts of 30 deg leave about 1.4 mm (test_first_hour_meter)."""
_FLANGE_AXIS_COS = math.cos(math.radians(25.0))   # within 25 deg of flange Z: "the flange axis"
_HORIZONTAL_SIN = math.sin(math.radians(30.0))    # within 30 deg of the floor: "horizontal"
_VERTICAL_COS = math.cos(math.radians(30.0))


def _world_direction(axis_world: np.ndarray) -> str:
    """A horizontal direction in words: "WORLD X", "WORLD Y" or between them."""
    x, y = abs(float(axis_world[0])), abs(float(axis_world[1]))
    if x >= 2.0 * y:
        return "WORLD X"
    if y >= 2.0 * x:
        return "WORLD Y"
    return "the diagonal between WORLD X and Y"


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


def axis_in_words(axis_flange: ArrayLike, R_world_flange: ArrayLike) -> str:
    """The turn the touches share, in words ("a turn about the flange axis (the tool turned
    about its own length)", "a tilt about a horizontal axis along WORLD Y", ...).

    Args:
        axis_flange: the axis, FLANGE coordinates (tcpcal's ``unobservable_axis``).
        R_world_flange: the flange's orientation now, to say where the axis points in WORLD.
    """
    kind, w = _kind(axis_flange, R_world_flange)
    if kind == "flange":
        return "a turn about the flange axis (the tool turned about its own length)"
    if kind == "horizontal":
        return f"a tilt about a horizontal axis along {_world_direction(w)}"
    if kind == "vertical":
        return "a turn about the vertical (WORLD Z)"
    return "a tilt about one slanted axis"


def missing_axis_in_words(axis_flange: ArrayLike, R_world_flange: ArrayLike) -> str:
    """What the next touch must add: a tilt about an axis at right angles to the shared one."""
    kind, w = _kind(axis_flange, R_world_flange)
    if kind == "horizontal":
        along = _world_direction(w)
        other = {"WORLD X": "WORLD Y", "WORLD Y": "WORLD X"}.get(along, "the other diagonal")
        lean = {"WORLD X": "toward +Y or -Y", "WORLD Y": "toward +X or -X"}.get(other, "the other way")
        return (f"tilt the tool about a horizontal axis along {other} (lean it {lean}), "
                "or turn it about its own length")
    if kind == "flange":
        return "tilt the tool sideways (about a horizontal axis), not only about its own length"
    return "tilt the tool about a horizontal axis (lean it sideways)"


_FLANGE_VECTOR = re.compile(r"\s*\((?:not about )?flange \[[^\]]*\]\)")


def failure_in_words(message: str, axis_flange: ArrayLike, R_world_flange: ArrayLike) -> str:
    """tcpcal's "all touches rotate about nearly the same axis (flange [..])" for a trainee:
    the FLANGE vector dropped, the axis and the tilt still missing said in words."""
    text = _FLANGE_VECTOR.sub("", str(message)).strip()
    text = text[:1].upper() + text[1:]
    if not text.endswith("."):
        text += "."
    return (f"{text} In words: the touches differ only by {axis_in_words(axis_flange, R_world_flange)}. "
            f"Still missing: {missing_axis_in_words(axis_flange, R_world_flange)}.")


def _max_angle_deg(rots: np.ndarray) -> float:
    """Largest angle between two of the orientations (degrees)."""
    r = Rotation.from_matrix(rots)
    return max((float(np.degrees((r[i].inv() * r[j]).magnitude())) for i in range(len(r))
                for j in range(i + 1, len(r))), default=0.0)


def diversity_advice(recorded: ArrayLike, candidate: ArrayLike, angle_to_nearest_deg: float) -> str:
    """The meter's words while the TCP is not determinable yet (markdown, no user text).

    Args:
        recorded: (N, 3, 3) ``R_world_flange`` of the touches recorded so far (N may be 0).
        candidate: (3, 3) ``R_world_flange`` now.
        angle_to_nearest_deg: angle from ``candidate`` to the nearest recorded orientation
            (``CandidateGain.angle_to_nearest_deg``; inf when nothing is recorded).
    """
    rots = np.asarray(recorded, dtype=float).reshape(-1, 3, 3)
    cand = np.asarray(candidate, dtype=float).reshape(3, 3)
    n = rots.shape[0]
    if n == 0:
        return (f"Touch 1 can have any orientation; each next one must be tilted at least "
                f"{MIN_TILT_DEG:.0f}° from the others, about two different axes.")
    angle = float(angle_to_nearest_deg)
    near = f"This orientation is **{angle:.0f}°** from " + ("touch 1" if n == 1 else "the nearest touch")
    quality = assess_touches(rots)
    if n == 1 or _max_angle_deg(rots) < 1.0:
        # one orientation so far (one touch, or all recorded ones alike): only the tilt counts
        if angle >= MIN_TILT_DEG:
            return f"{near}: ✔ far enough. Tilt about another axis for the touch after."
        return f"{near}: tilt at least {MIN_TILT_DEG:.0f}° from it before recording."
    axis = quality.unobservable_axis
    if axis is None:            # two axes already: only more touches are missing
        more = max(4 - n, 1)
        return (f"{near}. The touches so far are tilted about two different axes: record {more} "
                f"more, each at least {MIN_TILT_DEG:.0f}° from the others.")
    shared = axis_in_words(axis, cand)
    with_candidate = assess_touches(np.concatenate([rots, cand[None]]))
    if with_candidate.unobservable_axis is None and angle >= 1.0:
        return (f"{near}. The {n} touches so far differ only by {shared}; ✔ this orientation adds "
                "the axis still missing.")
    return (f"{near}. The {n} touches so far differ only by {shared}. Still missing: "
            f"{missing_axis_in_words(axis, cand)}.")


_TOOL_KEYS = {"X": "C", "Y": "B", "Z": "A"}
"""The jog key that turns about each TOOL axis (KUKA: A about Z, B about Y, C about X)."""


@dataclass(frozen=True)
class BestTilt:
    """The turn from the current orientation that helps the TCP most (:func:`best_tilt`).

    Attributes:
        axis: "X", "Y" or "Z": the TOOL axis to turn about.
        sign: +1 or -1, the direction of the turn (right hand about ``axis``).
        angle_deg: the turn, degrees.
        key: the jog key of that turn in the TOOL frame ("A", "B", "C").
        axis_world: the axis in WORLD now (unit vector).
        predicted_now_mm: tcpcal's predicted TCP RMS error if the current pose were recorded, mm
            (inf: not determinable).
        predicted_mm: the same after the turn, mm (inf: one more touch gives no prediction yet).
    """

    axis: str
    sign: int
    angle_deg: float
    key: str
    axis_world: np.ndarray
    predicted_now_mm: float
    predicted_mm: float


def _world_axis_name(w: np.ndarray) -> str:
    """The WORLD axis a direction is closest to, with its sign ("WORLD -Y"); "" when it is
    more than 30 deg from all of them."""
    i = int(np.argmax(np.abs(w)))
    if abs(float(w[i])) < _VERTICAL_COS:
        return ""
    return f"WORLD {'+' if w[i] > 0 else '-'}{'XYZ'[i]}"


def _least_observed(rots: np.ndarray) -> float:
    """Smallest eigenvalue of the touches' information matrix for the TCP, ``sum (R_i -
    R_mean)^T (R_i - R_mean)`` (the reference point eliminated): how well the worst-determined
    TCP direction is seen (0: not at all)."""
    d = rots - rots.mean(axis=0)
    M = np.einsum("nji,njk->ik", d, d)
    return float(np.linalg.eigvalsh(M)[0])


def best_tilt(recorded: ArrayLike, R_world_flange: ArrayLike, *, R_flange_tool: ArrayLike | None = None,
              sigma_mm: float = 0.5, angle_deg: float = MIN_TILT_DEG) -> BestTilt | None:
    """Of the six turns by ``angle_deg`` about the TOOL axes (both ways) from ``R_world_flange``,
    the one that helps the TCP most if recorded next: the smallest TCP RMS error tcpcal predicts
    after it; while one more touch cannot give a prediction yet (tcpcal wants four), the
    largest smallest eigenvalue of the information matrix (the least-observed TCP direction
    seen best).

    Args:
        recorded: (N, 3, 3) ``R_world_flange`` of the touches so far.
        R_world_flange: (3, 3) the flange's orientation now.
        R_flange_tool: (3, 3) the active TOOL frame's orientation on the flange (None: TOOL =
            FLANGE, no tool data).
        sigma_mm: the operator error per axis assumed, mm.
        angle_deg: the turn tried, degrees.

    Returns:
        The best turn, or None with fewer than two touches (every turn is as good), or when
        recording here is as good as the best turn (within 5 %).
    """
    rots = np.asarray(recorded, dtype=float).reshape(-1, 3, 3)
    R_wf = np.asarray(R_world_flange, dtype=float).reshape(3, 3)
    R_ft = np.eye(3) if R_flange_tool is None else np.asarray(R_flange_tool, dtype=float).reshape(3, 3)
    if rots.shape[0] < 2:
        return None
    now = float(candidate_gain(rots, R_wf, sigma=sigma_mm).predicted_after)
    tries = []
    for i, axis in enumerate("XYZ"):
        a_flange = R_ft[:, i]
        for sign in (1, -1):
            turn = Rotation.from_rotvec(sign * math.radians(angle_deg) * a_flange).as_matrix()
            R_try = R_wf @ turn                         # turned about a flange-fixed (TOOL) axis
            after = float(candidate_gain(rots, R_try, sigma=sigma_mm).predicted_after)
            seen = _least_observed(np.concatenate([rots, R_try[None]]))
            tries.append((BestTilt(axis, sign, float(angle_deg), _TOOL_KEYS[axis], R_wf @ a_flange, now, after), seen))
    finite = [(b, s) for b, s in tries if math.isfinite(b.predicted_mm)]
    if finite:
        best = min(finite, key=lambda bs: bs[0].predicted_mm)[0]
        return None if math.isfinite(now) and best.predicted_mm >= 0.95 * now else best
    best, seen = max(tries, key=lambda bs: bs[1])
    seen_now = _least_observed(np.concatenate([rots, R_wf[None]]))
    return None if seen <= 1e-6 or seen <= 1.05 * seen_now else best


def best_tilt_words(tilt: BestTilt) -> str:
    """"Tilt that helps most: about TOOL Y (WORLD -X now) by 45° (key B +) → predicted error 0.95 mm"."""
    world = _world_axis_name(tilt.axis_world)
    where = f" ({world} now)" if world else ""
    sym = "+" if tilt.sign > 0 else "−"
    head = (f"Tilt that helps most: about **TOOL {tilt.axis}**{where} by {tilt.angle_deg:.0f}° "
            f"(key **{tilt.key} {sym}**, TOOL frame)")
    if not math.isfinite(tilt.predicted_mm):
        return head + ": it shows the TCP from the side the touches see least."
    now = ("" if not math.isfinite(tilt.predicted_now_mm) else f"{tilt.predicted_now_mm:.2f} mm here → ")
    return f"{head}: predicted TCP error {now}**{tilt.predicted_mm:.2f} mm**."
