"""FANUC R-30iA/B: a TP program (``.LS``) that sets a tool frame; positions from ``/POS``.

Tool: a program whose ``/POS`` holds the frame as ``P[1]`` (``X, Y, Z`` mm, ``W, P, R`` deg,
3 decimals as the pendant shows them) and whose ``/MN`` copies it to a position register and
from there to the tool frame: ``PR[m]=P[1] ;`` then ``UTOOL[n]=PR[m] ;`` (a TP program cannot
write a frame from constants). ``R = Rz(R) Ry(P) Rx(W)``: W about X, P about Y, R about Z, all
fixed axes (scipy ``from_euler("xyz", [W, P, R])``). Sections ``/PROG``, ``/ATTR``, ``/MN``,
``/POS``, ``/END``. Positions: ``P[n]{ GP1: UF : u, UT : t, CONFIG : '...', X = .. mm, ...
R = .. deg };`` in ``/POS``. docs/formats.md cites the public examples.

Tool data text (``tcpcal.formats``, ``tcpcal convert``): the *Tool Frame / Direct Entry*
screen, ``UTOOL[n] Direct Entry``, ``Comment:`` (16 characters), ``X: ..`` ... ``R: ..``
(module docstring of :mod:`tcpcal.formats`). POSES.csv layout ``fanuc``: columns ``w, p, r``
(deg). :data:`FORMAT` declares all of it.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from tcpcal.controllers._common import (
    NUM,
    ControllerFileError,
    JointPoint,
    RecordedPose,
    ToolEntry,
    fixed,
    line_of,
    to_float,
)
from tcpcal.controllers._format import (
    TEXT_NUM,
    ControllerFormat,
    CsvLayout,
    check_slot,
    text_float,
    text_number,
    tool_from_rotation,
)
from tcpcal.errors import InvalidInputError
from tcpcal.tool import Tool, abc_deg_from_rotation

__all__ = ["COMMENT_LENGTH", "FORMAT", "parse_joint_points", "parse_poses", "parse_text",
           "parse_tool", "pose_warnings",
           "render_poses", "render_text", "render_tool"]

N_TOOLS = 10
TOOL_NUMBERS = range(1, N_TOOLS + 1)
COMMENT_LENGTH = 16
"""Characters of a tool frame comment on the pendant (the text writes the first 16)."""
N_REGISTERS = 100
DEFAULT_REGISTER = 100
_P = re.compile(r"^\s*P\[\s*(\d+)\s*(?::\s*\"([^\"]*)\")?\s*\]\s*\{(.*?)\}\s*;", re.S | re.M)
_FIELD = re.compile(rf"\b([XYZWPR])\s*=\s*({NUM})")
_UF_UT = re.compile(r"\bUF\s*:\s*(\d+)\s*,\s*UT\s*:\s*(\d+)")
_ORDERFIL = re.compile(r"^\s*\d?A05B-\d{4}-[A-Z]\d{3}\b", re.M)
"""A FANUC software option order number (``1A05B-2500-J601``), the lines of ORDERFIL.DAT."""
_ATTR = """/ATTR
OWNER\t\t= MNEDITOR;
COMMENT\t\t= "{comment}";
PROG_SIZE\t= 0;
FILE_NAME\t= ;
VERSION\t\t= 0;
LINE_COUNT\t= {lines};
MEMORY_SIZE\t= 0;
PROTECT\t\t= READ_WRITE;
TCD:  STACK_SIZE\t= 0,
      TASK_PRIORITY\t= 50,
      TIME_SLICE\t= 0,
      BUSY_LAMP_OFF\t= 0,
      ABORT_REQUEST\t= 0,
      PAUSE_REQUEST\t= 0;
