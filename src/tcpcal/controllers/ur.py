"""Universal Robots: a URScript file that sets the TCP; poses from ``p[...]`` lists.

Tool: ``set_tcp(p[x, y, z, rx, ry, rz])`` with x, y, z in **metres** and the rotation vector
``(rx, ry, rz)`` (axis times angle) in **radians**, 6 decimals each, plus the values as the
installation's named TCP (Installation > General > TCP) takes them, in a comment, and a
global ``tcp_<name>`` that programs can pass to ``set_tcp``. Positions: every 6-number pose
``p[...]`` of a script (``global name = p[...]``, ``movel(p[...])``), except the TCP of
``set_tcp``; metres are converted to mm. docs/formats.md cites the public examples.

Tool data text (``tcpcal.formats``, ``tcpcal convert``): ``set_tcp(p[x, y, z, rx, ry, rz])``
with ``repr`` numbers (module docstring of :mod:`tcpcal.formats`). POSES.csv layout
``rotvec``: columns ``rx, ry, rz`` (rad; positions in mm like every layout). :data:`FORMAT`
declares all of it.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike
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
from tcpcal.controllers._format import (
    ControllerFormat,
    CsvLayout,
    text_float,
    text_number,
    tool_from_rotation,
)
from tcpcal.errors import InvalidInputError
from tcpcal.tool import Tool

__all__ = ["FORMAT", "parse_poses", "parse_text", "parse_tool", "render_poses", "render_text",
           "render_tool"]

_POSE = re.compile(r"(?<![\w.\]])p\[([^\[\]]*)\]")
"""A pose literal: ``p[`` at the start of a token (``clamp[i]``, ``Kp[0]``, ``a.p[1]`` are
indexing, not poses)."""
_DEF = re.compile(r"^[ \t]*def[ \t]+\w+[ \t]*\(", re.M)
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


_NOT_CODE = re.compile(r"\"[^\"\n]*\"|'[^'\n]*'|#[^\n]*|^[ \t]*\$[^\n]*", re.M)
"""What is not code: string literals, ``#`` comments and PolyScope's ``$ 43 "..."`` line
labels (scanned left to right, so a ``#`` inside a string is the string's)."""


def _code(text: str) -> str:
    """``text`` with string literals, ``#`` comments and ``$`` line labels blanked (same
    length, so offsets and lines hold): nothing inside them is ever parsed."""
    return _NOT_CODE.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), text)


_RELATIVE_CALL = re.compile(r"(?<![\w.])(pose_trans|pose_add)\s*\(")


def _call_arguments(text: str, start: int) -> list[tuple[int, int]]:
    """The top-level argument spans of the call whose ``(`` ends at ``start``."""
    spans, depth, begin, i = [], 0, start, start
    while i < len(text):
        ch = text[i]
        if ch in "([":
            depth += 1
        elif ch in ")]":
            if depth == 0:
                spans.append((begin, i))
                return spans
            depth -= 1
        elif ch == "," and depth == 0:
            spans.append((begin, i))
            begin = i + 1
        i += 1
    return spans


def _relative_offsets(code: str) -> list[tuple[int, str]]:
    """Pose literals used as relative offsets: the arguments of ``pose_trans``/``pose_add``
    whose first argument is not a pose literal (``get_actual_tcp_pose()``, a variable): their
    start offsets and the call's name."""
    out: list[tuple[int, str]] = []
    for m in _RELATIVE_CALL.finditer(code):
        args = _call_arguments(code, m.end())
        if not args or re.fullmatch(r"\s*p\[[^\[\]]*\]\s*", code[args[0][0]:args[0][1]]):
            continue
        for a, b in args[1:]:
            out.extend((p.start(), m.group(1)) for p in _POSE.finditer(code, a, b))
    return out


def _numbers(body: str, what: str) -> list[float]:
    toks = body.split(",")
    if len(toks) != 6:
        raise ControllerFileError(f"ur: {what} needs 6 numbers x, y, z, rx, ry, rz, got "
                                  f"{len(toks)}")
    return [to_float(t, "ur", what) for t in toks]


