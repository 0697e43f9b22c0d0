"""Input checks shared by the controller's modules (poses given by callers), each a
``ControllerError`` naming the argument and what is wrong."""

from __future__ import annotations

import numpy as np

from tcp_pendant.controller.errors import ControllerError

__all__ = ["check_pose"]


def check_pose(T: object, what: str) -> np.ndarray:
    """A rigid transform (4, 4, metres) checked and copied: finite, a proper rotation in the
    upper-left 3x3 block (orthonormal to 1e-6, right-handed) and ``[0, 0, 0, 1]`` as last row.

    Raises:
        ControllerError: naming ``what``.
    """
    M = np.asarray(T, dtype=float)
    if M.shape != (4, 4) or not np.all(np.isfinite(M)):
        raise ControllerError(f"{what} must be a finite 4x4 homogeneous matrix (metres), got shape {M.shape}.")
    R = M[:3, :3]
    if np.abs(R.T @ R - np.eye(3)).max() > 1e-6 or np.linalg.det(R) <= 0.0:
        raise ControllerError(f"{what} has no proper rotation in its upper-left 3x3 block "
                              "(columns must be orthonormal and right-handed).")
    if np.abs(M[3] - [0.0, 0.0, 0.0, 1.0]).max() > 1e-12:
        raise ControllerError(f"{what} must have [0, 0, 0, 1] as its last row.")
    return M.copy()