DEFAULT_GROUP\t= 1,*,*,*,*;
CONTROL_CODE\t= 00000000 00000000;
"""


def _wpr(rotation: np.ndarray) -> list[float]:
    """W, P, R (deg): ``R = Rz(R) Ry(P) Rx(W)`` is KUKA's ``Rz(A) Ry(B) Rx(C)`` with A = R,
    B = P, C = W, so the gimbal-lock-safe KUKA conversion serves (no scipy warning)."""
    a, b, c = abc_deg_from_rotation(rotation)
    return [float(c), float(b), float(a)]


def _pos_block(k: int, xyz: Sequence[float], wpr: Sequence[float], uf: int = 0,
               ut: int = 0) -> str:
    x, y, z = (fixed(v, 3).rjust(10) for v in xyz)
    w, p, r = (fixed(v, 3).rjust(10) for v in wpr)
    return (f"P[{k}]{{\n   GP1:\n\tUF : {uf}, UT : {ut},\t\tCONFIG : 'N U T, 0, 0, 0',\n"
            f"\tX = {x}  mm,\tY = {y}  mm,\tZ = {z}  mm,\n"
            f"\tW = {w} deg,\tP = {p} deg,\tR = {r} deg\n}};")


def render_tool(tool: Tool, number: int, name: str | None = None, *,
                register: int = DEFAULT_REGISTER) -> str:
    """A TP program ``TCPCAL_UT<n>`` that writes the frame to ``PR[register]`` and sets
    ``UTOOL[number]`` from it."""
    if number not in TOOL_NUMBERS:
        raise ControllerFileError(f"fanuc: tool frame number must be 1..{N_TOOLS}, got {number}")
    if not 1 <= register <= N_REGISTERS:
        raise ControllerFileError(f"fanuc: position register must be 1..{N_REGISTERS}, got "
                                  f"{register}")
    label = re.sub(r"[^A-Za-z0-9_ ]", "_", tool.name if name is None else name)[:16]
    mn = [f"!tcpcal UTOOL[{number}] {label}",
          "!XYZ mm, WPR deg, fixed X Y Z",
          f"!overwrites PR[{register}]",
          f"PR[{register}]=P[1]",
          f"UTOOL[{number}]=PR[{register}]"]
    body = "\n".join(f"{k:>4}:  {s} ;" for k, s in enumerate(mn, 1))
    return (f"/PROG  TCPCAL_UT{number}\n"
            + _ATTR.format(comment=f"UTOOL{number} {label}"[:16], lines=len(mn))
            + f"/MN\n{body}\n/POS\n"
            + _pos_block(1, tool.tcp_mm, _wpr(tool.rotation)) + "\n/END\n")


_GROUP = re.compile(r"\bGP(\d+)\s*:")
_JOINT = re.compile(rf"\bJ(\d+)\s*=\s*({NUM})")
_EXTENDED = re.compile(rf"\bE(\d+)\s*=\s*({NUM})")
"""An integrated extended axis of group 1 (``E1 = 1500.000 mm``: a track the robot rides)."""


@dataclass(frozen=True)
class _Point:
    """One ``P[n]`` of ``/POS``: group 1's values (Cartesian or joints) and its other groups."""

    k: int
    comment: str
    line: int
    cartesian: dict[str, float] | None
    joints: tuple[float, ...] | None
    uf: int | None
    ut: int | None
    other_groups: tuple[int, ...]
    extended: tuple[tuple[int, float], ...] = ()


def _groups(body: str) -> dict[int, str]:
    """The text of each ``GPn:`` section of a point's braces (``{1: body}`` if there is none)."""
    marks = list(_GROUP.finditer(body))
    if not marks:
        return {1: body}
    return {int(m.group(1)): body[m.end():(marks[i + 1].start() if i + 1 < len(marks)
                                           else len(body))]
            for i, m in enumerate(marks)}


def _points(text: str) -> list[_Point]:
    """Every ``P[n]{...}`` of the ``/POS`` section: group 1 read, the other groups named."""
    pos_at = text.find("/POS")
    section = text[pos_at:] if pos_at >= 0 else text
    offset = pos_at if pos_at >= 0 else 0
    out = []
    for m in _P.finditer(section):
        k = int(m.group(1))
        line = line_of(text, offset + m.start())
        groups = _groups(m.group(3))
        gp1 = groups.get(1)
        others = tuple(sorted(g for g in groups if g != 1))
        if gp1 is None:
            out.append(_Point(k, m.group(2) or "", line, None, None, None, None, others))
            continue
        uf_ut = _UF_UT.search(gp1)
        uf = int(uf_ut.group(1)) if uf_ut else None
        ut = int(uf_ut.group(2)) if uf_ut else None
        joints = [(int(j.group(1)), to_float(j.group(2), "fanuc", f"P[{k}] J{j.group(1)}"))
                  for j in _JOINT.finditer(gp1)]
        if joints:
            values = tuple(v for _, v in sorted(joints))
            out.append(_Point(k, m.group(2) or "", line, None, values, uf, ut, others))
            continue
        vals: dict[str, float] = {}
        for f in _FIELD.finditer(gp1):
            vals[f.group(1)] = to_float(f.group(2), "fanuc", f"P[{k}] {f.group(1)}")
        missing = [c for c in "XYZWPR" if c not in vals]
        if missing:
            raise ControllerFileError(f"fanuc: line {line}: P[{k}] lacks {', '.join(missing)}")
        ext = tuple((int(e.group(1)), to_float(e.group(2), "fanuc", f"P[{k}] E{e.group(1)}"))
                    for e in _EXTENDED.finditer(gp1))
        out.append(_Point(k, m.group(2) or "", line, vals, None, uf, ut, others, ext))
    return out