def _default_spans(text: str) -> list[tuple[int, int]]:
    """The parameter lists of ``def name(...)`` headers (default values are not positions)."""
    spans = []
    for m in _DEF.finditer(text):
        depth, i = 1, m.end()
        while i < len(text) and depth:
            depth += {"(": 1, ")": -1}.get(text[i], 0)
            i += 1
        spans.append((m.end(), i))
    return spans


def _literal_poses(text: str) -> list[re.Match[str]]:
    """The pose literals of code ``text`` outside function headers' default arguments."""
    spans = _default_spans(text)
    return [m for m in _POSE.finditer(text)
            if not any(a <= m.start() < b for a, b in spans)]


def _is_numeric(body: str) -> bool:
    """Every element of the pose is a number (a pose of expressions is computed, not recorded;
    a count other than 6 is then an error of :func:`_numbers`)."""
    return all(re.fullmatch(rf"\s*{NUM}\s*", t) for t in body.split(","))


def _is_tcp(text: str, start: int) -> bool:
    """The pose at ``start`` is a TCP (inside ``set_tcp(``) or a ``tcp_`` variable."""
    before = text[text.rfind("\n", 0, start) + 1:start]
    return bool(re.search(r"set_tcp\s*\(\s*$", before) or re.search(r"tcp\w*\s*=\s*$", before))


def parse_tool(text: str) -> list[ToolEntry]:
    """The TCP poses of ``set_tcp(p[...])`` calls and ``tcp_*`` globals (file order)."""
    text = _code(text)
    out: list[ToolEntry] = []
    for m in _literal_poses(text):
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
    """Every pose literal ``p[x, y, z, rx, ry, rz]`` of six numbers in a script, read by
    tokens (``p[`` starts a token), except TCPs and functions' default arguments; positions
    converted m -> mm. A pose of expressions (``p[x, y, 0.3, 0, 0, 0]``) is not a recorded
    position, nor is a relative offset (an argument of ``pose_trans``/``pose_add`` whose first
    argument is not a pose literal): skipped, and :func:`_pose_warnings` names them. String
    literals and PolyScope's ``$`` line labels are never parsed."""
    text = _code(text)
    relative = {start for start, _ in _relative_offsets(text)}
    out: list[RecordedPose] = []
    for m in _literal_poses(text):
        if _is_tcp(text, m.start()) or not _is_numeric(m.group(1)) or m.start() in relative:
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


# ------------------------------------------------------------------ tool data text
_TEXT_POSE = re.compile(r"\[([^\[\]]*)\]")


def render_text(tool: Tool, slot: int = 1) -> str:
    """``set_tcp(p[x, y, z, rx, ry, rz])``: metres and the rotation vector in radians
    (``slot`` is not written)."""
    rotvec = Rotation.from_matrix(tool.rotation).as_rotvec()
    values = [v / 1000.0 for v in tool.tcp_mm] + list(rotvec)
    return "set_tcp(p[" + ", ".join(text_number(v) for v in values) + "])\n"


def parse_text(text: str, name: str | None) -> Tool:
    """The one pose ``p[...]`` or ``[...]`` of the text, alone or inside any statement."""
    poses = _TEXT_POSE.findall(text)
    if len(poses) != 1:
        raise InvalidInputError(
            f"ur: expected one pose p[x, y, z, rx, ry, rz] (metres, rotation vector in rad), "
            f"found {len(poses)} bracketed lists."
        )
    pieces = [p.strip() for p in poses[0].split(",")]
    if len(pieces) != 6:
        raise InvalidInputError(
            f"ur: the pose has {len(pieces)} values; it needs 6: x, y, z (m), rx, ry, rz (rad)."
        )
    labels = ("x", "y", "z", "rx", "ry", "rz")
    values = [text_float(p, "ur", lab) for p, lab in zip(pieces, labels)]
    R = Rotation.from_rotvec(values[3:]).as_matrix()
    tcp_mm = [v * 1000.0 for v in values[:3]]
    return tool_from_rotation("ur", name or "ur_tcp", name is not None, tcp_mm, R)


