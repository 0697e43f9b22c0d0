"""Controller files: tool data as files a controller loads, and touch poses read back from
program files (docs/formats.md).

One module per controller (``kuka``, ``abb``, ``fanuc``, ``ur``, ``yaskawa``); this registry
names each format, its file name, value layout and angle convention, and its functions: adding
a format touches one module, its tests and the :data:`CONTROLLER_FORMATS` entry. Lengths are
mm (UR files: m), angles deg (UR: rad); every rotation goes through scipy's ``Rotation``.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import PurePath

from tcpcal.controllers import abb, fanuc, kuka, ur, yaskawa
from tcpcal.controllers._common import ControllerFileError, RecordedPose, ToolEntry, fixed
from tcpcal.tool import Tool

__all__ = [
    "CONTROLLER_FORMATS",
    "POSE_FORMATS",
    "ControllerFileError",
    "ControllerFormat",
    "PoseImport",
    "RecordedPose",
    "ToolEntry",
    "detect_pose_format",
    "export_tool_file",
    "import_poses",
    "parse_tool_file",
    "poses_csv_text",
]


@dataclass(frozen=True)
class ControllerFormat:
    """One controller's files.

    Attributes:
        name: the ``--format`` value.
        label: the controller, in words.
        filename: the default file name of an exported tool (``{n}`` = tool number).
        values: the value layout of the tool frame, with units.
        angle_convention: the rotation convention, in words and as a formula.
        pose_extensions: file extensions of program files with poses (empty: no pose import).
        csv_layout: the POSES.csv layout its poses are printed in (docs/cli.md "POSES.csv").
    """

    name: str
    label: str
    filename: str
    values: str
    angle_convention: str
    render_tool: Callable[..., str]
    parse_tool: Callable[[str], list[ToolEntry]]
    parse_poses: Callable[[str], list[RecordedPose]] | None = None
    render_poses: Callable[[Sequence[RecordedPose]], str] | None = None
    pose_extensions: tuple[str, ...] = ()
    csv_layout: str = ""


CONTROLLER_FORMATS: dict[str, ControllerFormat] = {f.name: f for f in (
    ControllerFormat("kuka", "KUKA KR C ($config.dat lines)", "tool{n}_config.dat",
                     "TOOL_DATA[n]={X,Y,Z mm, A,B,C deg}, TOOL_NAME[n,]",
                     "R = Rz(A) Ry(B) Rx(C) (A about Z, B about the new Y, C about the newest X)",
                     kuka.render_tool, kuka.parse_tool, kuka.parse_poses, kuka.render_poses,
                     (".dat",), "kuka"),
    ControllerFormat("abb", "ABB RAPID module", "tool{n}.mod",
                     "PERS tooldata name:=[TRUE,[[x,y,z mm],[q1,q2,q3,q4]],[load]]",
                     "unit quaternion of R_flange_tool, q1 the scalar part",
                     abb.render_tool, abb.parse_tool, abb.parse_poses, abb.render_poses,
                     (".mod", ".modx", ".prg", ".sys"), "abb"),
    ControllerFormat("fanuc", "FANUC TP program (.LS)", "TCPCAL_UT{n}.LS",
                     "P[1] X,Y,Z mm, W,P,R deg -> PR[m] -> UTOOL[n]",
                     "R = Rz(R) Ry(P) Rx(W) (W about X, P about Y, R about Z, fixed axes)",
                     fanuc.render_tool, fanuc.parse_tool, fanuc.parse_poses, fanuc.render_poses,
                     (".ls",), "fanuc"),
    ControllerFormat("ur", "Universal Robots URScript", "tcp{n}.script",
                     "p[x,y,z m, rx,ry,rz rad]",
                     "rotation vector (axis times angle, rad) of R_flange_tool",
                     ur.render_tool, ur.parse_tool, ur.parse_poses, ur.render_poses,
                     (".script", ".urscript", ".urp.script"), "rotvec"),
    ControllerFormat("yaskawa", "Yaskawa Motoman TOOL.CND entry", "TOOL{n}.CND",
                     "//TOOL n, ///NAME, X,Y,Z mm, Rx,Ry,Rz deg, load lines",
                     "R = Rz(Rz) Ry(Ry) Rx(Rx) (about the fixed flange X, then Y, then Z)",
                     yaskawa.render_tool, yaskawa.parse_tool),
)}

POSE_FORMATS: tuple[str, ...] = tuple(n for n, f in CONTROLLER_FORMATS.items() if f.parse_poses)


def _format(name: str) -> ControllerFormat:
    fmt = CONTROLLER_FORMATS.get(name)
    if fmt is None:
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
    return _format(fmt).render_tool(tool, number, name, **options)


def parse_tool_file(text: str, fmt: str) -> list[ToolEntry]:
    """The tool frames in a controller file (the inverse of :func:`export_tool_file`)."""
    return _format(fmt).parse_tool(text)


@dataclass(frozen=True)
class PoseImport:
    """Poses read from a program file and what the technician should know about them."""

    format: str
    poses: tuple[RecordedPose, ...]
    warnings: tuple[str, ...]


def detect_pose_format(text: str, filename: str | None = None) -> str:
    """The controller of a program file: from its extension, else from its content."""
    if filename:
        suffix = PurePath(filename).suffix.lower()
        for name in POSE_FORMATS:
            if suffix in CONTROLLER_FORMATS[name].pose_extensions:
                return name
    if re.search(r"\b(E6POS|POS)\s+\w+\s*=\s*\{", text, re.I):
        return "kuka"
    if re.search(r"\brobtarget\b", text, re.I):
        return "abb"
    if re.search(r"^/POS\b", text, re.M):
        return "fanuc"
    if re.search(r"\bp\[", text):
        return "ur"
    raise ControllerFileError(
        "cannot tell which controller wrote this file (no KUKA E6POS/POS, ABB robtarget, "
        "FANUC /POS or UR p[...] found); pass --format kuka|abb|fanuc|ur")


def import_poses(text: str, fmt: str = "auto", *, filename: str | None = None) -> PoseImport:
    """Read the recorded positions of a KUKA ``.dat``, ABB ``.mod``, FANUC ``.LS`` or UR script.

    The solver needs flange poses in WORLD: positions recorded with no tool (KUKA TOOL_NO 0,
    FANUC UT 0, ABB tool0, UR TCP = flange) and no base / user frame. Where the file says which
    tool or base a position was recorded with and it is not 0, a warning names it.

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
    if not poses:
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
    if name == "ur" and _ur_sets_a_tcp(text):
        warnings.append("the script sets a TCP: poses recorded with a TCP active are TCP poses, "
                        "not the flange; record the touches with the TCP at the flange")
    return PoseImport(name, poses, tuple(warnings))


