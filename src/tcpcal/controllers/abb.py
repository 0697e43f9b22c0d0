"""ABB IRC5 / OmniCore: tool data as a RAPID module; positions from ``robtarget`` declarations.

Tool: ``MODULE .. PERS tooldata name:=[TRUE,[[x,y,z],[q1,q2,q3,q4]],[mass,[cx,cy,cz],
[1,0,0,0],0,0,0]]; ENDMODULE``: TCP in the wrist (FLANGE) frame, mm with 3 decimals; the
orientation ``R_flange_tool`` as a unit quaternion, ``q1`` the scalar part (written with
``q1 >= 0``, 6 decimals, as RobotStudio shows it). The identifier must be a RAPID name (a
letter, then letters, digits, ``_``; at most 32 characters), not a reserved word and not the
predefined ``tool0``. Positions: ``robtarget`` declarations ``[[x,y,z],[q1..q4],[cf..],[eax..]]``.
docs/formats.md cites the public examples.

Tool data text (``tcpcal.formats``, ``tcpcal convert``): the one-line ``PERS tooldata``
declaration with ``repr`` numbers and the tool name made a RAPID identifier (module docstring
of :mod:`tcpcal.formats`). POSES.csv layout ``abb``: columns ``qw, qx, qy, qz``. :data:`FORMAT`
declares all of it.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Sequence
from typing import Any

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
    inertia_or_none,
    line_of,
    to_float,
)
from tcpcal.controllers._format import (
    TEXT_NUM,
    ControllerFormat,
    CsvLayout,
    text_float,
    text_number,
    tool_from_rotation,
)
from tcpcal.errors import InvalidInputError
from tcpcal.tool import Tool, abc_deg_from_rotation, rotation_from_abc_deg
from tcpcal.validation import ORTHONORMAL_TOL

__all__ = ["DEFAULT_MASS_KG", "FORMAT", "RESERVED", "check_identifier", "parse_joint_points",
           "parse_poses", "pose_warnings",
           "parse_text", "parse_tool", "render_poses", "render_text", "render_tool",
           "text_identifier"]

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


def _rotation(q: ArrayLike, what: str) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    norm = float(np.linalg.norm(q))
    if abs(norm - 1.0) > QUAT_TOL:
        raise ControllerFileError(f"abb: {what}: quaternion norm {norm:.6g} is not 1 within "
                                  f"{QUAT_TOL:g}; check the four values q1..q4")
    return Rotation.from_quat(np.array([q[1], q[2], q[3], q[0]]) / norm).as_matrix()


def _short(v: float) -> str:
    """``v`` with 6 decimals, trailing zeros dropped (``0.055``, ``0``)."""
    text = fixed(v, 6).rstrip("0").rstrip(".")
    return text if text not in ("", "-") else "0"


def _tload(tool: Tool) -> str:
    """The ``tload`` aggregate ``[mass,[cx,cy,cz],[q1..q4],ix,iy,iz]`` of ``tool`` (kg, mm,
    kg m^2): its load where the library has one, else tool0's ``[0.001,[0,0,0.001],...]``;
    an unknown centre of gravity as ``[0,0,0.001]``, an unknown orientation as ``[1,0,0,0]``,
    unknown inertia as 0 (ABB: a point mass)."""
    if tool.mass_kg is None:
        return "[0.001,[0,0,0.001],[1,0,0,0],0,0,0]"
    cog = ("0,0,0.001" if tool.cog_mm is None else ",".join(fixed(v, 3) for v in tool.cog_mm))
    aom = ("1,0,0,0" if tool.load_abc_deg is None or not any(tool.load_abc_deg) else
           ",".join(fixed(v, 6) for v in _quaternion(rotation_from_abc_deg(tool.load_abc_deg))))
    inertia = ("0,0,0" if tool.inertia_kgm2 is None
               else ",".join(_short(v) for v in tool.inertia_kgm2))
    return f"[{fixed(tool.mass_kg, 3)},[{cog}],[{aom}],{inertia}]"


def render_tool(tool: Tool, number: int = 1, name: str | None = None) -> str:
    """A RAPID module with one ``PERS tooldata`` (``number`` only appears in the comment); the
    load is the tool's (mass, centre of gravity, inertia axes and moments) where it has one."""
    ident = check_identifier(tool.name if name is None else name)
    q = _quaternion(tool.rotation)
    pos = ",".join(fixed(v, 3) for v in tool.tcp_mm)
    quat = ",".join(fixed(v, 6) for v in q)
    module = f"tcpcal_{ident}"[:32]
    load_note = ("    ! tload: placeholder load; identify the real one (LoadIdentify) before use\n"
                 if tool.mass_kg is None else
                 "    ! tload: the tool's load in the library: mass kg, centre of gravity mm in the\n"
                 "    ! wrist frame, inertia axes [q1..q4], moments of inertia ix,iy,iz kg m^2\n")
    return (f"MODULE {module}\n"
            f"    ! tcpcal: tool {ident} (library slot {number}) for ABB RAPID\n"
            "    ! tframe: TCP [x,y,z] in mm in the wrist (flange) frame; orientation R_flange_tool\n"
            "    ! as a unit quaternion [q1,q2,q3,q4], q1 the scalar part\n"
            f"{load_note}"
            f"    PERS tooldata {ident}:=[TRUE,[[{pos}],[{quat}]],{_tload(tool)}];\n"
            "ENDMODULE\n")


