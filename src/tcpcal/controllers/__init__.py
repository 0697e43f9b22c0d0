"""Controller formats: tool data text, files a controller loads, touch poses read back from
program files, and the POSES.csv layouts (docs/formats.md, docs/architecture.md "Controller
formats").

One module per format (``kuka``, ``abb``, ``fanuc``, ``ur``, ``yaskawa`` and the ``matrix``
pseudo-format); each ends with ``FORMAT = ControllerFormat(...)`` declaring its name, label,
value layout, angle convention, slot and name rules, and its render/parse functions. Every
module of this package whose name does not start with ``_`` and that defines ``FORMAT`` is
registered in :data:`REGISTRY` when the package is imported: adding a format touches one module
(and its tests). Lengths are mm (UR: m), angles deg (UR: rad); every rotation goes through
scipy's ``Rotation``.
"""

from __future__ import annotations

import importlib
import pkgutil
import re
from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import overload

from tcpcal.controllers._common import (
    PULSE_SKIPPED,
    ControllerFileError,
    JointPoint,
    PulsePoint,
    RecordedPose,
    ToolEntry,
    fixed,
)
from tcpcal.controllers._format import ControllerFormat, CsvLayout
from tcpcal.errors import InvalidInputError
from tcpcal.tool import Tool

__all__ = [
    "CONTROLLER_FORMATS",
    "POSE_FORMATS",
    "PULSE_SKIPPED",
    "REGISTRY",
    "ROBOT_HINT",
    "ControllerFileError",
    "ControllerFormat",
    "CsvLayout",
    "JointPoint",
    "PoseImport",
    "PulsePoint",
    "RecordedPose",
    "ToolEntry",
    "csv_layouts",
    "detect_pose_format",
    "detect_tool_format",
    "export_tool_file",
    "formats",
    "get_format",
    "import_poses",
    "parse_tool_file",
    "poses_csv_text",
    "register",
    "skipped_joints_warning",
    "unregister",
]

REGISTRY: dict[str, ControllerFormat] = {}
"""Every format by name (filled from this package's modules at import; :func:`register`)."""

_RESERVED_NAMES = frozenset({"auto"})
_RESERVED_COLUMNS = frozenset({"x", "y", "z", "name", "label", "role"})


def register(fmt: ControllerFormat, *, replace: bool = False) -> ControllerFormat:
    """Add ``fmt`` to :data:`REGISTRY` (the format modules do this through ``FORMAT``).

    Raises:
        InvalidInputError: the name is not a lower-case word or is taken (unless
            ``replace``), or its POSES.csv layout reuses a name or column of another layout.
    """
    if not re.fullmatch(r"[a-z][a-z0-9_]*", fmt.name) or fmt.name in _RESERVED_NAMES:
        raise InvalidInputError(f"format name {fmt.name!r} must be a lower-case word, not "
                                f"{', '.join(sorted(_RESERVED_NAMES))}")
    if fmt.name in REGISTRY and not replace:
        raise InvalidInputError(f"format {fmt.name!r} is registered already")
    if fmt.csv is not None:
        others = [f.csv for n, f in REGISTRY.items() if f.csv is not None and n != fmt.name]
        for other in others:
            clash = set(other.columns) & set(fmt.csv.columns)
            if other.name == fmt.csv.name or clash:
                raise InvalidInputError(
                    f"format {fmt.name!r}: POSES.csv layout {fmt.csv.name!r} clashes with "
                    f"layout {other.name!r} ({', '.join(sorted(clash)) or 'same name'})")
        bad = [c for c in fmt.csv.columns
               if c in _RESERVED_COLUMNS or re.fullmatch(r"j\d+", c) or c != c.lower()]
        if bad:
            raise InvalidInputError(f"format {fmt.name!r}: POSES.csv columns {bad} are taken "
                                    "(x, y, z, name, label, role, j1..) or not lower case")
    REGISTRY[fmt.name] = fmt
    return fmt


def unregister(name: str) -> None:
    """Remove the format ``name`` from :data:`REGISTRY` (tests of a toy format)."""
    REGISTRY.pop(name, None)


def formats(where: Callable[[ControllerFormat], bool] | None = None) -> list[ControllerFormat]:
    """The registered formats (those for which ``where`` is true), in ``rank`` order."""
    return sorted((f for f in REGISTRY.values() if where is None or where(f)),
                  key=lambda f: (f.rank, f.name))


def csv_layouts() -> dict[str, CsvLayout]:
    """The POSES.csv orientation layouts by name, in ``CsvLayout.rank`` order."""
    lays = sorted((f.csv for f in REGISTRY.values() if f.csv is not None),
                  key=lambda lay: (lay.rank, lay.name))
    return {lay.name: lay for lay in lays}


