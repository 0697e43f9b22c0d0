"""Universal Robots: a URScript file that sets the TCP; poses from ``p[...]`` lists.

Tool: ``set_tcp(p[x, y, z, rx, ry, rz])`` with x, y, z in **metres** and the rotation vector
``(rx, ry, rz)`` (axis times angle) in **radians**, 6 decimals each, plus the values as the
installation's named TCP (Installation > General > TCP) takes them, in a comment, and a
global ``tcp_<name>`` that programs can pass to ``set_tcp``. Positions: every 6-number pose
``p[...]`` of a script (``global name = p[...]``, ``movel(p[...])``), except the TCP of
``set_tcp``; metres are converted to mm. docs/formats.md cites the public examples.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from tcpcal.controllers._common import (
    ControllerFileError,
    RecordedPose,
    ToolEntry,
    fixed,
    line_of,
    to_float,
)
from tcpcal.tool import Tool

__all__ = ["parse_poses", "parse_tool", "render_poses", "render_tool"]

_POSE = re.compile(r"p\[([^\[\]]*)\]")
_ASSIGN = re.compile(r"(?:global\s+)?([A-Za-z_]\w*)\s*=\s*$")


def _identifier(name: str) -> str:
    ident = re.sub(r"\W", "_", name, flags=re.ASCII).strip("_") or "tool"
    return ident if re.match(r"[A-Za-z]", ident) else "t_" + ident


def _pose_text(xyz_mm: Sequence[float], rotation: np.ndarray) -> str:
    rv = Rotation.from_matrix(rotation).as_rotvec()
    return "p[" + ", ".join([fixed(v / 1000.0, 6) for v in xyz_mm]
                            + [fixed(v, 6) for v in rv]) + "]"


def render_tool(tool: Tool, number: int = 1, name: str | None = None) -> str:
    """A URScript file: the named TCP as a global, ``set_tcp`` of it, and the installation
    values in a comment (``number`` only appears in the comment)."""
    label = tool.name if name is None else name
    ident = "tcp_" + _identifier(label)
    rv = Rotation.from_matrix(tool.rotation).as_rotvec()
    x, y, z = (fixed(v, 3) for v in tool.tcp_mm)
    rx, ry, rz = (fixed(v, 6) for v in rv)
    pose = _pose_text(tool.tcp_mm, tool.rotation)
    return (f"# tcpcal: tool {label!r} (library slot {number}) for Universal Robots URScript\n"
            "# set_tcp(p[x, y, z, rx, ry, rz]): x, y, z in metres from the tool flange; rx, ry, rz\n"
            "# the rotation vector (axis times angle, rad) of R_flange_tool\n"
            f"# Installation > General > TCP, a TCP named {_identifier(label)}:\n"
            f"#   X {x} mm  Y {y} mm  Z {z} mm  RX {rx} rad  RY {ry} rad  RZ {rz} rad\n"
            f"global {ident} = {pose}\n"
            f"set_tcp({ident})\n")


def _code(text: str) -> str:
    """``text`` with every ``#`` comment blanked (same length, so offsets and lines hold)."""
    return re.sub(r"#[^\n]*", lambda m: " " * len(m.group(0)), text)


def _numbers(body: str, what: str) -> list[float]:
    toks = body.split(",")
    if len(toks) != 6:
        raise ControllerFileError(f"ur: {what} needs 6 numbers x, y, z, rx, ry, rz, got "
                                  f"{len(toks)}")
    return [to_float(t, "ur", what) for t in toks]


def _is_tcp(text: str, start: int) -> bool:
    """The pose at ``start`` is a TCP (inside ``set_tcp(``) or a ``tcp_`` variable."""
    before = text[text.rfind("\n", 0, start) + 1:start]
    return bool(re.search(r"set_tcp\s*\(\s*$", before) or re.search(r"tcp\w*\s*=\s*$", before))


def parse_tool(text: str) -> list[ToolEntry]:
    """The TCP poses of ``set_tcp(p[...])`` calls and ``tcp_*`` globals (file order)."""
    text = _code(text)
    out: list[ToolEntry] = []
    for m in _POSE.finditer(text):
        if not _is_tcp(text, m.start()):
            continue
        v = _numbers(m.group(1), f"line {line_of(text, m.start())}: TCP")
        before = text[text.rfind("\n", 0, m.start()) + 1:m.start()]
        a = _ASSIGN.search(before)
        name = a.group(1)[4:] if a and a.group(1).startswith("tcp_") else ""
        out.append(ToolEntry(None, name, tuple(1000.0 * c for c in v[:3]),  # type: ignore[arg-type]
                             Rotation.from_rotvec(v[3:]).as_matrix()))
    if not out:
        raise ControllerFileError("ur: no set_tcp(p[x, y, z, rx, ry, rz]) found")
    return out


def parse_poses(text: str) -> list[RecordedPose]:
    """Every ``p[x, y, z, rx, ry, rz]`` of a script except TCPs, positions converted m -> mm."""
    text = _code(text)
    out: list[RecordedPose] = []
    for m in _POSE.finditer(text):
        if _is_tcp(text, m.start()):
            continue
        line = line_of(text, m.start())
        v = _numbers(m.group(1), f"line {line}: pose")
        before = text[text.rfind("\n", 0, m.start()) + 1:m.start()]
        a = _ASSIGN.search(before)
        name = a.group(1) if a else f"p{len(out) + 1}"
        out.append(RecordedPose(name, tuple(1000.0 * c for c in v[:3]),  # type: ignore[arg-type]
                                Rotation.from_rotvec(v[3:]).as_matrix(), tuple(v[3:]), line=line))
    return out


def render_poses(poses: Sequence[RecordedPose]) -> str:
    """A URScript file with one ``global touch_N = p[...]`` per pose (base frame, TCP = flange)."""
    lines = ["# tcpcal: touch poses, base frame, TCP = tool flange: p[x, y, z (m), rx, ry, rz "
             "(rotation vector, rad)]"]
    for k, p in enumerate(poses, 1):
        lines.append(f"global touch_{k} = {_pose_text(p.position_mm, p.rotation)}")
    return "\n".join(lines) + "\n"