def _numbers(text: str, n: int, what: str) -> list[float]:
    toks = [t for t in re.split(r"[\s,]+", text.strip()) if t]
    if len(toks) != n:
        raise ControllerFileError(f"abb: {what} needs {n} numbers, got {len(toks)}")
    return [to_float(t, "abb", what) for t in toks]


_Load = tuple[float | None, tuple[float, float, float] | None,
              tuple[float, float, float] | None, tuple[float, float, float] | None]


def _load(body: str, name: str) -> _Load:
    """Mass (kg), centre of gravity (mm), inertia axes (KUKA A, B, C deg) and moments of inertia
    (kg m^2; all zero: ``None``) of a tooldata's ``tload``; all ``None`` for tool0's placeholder
    load ``[0.001,[0,0,0.001],...]`` or a load that cannot be read."""
    try:
        agg = _parse_aggregate(body, 0)
        mass = float(agg[2][0])
        cog = tuple(float(v) for v in agg[2][1])
        aom = [float(v) for v in agg[2][2]]
        inertia = [float(v) for v in agg[2][3:6]]
    except (InvalidInputError, IndexError, TypeError, ValueError):
        return None, None, None, None
    if (mass <= 0 or (mass == DEFAULT_MASS_KG and cog == _DEFAULT_COG) or len(cog) != 3
            or len(aom) != 4 or len(inertia) != 3):
        return None, None, None, None
    try:
        axes = abc_deg_from_rotation(_rotation(aom, f"tooldata {name} tload.aom"))
    except ControllerFileError:
        axes = None
    abc = None if axes is None else (float(axes[0]), float(axes[1]), float(axes[2]))
    return mass, (cog[0], cog[1], cog[2]), abc, inertia_or_none(inertia)


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
        mass, cog, axes, inertia = _load(body, name)
        out.append(ToolEntry(None, name, tuple(pos), rot,  # type: ignore[arg-type]
                             mass_kg=mass, cog_mm=cog, load_abc_deg=axes, inertia_kgm2=inertia))
    if not out:
        raise ControllerFileError("abb: no 'PERS tooldata name:=[...];' declaration found")
    return out


_ROBTARGET_ARRAY = re.compile(r"robtarget\s+(\w+)\s*\{\s*(\d+)\s*\}\s*:=\s*\[", re.IGNORECASE)
"""A one-dimensional robtarget array with its values: ``PERS robtarget p{40}:=[[...],...];``."""