def _pose_warnings(text: str) -> list[str]:
    """A script that sets a TCP other than the flange (``set_tcp(p[0, 0, 0, 0, 0, 0])`` is
    fine): its poses may be TCP poses."""
    try:
        tcps = parse_tool(text)
    except ControllerFileError:
        sets = bool(re.search(r"set_tcp\s*\(", _code(text)))  # a TCP we cannot read: say so
    else:
        sets = any(max(map(abs, t.tcp_mm)) > 0 or abs(t.rotation.trace() - 3.0) > 1e-12
                   for t in tcps)
    out = (["the script sets a TCP: poses recorded with a TCP active are TCP poses, not the "
            "flange; record the touches with the TCP at the flange"] if sets else [])
    code = _code(text)
    computed = [line_of(code, m.start()) for m in _literal_poses(code)
                if not _is_tcp(code, m.start()) and not _is_numeric(m.group(1))]
    if computed:
        out.append(f"{len(computed)} pose{'s' if len(computed) != 1 else ''} on line"
                   f"{'s' if len(computed) != 1 else ''} {', '.join(map(str, computed))} "
                   "computed from variables (not numbers): not recorded positions, skipped")
    relative = _relative_offsets(code)
    if relative:
        named = ", ".join(f"p[{code[s + 2:code.index(']', s)].replace(' ', '')}] (line "
                          f"{line_of(code, s)}, {call})" for s, call in relative[:8])
        out.append(f"{len(relative)} pose{'s' if len(relative) != 1 else ''} used as relative "
                   f"offset{'s' if len(relative) != 1 else ''} of the current pose: {named}"
                   f"{', ...' if len(relative) > 8 else ''}: not recorded positions, skipped")
    defaults = sum(1 for a, b in _default_spans(code) for m in _POSE.finditer(code, a, b))
    if defaults:
        out.append(f"{defaults} pose{'s' if defaults != 1 else ''} in function default "
                   "arguments (def f(x=p[...])) skipped: a default is not a touch")
    return out


def _values_to_text(values: Sequence[float]) -> str:
    """x, y, z m; rx, ry, rz rad as ``p[...]``."""
    return "p[" + ",".join(repr(float(x)) for x in values) + "]"


def rotation_from_rotvec(rotvec: ArrayLike) -> np.ndarray:
    """The rotation of a rotation vector (rad): ``(3, 3)``, or ``(N, 3, 3)`` for ``(N, 3)``."""
    return Rotation.from_rotvec(np.asarray(rotvec, dtype=float)).as_matrix()


def _csv_rotations(values: np.ndarray, where: object) -> np.ndarray:
    return rotation_from_rotvec(values)


FORMAT = ControllerFormat(
    name="ur", label="UR", rank=40,
    angle_convention="rotation vector (axis times angle, rad) of R_flange_tool",
    rotation_from_angles=rotation_from_rotvec,
    angles_from_rotation=lambda rot: tuple(
        float(v) for v in Rotation.from_matrix(rot).as_rotvec()),
    numbers="x,y,z,rx,ry,rz m/rad", value_counts=(6,), values_to_text=_values_to_text,
    render_text=render_text, parse_text=parse_text,
    name_rule="no name in the pose; the file names a global tcp_<name>",
    controller="Universal Robots URScript", filename="tcp{n}.script",
    values="p[x,y,z m, rx,ry,rz rad]",
    render_file=render_tool, parse_file=parse_tool, parse_poses=parse_poses,
    render_poses=render_poses, pose_extensions=(".script", ".urscript", ".urp.script"),
    tool_file_extensions=(".script", ".urscript"), tool_file_detect=re.compile(r"\bset_tcp\s*\("),
    detect=re.compile(r"(?<![\w.\]])p\["), detect_text="UR p[...]", pose_warnings=_pose_warnings,
    csv=CsvLayout("rotvec", ("rx", "ry", "rz"), "rotation vector in rad", _csv_rotations,
                  decimals=9, rank=40),
)
