"""Yaskawa Motoman (DX/YRC): one entry of the tool file ``TOOL.CND``.

``//TOOL n``, ``///NAME name``, then the line ``X,Y,Z,Rx,Ry,Rz`` (mm with 3 decimals, deg with
4), then the load lines as the controller writes them (centre of gravity ``Xg,Yg,Zg`` mm,
moments of inertia ``Ix,Iy,Iz`` kg m^2, mass ``W`` kg, two flags), all zero here: identify the
load on the controller. ``R = Rz(Rz) Ry(Ry) Rx(Rx)``, rotations about the fixed flange axes X,
then Y, then Z (the FANUC W, P, R convention). The file format has no comment syntax, so the
convention is stated here and in docs/formats.md only. docs/formats.md cites the sources.
Yaskawa has no tool data text (``convert``) and no pose import: :data:`FORMAT` declares the
file only.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from tcpcal.controllers._common import ControllerFileError, ToolEntry, fixed, to_float
from tcpcal.controllers._format import ControllerFormat
from tcpcal.tool import Tool, abc_deg_from_rotation

__all__ = ["FORMAT", "parse_tool", "render_tool"]

N_TOOLS = 64
TOOL_NUMBERS = range(0, N_TOOLS)
NAME_CHARS = 16
_ENTRY = re.compile(r"^//TOOL\s+(\d+)\s*$", re.M)


def render_tool(tool: Tool, number: int, name: str | None = None) -> str:
    """The ``TOOL.CND`` entry of tool ``number`` (0..63; 0 is usually the flange tool)."""
    if not 0 <= number < N_TOOLS:
        raise ControllerFileError(f"yaskawa: tool number must be 0..{N_TOOLS - 1}, got {number}")
    label = (tool.name if name is None else name)
    if len(label) > NAME_CHARS or not re.fullmatch(r"[\x20-\x7e]*", label) or "," in label:
        raise ControllerFileError(
            f"yaskawa: a tool name holds at most {NAME_CHARS} ASCII characters and no comma; "
            f"{label!r} does not fit: pass a shorter name")
    rz, ry, rx = abc_deg_from_rotation(tool.rotation)  # Rz Ry Rx = KUKA's A, B, C order
    vals = [fixed(v, 3) for v in tool.tcp_mm] + [fixed(v, 4) for v in (rx, ry, rz)]
    return (f"//TOOL {number}\n///NAME {label}\n{','.join(vals)}\n"
            "0.000,0.000,0.000\n0.000,0.000,0.000\n0.000\n0,0\n")


def parse_tool(text: str) -> list[ToolEntry]:
    """Every ``//TOOL n`` entry of a ``TOOL.CND`` text (file order)."""
    out: list[ToolEntry] = []
    lines = text.splitlines()
    for i, line in enumerate(lines):
        m = _ENTRY.match(line.strip())
        if not m:
            continue
        n = int(m.group(1))
        j = i + 1
        name = ""
        if j < len(lines) and lines[j].startswith("///NAME"):
            name = lines[j][len("///NAME"):].strip()
            j += 1
        while j < len(lines) and lines[j].startswith("///"):
            j += 1
        if j >= len(lines):
            raise ControllerFileError(f"yaskawa: //TOOL {n} has no X,Y,Z,Rx,Ry,Rz line")
        toks = lines[j].split(",")
        if len(toks) != 6:
            raise ControllerFileError(f"yaskawa: line {j + 1}: //TOOL {n} needs 6 numbers "
                                      f"X,Y,Z,Rx,Ry,Rz, got {len(toks)}")
        v = [to_float(t, "yaskawa", f"//TOOL {n} value") for t in toks]
        rot = Rotation.from_euler("xyz", v[3:], degrees=True).as_matrix()
        out.append(ToolEntry(n, name, (v[0], v[1], v[2]), rot))
    if not out:
        raise ControllerFileError("yaskawa: no '//TOOL n' entry found")
    return out


def _rotation(rxyz_deg: Sequence[float]) -> np.ndarray:
    return Rotation.from_euler("xyz", np.asarray(rxyz_deg, dtype=float), degrees=True).as_matrix()


def _angles(rotation: np.ndarray) -> tuple[float, ...]:
    rz, ry, rx = abc_deg_from_rotation(rotation)
    return (float(rx), float(ry), float(rz))


FORMAT = ControllerFormat(
    name="yaskawa", label="Yaskawa", rank=60,
    angle_convention="R = Rz(Rz) Ry(Ry) Rx(Rx) (about the fixed flange X, then Y, then Z)",
    rotation_from_angles=_rotation, angles_from_rotation=_angles,
    tool_numbers=TOOL_NUMBERS,
    name_rule=f"at most {NAME_CHARS} ASCII characters, no comma",
    controller="Yaskawa Motoman TOOL.CND entry", filename="TOOL{n}.CND",
    values="//TOOL n, ///NAME, X,Y,Z mm, Rx,Ry,Rz deg, load lines",
    render_file=render_tool, parse_file=parse_tool,
)