def _array_elements(text: str) -> list[tuple[str, int, int, list[Any]]]:
    """Every element of every robtarget array of ``text``: ``(array name, 1-based index, line,
    element aggregate)``, in file order (comments blanked first).

    Raises:
        ControllerFileError: an array whose values cannot be read (names it and its line).
    """
    code = _comment_free(text)
    out: list[tuple[str, int, int, list[Any]]] = []
    for m in _ROBTARGET_ARRAY.finditer(code):
        line = line_of(text, m.start())
        try:
            agg = _parse_aggregate(code, m.end() - 1, "the values")
        except InvalidInputError as exc:
            raise ControllerFileError(f"abb: line {line}: robtarget {m.group(1)}{{{m.group(2)}}}"
                                      f" cannot be read: {str(exc).removeprefix('abb: ')}"
                                      ) from None
        if not isinstance(agg, list):
            continue
        out.extend((m.group(1), k, line, el) for k, el in enumerate(agg, 1))
    return out


def _all_zero(element: Any) -> bool:
    """A robtarget element whose position and orientation are all 0: never taught (RAPID
    fills the unset elements of a declared array so)."""
    try:
        return not any(float(v) for v in [*element[0], *element[1]])
    except (IndexError, TypeError, ValueError):
        return False


def _array_poses(text: str) -> list[RecordedPose]:
    """The elements of robtarget arrays as ``name{i}`` poses (all-zero elements skipped)."""
    out: list[RecordedPose] = []
    for name, k, line, el in _array_elements(text):
        if _all_zero(el):
            continue
        what = f"line {line}: robtarget {name}{{{k}}}"
        try:
            pos = [float(v) for v in el[0]]
            q = [float(v) for v in el[1]]
        except (IndexError, TypeError, ValueError):
            raise ControllerFileError(f"abb: {what} is not [[x,y,z],[q1,q2,q3,q4],...]") from None
        if len(pos) != 3 or len(q) != 4:
            raise ControllerFileError(f"abb: {what} needs [x,y,z] and [q1,q2,q3,q4]")
        out.append(RecordedPose(f"{name}{{{k}}}", (pos[0], pos[1], pos[2]), _rotation(q, what),
                                tuple(q), line=line))
    return out


def parse_poses(text: str) -> list[RecordedPose]:
    """``robtarget`` declarations (``CONST``/``PERS``/``VAR``/``LOCAL``) and the elements of
    robtarget arrays (``name{i}``; all-zero elements, never taught, skipped and counted by
    :func:`pose_warnings`), in file order."""
    out: list[RecordedPose] = []
    for m in _ROBTARGET.finditer(text):
        name = m.group(1)
        what = f"line {line_of(text, m.start())}: robtarget {name}"
        pos = _numbers(m.group(2), 3, f"{what} position")
        q = _numbers(m.group(3), 4, f"{what} orientation")
        out.append(RecordedPose(name, tuple(pos), _rotation(q, what), tuple(q),  # type: ignore[arg-type]
                                line=line_of(text, m.start())))
    out.extend(_array_poses(text))
    return sorted(out, key=lambda p: p.line)


_JOINTTARGET = re.compile(r"jointtarget\s+(\w+)\s*:=\s*\[\s*\[([^\]]*)\]\s*,\s*\[([^\]]*)\]",
                          re.IGNORECASE)
_MOVE = re.compile(r"^[ \t]*(Move(?:L|J|C|AbsJ|LDO|JDO|CDO|LSync|JSync|CSync|LAO|JAO|CAO|"
                   r"LGO|JGO|CGO))\b([^;]*);", re.IGNORECASE | re.MULTILINE)
"""Move instructions whose positional arguments are ToPoint (MoveC: CirPoint, ToPoint),
Speed, Zone, Tool (ABB RAPID reference manual)."""
_WOBJ = re.compile(r"\\WObj\s*:=\s*(\w+)", re.IGNORECASE)
_OPTIONAL_TOOL = re.compile(r"\\Tool\s*:=\s*(\w+)", re.IGNORECASE)
"""An optional ``\\Tool:=name`` argument (the tool of the move where the instruction takes one)."""
_UNSET_EXTAX = 9e8
"""An external axis value at or above this (RAPID writes 9E+09) is 'no axis'."""


def _comment_free(text: str) -> str:
    """``text`` with RAPID ``!`` comments blanked (same length: offsets and lines hold)."""
    return re.sub(r"![^\n]*", lambda m: " " * len(m.group(0)), text)


