"""TOOL-frame orientation methods (methods.md sections 4 and 5).

All functions return ``R_flange_tool`` (columns: tool X, Y, Z in FLANGE coordinates) in an
:class:`OrientationResult`. Inputs are flange poses ``R_world_flange`` (3x3) and
``p_world_flange`` (3-vectors) and, for the three-point methods, the calibrated TCP ``t`` in
FLANGE coordinates. Lengths are unit-agnostic (they come out in the unit they went in), but the
short-displacement warning threshold ``min_displacement`` defaults to 20, meant as millimetres:
pass another value when working in another unit.

Orthogonalisation (three-point variant 1 and the least-squares generalisation): with noisy
touches the measured tool X (``c1``) and tool Y (``c2``) are not exactly orthogonal. We use
**Gram-Schmidt keeping c1**: ``c2 <- normalise(c2 - (c1 . c2) c1)``, ``c3 = c1 x c2`` (30).
Tool X is the working direction (methods.md section 1) and the one a 5D tool needs, so it keeps
its measured direction and all of the inconsistency goes into Y. The defect
``|90 deg - angle(c1, c2)|`` measured before this step is reported as
``orthogonality_defect_deg``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from tcpcal.errors import DegenerateTouchesError, InvalidInputError
from tcpcal.tool import abc_deg_from_rotation
from tcpcal.validation import as_positions, as_rotation, as_rotations, as_vector3

__all__ = [
    "DEFECT_WARN_DEG",
    "MIN_DISPLACEMENT_DEFAULT",
    "R_WORLD_TOOL_PARALLEL",
    "OrientationResult",
    "solve_abc_world",
    "solve_three_point",
    "solve_three_point_lstsq",
]

R_WORLD_TOOL_PARALLEL: np.ndarray = np.array(
    [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]
)
"""(PA-1): tool X = WORLD -Z (down), tool Y = WORLD Y, tool Z = WORLD X (columns)."""
R_WORLD_TOOL_PARALLEL.setflags(write=False)

MIN_DISPLACEMENT_DEFAULT: float = 20.0
"""Displacements |Delta| shorter than this (mm) give a warning: angular error ~ sigma/|Delta|."""

DEFECT_WARN_DEG: float = 2.0
"""Orthogonality defects above this (degrees) give a warning."""

_SIN_DEGENERATE: float = 1e-6
"""sin of the angle below which a +Y point is taken to lie on the X axis (c2 undefined)."""

_PLANE_SPREAD: float = 0.1
"""lstsq: +Y points span a plane (for the defect) when s2 >= _PLANE_SPREAD * s1."""

_ROLES = ("touch", "minus_x", "plus_y")


@dataclass(frozen=True)
class OrientationResult:
    """Result of an orientation method.

    Attributes:
        method: ``"abc-world-6d"``, ``"abc-world-5d"``, ``"three-point-1"``,
            ``"three-point-2"`` or ``"three-point-lstsq"``.
        rotation: (3, 3) ``R_flange_tool``, a proper rotation (det +1).
        orthogonality_defect_deg: ``|90 - angle(c1, c2)|`` in degrees before
            orthogonalisation (0 when the method has no redundancy, e.g. variant 2).
        displacements: lever arms ``|Delta|`` used, input length unit. Three-point variant 1:
            ``(|Delta1|, Delta2)``; variant 2: ``(|Delta1|, Delta4)`` (Delta4 = distance of the
            +Y point from the tool X axis, the lever of c2); lstsq: one entry per non-touch row
            in row order (distance from t for -X rows, distance from the X axis for +Y rows);
            ABC world: ``()``.
        warnings: plain-words warnings for the operator: a displacement shorter than
            ``min_displacement``; an orthogonality defect above ``DEFECT_WARN_DEG``; tool X
            more than 120 deg from the TCP direction (the tip was probably put on +X, i.e.
            Delta1 > 0); lstsq rows on the wrong side (-X row with Delta1 >= 0, +Y row with
            negative Y); 5D: which axis tool Y was taken from.
    """

    method: str
    rotation: np.ndarray
    orthogonality_defect_deg: float
    displacements: tuple[float, ...]
    warnings: tuple[str, ...]

    def __post_init__(self) -> None:
        rot = np.array(self.rotation, dtype=float)
        rot.setflags(write=False)
        object.__setattr__(self, "rotation", rot)

    @property
    def kuka_abc_deg(self) -> np.ndarray:
        """KUKA (A, B, C) in degrees of ``rotation``: ``R = Rz(A) Ry(B) Rx(C)``."""
        return abc_deg_from_rotation(self.rotation)


def _unit(v: np.ndarray) -> np.ndarray:
    unit: np.ndarray = v / np.linalg.norm(v)
    return unit


def _angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    """Angle between two non-zero vectors, degrees (atan2 form: accurate near 0 and 90)."""
    return math.degrees(math.atan2(np.linalg.norm(np.cross(a, b)), float(np.dot(a, b))))


def _proper(c1: np.ndarray, c2: np.ndarray) -> np.ndarray:
    """[c1 c2 c1xc2] from unit, orthogonal c1, c2 (30), re-normalised to machine precision."""
    c3 = np.cross(c1, c2)
    R = np.column_stack([c1, c2, c3 / np.linalg.norm(c3)])
    return R


def solve_abc_world(
    rotation_world_flange: Any,
    *,
    variant: Literal["6d", "5d"] = "6d",
    current_rotation: Any | None = None,
) -> OrientationResult:
    """Parallel-axes method, KUKA "ABC World" (methods.md section 4, (PA-1), (PA-2)).

    The operator has aligned the tool so that tool X points along WORLD -Z, tool Y along
    WORLD Y and tool Z along WORLD X, i.e. ``R_world_tool = R_WORLD_TOOL_PARALLEL`` (PA-1).
    Then ``R_flange_tool = R_world_flange^T R_world_tool`` (PA-2).

    6D variant: the whole rotation comes from (PA-2).

    5D variant: only tool X was aligned (e.g. a welding torch, where the spin about X does not
    matter). Tool X = ``R_world_flange^T (0, 0, -1)`` (first column of (PA-2)). Tool Y is the
    projection of ``current_rotation``'s Y column (the tool's previous Y axis, in FLANGE) onto
    the plane normal to X, normalised; if ``current_rotation`` is None or its Y lies within
    about 0.06 deg of X, the flange Y axis (0, 1, 0) is projected instead, and if that is also
    (nearly) parallel to X, the flange Z axis. Tool Z = X x Y. The chosen fallback is named in
    the warnings.

    Args:
        rotation_world_flange: (3, 3) flange rotation ``R_world_flange`` at the aligned pose.
        variant: ``"6d"`` or ``"5d"``.
        current_rotation: 5D only: the tool's current ``R_flange_tool`` whose Y to keep.

    Returns:
        OrientationResult with ``method`` ``"abc-world-6d"`` or ``"abc-world-5d"``, zero
        defect and no displacements.

    Raises:
        InvalidInputError: a rotation that is not proper orthonormal, an unknown variant,
            or ``current_rotation`` given with ``variant="6d"``.
    """
    R_world_flange = as_rotation(rotation_world_flange, name="rotation_world_flange")
    if variant not in ("6d", "5d"):
        raise InvalidInputError(f"variant must be '6d' or '5d', got {variant!r}.")
    R_flange_tool_6d = R_world_flange.T @ R_WORLD_TOOL_PARALLEL  # (PA-2)
    if variant == "6d":
        if current_rotation is not None:
            raise InvalidInputError(
                "current_rotation is used only by the 5D variant; drop it or pass variant='5d'."
            )
        return OrientationResult(
            method="abc-world-6d",
            rotation=R_flange_tool_6d,
            orthogonality_defect_deg=0.0,
            displacements=(),
            warnings=(),
        )

    x = R_flange_tool_6d[:, 0]
    msgs: list[str] = []
    candidates: list[tuple[str, np.ndarray]] = []
    if current_rotation is not None:
        R_cur = as_rotation(current_rotation, name="current_rotation")
        candidates.append(("the current tool Y", R_cur[:, 1]))
    candidates.append(("the flange Y axis", np.array([0.0, 1.0, 0.0])))
    candidates.append(("the flange Z axis", np.array([0.0, 0.0, 1.0])))
    for i, (label, y_ref) in enumerate(candidates):
        y = y_ref - np.dot(y_ref, x) * x
        if np.linalg.norm(y) > 1e-3:  # y_ref more than ~0.06 deg away from X
            y = _unit(y)
            if i > 0 and current_rotation is not None:
                msgs.append(
                    "5D: the current tool Y is (nearly) parallel to the new tool X; tool Y was "
                    f"taken from {label} instead."
                )
            msgs.append(f"5D: only tool X is calibrated; tool Y is {label} projected normal to X.")
            break
    else:  # pragma: no cover - flange Y and Z cannot both be parallel to X
        raise AssertionError("unreachable")
    R = _proper(x, y)
    return OrientationResult(
        method="abc-world-5d",
        rotation=R,
        orthogonality_defect_deg=0.0,
        displacements=(),
        warnings=tuple(msgs),
    )


def _check_inputs(
    rotations: Any, positions: Any, tcp: Any, n: int | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    R = as_rotations(rotations, name="rotations")
    if n is not None and R.shape[0] != n:
        raise InvalidInputError(
            f"rotations has {R.shape[0]} flange poses; this method needs exactly {n} "
            "(0 = touch, 1 = tip on tool -X axis, 2 = tip on +Y)."
        )
    f = as_positions(positions, n=R.shape[0], name="positions")
    t = as_vector3(tcp, name="tcp")
    return R, f, t


def _tip_in_flange(
    R: np.ndarray, f: np.ndarray, t: np.ndarray
) -> tuple[np.ndarray, np.ndarray, float]:
    """Reference tip from touch 0 (7) and its FLANGE coordinates at every pose (eqs. 8-17).

    Returns ``(r, d, scale)`` with ``d[i] = R_i^T (r - f_i) - t`` (the tip relative to the TCP,
    FLANGE coordinates) and a length scale for the zero tests.
    """
    r = R[0] @ t + f[0]  # (7)
    v = np.einsum("nji,nj->ni", R, r - f)  # v_i = (T_i)^-1 r
    d = v - t
    scale = max(1.0, float(np.linalg.norm(t)), float(np.abs(f).max()), float(np.linalg.norm(r)))
    return r, d, scale


def _check_displaced(d: np.ndarray, index: int, scale: float, what: str) -> float:
    length = float(np.linalg.norm(d))
    if length <= 1e-9 * scale:
        raise DegenerateTouchesError(
            f"touch {index} ({what}): the reference tip is still at the TCP (|Delta| = "
            f"{length:.3g}); move the tool so that the tip lies on {what}, clearly away from "
            "the TCP (e.g. 50 mm or more), then record again.",
            index=index,
        )
    return length


def _short_warning(index: int, what: str, length: float, min_displacement: float) -> str:
    return (
        f"touch {index} ({what}): displacement {length:.3g} is shorter than "
        f"{min_displacement:g}; the angular error grows as (touch error)/(displacement), move "
        "farther from the TCP for a more accurate orientation."
    )


def _c2_from_perp(
    p: np.ndarray, index: int, d: np.ndarray, what: str
) -> np.ndarray:
    """Unit c2 from the component of a +Y point normal to c1; error if it is on the X axis."""
    norm_p = float(np.linalg.norm(p))
    if norm_p <= _SIN_DEGENERATE * float(np.linalg.norm(d)):
        raise DegenerateTouchesError(
            f"touch {index} ({what}): the reference tip lies on the tool X axis, so tool Y is "
            "undefined; move the tool sideways so that the tip lies on the tool's +Y side.",
            index=index,
        )
    return p / norm_p


def _common_warnings(
    t: np.ndarray, c1: np.ndarray, defect_deg: float
) -> list[str]:
    msgs: list[str] = []
    if defect_deg > DEFECT_WARN_DEG:
        msgs.append(
            f"orthogonality defect {defect_deg:.2f} deg is large (> {DEFECT_WARN_DEG:g} deg): "
            "the -X and +Y touches disagree; repeat them more carefully and farther from the TCP."
        )
    t_norm = float(np.linalg.norm(t))
    if t_norm > 0.0 and float(np.dot(c1, t)) < -0.5 * t_norm:
        msgs.append(
            "tool X points back towards the flange (more than 120 deg from the TCP direction): "
            "if the tool's working direction "
            "points away from the flange, the tip was probably placed on the +X axis in the "
            "second step (Delta1 > 0 instead of negative); check and repeat it."
        )
    return msgs


def solve_three_point(
    rotations: Any,
    positions: Any,
    tcp: Any,
    *,
    variant: Literal[1, 2],
    min_displacement: float = MIN_DISPLACEMENT_DEFAULT,
) -> OrientationResult:
    """Three-point orientation method (methods.md section 5, paper eqs. 7-30).

    Rows of ``rotations``/``positions`` (flange poses ``R_world_flange``, ``p_world_flange``):

    0. the TCP touches the reference tip: ``r = R_0 t + f_0`` (7);
    1. the tip lies on the tool's negative X axis: ``v1 = R_1^T (r - f_1) = t + Delta1 c1``,
       ``Delta1 = -|v1 - t|``, ``c1 = (v1 - t) / Delta1`` (8-17);
    2. variant 1: the tip lies on the tool's positive Y axis:
       ``c2 = (v2 - t) / |v2 - t|`` (18-24), then Gram-Schmidt keeping c1 (module docstring);
       variant 2: the tip lies anywhere in the tool XY plane with positive Y:
       ``w = v - t``, ``Delta3 = c1 . w``, ``Delta4 = |w - Delta3 c1|``,
       ``c2 = (w - Delta3 c1) / Delta4`` (25-29).

    ``c3 = c1 x c2`` (30); the result is ``R_flange_tool = [c1 c2 c3]``.

    Args:
        rotations: (3, 3, 3) flange rotations.
        positions: (3, 3) flange positions (any length unit).
        tcp: (3,) calibrated TCP ``t`` in FLANGE coordinates, same unit.
        variant: 1 or 2.
        min_displacement: displacements shorter than this give a warning (default 20, mm).

    Returns:
        OrientationResult (``method`` ``"three-point-1"`` / ``"three-point-2"``).

    Raises:
        InvalidInputError: wrong shapes, NaN, non-rotations, unknown variant.
        DegenerateTouchesError: the tip was not displaced (|Delta| ~ 0) in row 1 or 2, or in
            row 2 it lies on the tool X axis (tool Y undefined); ``.index`` names the row.
    """
    if variant not in (1, 2) or isinstance(variant, bool):
        raise InvalidInputError(f"variant must be 1 or 2, got {variant!r}.")
    R, f, t = _check_inputs(rotations, positions, tcp, n=3)
    _, d, scale = _tip_in_flange(R, f, t)
    minus_x = "the tool's -X axis"
    plus_y = "the tool's +Y axis" if variant == 1 else "the tool's +Y half-plane"

    delta1 = _check_displaced(d[1], 1, scale, minus_x)
    c1 = -d[1] / delta1  # Delta1 = -|v1 - t| (8-17)
    _check_displaced(d[2], 2, scale, plus_y)
    msgs: list[str] = []
    if variant == 1:
        delta2 = float(np.linalg.norm(d[2]))
        c2_raw = d[2] / delta2  # (18-24)
        _c2_from_perp(d[2] - np.dot(d[2], c1) * c1, 2, d[2], plus_y)
        defect = abs(90.0 - _angle_deg(c1, c2_raw))
        c2 = _unit(c2_raw - np.dot(c2_raw, c1) * c1)  # Gram-Schmidt keeping c1
        lever2 = delta2
    else:
        w = d[2]
        delta3 = float(np.dot(c1, w))  # (25-29)
        c2 = _c2_from_perp(w - delta3 * c1, 2, w, plus_y)
        lever2 = float(np.linalg.norm(w - delta3 * c1))  # Delta4
        defect = 0.0
    if delta1 < min_displacement:
        msgs.append(_short_warning(1, minus_x, delta1, min_displacement))
    if lever2 < min_displacement:
        what = plus_y if variant == 1 else plus_y + " (distance from the X axis, Delta4)"
        msgs.append(_short_warning(2, what, lever2, min_displacement))
    msgs.extend(_common_warnings(t, c1, defect))
    return OrientationResult(
        method=f"three-point-{variant}",
        rotation=_proper(c1, c2),
        orthogonality_defect_deg=float(defect),
        displacements=(delta1, lever2),
        warnings=tuple(msgs),
    )


def solve_three_point_lstsq(
    rotations: Any,
    positions: Any,
    tcp: Any,
    roles: Sequence[str],
    *,
    min_displacement: float = MIN_DISPLACEMENT_DEFAULT,
) -> OrientationResult:
    """Least-squares generalisation of the three-point method (methods.md section 5).

    One row has role ``"touch"`` (the TCP on the reference, (7)); rows with role ``"minus_x"``
    put the tip on the tool's negative X axis and rows with role ``"plus_y"`` put it anywhere in
    the tool's +Y half-plane (like variant 2). With ``d_i = R_i^T (r - f_i) - t``:

    - ``c1``: direction of the best line through ``t`` fitting the -X points, i.e. the unit
      ``u`` minimising ``sum |d_i - (d_i . u) u|^2``: the first right singular vector of the
      stacked ``d_i`` (SVD), signed so that ``sum d_i . c1 < 0`` (the points lie on -X);
      with one -X row this is exactly (8-17).
    - ``c2``: the +Y points' components normal to c1, ``p_i = d_i - (d_i . c1) c1``, fitted by
      the best half-line in that plane (first right singular vector of the stacked ``p_i``,
      signed so that ``sum p_i . c2 > 0``); with one +Y row this is exactly (25-29).
    - ``c3 = c1 x c2`` (30).

    ``orthogonality_defect_deg``: the +Y points and ``t`` span the tool XY plane, which must
    contain c1. When there are at least two +Y points spread over that plane (second singular
    value of the stacked ``d_i`` at least ``_PLANE_SPREAD`` = 0.1 times the first), the defect
    is ``|90 - angle(c1, n)|`` with ``n`` the normal of their best-fit plane through ``t`` (the
    last right singular vector): the angle by which the measured X leaves the measured XY
    plane. Otherwise (one +Y point, or all on one line through ``t``) the +Y points carry no
    redundant information about the angle between X and Y and the defect is 0, as in variant 2.

    Args:
        rotations: (N, 3, 3) flange rotations, N >= 3.
        positions: (N, 3) flange positions.
        tcp: (3,) calibrated TCP in FLANGE coordinates.
        roles: N strings, each ``"touch"``, ``"minus_x"`` or ``"plus_y"``; exactly one
            ``"touch"`` and at least one of each other role.
        min_displacement: displacements shorter than this give a warning (default 20, mm).

    Returns:
        OrientationResult (``method="three-point-lstsq"``); ``displacements`` has one entry per
        non-touch row in row order: ``|d_i|`` for -X rows, distance from the X axis for +Y rows.

    Raises:
        InvalidInputError: shapes, NaN, non-rotations, bad roles.
        DegenerateTouchesError: a row whose tip is not displaced, or all +Y points on the X axis.
    """
    R, f, t = _check_inputs(rotations, positions, tcp, n=None)
    if isinstance(roles, str) or len(roles) != R.shape[0]:
        raise InvalidInputError(
            f"roles must list one role per flange pose ({R.shape[0]}), got {roles!r}."
        )
    for i, role in enumerate(roles):
        if role not in _ROLES:
            raise InvalidInputError(
                f"roles[{i}] = {role!r} is not a role; use 'touch', 'minus_x' or 'plus_y'.",
                index=i,
            )
    touch = [i for i, role in enumerate(roles) if role == "touch"]
    mx = [i for i, role in enumerate(roles) if role == "minus_x"]
    py = [i for i, role in enumerate(roles) if role == "plus_y"]
    if len(touch) != 1:
        raise InvalidInputError(
            f"roles must contain exactly one 'touch' (the TCP on the reference), found "
            f"{len(touch)}."
        )
    if not mx or not py:
        raise InvalidInputError(
            "roles need at least one 'minus_x' row (tip on the tool -X axis) and one 'plus_y' "
            f"row (tip in the +Y half-plane); got {len(mx)} and {len(py)}."
        )
    order = [touch[0]] + [i for i in range(R.shape[0]) if i != touch[0]]
    _, d_sorted, scale = _tip_in_flange(R[order], f[order], t)
    d = np.empty_like(d_sorted)
    d[order] = d_sorted

    minus_x = "the tool's -X axis"
    plus_y = "the tool's +Y half-plane"
    lengths = {i: _check_displaced(d[i], i, scale, minus_x) for i in mx}
    for i in py:
        _check_displaced(d[i], i, scale, plus_y)

    D = d[mx]
    _, _, vt = np.linalg.svd(D, full_matrices=False)
    c1 = vt[0]
    if float(np.sum(D @ c1)) > 0.0:
        c1 = -c1
    msgs: list[str] = []
    for i in mx:
        if float(np.dot(d[i], c1)) >= 0.0:
            msgs.append(
                f"touch {i} ({minus_x}): the tip lies on the +X side of the TCP (Delta1 not "
                "negative) while the other -X points are on the -X side; check that row."
            )

    P = d[py] - np.outer(d[py] @ c1, c1)
    norms = np.linalg.norm(P, axis=1)
    scales = np.linalg.norm(d[py], axis=1)
    if np.all(norms <= _SIN_DEGENERATE * scales):
        raise DegenerateTouchesError(
            "every +Y point lies on the tool X axis, so tool Y is undefined; move the tool "
            "sideways so that the tip lies on the tool's +Y side.",
            index=py[0],
        )
    _, _, vt = np.linalg.svd(P, full_matrices=False)
    c2 = vt[0] - np.dot(vt[0], c1) * c1
    c2 = _unit(c2)
    if float(np.sum(P @ c2)) < 0.0:
        c2 = -c2
    levers = {i: float(np.dot(d[i], c2)) for i in py}
    for i in py:
        if levers[i] <= 0.0:
            msgs.append(
                f"touch {i} ({plus_y}): the tip lies on the -Y side of the tool while the other "
                "+Y points are on the +Y side; check that row."
            )

    defect = 0.0
    if len(py) >= 2:
        sv, vt = np.linalg.svd(d[py], full_matrices=True)[1:]
        if sv[1] >= _PLANE_SPREAD * sv[0]:
            defect = abs(90.0 - _angle_deg(c1, vt[2]))  # c1 should lie in the +Y points' plane

    lengths.update({i: abs(levers[i]) for i in py})
    for i in sorted(lengths):
        if lengths[i] < min_displacement:
            what = minus_x if i in mx else plus_y + " (distance from the X axis)"
            msgs.append(_short_warning(i, what, lengths[i], min_displacement))
    msgs.extend(_common_warnings(t, c1, defect))
    return OrientationResult(
        method="three-point-lstsq",
        rotation=_proper(c1, c2),
        orthogonality_defect_deg=float(defect),
        displacements=tuple(lengths[i] for i in sorted(lengths)),
        warnings=tuple(msgs),
    )
