"""The errors tcpcal raises.

Every error the package raises on bad input is a :class:`TcpcalError`, itself a
``ValueError`` so that callers that already catch ``ValueError`` keep working. Messages name
what is wrong and what to do about it. An error about one touch (one recorded flange pose)
carries ``.index``, the 0-based index of that touch; otherwise ``.index`` is ``None``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["DegenerateTouchesError", "InvalidInputError", "TcpcalError"]


class TcpcalError(ValueError):
    """Base class of every error tcpcal raises on bad input.

    Args:
        message: what is wrong and what to do, in plain words.
        index: 0-based index of the touch the error is about, if it is about one touch.
    """

    index: int | None

    def __init__(self, message: str, *, index: int | None = None) -> None:
        super().__init__(message)
        self.index = None if index is None else int(index)


class InvalidInputError(TcpcalError):
    """Malformed input: NaN or inf, wrong shape, a rotation that is not a proper orthonormal
    matrix, too few touches."""


class DegenerateTouchesError(TcpcalError):
    """Well-formed touches that cannot determine the unknowns (methods.md section 2,
    "Degeneracy").

    Attributes:
        unobservable_axis: unit vector in FLANGE coordinates along which the TCP cannot be
            observed (e.g. the common rotation axis of all touches), or ``None`` when no single
            axis describes the defect (e.g. all touches have the same orientation).
        indices: the 0-based touches the defect is about (e.g. the two with the same
            orientation), empty when it is about all of them.
    """

    unobservable_axis: np.ndarray | None
    indices: tuple[int, ...]

    def __init__(
        self,
        message: str,
        *,
        unobservable_axis: np.ndarray | None = None,
        index: int | None = None,
        indices: tuple[int, ...] = (),
    ) -> None:
        super().__init__(message, index=index)
        self.indices = tuple(int(i) for i in indices)
        if unobservable_axis is None:
            self.unobservable_axis = None
        else:
            axis = np.array(unobservable_axis, dtype=float).reshape(3)
            axis.setflags(write=False)
            self.unobservable_axis = axis