def _arguments(args: str) -> list[str]:
    """The positional arguments of a RAPID instruction: split at top-level commas, optional
    arguments (``\\Conc``, ``\\WObj:=w``, ``v100\\T:=2``) removed."""
    parts, depth, cur = [], 0, ""
    for ch in args:
        depth += {"[": 1, "(": 1, "]": -1, ")": -1}.get(ch, 0)
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    parts.append(cur)
    out = []
    for part in parts:
        bare = re.sub(r"\\\w+(?:\s*:=\s*[^\\]*)?", "", part).strip()
        bare = re.sub(r"^[A-Za-z]\w*\s*:=\s*", "", bare)  # a named argument: Tool:=tool0
        if bare:
            out.append(bare)
    return out


def _moves(text: str) -> list[tuple[str, list[str], str, str | None, int]]:
    """Every move instruction: ``(instruction, its target names, tool, work object, line)``."""
    code = _comment_free(text)
    out = []
    for m in _MOVE.finditer(code):
        instr = m.group(1)
        args = _arguments(m.group(2))
        n_points = 2 if instr.upper().startswith("MOVEC") else 1
        tool_at = n_points + 2
        if len(args) <= tool_at:
            continue
        targets = [a for a in args[:n_points] if re.fullmatch(r"[A-Za-z]\w*", a)]
        wobj = _WOBJ.search(m.group(2))
        optional_tool = _OPTIONAL_TOOL.search(m.group(2))
        tool = optional_tool.group(1) if optional_tool else args[tool_at]
        out.append((instr, targets, tool, wobj.group(1) if wobj else None,
                    line_of(text, m.start(1))))
    return out


def _has_extax(values: Any) -> bool:
    """An element's external axes hold a value (not 9E+09)."""
    try:
        return any(abs(float(v)) < _UNSET_EXTAX for v in values)
    except (TypeError, ValueError):
        return False


def pose_warnings(text: str) -> list[str]:
    """Moves whose tool is not ``tool0`` or that name a work object (``\\WObj:=``): the
    positions they reach are TCP poses, or poses in that work object, not the flange in WORLD.
    Also named: robtargets whose external axes hold values (not 9E+09)."""
    out: list[str] = []
    tooled: dict[str, list[str]] = {}
    based: dict[str, list[str]] = {}
    for _, targets, tool, wobj, line in _moves(text):
        names = targets or [f"line {line}"]
        if tool.upper() != "TOOL0":
            tooled.setdefault(tool, []).extend(n for n in names if n not in tooled.get(tool, []))
        if wobj is not None and wobj.upper() != "WOBJ0":
            based.setdefault(wobj, []).extend(n for n in names if n not in based.get(wobj, []))
    for tool, names in tooled.items():
        out.append(f"{', '.join(names)} reached by moves with tool {tool} (not tool0): those "
                   "are TCP poses, not the flange; record the touches with tool0")
    for wobj, names in based.items():
        out.append(f"{', '.join(names)} reached by moves in work object {wobj}: those "
                   "positions are in the work object, not WORLD; record the touches with wobj0")
    extax = []
    for m in _ROBTARGET.finditer(text):
        rest = text[m.end():text.find(";", m.end())]
        groups = re.findall(r"\[([^\[\]]*)\]", rest)
        if len(groups) >= 2:
            vals = [t for t in re.split(r"[\s,]+", groups[1].strip()) if t]
            try:
                if any(abs(float(v)) < _UNSET_EXTAX for v in vals):
                    extax.append(m.group(1))
            except ValueError:
                continue
    zeros: dict[str, list[int]] = {}
    sizes: dict[str, int] = {}
    for name, k, _, el in _array_elements(text):
        zeros.setdefault(name, [])
        sizes[name] = k
        if _all_zero(el):
            zeros[name].append(k)
        elif len(el) >= 4 and _has_extax(el[3]):
            extax.append(f"{name}{{{k}}}")
    for name, skipped in zeros.items():
        if skipped:
            out.append(f"{name}: {len(skipped)} of {sizes[name]} elements all zero (never "
                       "taught), skipped")
    if extax:
        out.append(f"{', '.join(extax)} hold external axis values (eax not 9E+09): tcpcal "
                   "ignores them; the poses are right only if no external axis moves the robot "
                   "or the reference")
    return out


