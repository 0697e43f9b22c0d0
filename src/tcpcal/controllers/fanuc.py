"""FANUC R-30iA/B: a TP program (``.LS``) that sets a tool frame; positions from ``/POS``.

Tool: a program whose ``/POS`` holds the frame as ``P[1]`` (``X, Y, Z`` mm, ``W, P, R`` deg,
3 decimals as the pendant shows them) and whose ``/MN`` copies it to a position register and
from there to the tool frame: ``PR[m]=P[1] ;`` then ``UTOOL[n]=PR[m] ;`` (a TP program cannot
write a frame from constants). ``R = Rz(R) Ry(P) Rx(W)``: W about X, P about Y, R about Z, all
fixed axes (scipy ``from_euler("xyz", [W, P, R])``). Sections ``/PROG``, ``/ATTR``, ``/MN``,
``/POS``, ``/END``. Positions: ``P[n]{ GP1: UF : u, UT : t, CONFIG : '...', X = .. mm, ...
R = .. deg };`` in ``/POS``. docs/formats.md cites the public examples.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from tcpcal.controllers._common import (
    NUM,
    ControllerFileError,
    RecordedPose,
    ToolEntry,
    fixed,
    line_of,
    to_float,
)
from tcpcal.tool import Tool, abc_deg_from_rotation

__all__ = ["parse_poses", "parse_tool", "render_poses", "render_tool"]

N_TOOLS = 10
N_REGISTERS = 100
DEFAULT_REGISTER = 100
_P = re.compile(r"^\s*P\[\s*(\d+)\s*(?::\s*\"([^\"]*)\")?\s*\]\s*\{(.*?)\}\s*;", re.S | re.M)
_FIELD = re.compile(rf"\b([XYZWPR])\s*=\s*({NUM})")
_UF_UT = re.compile(r"\bUF\s*:\s*(\d+)\s*,\s*UT\s*:\s*(\d+)")
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
    if not 1 <= number <= N_TOOLS:
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


def _positions(text: str) -> list[tuple[int, str, dict[str, float], int | None, int | None, int]]:
    pos_at = text.find("/POS")
    section = text[pos_at:] if pos_at >= 0 else text
    offset = pos_at if pos_at >= 0 else 0
    out = []
    for m in _P.finditer(section):
        k = int(m.group(1))
        body = m.group(3)
        line = line_of(text, offset + m.start())
        if re.search(r"\bJ1\s*=", body):
            raise ControllerFileError(
                f"fanuc: line {line}: P[{k}] is in joint representation; record the touches "
                "in Cartesian (WORLD, UFRAME 0) or convert them on the pendant (REPRE)")
        gp1 = body.split("GP2:")[0]
        vals: dict[str, float] = {}
        for f in _FIELD.finditer(gp1):
            vals[f.group(1)] = to_float(f.group(2), "fanuc", f"P[{k}] {f.group(1)}")
        missing = [c for c in "XYZWPR" if c not in vals]
        if missing:
            raise ControllerFileError(f"fanuc: line {line}: P[{k}] lacks {', '.join(missing)}")
        uf_ut = _UF_UT.search(gp1)
        uf = int(uf_ut.group(1)) if uf_ut else None
        ut = int(uf_ut.group(2)) if uf_ut else None
        out.append((k, m.group(2) or "", vals, uf, ut, line))
    return out


def parse_tool(text: str) -> list[ToolEntry]:
    """The tool frames a TP program sets by ``PR[m]=P[k]`` and ``UTOOL[n]=PR[m]``."""
    points = {k: v for k, _, v, _, _, _ in _positions(text)}
    pr_from_p = {int(m.group(1)): int(m.group(2)) for m in
                 re.finditer(r"PR\[\s*(\d+)\s*(?::[^\]]*)?\]\s*=\s*P\[\s*(\d+)\s*\]", text)}
    out: list[ToolEntry] = []
    for m in re.finditer(r"UTOOL\[\s*(\d+)\s*\]\s*=\s*PR\[\s*(\d+)\s*(?::[^\]]*)?\]", text):
        n, reg = int(m.group(1)), int(m.group(2))
        k = pr_from_p.get(reg)
        if k is None or k not in points:
            raise ControllerFileError(f"fanuc: UTOOL[{n}]=PR[{reg}] but the program does not "
                                      f"set PR[{reg}] from a P[] of its /POS section")
        v = points[k]
        name = re.search(rf"!tcpcal UTOOL\[{n}\] ([^;]*);", text)
        rot = Rotation.from_euler("xyz", [v["W"], v["P"], v["R"]], degrees=True).as_matrix()
        out.append(ToolEntry(n, name.group(1).strip() if name else "",
                             (v["X"], v["Y"], v["Z"]), rot))
    if not out:
        raise ControllerFileError("fanuc: no 'UTOOL[n]=PR[m]' line found")
    return out


def parse_poses(text: str) -> list[RecordedPose]:
    """The Cartesian positions ``P[n]`` of a ``.LS`` file's ``/POS`` section (group 1)."""
    out: list[RecordedPose] = []
    for k, comment, v, uf, ut, line in _positions(text):
        wpr = (v["W"], v["P"], v["R"])
        rot = Rotation.from_euler("xyz", wpr, degrees=True).as_matrix()
        out.append(RecordedPose(comment or f"P[{k}]", (v["X"], v["Y"], v["Z"]), rot, wpr,
                                tool=ut, base=uf, line=line))
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
