"""Reusable input checks: turn user input into float arrays or raise a clear error.

Every function returns a new float64 array (never a view of the caller's data) and raises
:class:`tcpcal.errors.InvalidInputError` whose message names the argument, the 0-based index of
the bad item (also in ``.index``), what is wrong and what to do. Used by the solvers, the
orientation methods and the CLI.

A rotation is accepted when it is finite, orthonormal within ``ORTHONORMAL_TOL`` (maximum
absolute entry of ``R^T R - I``) and proper (``det R > 0``, i.e. +1 within the tolerance).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from tcpcal import _lapack
from tcpcal.errors import InvalidInputError

__all__ = [
    "MAX_ABS_COORDINATE",
    "ORTHONORMAL_TOL",
    "as_positions",
    "as_rotation",
    "as_rotations",
    "as_vector3",
    "read_only_array",
    "rotations_and_soa",
]

ORTHONORMAL_TOL: float = 1e-6
"""Largest accepted ``max |R^T R - I|`` of a rotation matrix."""

MAX_ABS_COORDINATE: float = 1e9
"""Largest accepted ``|coordinate|`` of a position or vector, in the caller's length unit
(unit-agnostic: a kilometre in micrometres; the CLI's own bound is 1e6 mm, docs/cli.md).
Beyond it no robot cell is meant, and sums of squares over many touches would lose their
meaning or overflow."""

_EYE = np.eye(3)
_EYE_COLUMN = _EYE[:, :, None]
# ufunc reductions without the Python wrappers of ndarray.sum/max/min (the solvers' hot path)
_add, _max, _min = np.add.reduce, np.maximum.reduce, np.minimum.reduce
_vdot = _lapack.vdot  # the sum of squares of a whole array (hot path)
_CYCLIC = np.array([0, 1, 2, 0, 1])
_ORTHONORMAL_TOL_SQ = ORTHONORMAL_TOL * ORTHONORMAL_TOL
_MAX_ABS_COORDINATE_SQ = MAX_ABS_COORDINATE * MAX_ABS_COORDINATE  # 1e18: exact in float64


def read_only_array(a: Any) -> np.ndarray:
    """A float copy of ``a`` that cannot be written (the arrays of frozen result dataclasses)."""
    out = np.array(a, dtype=float)
    out.setflags(write=False)
    return out


def _as_float_array(x: Any, name: str, expected: str) -> np.ndarray:
    try:
        arr = np.array(x, dtype=float)  # always a copy
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"{name} must be {expected} of numbers; could not read it as numbers ({exc})."
        ) from None
    return arr


def _first_nonfinite(arr: np.ndarray) -> int | None:
    """0-based index along axis 0 of the first item holding NaN or inf, or None."""
    flat = arr.reshape(arr.shape[0], -1)
    bad = ~np.isfinite(flat).all(axis=1)
    if bad.any():
        return int(np.argmax(bad))
    return None


def as_rotations(x: Any, name: str = "rotations") -> np.ndarray:
    """Check a stack of rotation matrices (e.g. ``R_world_flange`` of every touch).

    Args:
        x: array-like of shape (N, 3, 3), N >= 1.
        name: argument name used in error messages.

    Returns:
        (N, 3, 3) float64 array (a copy).

    Raises:
        InvalidInputError: wrong shape, NaN/inf, a matrix that is not orthonormal within
            ``ORTHONORMAL_TOL`` or has determinant -1 (a reflection). Errors about one matrix
            carry ``.index``.
    """
    return rotations_and_soa(x, name)[0]


SMALL_STACK = 64
"""Up to this many matrices the checks use batched (N, 3, 3) products (fewest numpy calls);
above, element-wise products of contiguous length-N rows (``(3, 3, N)`` layout, faster)."""


@functools.lru_cache(maxsize=16)
def _eye_stack(n: int) -> np.ndarray:
    """``n`` 3x3 identities, (n, 3, 3), read-only: subtracting an array of the same shape is
    several times faster in numpy than broadcasting one 3x3 identity over the stack."""
    eye = np.tile(_EYE, (n, 1, 1))
    eye.setflags(write=False)
    return eye


def rotations_and_soa(x: Any, name: str = "rotations") -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`as_rotations`, also returning the ``(3, 3, N)`` layout ``y[j, k] = R[:, j, k]``
    (``tcpcal._stats.soa``) when the check computed it (N > ``SMALL_STACK``), else None.

    The clean path costs a handful of numpy calls at any N (the solvers run it on every call):
    the column dot products ``R^T R`` (a NaN or inf fails their check; above ``SMALL_STACK``
    one sum looks for them first) and the determinants; the reason of a failure is looked up
    matrix by matrix only then (slow path, errors only).
    """
    arr = _as_float_array(x, name, "an (N, 3, 3) array of rotation matrices")
    if arr.ndim != 3 or arr.shape[1:] != (3, 3):
        raise InvalidInputError(
            f"{name} must have shape (N, 3, 3) (one 3x3 rotation matrix per touch), "
            f"got shape {arr.shape}."
        )
    if arr.shape[0] == 0:
        raise InvalidInputError(f"{name} is empty; pass at least one 3x3 rotation matrix.")
    n = arr.shape[0]
    y = None
    if n <= SMALL_STACK:
        # a NaN or inf makes R^T R so, which fails the check below: _raise_first_bad names it
        gram = arr.transpose(0, 2, 1) @ arr  # R^T R
        gram -= _eye_stack(n)
        # Clean path, one call: a sum of squares below tol^2 bounds every |entry| (float
        # rounding is monotone: no rounded partial sum of squares falls below a rounded
        # square, so an entry beyond tol makes the sum at least fl(tol^2)); else, or for a
        # NaN, the entry-by-entry check decides.
        if not float(_vdot(gram, gram)) < _ORTHONORMAL_TOL_SQ:
            np.abs(gram, out=gram)
            if not float(_max(gram, axis=None)) <= ORTHONORMAL_TOL:
                _raise_first_bad(arr, gram.reshape(n, 9).max(axis=1), name)
        det = _lapack.det(arr)
    else:
        if not math.isfinite(float(_add(arr, axis=None))):  # NaN/inf (or an overflow: then go on)
            _raise_nonfinite(arr, name)
        y = np.ascontiguousarray(arr.reshape(n, 9).T).reshape(3, 3, n)
        # R^T R entries: c_k . c_l = sum_j y[j, k] y[j, l]
        gram = np.einsum("jkn,jln->kln", y, y)
        gram -= _EYE_COLUMN
        np.abs(gram, out=gram)
        defect = gram.reshape(9, n).max(axis=0)
        if not float(defect.max()) <= ORTHONORMAL_TOL:
            _raise_first_bad(arr, defect, name)
        # Orthonormal => det = +-1 = sum_j c0_j (c1 x c2)_j (np.linalg.det: ~0.1 us per matrix)
        yc = y[_CYCLIC]  # rows j, j+1, j+2 (mod 3) for the cross products
        det = (yc[0:3, 0] * (yc[1:4, 1] * yc[2:5, 2] - yc[2:5, 1] * yc[1:4, 2])).sum(axis=0)
    # (no NaN here: the orthonormality check refused it; a few numbers: a Python min is cheaper)
    if (min(det.tolist()) if n <= SMALL_STACK else float(_min(det))) < 0.0:
        i = int(np.argmax(det < 0.0))
        raise InvalidInputError(
            f"{name}[{i}] is a reflection (determinant {det[i]:.6g}), not a rotation; a proper "
            "rotation has determinant +1 (check for a swapped or negated axis).",
            index=i,
        )
    return arr, y


def _raise_nonfinite(arr: np.ndarray, name: str) -> None:
    """Raise the error about the first matrix holding NaN or inf, if any."""
    i = _first_nonfinite(arr)
    if i is not None:
        raise InvalidInputError(
            f"{name}[{i}] contains NaN or inf; every entry of a rotation matrix must be a "
            "finite number (re-record or remove that touch).",
            index=i,
        )


def _raise_first_bad(arr: np.ndarray, defect: np.ndarray, name: str) -> None:
    """Raise the error about the first matrix that is not finite or not orthonormal."""
    _raise_nonfinite(arr, name)
    i = int(np.argmax(~(defect <= ORTHONORMAL_TOL)))  # NaN counts as bad
    raise InvalidInputError(
        f"{name}[{i}] is not a rotation matrix: it is not orthonormal within "
        f"{ORTHONORMAL_TOL:g} (max |R^T R - I| = {defect[i]:.3g}); pass a proper rotation "
        "(check the column order, the angle units and that enough digits were printed).",
        index=i,
    )


def as_rotation(x: Any, name: str = "rotation") -> np.ndarray:
    """Check one rotation matrix.

    Args:
        x: array-like of shape (3, 3).
        name: argument name used in error messages.

    Returns:
        (3, 3) float64 array (a copy).

    Raises:
        InvalidInputError: wrong shape, NaN/inf, not orthonormal within ``ORTHONORMAL_TOL``,
            or a reflection.
    """
    arr = _as_float_array(x, name, "a 3x3 rotation matrix")
    if arr.shape != (3, 3):
        raise InvalidInputError(
            f"{name} must be a 3x3 rotation matrix, got shape {arr.shape}."
        )
    try:
        rotation: np.ndarray = as_rotations(arr[None], name=name)[0]
        return rotation
    except InvalidInputError as exc:
        # Drop the "[0]" index of the one-element stack from the message.
        raise InvalidInputError(str(exc).replace(f"{name}[0]", name, 1)) from None


def as_positions(x: Any, n: int | None = None, name: str = "positions") -> np.ndarray:
    """Check a stack of 3-vectors (e.g. ``p_world_flange`` of every touch).

    Args:
        x: array-like of shape (N, 3).
        n: required number of rows (e.g. the number of rotations), or None for any N >= 1.
        name: argument name used in error messages.

    Returns:
        (N, 3) float64 array (a copy).

    Raises:
        InvalidInputError: wrong shape, a row count different from ``n``, NaN/inf or a
            coordinate beyond ``MAX_ABS_COORDINATE`` (with ``.index`` of the first bad row).
    """
    arr = _as_float_array(x, name, "an (N, 3) array of positions")
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InvalidInputError(
            f"{name} must have shape (N, 3) (one x, y, z position per touch), got shape "
            f"{arr.shape}."
        )
    if arr.shape[0] == 0:
        raise InvalidInputError(f"{name} is empty; pass at least one x, y, z position.")
    if n is not None and arr.shape[0] != n:
        raise InvalidInputError(
            f"{name} has {arr.shape[0]} rows but there are {n} rotations; pass exactly one "
            "position per rotation (same touches, same order)."
        )
    # Up to SMALL_STACK rows the clean path is one call: a sum of squares below
    # MAX_ABS_COORDINATE^2 bounds every |entry| (monotone rounding, as in rotations_and_soa).
    # Otherwise one reduction decides: the largest |entry| is NaN for a NaN (maximum
    # propagates it), inf for an inf.
    if not (arr.shape[0] <= SMALL_STACK and float(_vdot(arr, arr)) < _MAX_ABS_COORDINATE_SQ):
        if not float(_max(np.abs(arr), axis=None)) <= MAX_ABS_COORDINATE:
            _raise_bad_coordinate(arr, name)
    return arr


def _raise_bad_coordinate(arr: np.ndarray, name: str) -> None:
    """Raise the error about the first row holding NaN, inf or a coordinate beyond
    ``MAX_ABS_COORDINATE`` (the caller found one)."""
    i = _first_nonfinite(arr)
    if i is not None:
        raise InvalidInputError(
            f"{name}[{i}] contains NaN or inf; every coordinate must be a finite number "
            "(re-record or remove that touch).",
            index=i,
        )
    flat = np.abs(arr.reshape(arr.shape[0], -1))
    i = int(np.argmax((flat > MAX_ABS_COORDINATE).any(axis=1)))
    raise InvalidInputError(
        f"{name}[{i}] has a coordinate {float(flat[i].max()):.6g} beyond +-{MAX_ABS_COORDINATE:g} "
        "(length units): not a position in a robot cell; check the unit and the column order, "
        "or re-record or remove that touch.",
        index=i,
    )


def as_vector3(x: Any, name: str = "vector") -> np.ndarray:
    """Check one finite 3-vector.

    Args:
        x: array-like of 3 numbers.
        name: argument name used in error messages.

    Returns:
        (3,) float64 array (a copy).

    Raises:
        InvalidInputError: not 3 numbers, NaN/inf, or beyond ``MAX_ABS_COORDINATE``.
    """
    arr = _as_float_array(x, name, "a 3-vector")
    if arr.shape != (3,):
        raise InvalidInputError(
            f"{name} must be 3 numbers (x, y, z), got shape {arr.shape}."
        )
    if not np.isfinite(arr).all():
        raise InvalidInputError(f"{name} contains NaN or inf; pass 3 finite numbers.")
    if float(np.abs(arr).max()) > MAX_ABS_COORDINATE:
        raise InvalidInputError(
            f"{name} has a coordinate {float(np.abs(arr).max()):.6g} beyond +-{MAX_ABS_COORDINATE:g} "
            "(length units): check the unit and the order of the numbers."
        )
    return arr
