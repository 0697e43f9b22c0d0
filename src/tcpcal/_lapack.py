"""numpy's own LAPACK routines without the Python wrappers of ``numpy.linalg`` (hot path).

For a 3x3 matrix ``numpy.linalg.eigh`` spends ~4x as long in its wrapper (type checks, an
``errstate`` context, result wrapping) as in LAPACK, and ``numpy.linalg.det`` of a few 3x3
matrices ~2x; the solver calls them on every solve (``tests/bench/bench_solver.py``). These
call the same gufuncs (``numpy.linalg._umath_linalg``) with the same signature, so the numbers
are bit-identical. Only for finite real float64 input (the callers' inputs are checked): the
wrapper's error for a LAPACK failure, which finite real symmetric 3x3 input cannot cause, is
not raised. Falls back to ``numpy.linalg`` when numpy's internals differ.

``dot`` and ``vdot`` are ``numpy.dot`` and ``numpy.vdot`` without their ``__array_function__``
dispatch (the same C functions, ~0.3 us less per call on small arrays): for plain ndarrays
only, which is all the solvers pass them.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["det", "dot", "eigh", "vdot"]

try:
    from numpy.linalg import _umath_linalg

    _eigh_lo: Any = _umath_linalg.eigh_lo
    _det: Any = _umath_linalg.det
except (ImportError, AttributeError):  # pragma: no cover - another numpy
    _eigh_lo = _det = None

dot: Any = getattr(np.dot, "_implementation", np.dot)
vdot: Any = getattr(np.vdot, "_implementation", np.vdot)


def eigh(m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``numpy.linalg.eigh(m)`` (lower triangle) of a finite real symmetric float64 matrix:
    ascending eigenvalues and the eigenvectors as columns."""
    if _eigh_lo is None:  # pragma: no cover
        w, v = np.linalg.eigh(m)
        return w, v
    w, v = _eigh_lo(m, signature="d->dd")
    return w, v


def det(a: np.ndarray) -> np.ndarray:
    """``numpy.linalg.det(a)`` of a finite real float64 (..., 3, 3) stack."""
    if _det is None:  # pragma: no cover
        return np.asarray(np.linalg.det(a))
    return np.asarray(_det(a, signature="d->d"))