def _positions(text: str) -> list[tuple[int, str, dict[str, float], int | None, int | None, int]]:
    """The points whose group 1 is Cartesian: ``(k, comment, X..R, UF, UT, line)``."""
    return [(p.k, p.comment, p.cartesian, p.uf, p.ut, p.line) for p in _points(text)
            if p.cartesian is not None]


def _name(p: _Point) -> str:
    return p.comment or f"P[{p.k}]"


_C = r"\s*(?::[^\]]*)?"
"""An optional ``:comment`` in a register's brackets (``PR[109:temp]``, ``UTOOL[1:Vac]``)."""
_PR_FROM_P = re.compile(rf"\bPR\[\s*(\d+){_C}\]\s*=\s*P\[\s*(\d+){_C}\]")
_PR_ELEMENT = re.compile(rf"\bPR\[\s*(\d+)\s*,\s*([1-6]){_C}\]\s*=\s*\(?\s*({NUM})\s*\)?\s*;")
_PR_OTHER = re.compile(rf"\bPR\[\s*(\d+){_C}\]\s*=")
_UTOOL_FROM_PR = re.compile(rf"\bUTOOL\[\s*(\d+)\s*(?::([^\]]*))?\]\s*=\s*PR\[\s*(\d+){_C}\]")


def _main_lines(text: str) -> list[str]:
    """The lines of a TP program's ``/MN`` section (the whole text when it has none)."""
    start = text.find("/MN")
    end = text.find("/POS", start if start >= 0 else 0)
    body = text[start if start >= 0 else 0:end if end >= 0 else len(text)]
    return body.splitlines()


def parse_tool(text: str) -> list[ToolEntry]:
    """The tool frames a TP program sets by ``UTOOL[n]=PR[m]``, with the register's value at
    that line: set from a position (``PR[m]=P[k]``) or element by element (``PR[m,1]=x`` ..
    ``PR[m,6]=r``, X, Y, Z mm, W, P, R deg, after e.g. ``PR[m]=LPOS``), the program's lines in
    order. The comments pendants add (``UTOOL[1:Vac]=PR[109:temp]``, ``PR[109:temp]=P[1:tip]``)
    are read as the bare forms, a ``UTOOL`` comment as the tool's name."""
    points = {k: v for k, _, v, _, _, _ in _positions(text)}
    registers: dict[int, dict[str, float]] = {}
    out: list[ToolEntry] = []
    for line in _main_lines(text):
        if m := _PR_FROM_P.search(line):
            registers[int(m.group(1))] = dict(points.get(int(m.group(2)), {}))
        elif m := _PR_ELEMENT.search(line):
            key = "XYZWPR"[int(m.group(2)) - 1]
            registers.setdefault(int(m.group(1)), {})[key] = to_float(m.group(3), "fanuc", key)
        elif (m := _PR_OTHER.search(line)) and not _UTOOL_FROM_PR.search(line):
            registers[int(m.group(1))] = {}  # PR[m]=LPOS, =JPOS, ...: not known here
        if m := _UTOOL_FROM_PR.search(line):
            n, reg = int(m.group(1)), int(m.group(3))
            v = registers.get(reg, {})
            if any(k not in v for k in "XYZWPR"):
                raise ControllerFileError(
                    f"fanuc: UTOOL[{n}]=PR[{reg}] but the program does not set PR[{reg}] before "
                    f"it, from a P[] of its /POS section or by PR[{reg},1..6]=")
            name = re.search(rf"!tcpcal UTOOL\[{n}\] ([^;]*);", text)
            label = name.group(1).strip() if name else (m.group(2) or "").strip()
            rot = Rotation.from_euler("xyz", [v["W"], v["P"], v["R"]], degrees=True).as_matrix()
            out.append(ToolEntry(n, label, (v["X"], v["Y"], v["Z"]), rot))
    if not out:
        raise ControllerFileError("fanuc: no 'UTOOL[n]=PR[m]' line found")
    return out


def _check_program(text: str) -> None:
    """A FANUC file that holds no positions by nature says so (``ORDERFIL.DAT``)."""
    if "/POS" not in text and _ORDERFIL.search(text):
        raise ControllerFileError(
            "fanuc: this is ORDERFIL.DAT, the controller's list of software options (A05B-... "
            "order numbers): it holds no position; import a TP program (.LS) instead")


