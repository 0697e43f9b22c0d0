"""Tool data as robot controllers write it (methods.md section 6).

``export_tool(tool, fmt, slot=1)`` writes one tool as text; ``import_tool(text, fmt, name=None)``
reads it back. Formats (positions in mm unless noted, angles in degrees unless noted; every
rotation conversion goes through ``scipy.spatial.transform.Rotation``):

``kuka``
    As in a KUKA ``$config.dat``::

        TOOL_DATA[1]={X 12.5,Y 0.0,Z 180.25,A 0.0,B -90.0,C 0.0}
        TOOL_NAME[1,]="gripper"

    ``R = Rz(A) Ry(B) Rx(C)`` = ``from_euler("ZYX", [A, B, C])``. A, B, C are written exactly as
    stored in the tool. Import accepts a surrounding declaration (``DECL FRAME TOOL_DATA[1]=...``),
    any whitespace, lower case, and reads ``TOOL_NAME[n,]`` of the same index if present and
    ``LOAD_DATA[n]={M ...}`` for the mass (``M`` <= 0, e.g. KUKA's default -1, means unknown).
    Export does not write ``LOAD_DATA`` (tcpcal knows no centre of mass).
``abb``
    A RAPID ``tooldata`` declaration::

        PERS tooldata gripper:=[TRUE,[[12.5,0,180.25],[q1,q2,q3,q4]],
                                [mass,[0,0,0.001],[1,0,0,0],0,0,0]];

    (written on one line).

    ``q1`` is the scalar part, written with ``q1 >= 0``. ABB requires a positive mass: the tool's
    ``mass_kg`` or, when unknown, :data:`ABB_DEFAULT_MASS_KG` = 0.001 kg with the centre of
    gravity ``[0, 0, 0.001]`` (the load of ABB's ``tool0``); import maps exactly that load back
    to ``mass_kg=None``. The centre of gravity of a known mass is written as ``[0, 0, 0.001]``
    too: identify the real load data on the controller before moving fast. The identifier is the
    tool name with every character that is not an ASCII letter, digit or ``_`` replaced by ``_``
    (and a leading ``t`` if it does not start with a letter or is a RAPID reserved word such as
    ``IF`` or ``TRUE``): a tcpcal name (at most 24 characters) always gives a valid identifier of
    at most 25 of RAPID's 32. Import accepts ``PERS``/``CONST``/``VAR``/
    ``TASK PERS`` declarations or the bare aggregate ``[TRUE,[[...],[...]],[...]]``; it rejects
    ``robhold`` FALSE (a stationary tool has its frame in WORLD, not FLANGE).
``fanuc``
    The tool frame as FANUC's *Tool Frame / Direct Entry* screen shows it::

        UTOOL[1] Direct Entry
        Comment: gripper
        X: 12.5
        Y: 0.0
        Z: 180.25
        W: 0.0
        P: -90.0
        R: 0.0

    ``R = Rz(R) Ry(P) Rx(W)`` (fixed axes) = ``from_euler("xyz", [W, P, R])``. Import finds
    ``X``, ``Y``, ``Z``, ``W``, ``P``, ``R`` each once, with ``:``, ``=`` or a space, one per
    line or all on one line (e.g. a ``$MNUTOOL`` dump ``X: 12.5 Y: 0.0 ...``); the name comes
    from a ``Comment:`` line if present. FANUC frame comments hold 16 characters on the
    pendant: export writes the first :data:`FANUC_COMMENT_LENGTH` (16) characters of the name
    (trailing spaces dropped).
``ur``
    Universal Robots URScript::

        set_tcp(p[0.0125, 0.0, 0.18025, 0.0, -1.5707963267948966, 0.0])

    metres and a rotation vector in radians (``Rotation.from_rotvec``). Import accepts the pose
    alone (``p[...]`` or ``[...]``) or inside any statement.
``matrix``
    ``T_flange_tool`` as 4 lines of 4 numbers (row-major, translation in mm). Import accepts
    any separators (spaces, commas, brackets) and ``#`` comments, 16 numbers (or 12: the top 3x4),
    checks the last row is ``0 0 0 1`` and the rotation is orthonormal within 1e-6.

Numbers are written with Python's shortest round-trip representation (``repr``), so a round
trip returns the same frame to better than 1e-9 (a real KUKA controller writes fewer digits;
import accepts any). Values smaller than 1e-13 in magnitude (floating-point noise of the
rotation conversions) are written as 0. Only the frame, the name and (ABB) the mass travel
through a format; notes and calibration records do not.

Import names: ``name=`` if given, else the name found in the text (KUKA ``TOOL_NAME``, ABB
identifier, FANUC ``Comment``), else ``tool<n>`` (KUKA), ``utool<n>`` (FANUC), ``ur_tcp``,
``imported``. Errors are :class:`tcpcal.errors.InvalidInputError` naming the format and what
could not be parsed.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from tcpcal.errors import InvalidInputError, TcpcalError
from tcpcal.tool import Tool, abc_deg_from_rotation
from tcpcal.validation import as_rotation

__all__ = ["ABB_DEFAULT_MASS_KG", "FANUC_COMMENT_LENGTH", "FORMATS", "export_tool", "import_tool"]

FORMATS = ("kuka", "abb", "fanuc", "ur", "matrix")
ABB_DEFAULT_MASS_KG = 0.001
FANUC_COMMENT_LENGTH = 16
_ABB_DEFAULT_COG = (0.0, 0.0, 0.001)
_KUKA_SLOTS = 16
_FANUC_SLOTS = 10
_ZERO_BELOW = 1e-13

_NUM = r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?|[-+]?(?:nan|inf(?:inity)?)"
_NUM_RE = re.compile(_NUM, re.IGNORECASE)


# --------------------------------------------------------------------------- helpers
def _fmt(x: float, upper_e: bool = False) -> str:
    x = float(x)
    if abs(x) < _ZERO_BELOW:
        x = 0.0
    s = repr(x)
    return s.upper() if upper_e and "e" in s else s


def _to_float(token: str, fmt: str, what: str) -> float:
    try:
        value = float(token)
    except ValueError:
        raise InvalidInputError(f"{fmt}: {what} {token!r} is not a number.") from None
    if not math.isfinite(value):
        raise InvalidInputError(f"{fmt}: {what} is {token!r}; it must be a finite number.")
    return value


def _check_fmt(fmt: Any) -> str:
    if fmt not in FORMATS:
        raise InvalidInputError(f"unknown tool format {fmt!r}; use one of {', '.join(FORMATS)}.")
    return fmt


def _check_slot(slot: Any, n: int, fmt: str) -> int:
    if isinstance(slot, bool) or not isinstance(slot, int) or not 1 <= slot <= n:
        raise InvalidInputError(f"{fmt}: tool number must be 1..{n}, got {slot!r}.")
    return slot


def _make_tool(fmt: str, name: str, name_given: bool, **kw: Any) -> Tool:
    try:
        return Tool(name=name, **kw)
    except TcpcalError as exc:
        hint = "" if name_given else " (pass name=... to import it under another name)"
        raise InvalidInputError(f"{fmt}: the imported tool is invalid: {exc}{hint}") from None


def _tool_from_rotation(
    fmt: str, name: str, name_given: bool, tcp_mm: Any, R: np.ndarray, **kw: Any
) -> Tool:
    abc = abc_deg_from_rotation(R)
    return _make_tool(
        fmt, name, name_given, tcp_mm=tuple(float(v) for v in tcp_mm),
        abc_deg=tuple(float(v) for v in abc), **kw,
    )


# --------------------------------------------------------------------------- KUKA
_KUKA_DATA = re.compile(r"TOOL_DATA\s*\[\s*(\d+)\s*\]\s*=\s*\{([^}]*)\}", re.IGNORECASE)
_KUKA_COMPONENT = re.compile(rf"^\s*([XYZABC])\s*({_NUM})\s*$", re.IGNORECASE)


def _export_kuka(tool: Tool, slot: int) -> str:
    n = _check_slot(slot, _KUKA_SLOTS, "kuka")
    values = (*tool.tcp_mm, *tool.abc_deg)
    body = ",".join(f"{k} {_fmt(v, True)}" for k, v in zip("XYZABC", values))
    return f'TOOL_DATA[{n}]={{{body}}}\nTOOL_NAME[{n},]="{tool.name}"\n'


def _import_kuka(text: str, name: str | None) -> Tool:
    matches = _KUKA_DATA.findall(text)
    if not matches:
        raise InvalidInputError(
            "kuka: no TOOL_DATA[n]={X ..,Y ..,Z ..,A ..,B ..,C ..} found; paste the line of "
            "the tool from $config.dat."
        )
    if len(matches) > 1:
        found = ", ".join(f"TOOL_DATA[{m[0]}]" for m in matches)
        raise InvalidInputError(
            f"kuka: found {len(matches)} tools ({found}); paste only the line of the one to "
            "import."
        )
    index, body = matches[0]
    values: dict[str, float] = {}
    for piece in body.split(","):
        m = _KUKA_COMPONENT.match(piece)
        if not m:
            raise InvalidInputError(
                f"kuka: could not parse {piece.strip()!r} in TOOL_DATA[{index}]; each component "
                "is a letter X, Y, Z, A, B or C, a space and a number."
            )
        key = m.group(1).upper()
        if key in values:
            raise InvalidInputError(f"kuka: component {key} appears twice in TOOL_DATA[{index}].")
        values[key] = _to_float(m.group(2), "kuka", key)
    missing = [k for k in "XYZABC" if k not in values]
    if missing:
        raise InvalidInputError(
            f"kuka: TOOL_DATA[{index}] lacks {', '.join(missing)}; a tool frame needs X, Y, Z, "
            "A, B and C."
        )
    found_name = None
    m = re.search(
        rf'TOOL_NAME\s*\[\s*{int(index)}\s*,\s*\]\s*=\s*"([^"]*)"', text, re.IGNORECASE
    )
    if m:
        found_name = m.group(1).strip()
    mass = None
    m = re.search(
        rf"LOAD_DATA\s*\[\s*{int(index)}\s*\]\s*=\s*\{{\s*M\s*({_NUM})", text, re.IGNORECASE
    )
    if m:
        value = _to_float(m.group(1), "kuka", "LOAD_DATA mass M")
        mass = value if value > 0 else None
    return _make_tool(
        "kuka", name or found_name or f"tool{int(index)}", name is not None,
        tcp_mm=(values["X"], values["Y"], values["Z"]),
        abc_deg=(values["A"], values["B"], values["C"]), mass_kg=mass,
    )


# --------------------------------------------------------------------------- ABB
_ABB_DECL = re.compile(r"tooldata\s+([A-Za-z]\w*)\s*:=", re.IGNORECASE)
_ABB_TOKEN = re.compile(rf"\s*(\[|\]|,|TRUE|FALSE|{_NUM})", re.IGNORECASE)


# RAPID's reserved words (RAPID reference manual, "Reserved words"); identifiers ignore case.
_RAPID_RESERVED = frozenset("""
    ALIAS AND BACKWARD CASE CONNECT CONST DEFAULT DIV DO ELSE ELSEIF ENDFOR ENDFUNC ENDIF
    ENDMODULE ENDPROC ENDRECORD ENDTEST ENDTRAP ENDWHILE ERROR EXIT FALSE FOR FROM FUNC GOTO IF
    INOUT LOCAL MOD MODULE NOSTEPIN NOT NOVIEW OR PERS PROC RAISE READONLY RECORD RETRY RETURN
    STEP SYSMODULE TEST THEN TO TRAP TRUE TRYNEXT UNDO VAR VIEWONLY WHILE WITH XOR