def parse_joint_points(text: str) -> list[JointPoint]:
    """``jointtarget`` declarations ``[[rax_1..rax_6],[eax_a..eax_f]]`` (deg), file order."""
    out: list[JointPoint] = []
    for m in _JOINTTARGET.finditer(text):
        what = f"line {line_of(text, m.start())}: jointtarget {m.group(1)}"
        axes = _numbers(m.group(2), 6, f"{what} robot axes")
        out.append(JointPoint(m.group(1), tuple(axes), line_of(text, m.start()),
                              kind="jointtarget"))
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


# ------------------------------------------------------------------ tool data text
_DEFAULT_COG = (0.0, 0.0, 0.001)
_TEXT_DECL = re.compile(r"tooldata\s+([A-Za-z]\w*)\s*:=", re.IGNORECASE)
_TEXT_TOKEN = re.compile(rf"\s*(\[|\]|,|TRUE|FALSE|{TEXT_NUM})", re.IGNORECASE)
_TEXT_RESERVED = RESERVED - {"TASK"}
"""The reserved words the tool data text has always avoided (``TASK`` is not among them)."""


def text_identifier(name: str) -> str:
    """A RAPID identifier for ``name`` (the tool data text): every character that is not an
    ASCII letter, digit or ``_`` becomes ``_``, a ``t`` is put first if it does not start with
    a letter or is a reserved word; at most 32 characters."""
    ident = re.sub(r"\W", "_", name, flags=re.ASCII)
    if not re.match(r"[A-Za-z]", ident) or ident.upper() in _TEXT_RESERVED:
        ident = "t" + ident
    return ident[:32]


def render_text(tool: Tool, slot: int = 1) -> str:
    """``PERS tooldata <identifier>:=[TRUE,[[x,y,z],[q1,q2,q3,q4]],[mass,[cx,cy,cz],
    [aom q1..q4],ix,iy,iz]];`` on one line (mm; ``q1 >= 0``; an unknown load as tool0's
    ``[0.001,[0,0,0.001],[1,0,0,0],0,0,0]``, an unknown part of a known one as those defaults;
    ``slot`` is not written)."""
    q1234 = _quaternion(tool.rotation)
    known = tool.mass_kg is not None
    mass = DEFAULT_MASS_KG if tool.mass_kg is None else tool.mass_kg
    cog = _DEFAULT_COG if tool.cog_mm is None or not known else tool.cog_mm
    aom = ("1,0,0,0" if not known or tool.load_abc_deg is None or not any(tool.load_abc_deg)
           else ",".join(text_number(x, True)
                         for x in _quaternion(rotation_from_abc_deg(tool.load_abc_deg))))
    inertia = (0, 0, 0) if not known or tool.inertia_kgm2 is None else tool.inertia_kgm2

    def lst(v: Iterable[float]) -> str:
        return "[" + ",".join(text_number(x, True) for x in v) + "]"

    def bare(v: Iterable[float]) -> str:
        return ",".join("0" if x == 0 else text_number(x, True) for x in v)

    return (
        f"PERS tooldata {text_identifier(tool.name)}:=[TRUE,[{lst(tool.tcp_mm)},{lst(q1234)}],"
        f"[{text_number(mass, True)},{lst(cog)},[{aom}],{bare(inertia)}]];\n"
    )


def _parse_aggregate(text: str, start: int, what: str = "the tooldata") -> Any:
    """Parse a RAPID aggregate ``[a,[b,c],...]`` beginning at ``text[start] == '['`` (``what``
    names it in the error messages)."""
    pos = start

    def token() -> str:
        nonlocal pos
        m = _TEXT_TOKEN.match(text, pos)
        if not m:
            snippet = text[pos:pos + 20].strip() or "end of text"
            raise InvalidInputError(f"abb: could not parse {what} near {snippet!r}.")
        pos = m.end()
        return m.group(1)

    def value(tok: str) -> Any:
        if tok == "[":
            items: list[Any] = []
            tok = token()
            if tok == "]":
                return items
            while True:
                items.append(value(tok))
                tok = token()
                if tok == "]":
                    return items
                if tok != ",":
                    raise InvalidInputError(
                        f"abb: expected ',' or ']' in {what}, got {tok!r}."
                    )
                tok = token()
        if tok in ("]", ","):
            raise InvalidInputError(f"abb: unexpected {tok!r} in {what}.")
        if tok.upper() in ("TRUE", "FALSE"):
            return tok.upper() == "TRUE"
        return text_float(tok, "abb", "value")

    return value(token())