class _Formats(Mapping[str, ControllerFormat]):
    """A live, read-only view of the registered formats that have something (rank order)."""

    def __init__(self, where: Callable[[ControllerFormat], bool]) -> None:
        self._where = where

    def __getitem__(self, name: str) -> ControllerFormat:
        fmt = REGISTRY.get(name)
        if fmt is None or not self._where(fmt):
            raise KeyError(name)
        return fmt

    def __iter__(self) -> Iterator[str]:
        return iter([f.name for f in formats(self._where)])

    def __len__(self) -> int:
        return len(formats(self._where))

    def __repr__(self) -> str:
        return f"{type(self).__name__}({list(self)})"


class _Names(Sequence[str]):
    """A live, read-only tuple-like view of the names of the formats that have something."""

    def __init__(self, where: Callable[[ControllerFormat], bool]) -> None:
        self._where = where

    def _names(self) -> tuple[str, ...]:
        return tuple(f.name for f in formats(self._where))

    @overload
    def __getitem__(self, i: int) -> str: ...
    @overload
    def __getitem__(self, i: slice) -> tuple[str, ...]: ...
    def __getitem__(self, i: int | slice) -> str | tuple[str, ...]:
        return self._names()[i]

    def __len__(self) -> int:
        return len(self._names())

    def __eq__(self, other: object) -> bool:
        return self._names() == (tuple(other) if isinstance(other, Sequence) else other)

    def __hash__(self) -> int:
        return hash(self._names())

    def __repr__(self) -> str:
        return repr(self._names())


CONTROLLER_FORMATS: Mapping[str, ControllerFormat] = _Formats(lambda f: f.has_file)
"""The formats with a controller file (``tools export --file``), by name."""
POSE_FORMATS: Sequence[str] = _Names(lambda f: f.parse_poses is not None)
"""The names of the formats ``poses import`` reads."""


def get_format(name: str) -> ControllerFormat:
    """The registered format ``name`` (any kind), or an ``InvalidInputError`` listing them."""
    fmt = REGISTRY.get(name) if isinstance(name, str) else None
    if fmt is None:
        raise InvalidInputError(f"unknown format {name!r}; use one of "
                                f"{', '.join(f.name for f in formats())}")
    return fmt


def _format(name: str) -> ControllerFormat:
    fmt = REGISTRY.get(name)
    if fmt is None or not fmt.has_file:
        raise ControllerFileError(f"unknown controller format {name!r}; use one of "
                                  f"{', '.join(CONTROLLER_FORMATS)}")
    return fmt


def export_tool_file(tool: Tool, fmt: str, *, number: int = 1, name: str | None = None,
                     **options: int) -> str:
    """The whole file of ``tool`` for controller ``fmt`` (tool ``number``; ``name`` replaces
    the tool's name in the file). FANUC takes ``register=`` (the PR, default 100).

    Raises:
        ControllerFileError: unknown format, a number out of the controller's range, a name the
            controller refuses (ABB: ``tool0``, not a RAPID identifier; KUKA > 24 characters).
    """
    return _format(fmt).render_file(tool, number, name, **options)  # type: ignore[misc]


def parse_tool_file(text: str, fmt: str) -> list[ToolEntry]:
    """The tool frames in a controller file (the inverse of :func:`export_tool_file`)."""
    return _format(fmt).parse_file(text)  # type: ignore[misc]


@dataclass(frozen=True)
class PoseImport:
    """Poses read from a program file and what the technician should know about them.

    Attributes:
        format: the format's name.
        poses: the Cartesian positions, in file order.
        warnings: what the technician should know (one sentence each).
        joint_points: the positions in joint representation (axis values, deg), in file
            order: not in ``poses`` (tcpcal has no robot model); see
            :func:`skipped_joints_warning`.
    """

    format: str
    poses: tuple[RecordedPose, ...]
    warnings: tuple[str, ...]
    joint_points: tuple[JointPoint, ...] = ()


ROBOT_HINT = ("tcp-pendant poses import FILE --robot kr6|gp12|PATH.urdf converts them with "
              "the robot's forward kinematics")
"""How to turn joint points into flange poses (the app has the robot model tcpcal lacks)."""


def skipped_joints_warning(imported: PoseImport) -> str | None:
    """The sentence ``tcpcal poses import`` prints when it skips joint-representation points
    (``None`` when there are none): how many, which, and the hint to use ``--robot``."""
    joints = imported.joint_points
    if not joints:
        return None
    names = ", ".join(p.name for p in joints[:8]) + (", ..." if len(joints) > 8 else "")
    return (f"skipped {len(joints)} point{'s' if len(joints) != 1 else ''} in joint "
            f"representation ({names}): tcpcal has no robot model to turn axis values into "
            f"flange poses; {ROBOT_HINT}, or record the touches in Cartesian")


def _or_list(items: Sequence[str]) -> str:
    return items[0] if len(items) == 1 else f"{', '.join(items[:-1])} or {items[-1]}"


def _by_extension(readers: Sequence[ControllerFormat], filename: str | None,
                  extensions: Callable[[ControllerFormat], Collection[str]]) -> str | None:
    """The first of ``readers`` (rank order) whose ``extensions`` hold ``filename``'s suffix
    (lower case), or None (no file name, or no format claims the suffix)."""
    if not filename:
        return None
    from pathlib import PurePath

    suffix = PurePath(filename).suffix.lower()
    return next((fmt.name for fmt in readers if suffix in extensions(fmt)), None)


