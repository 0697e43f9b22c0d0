"""The ``matrix`` pseudo-format: ``T_flange_tool`` as a 4x4 homogeneous matrix.

Not a controller: tool data text only (``tcpcal convert``, ``tools export --format matrix``,
the app's export list) and the POSES.csv layout ``matrix`` (columns ``r11, r12, ..., r33``,
``R_world_flange`` row-major). No controller file, no pose import. Translation in mm.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from tcpcal.controllers._format import (
    TEXT_NUM_RE,
    ControllerFormat,
    CsvLayout,
    text_float,
    text_number,
    tool_from_rotation,
)
from tcpcal.errors import InvalidInputError
from tcpcal.tool import Tool
from tcpcal.validation import ORTHONORMAL_TOL, as_rotation

__all__ = ["FORMAT", "parse_text", "render_text"]


def render_text(tool: Tool, slot: int = 1) -> str:
    """4 lines of 4 numbers, row-major, translation in mm (``slot`` is not written)."""
    T = tool.T_flange_tool_mm
    T[3] = (0.0, 0.0, 0.0, 1.0)
    return "\n".join(" ".join(text_number(v) for v in row) for row in T) + "\n"


def parse_text(text: str, name: str | None) -> Tool:
    """16 numbers (or 12: the top 3x4) with any separators and ``#`` comments; the last row
    must be ``0 0 0 1`` and the rotation orthonormal within 1e-6."""
    body = re.sub(r"#[^\n]*", " ", text)
    leftovers = TEXT_NUM_RE.sub(" ", body)
    bad = re.findall(r"[^\s,;\[\]()]+", leftovers)
    if bad:
        raise InvalidInputError(
            f"matrix: could not parse {bad[0]!r}; write 4 rows of 4 numbers (row-major, mm)."
        )
    tokens = TEXT_NUM_RE.findall(body)
    if len(tokens) not in (12, 16):
        raise InvalidInputError(
            f"matrix: found {len(tokens)} numbers; a tool frame is 4 rows of 4 numbers "
            "(or the top 3 rows), row-major, translation in mm."
        )
    values = np.array([text_float(t, "matrix", "entry") for t in tokens])
    T = np.vstack([values.reshape(-1, 4), [0.0, 0.0, 0.0, 1.0]])[:4] if len(tokens) == 12 \
        else values.reshape(4, 4)
    if np.abs(T[3] - [0.0, 0.0, 0.0, 1.0]).max() > 1e-9:
        raise InvalidInputError(
            f"matrix: the last row is {T[3].tolist()}; a homogeneous transform ends with "
            "0 0 0 1 (check the row order: row-major)."
        )
    try:
        R = as_rotation(T[:3, :3], name="matrix rotation part")
    except InvalidInputError as exc:
        raise InvalidInputError(f"matrix: {exc}") from None
    return tool_from_rotation("matrix", name or "imported", name is not None, T[:3, 3], R)


def _values_to_text(values: Sequence[float]) -> str:
    """16 (or 12) numbers row-major, mm."""
    return " ".join(repr(float(x)) for x in values)


def _rotation(values: Sequence[float]) -> np.ndarray:
    """r11..r33 row-major -> (3, 3) (``(N, 9)`` -> ``(N, 3, 3)``)."""
    v = np.asarray(values, dtype=float)
    return v.reshape(*v.shape[:-1], 3, 3)


def _csv_rotations(v: np.ndarray, where: Callable[[int], str]) -> np.ndarray:
    n = v.shape[0]
    m = v.reshape(n, 3, 3)
    defect = np.abs(np.einsum("nji,njk->nik", m, m) - np.eye(3)).reshape(n, 9).max(axis=1)
    bad = ~(defect <= ORTHONORMAL_TOL)
    if bad.any():
        i = int(np.argmax(bad))
        raise InvalidInputError(
            f"{where(i)}: rotation r11..r33 is not orthonormal within "
            f"{ORTHONORMAL_TOL:g} (max |R^T R - I| = {defect[i]:.3g}); check the "
            f"row-major column order and print more digits", index=i)
    det = np.linalg.det(m)
    if (det < 0).any():
        i = int(np.argmax(det < 0))
        raise InvalidInputError(
            f"{where(i)}: rotation r11..r33 is a reflection (det = -1), not a "
            f"rotation; check the row-major column order", index=i)
    return Rotation.from_matrix(m).as_matrix()


FORMAT = ControllerFormat(
    name="matrix", label="Matrix", rank=50,
    angle_convention="the rotation matrix R_flange_tool itself (top-left 3x3 of T_flange_tool, "
                     "row-major)",
    rotation_from_angles=_rotation,
    angles_from_rotation=lambda rot: tuple(float(x) for x in np.asarray(rot).reshape(9)),
    numbers="12 or 16 numbers of the 4x4 T_flange_tool row-major, mm", value_counts=(12, 16),
    values_to_text=_values_to_text, render_text=render_text, parse_text=parse_text,
    name_rule="no name in the text",
    csv=CsvLayout("matrix", tuple(f"r{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3)),
                  "rotation matrix, row-major", _csv_rotations, decimals=9, rank=50,
                  header_text="r11,r12,...,r33"),
)
