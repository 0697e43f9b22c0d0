"""ABB "TCP & Z, X": the TCP and the TOOL frame from one set of poses (methods.md section 8).

Rows have a *role*: ``"touch"`` (the TCP touches the fixed reference point, >= 4 of them),
``"z"`` (the reference point lies on the tool's **+Z** axis ahead of the TCP,
``r = R_k (t + d_k z) + f_k`` with ``d_k > 0``: the operator backed off along the tool's Z)
and ``"x"`` (the same on the tool's **+X** axis). Several z and x rows are allowed.

The TCP ``t`` and reference ``r`` come from the touches alone by the joint least squares
(4P-3) (:func:`tcpcal.origin.solve_xyz4`, with all its figures); each axis row gives the
direction ``v_k = R_k^T (r - f_k) - t = d_k axis`` in FLANGE coordinates, and the axis is the
maximum-likelihood direction (ZX-3): the leading eigenvector of ``sum v_k v_k^T`` with the sign
that makes ``sum d_k > 0``. Z defines, X only completes (as ABB): ``x`` is orthogonalised
against ``z`` (Gram-Schmidt keeping ``z``), ``y = z x x``.

Unit-agnostic: lengths come out in the unit they went in (the CLI feeds mm); the
short-distance warning threshold ``min_distance`` defaults to 20, meant as millimetres.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from tcpcal.errors import InvalidInputError, TcpcalError
from tcpcal.origin import TcpResult, solve_xyz4
from tcpcal.tool import abc_deg_from_rotation
from tcpcal.validation import as_positions, as_rotations

__all__ = [
    "MIN_PARALLEL_ANGLE_DEG",
    "ROLES",
    "TcpZxResult",
    "parse_role",
    "solve_tcp_zx",
]

ROLES: tuple[str, ...] = ("touch", "z", "x")
"""The row roles of TCP & Z, X."""

MIN_PARALLEL_ANGLE_DEG: float = 10.0
"""Measured X closer than this (degrees) to +-Z cannot complete a frame: an error."""

_DEFECT_WARN_DEG = 2.0
_BACKWARDS_WARN_DEG = 120.0


@dataclass(frozen=True)
class TcpZxResult:
    """Result of :func:`solve_tcp_zx`.

    Attributes:
        origin: the XYZ 4-point result of the touch rows (TCP ``t`` in FLANGE, reference ``r``
            in WORLD, residuals, 95 % radius, outliers; input length unit). Its touch indices
            count the touch rows only; ``touch_rows`` maps them to input rows.
        rotation: (3, 3) ``R_flange_tool``, columns tool X, Y, Z in FLANGE (proper rotation).
        orthogonality_defect_deg: ``|90 - angle(x_meas, z)|`` in degrees, before X was
            orthogonalised against Z.
        z_distances: ``d_k`` of each z row (input length unit), in row order.
        x_distances: ``d_k`` of each x row (input length unit), in row order.
        touch_rows, z_rows, x_rows: 0-based input row of each touch / z / x row.
        warnings: plain-words warnings (the 4-point warnings first).
    """

    origin: TcpResult
    rotation: np.ndarray
    orthogonality_defect_deg: float
    z_distances: tuple[float, ...]
    x_distances: tuple[float, ...]
    touch_rows: tuple[int, ...]
    z_rows: tuple[int, ...]
    x_rows: tuple[int, ...]
    warnings: tuple[str, ...]

    def __post_init__(self) -> None:
        rot = np.array(self.rotation, dtype=float)
        rot.setflags(write=False)
        object.__setattr__(self, "rotation", rot)

    @property
    def method(self) -> str:
        """``"tcp-zx"``."""
        return "tcp-zx"

    @property
    def tcp(self) -> np.ndarray:
        """The TCP ``t`` in FLANGE coordinates (input length unit)."""
        return self.origin.tcp

    @property
    def reference(self) -> np.ndarray:
        """The reference point ``r`` in WORLD coordinates (input length unit)."""
        return self.origin.reference

    @property
    def kuka_abc_deg(self) -> np.ndarray:
        """KUKA (A, B, C) in degrees of ``rotation``: ``R = Rz(A) Ry(B) Rx(C)``."""
        return abc_deg_from_rotation(self.rotation)

    @property
    def T_flange_tool(self) -> np.ndarray:
        """4x4 ``T_flange_tool`` (translation in the input length unit)."""
        T = np.eye(4)
        T[:3, :3] = self.rotation
        T[:3, 3] = self.origin.tcp
        return T


def parse_role(text: Any, index: int | None = None) -> str:
    """A row role from text: ``touch``, ``z`` or ``x``, case-insensitive, spaces ignored.

    Raises:
        InvalidInputError: anything else (``.index`` = ``index``).
    """
    role = str(text).strip().lower()
    if role not in ROLES:
        where = "" if index is None else f"row {index + 1}: "
        raise InvalidInputError(
            f"{where}role {str(text).strip()!r} is not one of touch, z, x (touch: the TCP on the "
            "reference point; z: the reference on the tool's +Z axis ahead of the TCP; x: on "
            "its +X axis).", index=index)
    return role


def _axis(rot: np.ndarray, f: np.ndarray, rows: Sequence[int], t: np.ndarray, r: np.ndarray,
          name: str, resolution: float) -> tuple[np.ndarray, np.ndarray]:
    """(ZX-3): the unit axis and the distances ``d_k`` of the rows of one axis.

    Raises:
        InvalidInputError: a distance at or below ``resolution`` (the tool did not move away) or
            a row whose reference lies behind the TCP (``d_k <= 0``), naming that row.
    """
    v = np.einsum("kji,kj->ki", rot[list(rows)], r[None, :] - f[list(rows)]) - t[None, :]
    lengths = np.linalg.norm(v, axis=1)
    for k, row in enumerate(rows):
        if lengths[k] <= resolution:
            raise InvalidInputError(
                f"{name} row {row + 1}: the reference point is only {lengths[k]:.3g} from the TCP "
                f"(touch resolution {resolution:.3g}); back the tool off further along its "
                f"+{name.upper()} axis so the reference lies ahead of the TCP.", index=row)
    _, vecs = np.linalg.eigh(v.T @ v)
    axis = vecs[:, -1]
    d = v @ axis
    if d.sum() < 0:
        axis, d = -axis, -d
    for k, row in enumerate(rows):
        if d[k] <= 0:
            raise InvalidInputError(
                f"{name} row {row + 1}: the reference point lies behind the TCP on the tool's "
                f"{name.upper()} axis (d = {d[k]:.3g}, the other {name} rows put it ahead): the "
                f"tool was moved the wrong way. Back it off along its own -{name.upper()} "
                f"direction so the reference lies on +{name.upper()} ahead of the TCP, and "
                "record the pose again.", index=row)
    return axis / np.linalg.norm(axis), d


def solve_tcp_zx(rotations: Any, positions: Any, roles: Sequence[str], *,
                 sigma: float | None = None, detect_outliers: bool = True,
                 min_distance: float = 20.0) -> TcpZxResult:
    """ABB TCP & Z, X (methods.md section 8, (4P-1), (ZX-1)-(ZX-3)).

    Args:
        rotations: (N, 3, 3) ``R_world_flange`` of every row.
        positions: (N, 3) ``p_world_flange`` of every row (any length unit).
        roles: N roles, each ``"touch"``, ``"z"`` or ``"x"`` (case-insensitive).
        sigma: known touch noise per axis for the 4-point figures (input length unit).
        detect_outliers: flag outlying touches (see :func:`tcpcal.origin.solve_xyz4`).
        min_distance: axis distances ``d_k`` shorter than this give a warning (angular error
            ~ sigma / d); 20 is meant as mm.

    Returns:
        A frozen :class:`TcpZxResult`.

    Raises:
        InvalidInputError: wrong shapes or roles; fewer than 4 touch rows; no z row; no x row;
            an axis row whose reference lies behind the TCP (``d <= 0``: the tool moved the
            wrong way) or at the TCP; measured X within ``MIN_PARALLEL_ANGLE_DEG`` of +-Z.
            Errors about one row carry ``.index`` (0-based input row).
        DegenerateTouchesError: the touches cannot determine the TCP (as for the 4-point
            method); its ``.index``, if any, counts input rows.
    """
    rot = as_rotations(rotations)
    f = as_positions(positions, n=rot.shape[0])
    if len(roles) != rot.shape[0]:
        raise InvalidInputError(
            f"{len(roles)} roles for {rot.shape[0]} poses; give one role (touch, z or x) per row.")
    parsed = [parse_role(text, i) for i, text in enumerate(roles)]
    touch_rows = tuple(i for i, p in enumerate(parsed) if p == "touch")
    z_rows = tuple(i for i, p in enumerate(parsed) if p == "z")
    x_rows = tuple(i for i, p in enumerate(parsed) if p == "x")
    if len(touch_rows) < 4:
        raise InvalidInputError(
            f"TCP & Z, X needs at least 4 touch rows (the TCP on the reference point from clearly "
            f"different orientations), got {len(touch_rows)}; record "
            f"{4 - len(touch_rows)} more.")
    if not z_rows:
        raise InvalidInputError(
            "TCP & Z, X needs at least one z row: a pose with the reference point on the tool's "
            "+Z axis ahead of the TCP (back the tool off straight along its Z).")
    if not x_rows:
        raise InvalidInputError(
            "TCP & Z, X needs at least one x row: a pose with the reference point on the tool's "
            "+X axis (move the tool along its own -X from the touch).")
    try:
        origin = solve_xyz4(rot[list(touch_rows)], f[list(touch_rows)], sigma=sigma,
                            detect_outliers=detect_outliers)
    except TcpcalError as exc:  # its touch index counts touch rows: map it to the input row
        if exc.index is not None and 0 <= exc.index < len(touch_rows):
            exc.index = touch_rows[exc.index]
        raise
    t, r = origin.tcp, origin.reference
    noise = origin.noise_sigma if math.isfinite(origin.noise_sigma) else 0.0
    resolution = max(3.0 * noise, 1e-9 * max(1.0, float(np.linalg.norm(r))))
    z, dz = _axis(rot, f, z_rows, t, r, "z", resolution)
    x_meas, dx = _axis(rot, f, x_rows, t, r, "x", resolution)
    angle_xz = math.degrees(math.atan2(float(np.linalg.norm(np.cross(x_meas, z))),
                                       float(x_meas @ z)))
    if angle_xz < MIN_PARALLEL_ANGLE_DEG or angle_xz > 180.0 - MIN_PARALLEL_ANGLE_DEG:
        raise InvalidInputError(
            f"the measured tool X is {min(angle_xz, 180.0 - angle_xz):.1f} deg from the tool Z "
            f"axis (at least {MIN_PARALLEL_ANGLE_DEG:g} deg needed): the x rows put the "
            "reference on the Z axis again. For the x rows move the tool sideways, along its "
            "own -X, so the reference lies on +X.", index=x_rows[0])
    x = x_meas - (x_meas @ z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    rotation = np.column_stack([x, y / np.linalg.norm(y), z])
    defect = abs(90.0 - angle_xz)

    warnings = list(origin.warnings)
    if defect > _DEFECT_WARN_DEG:
        warnings.append(
            f"the measured X is {defect:.1f} deg from perpendicular to Z; X was corrected (Z "
            "kept). Check that the x rows put the reference exactly on the tool's X axis.")
    short = [(name, row, d) for name, rows, ds in (("z", z_rows, dz), ("x", x_rows, dx))
             for row, d in zip(rows, ds) if d < min_distance]
    for name, row, d in short:
        warnings.append(
            f"{name} row {row + 1}: the reference is only {d:.1f} from the TCP; the angular "
            f"error grows as the distance shrinks (back off at least {min_distance:g}).")
    t_norm = float(np.linalg.norm(t))
    if t_norm > 0:
        ang_t = math.degrees(math.acos(float(np.clip(z @ t / t_norm, -1.0, 1.0))))
        if ang_t > _BACKWARDS_WARN_DEG:
            warnings.append(
                f"tool Z points {ang_t:.0f} deg away from the TCP direction (back towards the "
                "flange); for a straight tool the z rows probably put the reference behind the "
                "TCP (the tool moved forwards instead of backing off).")
    return TcpZxResult(
        origin=origin, rotation=rotation, orthogonality_defect_deg=defect,
        z_distances=tuple(float(v) for v in dz), x_distances=tuple(float(v) for v in dx),
        touch_rows=touch_rows, z_rows=z_rows, x_rows=x_rows, warnings=tuple(warnings))
