"""Yaskawa Motoman (DX/YRC): the tool file ``TOOL.CND``.

One entry per tool, as DX100 and YRC1000 controllers save it:

    //TOOL n
    ///CRC 381761669              (YRC1000 only: a checksum line; tcpcal reads past it)
    ///NAME name
    X,Y,Z,Rx,Ry,Rz                (TCP mm 3 decimals, orientation deg 4 decimals)
    Xg,Yg,Zg                      (centre of gravity in FLANGE, mm)
    W                             (mass, kg)
    Ix,Iy,Iz                      (moments of inertia about the centre of gravity, kg m^2)
    0.000,0,1                     (a line of three fields whose meaning tcpcal does not know)

``R = Rz(Rz) Ry(Ry) Rx(Rx)``, rotations about the fixed flange axes X, then Y, then Z (the
FANUC W, P, R convention). The load is written from the tool's ``mass_kg``, ``cog_mm`` and
moments of inertia (about axes parallel to FLANGE's through the centre of gravity: the
diagonal of ``R diag(I) R^T`` for a load whose inertia axes ``load_abc_deg`` are turned); a
tool without them gets 0.000 (the value of an unset load in the controller's own files): set
the load on the controller. Read back, the moments are the tool's ``inertia_kgm2`` with
``load_abc_deg`` 0, 0, 0 (all zero: unset). The last line as the public files have it for a
tool with no special setting, ``0.000,0,1``.
The file format has no comment syntax, so the convention is stated here and in
docs/formats.md only. docs/formats.md cites the public files this layout is taken from.
Yaskawa has no tool data text (``convert``). Poses come from INFORM jobs (``.JBI``): RECTAN
positions are read, PULSE ones refused with the way out (:mod:`tcpcal.controllers._yaskawa_job`);
they are written in the ``fanuc`` POSES.csv layout (the same convention). :data:`FORMAT`
declares all of it.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from tcpcal.controllers._common import (
    ControllerFileError,
    ToolEntry,
    fixed,
    inertia_or_none,
    to_float,
)
from tcpcal.controllers._format import ControllerFormat
from tcpcal.controllers._yaskawa_job import (
    job_warnings,
    parse_job_poses,
    parse_pulse_points,
    pulse_refusal,
    render_job,
)
from tcpcal.tool import Tool, abc_deg_from_rotation, rotation_from_abc_deg

__all__ = ["FORMAT", "job_warnings", "parse_job_poses", "parse_pulse_points", "parse_tool",
           "pulse_refusal", "render_job", "render_tool"]

N_TOOLS = 64
TOOL_NUMBERS = range(0, N_TOOLS)
NAME_CHARS = 16
_ENTRY = re.compile(r"^//TOOL\s+(\d+)\s*$", re.M)
LAST_LINE = "0.000,0,1"
"""The last line of an entry as the public files write it for a tool with no setting."""


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
    known = tool.mass_kg is not None
    cog = (0.0, 0.0, 0.0) if tool.cog_mm is None or not known else tool.cog_mm
    mass = 0.0 if tool.mass_kg is None else tool.mass_kg
    inertia = _flange_axis_moments(tool) if known else (0.0, 0.0, 0.0)
    return (f"//TOOL {number}\n///NAME {label}\n{','.join(vals)}\n"
            f"{','.join(fixed(v, 3) for v in cog)}\n{fixed(mass, 3)}\n"
            f"{','.join(fixed(v, 3) for v in inertia)}\n{LAST_LINE}\n")


def _flange_axis_moments(tool: Tool) -> tuple[float, float, float]:
    """The moments of inertia ``Ix, Iy, Iz`` (kg m^2) about axes parallel to FLANGE's through
    the centre of gravity, as ``TOOL.CND`` takes them: the diagonal of
    ``R diag(I) R^T`` (``R = R_flange_load`` from ``load_abc_deg``; products of inertia, which
    the file has no place for, dropped); 0 where the tool has no inertia."""
    if tool.inertia_kgm2 is None:
        return (0.0, 0.0, 0.0)
    R = rotation_from_abc_deg(tool.load_abc_deg or (0.0, 0.0, 0.0))
    d = np.diag(R @ np.diag(tool.inertia_kgm2) @ R.T)
    return (float(d[0]), float(d[1]), float(d[2]))


def _numbers(line: str, n: int, what: str, lineno: int) -> list[float]:
    toks = line.split(",")
    if len(toks) != n:
        raise ControllerFileError(f"yaskawa: line {lineno}: {what} needs {n} numbers, got "
                                  f"{len(toks)} ({line.strip()!r})")
    return [to_float(t, "yaskawa", what) for t in toks]


def parse_tool(text: str) -> list[ToolEntry]:
    """Every ``//TOOL n`` entry of a ``TOOL.CND`` text (file order), with its name (also
    after a YRC1000 ``///CRC`` line), mass and centre of gravity (a mass of 0: unset)."""
    out: list[ToolEntry] = []
    lines = text.splitlines()
    for i, line in enumerate(lines):
        m = _ENTRY.match(line.strip())
        if not m:
            continue
        n = int(m.group(1))
        j = i + 1
        name = ""
        while j < len(lines) and lines[j].startswith("///"):
            if lines[j].startswith("///NAME"):
                name = lines[j][len("///NAME"):].strip()
            j += 1
        if j >= len(lines):
            raise ControllerFileError(f"yaskawa: //TOOL {n} has no X,Y,Z,Rx,Ry,Rz line")
        v = _numbers(lines[j], 6, f"//TOOL {n} X,Y,Z,Rx,Ry,Rz", j + 1)
        rot = Rotation.from_euler("xyz", v[3:], degrees=True).as_matrix()
        mass: float | None = None
        cog: tuple[float, float, float] | None = None
        inertia: tuple[float, float, float] | None = None
        load = [ln for ln in lines[j + 1:j + 3]]
        if len(load) == 2 and not load[0].startswith("//") and not load[1].startswith("//"):
            g = _numbers(load[0], 3, f"//TOOL {n} centre of gravity Xg,Yg,Zg", j + 2)
            if len(load[1].split(",")) != 1:
                raise ControllerFileError(
                    f"yaskawa: line {j + 3}: //TOOL {n}: the line after the centre of gravity is "
                    f"the mass W (1 number), got {load[1].strip()!r}; a TOOL.CND entry is X,Y,Z,"
                    "Rx,Ry,Rz / Xg,Yg,Zg / W / Ix,Iy,Iz / 3 fields (DX100, YRC1000)")
            w = _numbers(load[1], 1, f"//TOOL {n} mass W", j + 3)[0]
            if w < 0:
                raise ControllerFileError(f"yaskawa: line {j + 3}: //TOOL {n} mass {w} kg is "
                                          "negative")
            if w > 0:
                mass, cog = w, (g[0], g[1], g[2])
                moments = lines[j + 3] if j + 3 < len(lines) else ""
                if mass is not None and len(moments.split(",")) == 3:
                    inertia = inertia_or_none(_numbers(
                        moments, 3, f"//TOOL {n} moments of inertia Ix,Iy,Iz", j + 4))
        out.append(ToolEntry(n, name, (v[0], v[1], v[2]), rot, mass_kg=mass, cog_mm=cog,
                             load_abc_deg=None if inertia is None else (0.0, 0.0, 0.0),
                             inertia_kgm2=inertia))
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
    values="//TOOL n, ///NAME, X,Y,Z mm, Rx,Ry,Rz deg, Xg,Yg,Zg mm, W kg, Ix,Iy,Iz, 0.000,0,1",
    render_file=render_tool, parse_file=parse_tool,
    tool_file_extensions=(".cnd",), tool_file_detect=re.compile(r"^//TOOL\s+\d+", re.M),
    parse_poses=parse_job_poses, pose_warnings=job_warnings, pose_extensions=(".jbi",),
    render_poses=render_job, parse_pulse_points=parse_pulse_points,
    claim=re.compile(r"^/JOB[ \t]*\r?\n//NAME[ \t]", re.M),
    detect=re.compile(r"^//POS[ \t]*\r?$", re.M), detect_text="Yaskawa //POS",
    pose_layout="fanuc",
)