def parse_poses(text: str) -> list[RecordedPose]:
    """The Cartesian positions ``P[n]`` of a ``.LS`` file's ``/POS`` section (group 1; the
    other motion groups are named by :func:`pose_warnings`, joint points by
    :func:`parse_joint_points`)."""
    _check_program(text)
    out: list[RecordedPose] = []
    for k, comment, v, uf, ut, line in _positions(text):
        wpr = (v["W"], v["P"], v["R"])
        rot = Rotation.from_euler("xyz", wpr, degrees=True).as_matrix()
        out.append(RecordedPose(comment or f"P[{k}]", (v["X"], v["Y"], v["Z"]), rot, wpr,
                                tool=ut, base=uf, line=line))
    return out


def parse_joint_points(text: str) -> list[JointPoint]:
    """The points whose group 1 is in joint representation (``J1 = .. deg`` ...)."""
    return [JointPoint(_name(p), p.joints, p.line, p.ut, p.uf, "FANUC J")
            for p in _points(text) if p.joints is not None]


def pose_warnings(text: str) -> list[str]:
    """The points that also hold other motion groups (``GP2:`` ...): only group 1 is read;
    and those whose group 1 has extended-axis values (``E1 = ..``) not 0."""
    points = _points(text)
    out = []
    pts = [p for p in points if p.other_groups]
    if pts:
        groups = sorted({g for p in pts for g in p.other_groups})
        names = ", ".join(_name(p) for p in pts[:8]) + (", ..." if len(pts) > 8 else "")
        out.append(f"{len(pts)} point{'s' if len(pts) != 1 else ''} ({names}) also hold motion "
                   f"group {', '.join(f'GP{g}' for g in groups)} (an extended axis or another "
                   "robot): only group 1 (GP1, the robot) was read; its poses are valid only if "
                   "the other groups do not carry the robot or the reference")
    moved = [p for p in points if any(v != 0.0 for _, v in p.extended)]
    if moved:
        names = ", ".join(f"{_name(p)} ({', '.join(f'E{i} {v:g}' for i, v in p.extended if v)})"
                          for p in moved[:8]) + (", ..." if len(moved) > 8 else "")
        out.append(f"{names}: extended-axis values are not part of the pose; tcpcal ignores "
                   "them, so the poses are right only if no extended axis moves the robot or "
                   "the reference between touches")
    return out


def render_poses(poses: Sequence[RecordedPose], program: str = "TOUCHES") -> str:
    """A TP program whose ``/POS`` holds the poses (UF 0, UT 0) and whose ``/MN`` lists them."""
    mn = [f"!tcpcal touches, {len(poses)} points"] + [f"J P[{k}] 10% FINE"
                                                      for k in range(1, len(poses) + 1)]
    body = "\n".join(f"{k:>4}:{'' if s.startswith('J ') else '  '}{s} ;"
                     for k, s in enumerate(mn, 1))
    pos = "\n".join(_pos_block(k, p.position_mm, _wpr(p.rotation))
                    for k, p in enumerate(poses, 1))
    return (f"/PROG  {program}\n" + _ATTR.format(comment="tcpcal touches", lines=len(mn))
            + f"/MN\n{body}\n/POS\n{pos}\n/END\n")


# ------------------------------------------------------------------ tool data text
_TEXT_COMMENT = re.compile(r"^[ \t]*(?:\d+[ \t]+)?Comment[ \t]*:[ \t]*(.*?)[ \t]*$",
                           re.IGNORECASE | re.MULTILINE)
_TEXT_FRAME = re.compile(r"(?:UTOOL\s*\[\s*(\d+)\s*\]|Frame\s+Number\s*:\s*(\d+))",
                         re.IGNORECASE)
_TEXT_VALUE = re.compile(rf"\b([XYZWPR])\b\s*[:=]?\s*({TEXT_NUM})", re.IGNORECASE)


def render_text(tool: Tool, slot: int = 1) -> str:
    """``UTOOL[n] Direct Entry``, ``Comment: <16 characters>``, ``X: ..`` to ``R: ..`` (mm,
    deg), as the *Tool Frame / Direct Entry* screen shows it."""
    n = check_slot(slot, TOOL_NUMBERS, "fanuc")
    # from_euler("xyz", [W, P, R]) = Rz(R) Ry(P) Rx(W) = from_euler("ZYX", [R, P, W]), so
    # (W, P, R) is (C, B, A) of KUKA; abc_deg_from_rotation stays exact near P = +-90.
    wpr = abc_deg_from_rotation(tool.rotation)[::-1]
    values = (*tool.tcp_mm, *wpr)
    comment = tool.name[:COMMENT_LENGTH].rstrip()  # the pendant's frame comment field
    lines = [f"UTOOL[{n}] Direct Entry", f"Comment: {comment}"]
    lines += [f"{k}: {text_number(v)}" for k, v in zip("XYZWPR", values)]
    return "\n".join(lines) + "\n"