def _aggregate_numbers(v: Any, n: int, what: str) -> list[float]:
    if (
        not isinstance(v, list) or len(v) != n
        or any(isinstance(x, (bool, list)) for x in v)
    ):
        raise InvalidInputError(f"abb: {what} must be [{n} numbers], got {v!r}.")
    return [float(x) for x in v]


def parse_text(text: str, name: str | None) -> Tool:
    """One ``tooldata`` declaration (``PERS``/``CONST``/``VAR``/``TASK PERS``) or the bare
    aggregate; ``robhold`` FALSE is refused; tool0's load maps back to ``mass_kg=None``; a known
    load keeps its centre of gravity, inertia axes (``aom``) and moments (all zero: unset)."""
    decls = _TEXT_DECL.findall(text)
    if len(decls) > 1:
        raise InvalidInputError(
            f"abb: found {len(decls)} tooldata declarations ({', '.join(decls)}); paste only "
            "the one to import."
        )
    m = _TEXT_DECL.search(text)
    found_name = m.group(1) if m else None
    start = text.find("[", m.end() if m else 0)
    if start < 0:
        raise InvalidInputError(
            "abb: no tooldata found; paste a line like PERS tooldata t1:=[TRUE,[[x,y,z],"
            "[q1,q2,q3,q4]],[mass,[cx,cy,cz],[1,0,0,0],0,0,0]];"
        )
    agg = _parse_aggregate(text, start)
    if not (isinstance(agg, list) and len(agg) == 3):
        raise InvalidInputError(
            "abb: tooldata must have 3 parts [robhold, tframe, tload], got "
            f"{len(agg) if isinstance(agg, list) else agg!r} parts."
        )
    robhold, tframe, tload = agg
    if not isinstance(robhold, bool):
        raise InvalidInputError(f"abb: robhold must be TRUE or FALSE, got {robhold!r}.")
    if not robhold:
        raise InvalidInputError(
            "abb: robhold is FALSE (a stationary tool, its frame is in WORLD); tcpcal imports "
            "robot-held tools only."
        )
    if not (isinstance(tframe, list) and len(tframe) == 2):
        raise InvalidInputError(f"abb: tframe must be [[x,y,z],[q1,q2,q3,q4]], got {tframe!r}.")
    trans = _aggregate_numbers(tframe[0], 3, "tframe.trans")
    q = np.array(_aggregate_numbers(tframe[1], 4, "tframe.rot (quaternion q1..q4)"))
    norm = float(np.linalg.norm(q))
    if abs(norm - 1.0) > 1e-3:
        raise InvalidInputError(
            f"abb: the quaternion {q.tolist()} has norm {norm:.6g}; a rotation quaternion has "
            "norm 1 (check that all four values were copied)."
        )
    if not (isinstance(tload, list) and len(tload) == 6):
        raise InvalidInputError(
            "abb: tload must be [mass,[cx,cy,cz],[q1,q2,q3,q4],ix,iy,iz], got "
            f"{tload!r}."
        )
    if isinstance(tload[0], (bool, list)):
        raise InvalidInputError(f"abb: tload mass must be a number, got {tload[0]!r}.")
    mass = float(tload[0])
    cog = _aggregate_numbers(tload[1], 3, "tload.cog")
    if mass <= 0:
        raise InvalidInputError(f"abb: tload mass must be positive (kg), got {mass!r}.")
    mass_kg = None if (mass == DEFAULT_MASS_KG and tuple(cog) == _DEFAULT_COG) else mass
    R = Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix()  # scipy order x, y, z, w
    cog_mm = None if mass_kg is None else (cog[0], cog[1], cog[2])
    axes, inertia = None, None
    if mass_kg is not None:
        aom = np.array(_aggregate_numbers(tload[2], 4, "tload.aom (quaternion q1..q4)"))
        moments = [_aggregate_numbers([v], 1, "tload inertia")[0] for v in tload[3:6]]
        if abs(float(np.linalg.norm(aom)) - 1.0) > 1e-3:
            raise InvalidInputError(f"abb: tload.aom {aom.tolist()} is not a unit quaternion.")
        abc = abc_deg_from_rotation(Rotation.from_quat(aom[[1, 2, 3, 0]]).as_matrix())
        axes = (float(abc[0]), float(abc[1]), float(abc[2]))
        inertia = inertia_or_none(moments)
    return tool_from_rotation(
        "abb", name or found_name or "imported", name is not None, trans, R, mass_kg=mass_kg,
        cog_mm=cog_mm, load_abc_deg=axes, inertia_kgm2=inertia,
    )