def detect_pose_format(text: str, filename: str | None = None) -> str:
    """The controller of a program file: a content only one controller writes
    (``ControllerFormat.claim``), else its extension, else its content."""
    readers = formats(lambda f: f.parse_poses is not None)
    for fmt in readers:
        if fmt.claim is not None and fmt.claim.search(text):
            return fmt.name
    by_suffix = _by_extension(readers, filename, lambda f: f.pose_extensions)
    if by_suffix is not None:
        return by_suffix
    for fmt in readers:
        if fmt.detect is not None and fmt.detect.search(text):
            return fmt.name
    raise ControllerFileError(
        "cannot tell which controller wrote this file (no "
        f"{_or_list([f.detect_text for f in readers if f.detect is not None])} found); pass "
        f"--format {'|'.join(f.name for f in readers)}")


def detect_tool_format(text: str, filename: str | None = None) -> str:
    """The controller of a tool file (``tools import --format auto``): from its extension,
    else from its content (``ControllerFormat.tool_file_detect``, in ``rank`` order)."""
    readers = formats(lambda f: f.parse_file is not None)
    by_suffix = _by_extension(readers, filename, lambda f: f.tool_file_extensions)
    if by_suffix is not None:
        return by_suffix
    for fmt in readers:
        if fmt.tool_file_detect is not None and fmt.tool_file_detect.search(text):
            return fmt.name
    raise ControllerFileError(
        "cannot tell which controller wrote this tool file; pass "
        f"--format {'|'.join(f.name for f in readers)}")


def import_poses(text: str, fmt: str = "auto", *, filename: str | None = None) -> PoseImport:
    """Read the recorded positions of a program file (KUKA ``.dat``, ABB ``.mod``, FANUC
    ``.LS``, UR script: every format with ``parse_poses``).

    The solver needs flange poses in WORLD: positions recorded with no tool (KUKA TOOL_NO 0,
    FANUC UT 0, ABB tool0, UR TCP = flange) and no base / user frame. Where the file says which
    tool or base a position was recorded with and it is not 0, a warning names it.

    Positions in joint representation are not poses: they are returned in
    ``PoseImport.joint_points`` (not an error, even when they are all the file has).

    Raises:
        ControllerFileError: unknown format, a position that cannot be read (the message
            names the line), or no position at all.
    """
    name = detect_pose_format(text, filename) if fmt == "auto" else fmt
    cf = _format(name)
    if cf.parse_poses is None:
        raise ControllerFileError(f"{name}: tcpcal reads poses only from "
                                  f"{', '.join(POSE_FORMATS)} files")
    poses = tuple(cf.parse_poses(text))
    joints = tuple(cf.parse_joint_points(text)) if cf.parse_joint_points is not None else ()
    if not poses and not joints:
        raise ControllerFileError(f"{name}: no recorded position found in the file")
    warnings: list[str] = []
    tooled = [p.name for p in poses if p.tool not in (None, 0)]
    based = [p.name for p in poses if p.base not in (None, 0)]
    if tooled:
        warnings.append(f"{', '.join(tooled)} recorded with a tool active (not 0): those are TCP "
                        "poses, not the flange; record the touches with no tool (tool 0)")
    if based:
        warnings.append(f"{', '.join(based)} recorded in a base / user frame (not 0): record the "
                        "touches in WORLD (base 0)")
    if cf.pose_warnings is not None:
        warnings.extend(cf.pose_warnings(text))
    return PoseImport(name, poses, tuple(warnings), joints)


def poses_csv_text(imported: PoseImport) -> str:
    """POSES.csv (docs/cli.md) of imported poses: ``name,x,y,z`` and the controller's own
    orientation layout (``ControllerFormat.csv``), numbers with fixed decimals (mm 4)."""
    fmt = REGISTRY[imported.format]
    layout = fmt.csv if fmt.csv is not None or not fmt.pose_layout else REGISTRY[fmt.pose_layout].csv
    if layout is None:
        raise ControllerFileError(f"{imported.format}: the format has no POSES.csv layout")
    rows = [f"name,x,y,z,{','.join(layout.columns)}"]
    for p in imported.poses:
        values = p.values if layout.row_values is None else layout.row_values(p)
        name = p.name.replace(",", "_").replace('"', "")
        rows.append(",".join([name, *(fixed(v, 4) for v in p.position_mm),
                              *(fixed(v, layout.decimals) for v in values)]))
    return "\n".join(rows) + "\n"


def _discover() -> None:
    """Register the ``FORMAT`` of every public module of this package."""
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        fmt = getattr(module, "FORMAT", None)
        if isinstance(fmt, ControllerFormat):
            register(fmt)


_discover()

from tcpcal.controllers import abb, fanuc, kuka, matrix, ur, yaskawa  # noqa: E402  (modules)