def parse_text(text: str, name: str | None) -> Tool:
    """``X``, ``Y``, ``Z``, ``W``, ``P``, ``R`` once each (``:``, ``=`` or a space), the name
    from a ``Comment:`` line, the frame number from ``UTOOL[n]`` or ``Frame Number: n``."""
    m = _TEXT_COMMENT.search(text)
    found_name = m.group(1) if m and m.group(1) else None
    body = _TEXT_COMMENT.sub("", text)
    frame = _TEXT_FRAME.search(body)
    frame_no = None
    if frame:
        frame_no = int(frame.group(1) or frame.group(2))
    body = _TEXT_FRAME.sub(" ", body)
    values: dict[str, float] = {}
    for key, token in _TEXT_VALUE.findall(body):
        key = key.upper()
        if key in values:
            raise InvalidInputError(
                f"fanuc: {key} appears twice; paste one tool frame (X, Y, Z, W, P, R once each)."
            )
        values[key] = text_float(token, "fanuc", key)
    missing = [k for k in "XYZWPR" if k not in values]
    if missing:
        raise InvalidInputError(
            f"fanuc: could not find {', '.join(missing)} in the text; a tool frame needs "
            "X, Y, Z (mm) and W, P, R (deg), e.g. 'X: 12.5' on its own line."
        )
    R = Rotation.from_euler(
        "xyz", [values["W"], values["P"], values["R"]], degrees=True
    ).as_matrix()
    default = f"utool{frame_no}" if frame_no is not None else "utool"
    return tool_from_rotation(
        "fanuc", name or found_name or default, name is not None,
        (values["X"], values["Y"], values["Z"]), R,
    )


def _values_to_text(values: Sequence[float]) -> str:
    """X, Y, Z mm; W, P, R deg as ``X: .. Y: ..`` on one line."""
    v = [repr(float(x)) for x in values]
    return " ".join(f"{k}: {x}" for k, x in zip("XYZWPR", v))


def rotation_from_wpr(wpr_deg: ArrayLike) -> np.ndarray:
    """``R = Rz(R) Ry(P) Rx(W)`` of W, P, R (deg): ``(3, 3)``, or ``(N, 3, 3)`` for ``(N, 3)``."""
    return Rotation.from_euler("xyz", np.asarray(wpr_deg, dtype=float), degrees=True).as_matrix()


def _csv_rotations(values: np.ndarray, where: object) -> np.ndarray:
    return rotation_from_wpr(values)


FORMAT = ControllerFormat(
    name="fanuc", label="FANUC", rank=30,
    angle_convention="R = Rz(R) Ry(P) Rx(W) (W about X, P about Y, R about Z, fixed axes)",
    rotation_from_angles=rotation_from_wpr,
    angles_from_rotation=lambda rot: tuple(_wpr(rot)),
    numbers="X,Y,Z,W,P,R mm/deg", value_counts=(6,), values_to_text=_values_to_text,
    render_text=render_text, parse_text=parse_text, tool_numbers=TOOL_NUMBERS,
    name_rule=f"a frame comment of {COMMENT_LENGTH} characters",
    controller="FANUC TP program (.LS)", filename="TCPCAL_UT{n}.LS",
    values="P[1] X,Y,Z mm, W,P,R deg -> PR[m] -> UTOOL[n]",
    render_file=render_tool, parse_file=parse_tool, file_options=("register",),
    parse_poses=parse_poses, render_poses=render_poses, pose_extensions=(".ls",),
    detect=re.compile(r"^/POS\b", re.M), detect_text="FANUC /POS",
    pose_warnings=pose_warnings, parse_joint_points=parse_joint_points, claim=_ORDERFIL,
    tool_file_extensions=(".ls",),
    tool_file_detect=re.compile(r"\bUTOOL\[\s*\d+\s*(?::[^\]]*)?\]\s*=\s*PR\["),
    csv=CsvLayout("fanuc", ("w", "p", "r"), "FANUC W,P,R in deg", _csv_rotations, decimals=6,
                  rank=20),
)