def _ur_sets_a_tcp(text: str) -> bool:
    """The script sets a TCP other than the flange (``set_tcp(p[0, 0, 0, 0, 0, 0])`` is fine)."""
    try:
        tcps = ur.parse_tool(text)
    except ControllerFileError:
        return bool(re.search(r"set_tcp\s*\(", text))  # a TCP we cannot read: say so
    return any(max(map(abs, t.tcp_mm)) > 0 or abs(t.rotation.trace() - 3.0) > 1e-12
               for t in tcps)


_CSV_HEADERS = {"kuka": "a,b,c", "fanuc": "w,p,r", "abb": "qw,qx,qy,qz", "rotvec": "rx,ry,rz"}
_CSV_DECIMALS = {"kuka": 6, "fanuc": 6, "abb": 9, "rotvec": 9}


def poses_csv_text(imported: PoseImport) -> str:
    """POSES.csv (docs/cli.md) of imported poses: ``name,x,y,z`` and the controller's own
    orientation layout, numbers with fixed decimals (mm 4)."""
    layout = CONTROLLER_FORMATS[imported.format].csv_layout
    rows = [f"name,x,y,z,{_CSV_HEADERS[layout]}"]
    for p in imported.poses:
        values: Sequence[float] = p.values
        if layout == "abb":  # normalised, so the CSV reader's 1e-6 check passes
            q = [float(v) for v in p.values]
            n = sum(v * v for v in q) ** 0.5
            values = [v / n for v in q]
        name = p.name.replace(",", "_").replace('"', "")
        rows.append(",".join([name, *(fixed(v, 4) for v in p.position_mm),
                              *(fixed(v, _CSV_DECIMALS[layout]) for v in values)]))
    return "\n".join(rows) + "\n"
