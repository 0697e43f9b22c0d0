"""ABB IRC5 / OmniCore: tool data as a RAPID module; positions from ``robtarget`` declarations.

Tool: ``MODULE .. PERS tooldata name:=[TRUE,[[x,y,z],[q1,q2,q3,q4]],[mass,[cx,cy,cz],
[1,0,0,0],0,0,0]]; ENDMODULE``: TCP in the wrist (FLANGE) frame, mm with 3 decimals; the
orientation ``R_flange_tool`` as a unit quaternion, ``q1`` the scalar part (written with
``q1 >= 0``, 6 decimals, as RobotStudio shows it). The identifier must be a RAPID name (a
letter, then letters, digits, ``_``; at most 32 characters), not a reserved word and not the
predefined ``tool0``. Positions: ``robtarget`` declarations ``[[x,y,z],[q1..q4],[cf..],[eax..]]``.
docs/formats.md cites the public examples.
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
from tcpcal.tool import Tool

__all__ = ["RESERVED", "check_identifier", "parse_poses", "parse_tool", "render_poses",
           "render_tool"]

DEFAULT_MASS_KG = 0.001
QUAT_TOL = 1e-3
"""A quaternion whose norm is within this of 1 is normalised (RAPID writes ~6 digits)."""

RESERVED = frozenset("""ALIAS AND BACKWARD CASE CONNECT CONST DEFAULT DIV DO ELSE ELSEIF ENDFOR
ENDFUNC ENDIF ENDMODULE ENDPROC ENDRECORD ENDTEST ENDTRAP ENDWHILE ERROR EXIT FALSE FOR FROM FUNC
GOTO IF INOUT LOCAL MOD MODULE NOSTEPIN NOT NOVIEW OR PERS PROC RAISE READONLY RECORD RETRY
RETURN STEP SYSMODULE TASK TEST THEN TO TRAP TRUE TRYNEXT UNDO VAR VIEWONLY WHILE WITH
XOR""".split())
"""RAPID reserved words (RAPID is case-insensitive)."""

PREDEFINED = frozenset({"TOOL0", "WOBJ0", "LOAD0"})

_IDENT = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,31}$")
_TOOLDATA = re.compile(r"tooldata\s+(\w+)\s*:=\s*(\[[^;]*\])\s*;", re.IGNORECASE)
_ROBTARGET = re.compile(rf"robtarget\s+(\w+)\s*:=\s*\[\s*\[([^\]]*)\]\s*,\s*\[([^\]]*)\]",
                        re.IGNORECASE)


def check_identifier(name: str) -> str:
    """``name`` if it can name a ``tooldata`` in RAPID, else a :class:`ControllerFileError`."""
    if name.upper() == "TOOL0":
        raise ControllerFileError(
            "abb: 'tool0' is the robot's predefined flange tool and cannot be redefined; give "
            "the tool another name (e.g. --name tPointer)")
    if not _IDENT.match(name):
        raise ControllerFileError(
            f"abb: {name!r} is not a RAPID identifier (a letter, then letters, digits or _, at "
            "most 32 characters, no spaces); give the tool such a name (e.g. --name tPointer)")
    if name.upper() in RESERVED or name.upper() in PREDEFINED:
        raise ControllerFileError(f"abb: {name!r} is a reserved or predefined RAPID name; "
                                  "give the tool another name (e.g. --name tPointer)")
    return name


def _quaternion(rotation: np.ndarray) -> np.ndarray:
    x, y, z, w = Rotation.from_matrix(rotation).as_quat()
    q = np.array([w, x, y, z])
    return -q if q[0] < 0 else q


def _rotation(q: Sequence[float], what: str) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    norm = float(np.linalg.norm(q))
    if abs(norm - 1.0) > QUAT_TOL:
        raise ControllerFileError(f"abb: {what}: quaternion norm {norm:.6g} is not 1 within "
                                  f"{QUAT_TOL:g}; check the four values q1..q4")
    return Rotation.from_quat(np.array([q[1], q[2], q[3], q[0]]) / norm).as_matrix()


def render_tool(tool: Tool, number: int = 1, name: str | None = None) -> str:
    """A RAPID module with one ``PERS tooldata`` (``number`` only appears in the comment)."""
    ident = check_identifier(tool.name if name is None else name)
    q = _quaternion(tool.rotation)
    mass = DEFAULT_MASS_KG if tool.mass_kg is None else float(tool.mass_kg)
    pos = ",".join(fixed(v, 3) for v in tool.tcp_mm)
    quat = ",".join(fixed(v, 6) for v in q)
    module = f"tcpcal_{ident}"[:32]
    return (f"MODULE {module}\n"
            f"    ! tcpcal: tool {ident} (library slot {number}) for ABB RAPID\n"
            "    ! tframe: TCP [x,y,z] in mm in the wrist (flange) frame; orientation R_flange_tool\n"
            "    ! as a unit quaternion [q1,q2,q3,q4], q1 the scalar part\n"
            "    ! tload: placeholder load; identify the real one (LoadIdentify) before use\n"
            f"    PERS tooldata {ident}:=[TRUE,[[{pos}],[{quat}]],"
            f"[{fixed(mass, 3)},[0,0,0.001],[1,0,0,0],0,0,0]];\n"
            "ENDMODULE\n")


def _numbers(text: str, n: int, what: str) -> list[float]:
    toks = [t for t in re.split(r"[\s,]+", text.strip()) if t]
    if len(toks) != n:
        raise ControllerFileError(f"abb: {what} needs {n} numbers, got {len(toks)}")
    return [to_float(t, "abb", what) for t in toks]


def parse_tool(text: str) -> list[ToolEntry]:
    """Every ``tooldata`` declaration of a RAPID module (file order)."""
    out: list[ToolEntry] = []
    for m in _TOOLDATA.finditer(text):
        name = m.group(1)
        body = m.group(2)
        inner = re.match(r"\[\s*(TRUE|FALSE)\s*,\s*\[\s*\[([^\]]*)\]\s*,\s*\[([^\]]*)\]", body,
                         re.IGNORECASE)
        if not inner:
            raise ControllerFileError(f"abb: cannot read tooldata {name}; expected "
                                      "[robhold,[[x,y,z],[q1,q2,q3,q4]],[load...]]")
        if inner.group(1).upper() == "FALSE":
            raise ControllerFileError(f"abb: tooldata {name} is a stationary tool (robhold "
                                      "FALSE): its frame is in WORLD, not FLANGE")
        pos = _numbers(inner.group(2), 3, f"tooldata {name} position")
        rot = _rotation(_numbers(inner.group(3), 4, f"tooldata {name} orientation"),
                        f"tooldata {name}")
        out.append(ToolEntry(None, name, tuple(pos), rot))  # type: ignore[arg-type]
    if not out:
        raise ControllerFileError("abb: no 'PERS tooldata name:=[...];' declaration found")
    return out


def parse_poses(text: str) -> list[RecordedPose]:
    """``robtarget`` declarations (``CONST``/``PERS``/``VAR``/``LOCAL``), in file order."""
    out: list[RecordedPose] = []
    for m in _ROBTARGET.finditer(text):
        name = m.group(1)
        what = f"line {line_of(text, m.start())}: robtarget {name}"
        pos = _numbers(m.group(2), 3, f"{what} position")
        q = _numbers(m.group(3), 4, f"{what} orientation")
        out.append(RecordedPose(name, tuple(pos), _rotation(q, what), tuple(q),  # type: ignore[arg-type]
                                line=line_of(text, m.start())))
    return out


def render_poses(poses: Sequence[RecordedPose], module: str = "touches") -> str:
    """A RAPID module declaring each pose as ``CONST robtarget pN`` (record them with tool0
    and wobj0: the flange in WORLD)."""
    lines = [f"MODULE {module}", "    ! tcpcal: touch poses recorded with tool0 and wobj0; "
             "[x,y,z] mm, [q1,q2,q3,q4] q1 scalar"]
    for k, p in enumerate(poses, 1):
        pos = ",".join(fixed(v, 3) for v in p.position_mm)
        quat = ",".join(fixed(v, 6) for v in _quaternion(p.rotation))
        lines.append(f"    CONST robtarget p{k}:=[[{pos}],[{quat}],[0,0,0,0],"
                     "[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];")
    lines.append("ENDMODULE")
    return "\n".join(lines) + "\n"
