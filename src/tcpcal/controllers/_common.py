"""Shared pieces of the controller-file modules: fixed-decimal numbers, the parsed records and
the errors (docs/formats.md).

Numbers are written as a pendant shows them: a fixed number of decimals, never an exponent,
never ``-0.000``, never a float artefact such as ``0.33589800000000003``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from tcpcal.errors import InvalidInputError

__all__ = ["NUM", "PULSE_SKIPPED", "ControllerFileError", "JointPoint", "PulsePoint",
           "RecordedPose", "ToolEntry", "fixed", "inertia_or_none",
           "line_of", "to_float"]

NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
"""A decimal number as controllers write it (``.044``, ``-12.``, ``9E+09``)."""

_NUM_RE = re.compile(rf"^{NUM}$")


class ControllerFileError(InvalidInputError):
    """A controller file that cannot be read or written (the message names the format, what is
    wrong and what to do)."""


def fixed(value: float, decimals: int) -> str:
    """``value`` with exactly ``decimals`` decimals, no exponent, no negative zero.

    Raises:
        ControllerFileError: ``value`` is NaN or infinite.
    """
    x = float(value)
    if not math.isfinite(x):
        raise ControllerFileError(f"cannot write {x!r} into a controller file: not a finite number")
    text = f"{x:.{decimals}f}"
    if float(text) == 0.0:
        text = text.lstrip("-")
    return text


def to_float(token: str, fmt: str, what: str) -> float:
    """A finite float from a controller file's token, or a :class:`ControllerFileError`."""
    token = token.strip()
    if not _NUM_RE.match(token):
        raise ControllerFileError(f"{fmt}: {what} {token!r} is not a number")
    value = float(token)
    if not math.isfinite(value):
        raise ControllerFileError(f"{fmt}: {what} is {token!r}, not a finite number")
    return value


@dataclass(frozen=True)
class ToolEntry:
    """One tool frame read from a controller file.

    Attributes:
        number: the controller's tool number (slot), or ``None`` if the file has none (UR).
        name: the tool's name in the file ('' when it has none).
        tcp_mm: TCP in FLANGE, mm.
        rotation: (3, 3) ``R_flange_tool``.
        mass_kg: the load's mass the file gives, kg, or ``None`` (not in the file, or 0: unset).
        cog_mm: the load's centre of gravity in FLANGE, mm, or ``None`` (not in the file).
        load_abc_deg: KUKA A, B, C (deg) of ``R_flange_load``, the axes of the load's moments of
            inertia, or ``None`` (not in the file, or no mass).
        inertia_kgm2: the load's moments of inertia about those axes through the centre of
            gravity, kg m^2, or ``None`` (not in the file, all zero, or no mass).
    """

    number: int | None
    name: str
    tcp_mm: tuple[float, float, float]
    rotation: np.ndarray
    mass_kg: float | None = None
    cog_mm: tuple[float, float, float] | None = None
    load_abc_deg: tuple[float, float, float] | None = None
    inertia_kgm2: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        rot = np.array(self.rotation, dtype=float)
        rot.setflags(write=False)
        object.__setattr__(self, "rotation", rot)


def inertia_or_none(values: Sequence[float]) -> tuple[float, float, float] | None:
    """Three moments of inertia (kg m^2), or ``None`` when all are zero: the controllers'
    "not given" (ABB treats the load as a point mass, KUKA and Yaskawa as unset)."""
    ix, iy, iz = (float(v) for v in values)
    return None if ix == iy == iz == 0.0 else (ix, iy, iz)


@dataclass(frozen=True)
class RecordedPose:
    """One robot position read from a program file (``T_world_flange`` only if it was recorded
    with no tool and no base active; ``tool``/``base`` say what the file recorded).

    Attributes:
        name: the position's name in the file (``XP1``, ``p10``, ``P[3]``...).
        position_mm: (3,) position, mm.
        rotation: (3, 3) rotation matrix.
        values: the orientation numbers as the file writes them, in the vendor's layout
            (KUKA A, B, C deg; ABB q1..q4; FANUC W, P, R deg; UR rx, ry, rz rad).
        tool: the tool number the file says the position was recorded with, if it says.
        base: the base / user frame number, if the file says.
        line: 1-based line of the position in the file.
    """

    name: str
    position_mm: tuple[float, float, float]
    rotation: np.ndarray
    values: tuple[float, ...]
    tool: int | None = None
    base: int | None = None
    line: int = 0
    notes: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        rot = np.array(self.rotation, dtype=float)
        rot.setflags(write=False)
        object.__setattr__(self, "rotation", rot)


@dataclass(frozen=True)
class JointPoint:
    """One robot position a program file records in joint representation (axis values, not a
    Cartesian pose): FANUC ``J1 = ..`` points, ABB ``jointtarget``, KUKA ``E6AXIS``/``AXIS``.

    tcpcal has no robot model, so it cannot turn these into flange poses; ``tcpcal poses
    import`` skips them and says how many. A caller with forward kinematics (the app's
    ``tcp-pendant poses import --robot``) converts ``joints_deg`` itself.

    Attributes:
        name: the position's name in the file (``P[2]``, ``jHome``, ``XHOME``).
        joints_deg: the robot's axis values in file order (A1/J1/rax_1 first), **degrees**
            (revolute axes; the vendors write them so).
        line: 1-based line of the position in the file.
        tool: the tool number the file says the position was recorded with, if it says.
        base: the base / user frame number, if the file says.
        kind: the file's name for the representation (``"FANUC J"``, ``"jointtarget"``,
            ``"E6AXIS"``, ``"AXIS"``).
    """

    name: str
    joints_deg: tuple[float, ...]
    line: int = 0
    tool: int | None = None
    base: int | None = None
    kind: str = ""


PULSE_SKIPPED = "in PULSE (encoder counts)"
"""Words of the warning and the refusal about positions in encoder counts (the app drops the
warning once it converts them)."""


@dataclass(frozen=True)
class PulsePoint:
    """A robot position a program holds in encoder counts (Yaskawa ``///PULSE``): an axis
    angle is ``pulses / pulses_per_degree`` of that axis, a controller parameter tcpcal does not
    know; the app's ``tcp-pendant poses import --pulses-per-degree`` converts them.

    Attributes:
        name: the position's name in the file (``C00000``, ``P00007``).
        pulses: the counts of each robot axis, file order.
        line: 1-based line in the file.
        tool: the tool number it was taught with, if the file says.
    """

    name: str
    pulses: tuple[int, ...]
    line: int
    tool: int | None = None


def line_of(text: str, pos: int) -> int:
    """1-based line number of character offset ``pos`` in ``text``."""
    return text.count("\n", 0, pos) + 1