""".split())


def _abb_identifier(name: str) -> str:
    """A RAPID identifier for ``name`` (module docstring, ``abb``): at most 32 ASCII letters,
    digits and ``_``, a letter first, not a reserved word."""
    ident = re.sub(r"\W", "_", name, flags=re.ASCII)
    if not re.match(r"[A-Za-z]", ident) or ident.upper() in _RAPID_RESERVED:
        ident = "t" + ident
    return ident[:32]


def _export_abb(tool: Tool) -> str:
    q = Rotation.from_matrix(tool.rotation).as_quat()  # scipy order: x, y, z, w
    q1234 = np.array([q[3], q[0], q[1], q[2]])
    if q1234[0] < 0:
        q1234 = -q1234
    mass = ABB_DEFAULT_MASS_KG if tool.mass_kg is None else tool.mass_kg
    cog = _ABB_DEFAULT_COG  # tcpcal knows no centre of gravity (module docstring)

    def lst(v: Any) -> str:
        return "[" + ",".join(_fmt(x, True) for x in v) + "]"

    return (
        f"PERS tooldata {_abb_identifier(tool.name)}:=[TRUE,[{lst(tool.tcp_mm)},{lst(q1234)}],"
        f"[{_fmt(mass, True)},{lst(cog)},[1,0,0,0],0,0,0]];\n"
    )


def _parse_aggregate(text: str, start: int) -> Any:
    """Parse a RAPID aggregate ``[a,[b,c],...]`` beginning at ``text[start] == '['``."""
    pos = start

    def token() -> str:
        nonlocal pos
        m = _ABB_TOKEN.match(text, pos)
        if not m:
            snippet = text[pos:pos + 20].strip() or "end of text"
            raise InvalidInputError(f"abb: could not parse the tooldata near {snippet!r}.")
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
                        f"abb: expected ',' or ']' in the tooldata, got {tok!r}."
                    )
                tok = token()
        if tok in ("]", ","):
            raise InvalidInputError(f"abb: unexpected {tok!r} in the tooldata.")
        if tok.upper() in ("TRUE", "FALSE"):
            return tok.upper() == "TRUE"
        return _to_float(tok, "abb", "value")

    return value(token())


def _abb_numbers(v: Any, n: int, what: str) -> list[float]:
    if (
        not isinstance(v, list) or len(v) != n
        or any(isinstance(x, (bool, list)) for x in v)
    ):
        raise InvalidInputError(f"abb: {what} must be [{n} numbers], got {v!r}.")
    return [float(x) for x in v]


def _import_abb(text: str, name: str | None) -> Tool:
    decls = _ABB_DECL.findall(text)
    if len(decls) > 1:
        raise InvalidInputError(
            f"abb: found {len(decls)} tooldata declarations ({', '.join(decls)}); paste only "
            "the one to import."
        )
    m = _ABB_DECL.search(text)
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
    trans = _abb_numbers(tframe[0], 3, "tframe.trans")
    q = np.array(_abb_numbers(tframe[1], 4, "tframe.rot (quaternion q1..q4)"))
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
    cog = _abb_numbers(tload[1], 3, "tload.cog")
    if mass <= 0:
        raise InvalidInputError(f"abb: tload mass must be positive (kg), got {mass!r}.")
    mass_kg = None if (mass == ABB_DEFAULT_MASS_KG and tuple(cog) == _ABB_DEFAULT_COG) else mass
    R = Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix()  # scipy order x, y, z, w
    return _tool_from_rotation(
        "abb", name or found_name or "imported", name is not None, trans, R, mass_kg=mass_kg
    )


# --------------------------------------------------------------------------- FANUC
_FANUC_COMMENT = re.compile(r"^[ \t]*(?:\d+[ \t]+)?Comment[ \t]*:[ \t]*(.*?)[ \t]*$",
                            re.IGNORECASE | re.MULTILINE)
_FANUC_FRAME = re.compile(r"(?:UTOOL\s*\[\s*(\d+)\s*\]|Frame\s+Number\s*:\s*(\d+))",
                          re.IGNORECASE)
_FANUC_VALUE = re.compile(rf"\b([XYZWPR])\b\s*[:=]?\s*({_NUM})", re.IGNORECASE)


def _export_fanuc(tool: Tool, slot: int) -> str:
    n = _check_slot(slot, _FANUC_SLOTS, "fanuc")
    # from_euler("xyz", [W, P, R]) = Rz(R) Ry(P) Rx(W) = from_euler("ZYX", [R, P, W]), so
    # (W, P, R) is (C, B, A) of KUKA; abc_deg_from_rotation stays exact near P = +-90.
    wpr = abc_deg_from_rotation(tool.rotation)[::-1]
    values = (*tool.tcp_mm, *wpr)
    comment = tool.name[:FANUC_COMMENT_LENGTH].rstrip()  # the pendant's frame comment field
    lines = [f"UTOOL[{n}] Direct Entry", f"Comment: {comment}"]
    lines += [f"{k}: {_fmt(v)}" for k, v in zip("XYZWPR", values)]
    return "\n".join(lines) + "\n"


def _import_fanuc(text: str, name: str | None) -> Tool:
    m = _FANUC_COMMENT.search(text)
    found_name = m.group(1) if m and m.group(1) else None
    body = _FANUC_COMMENT.sub("", text)
    frame = _FANUC_FRAME.search(body)
    frame_no = None
    if frame:
        frame_no = int(frame.group(1) or frame.group(2))
    body = _FANUC_FRAME.sub(" ", body)
    values: dict[str, float] = {}
    for key, token in _FANUC_VALUE.findall(body):
        key = key.upper()
        if key in values:
            raise InvalidInputError(
                f"fanuc: {key} appears twice; paste one tool frame (X, Y, Z, W, P, R once each)."
            )
        values[key] = _to_float(token, "fanuc", key)
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
    return _tool_from_rotation(
        "fanuc", name or found_name or default, name is not None,
        (values["X"], values["Y"], values["Z"]), R,
    )


# --------------------------------------------------------------------------- UR
_UR_POSE = re.compile(r"\[([^\[\]]*)\]")


def _export_ur(tool: Tool) -> str:
    rotvec = Rotation.from_matrix(tool.rotation).as_rotvec()
    values = [v / 1000.0 for v in tool.tcp_mm] + list(rotvec)
    return "set_tcp(p[" + ", ".join(_fmt(v) for v in values) + "])\n"


def _import_ur(text: str, name: str | None) -> Tool:
    poses = _UR_POSE.findall(text)
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
    values = [_to_float(p, "ur", lab) for p, lab in zip(pieces, labels)]
    R = Rotation.from_rotvec(values[3:]).as_matrix()
    tcp_mm = [v * 1000.0 for v in values[:3]]
    return _tool_from_rotation("ur", name or "ur_tcp", name is not None, tcp_mm, R)


# --------------------------------------------------------------------------- matrix
def _export_matrix(tool: Tool) -> str:
    T = tool.T_flange_tool_mm
    T[3] = (0.0, 0.0, 0.0, 1.0)
    return "\n".join(" ".join(_fmt(v) for v in row) for row in T) + "\n"


def _import_matrix(text: str, name: str | None) -> Tool:
    body = re.sub(r"#[^\n]*", " ", text)
    leftovers = _NUM_RE.sub(" ", body)
    bad = re.findall(r"[^\s,;\[\]()]+", leftovers)
    if bad:
        raise InvalidInputError(
            f"matrix: could not parse {bad[0]!r}; write 4 rows of 4 numbers (row-major, mm)."
        )
    tokens = _NUM_RE.findall(body)
    if len(tokens) not in (12, 16):
        raise InvalidInputError(
            f"matrix: found {len(tokens)} numbers; a tool frame is 4 rows of 4 numbers "
            "(or the top 3 rows), row-major, translation in mm."
        )
    values = np.array([_to_float(t, "matrix", "entry") for t in tokens])
    T = np.vstack([values.reshape(-1, 4), [0.0, 0.0, 0.0, 1.0]])[:4] if len(tokens) == 12 \
        else values.reshape(4, 4)
    if np.abs(T[3] - [0.0, 0.0, 0.0, 1.0]).max() > 1e-9:
        raise InvalidInputError(
            f"matrix: the last row is {T[3].tolist()}; a homogeneous transform ends with "
            "0 0 0 1 (check the row order: row-major)."
        )
    try:
        R = as_rotation(T[:3, :3], name="matrix rotation part")
    except InvalidInputError as exc:
        raise InvalidInputError(f"matrix: {exc}") from None
    return _tool_from_rotation("matrix", name or "imported", name is not None, T[:3, 3], R)


# --------------------------------------------------------------------------- public API
def export_tool(tool: Tool, fmt: str, *, slot: int = 1) -> str:
    """Write ``tool`` as the controller ``fmt`` does (module docstring), ending in a newline.

    Args:
        tool: the tool.
        fmt: one of :data:`FORMATS`.
        slot: tool number for ``kuka`` (1..16) and ``fanuc`` (1..10); ignored otherwise.

    Raises:
        InvalidInputError: unknown format, bad slot, not a Tool.
    """
    _check_fmt(fmt)
    if not isinstance(tool, Tool):
        raise InvalidInputError(f"export_tool needs a tcpcal.Tool, got {type(tool).__name__}.")
    if fmt == "kuka":
        return _export_kuka(tool, slot)
    if fmt == "abb":
        return _export_abb(tool)
    if fmt == "fanuc":
        return _export_fanuc(tool, slot)
    if fmt == "ur":
        return _export_ur(tool)
    return _export_matrix(tool)


def import_tool(text: str, fmt: str, *, name: str | None = None) -> Tool:
    """Read one tool written in controller format ``fmt`` (module docstring).

    Args:
        text: the controller text (surrounding lines and whitespace are tolerated).
        fmt: one of :data:`FORMATS`.
        name: name of the tool; default: the name in the text, else a default per format.

    Returns:
        The tool; rotations are converted to KUKA A, B, C (``Tool.abc_deg``).

    Raises:
        InvalidInputError: unknown format, or text that cannot be parsed (the message names
            the format and the part that failed).
    """
    _check_fmt(fmt)
    if not isinstance(text, str):
        raise InvalidInputError(f"{fmt}: import_tool needs the text as a string, got {text!r}.")
    if fmt == "kuka":
        return _import_kuka(text, name)
    if fmt == "abb":
        return _import_abb(text, name)
    if fmt == "fanuc":
        return _import_fanuc(text, name)
    if fmt == "ur":
        return _import_ur(text, name)
    return _import_matrix(text, name)