def _values_to_text(values: Sequence[float]) -> str:
    """x, y, z mm; q1..q4 (q1 scalar) as a bare tooldata aggregate, unknown load as tool0's."""
    v = [repr(float(x)) for x in values]
    return (f"[TRUE,[[{v[0]},{v[1]},{v[2]}],[{','.join(v[3:7])}]],"
            f"[0.001,[0,0,0.001],[1,0,0,0],0,0,0]]")


def _rotation_from_q(q: ArrayLike) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    return Rotation.from_quat(np.stack([q[..., 1], q[..., 2], q[..., 3], q[..., 0]], axis=-1)
                              ).as_matrix()


def _csv_rotations(v: np.ndarray, where: Callable[[int], str]) -> np.ndarray:
    norm = np.sqrt(np.einsum("ij,ij->i", v, v))
    bad = ~(np.abs(norm - 1.0) <= ORTHONORMAL_TOL)
    if bad.any():
        i = int(np.argmax(bad))
        raise InvalidInputError(
            f"{where(i)}: quaternion qw,qx,qy,qz has norm {norm[i]:.9g}, not 1 within "
            f"{ORTHONORMAL_TOL:g}; check the column order and print more digits", index=i)
    return Rotation.from_quat(v[:, [1, 2, 3, 0]]).as_matrix()  # scipy order x, y, z, w


def _csv_row(pose: RecordedPose) -> list[float]:
    """The quaternion of a pose normalised, so the CSV reader's 1e-6 check passes."""
    q = [float(v) for v in pose.values]
    n = sum(v * v for v in q) ** 0.5
    return [v / n for v in q]


FORMAT = ControllerFormat(
    name="abb", label="ABB", rank=20,
    angle_convention="unit quaternion of R_flange_tool, q1 the scalar part",
    rotation_from_angles=_rotation_from_q,
    angles_from_rotation=lambda rot: tuple(float(v) for v in _quaternion(rot)),
    numbers="x,y,z,q1,q2,q3,q4 mm/unit quaternion scalar first", value_counts=(7,),
    values_to_text=_values_to_text, render_text=render_text, parse_text=parse_text,
    name_rule="a RAPID identifier (a letter, then letters, digits or _, at most 32), not a "
              "reserved word, not tool0",
    controller="ABB RAPID module", filename="tool{n}.mod",
    values="PERS tooldata name:=[TRUE,[[x,y,z mm],[q1,q2,q3,q4]],[load]]",
    render_file=render_tool, parse_file=parse_tool, parse_poses=parse_poses,
    render_poses=render_poses, pose_extensions=(".mod", ".modx", ".prg", ".sys"),
    detect=re.compile(r"\b(robtarget|jointtarget)\b", re.I), detect_text="ABB robtarget",
    pose_warnings=pose_warnings, parse_joint_points=parse_joint_points,
    tool_file_extensions=(".mod", ".modx", ".sys", ".prg"),
    tool_file_detect=re.compile(r"\btooldata\s+\w+\s*:=", re.I),
    csv=CsvLayout("abb", ("qw", "qx", "qy", "qz"), "unit quaternion, scalar first",
                  _csv_rotations, decimals=9, rank=30, row_values=_csv_row),
)
