"""KUKA KR C: tool data as ``$config.dat`` lines; positions from a program's ``.dat`` file.

Tool: ``TOOL_DATA[n]={X mm,Y mm,Z mm,A deg,B deg,C deg}`` and ``TOOL_NAME[n,]="name"`` (the
lines of the tool in ``KRC:\\R1\\System\\$config.dat``), ``R = Rz(A) Ry(B) Rx(C)`` (A about Z,
B about the new Y, C about the newest X; scipy ``from_euler("ZYX", [A, B, C])``). mm with 3
decimals, degrees with 4. Positions: ``DECL E6POS XP1={X ..,Y ..,Z ..,A ..,B ..,C ..,S ..,T ..,
E1 ..}`` and ``DECL POS ...`` in a ``.dat`` file, with the ``FDAT`` of the same point giving
``TOOL_NO`` and ``BASE_NO``. docs/formats.md cites the public examples.

Tool data text (``tcpcal.formats``, ``tcpcal convert``): the two lines without comments, numbers
as ``repr`` (module docstring of :mod:`tcpcal.formats`). POSES.csv layout ``kuka``: columns
``a, b, c`` (deg). :data:`FORMAT` declares all of it.
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
    check_slot,
    make_tool,
    text_float,
    text_number,
)
from tcpcal.errors import InvalidInputError
from tcpcal.tool import Tool, abc_deg_from_rotation

__all__ = ["FORMAT", "parse_joint_points", "parse_poses", "parse_text", "parse_tool",
           "pose_warnings", "render_poses", "render_text", "render_tool"]

N_TOOLS = 16
TOOL_NUMBERS = range(1, N_TOOLS + 1)
NAME_CHARS = 24
_DATA = re.compile(r"TOOL_DATA\s*\[\s*(\d+)\s*\]\s*=\s*\{([^}]*)\}", re.IGNORECASE)
_POSE = re.compile(r"(?:DECL\s+)?(?:GLOBAL\s+)?\b(E6POS|POS|FRAME)\s+(\w+)\s*=\s*\{([^}]*)\}",
                   re.IGNORECASE)
_AXIS = re.compile(r"(?:DECL\s+)?(?:GLOBAL\s+)?\b(E6AXIS|AXIS)\s+(\w+)\s*=\s*\{([^}]*)\}",
                   re.IGNORECASE)
_ARRAY = re.compile(r"\bDECL\s+(?:GLOBAL\s+)?(E6POS|POS|FRAME|E6AXIS|AXIS)\s+(\w+)\s*\[",
                    re.IGNORECASE)
_ELEMENT = re.compile(r"^[ \t]*(\w+)\s*\[\s*(\d+)\s*\]\s*=\s*\{([^}]*)\}", re.MULTILINE)
_EXTERNAL = tuple(f"E{i}" for i in range(1, 7))
_FDAT = re.compile(r"FDAT\s+(\w+)\s*=\s*\{([^}]*)\}", re.IGNORECASE)
_COMPONENT = re.compile(
    rf"^\s*([A-Z][\w\[\]]*)\s+({NUM}|'[^']*'|\"[^\"]*\"|#\w+|[A-Za-z_]\w*)\s*$", re.IGNORECASE)


def _code(text: str) -> str:
    """``text`` with KRL ``;`` comments blanked (same length: offsets and lines hold)."""
    return re.sub(r';[^"\n]*$', lambda m: " " * len(m.group(0)), text, flags=re.M)


def _components(body: str, what: str) -> dict[str, str]:
    out: dict[str, str] = {}
    for piece in body.split(","):
        if not piece.strip():
            continue
        m = _COMPONENT.match(piece)
        if not m:
            raise ControllerFileError(f"kuka: cannot read {piece.strip()!r} in {what}; each "
                                      "component is a name, a space and a value")
        out[m.group(1).upper()] = m.group(2)
    return out


def _xyzabc(comp: dict[str, str], what: str) -> tuple[float, ...]:
    missing = [k for k in "XYZABC" if k not in comp]
    if missing:
        raise ControllerFileError(f"kuka: {what} lacks {', '.join(missing)}; a frame needs X, "
                                  "Y, Z, A, B and C")
    return tuple(to_float(comp[k], "kuka", f"{what} {k}") for k in "XYZABC")


def _short(v: float) -> str:
    """``v`` with 7 decimals (KRC writes about 9 digits), trailing zeros dropped, ``0.0``
    for zero (as KRC writes it)."""
    text = fixed(v, 7).rstrip("0")
    return text + "0" if text.endswith(".") else text


def _load_line(tool: Tool, number: int) -> str:
    """``LOAD_DATA[n]={M ..,CM {X ..,Y ..,Z ..,A ..,B ..,C ..},J {X ..,Y ..,Z ..}}`` of a tool
    with a known mass (kg; mm; deg; kg m^2; an unknown part as 0), else ``""``."""
    if tool.mass_kg is None:
        return ""
    cm = (*(tool.cog_mm or (0.0, 0.0, 0.0)), *(tool.load_abc_deg or (0.0, 0.0, 0.0)))
    j = tool.inertia_kgm2 or (0.0, 0.0, 0.0)
    cm_text = ",".join(f"{k} {_short(v)}" for k, v in zip("XYZABC", cm))
    j_text = ",".join(f"{k} {_short(v)}" for k, v in zip("XYZ", j))
    return (f"LOAD_DATA[{number}]={{M {_short(tool.mass_kg)},CM {{{cm_text}}},"
            f"J {{{j_text}}}}}\n")


def render_tool(tool: Tool, number: int, name: str | None = None) -> str:
    """The ``$config.dat`` lines of one tool (``;`` comments name the convention), with its
    ``LOAD_DATA[n]`` when the tool's mass is known."""
    if not 1 <= number <= N_TOOLS:
        raise ControllerFileError(f"kuka: tool number must be 1..{N_TOOLS}, got {number}")
    label = tool.name if name is None else name
    if len(label) > NAME_CHARS or '"' in label:
        raise ControllerFileError(
            f"kuka: TOOL_NAME holds at most {NAME_CHARS} characters and no '\"'; {label!r} does "
            "not fit: pass a shorter name")
    x, y, z = (fixed(v, 3) for v in tool.tcp_mm)
    a, b, c = (fixed(v, 4) for v in abc_deg_from_rotation(tool.rotation))
    load = _load_line(tool, number)
    load_note = ("set the load data on the controller)" if not load else
                 f"and LOAD_DATA[{number}]: M kg, CM mm and deg, J kg m^2)")
    return (f"; tcpcal: tool {number} {label!r} for KUKA KR C $config.dat (replace the lines of\n"
            f"; TOOL_DATA[{number}] and TOOL_NAME[{number},]; {load_note}\n"
            "; X, Y, Z: TCP in FLANGE, mm; A, B, C deg: R = Rz(A) Ry(B) Rx(C) "
            "(A about Z, then B about the new Y, then C about the newest X)\n"
            f"TOOL_DATA[{number}]={{X {x},Y {y},Z {z},A {a},B {b},C {c}}}\n"
            f'TOOL_NAME[{number},]="{label}"\n'
            f"{load}")


_Load = tuple[float | None, tuple[float, float, float] | None,
              tuple[float, float, float] | None, tuple[float, float, float] | None]
_LOAD_CM = re.compile(r"CM\s*\{([^}]*)\}", re.IGNORECASE)
_LOAD_J = re.compile(r"\bJ\s*\{([^}]*)\}", re.IGNORECASE)


def _load(text: str, n: int) -> _Load:
    """Mass (kg), centre of gravity (mm), inertia axes (A, B, C deg) and moments of inertia
    (kg m^2) of ``LOAD_DATA[n]={M ..,CM {X ..,Y ..,Z ..,A ..,B ..,C ..},J {X ..,Y ..,Z ..}}``.
    ``M`` <= 0 (KUKA's -1 "default"): no load at all; a part the line lacks is ``None``; J all
    zero is ``None`` (not given)."""
    m = re.search(rf"LOAD_DATA\s*\[\s*{n}\s*\]\s*=\s*\{{\s*M\s+({NUM})(.*)$", text,
                  re.IGNORECASE | re.MULTILINE)
    if not m or float(m.group(1)) <= 0:
        return None, None, None, None
    what = f"LOAD_DATA[{n}]"
    cm = _LOAD_CM.search(m.group(2))
    comp = _components(cm.group(1), f"{what} CM") if cm else {}
    cog = axes = inertia = None
    if all(k in comp for k in "XYZ"):
        x, y, z = (to_float(comp[k], "kuka", f"{what} CM {k}") for k in "XYZ")
        cog = (x, y, z)
    if all(k in comp for k in "ABC"):
        a, b, c = (to_float(comp[k], "kuka", f"{what} CM {k}") for k in "ABC")
        axes = (a, b, c)
    j = _LOAD_J.search(m.group(2))
    jcomp = _components(j.group(1), f"{what} J") if j else {}
    if all(k in jcomp for k in "XYZ"):
        inertia = inertia_or_none([to_float(jcomp[k], "kuka", f"{what} J {k}") for k in "XYZ"])
    return float(m.group(1)), cog, axes, inertia


def parse_tool(text: str) -> list[ToolEntry]:
    """Every ``TOOL_DATA[n]`` of ``text`` with its ``TOOL_NAME[n,]`` (file order)."""
    text = _code(text)
    out: list[ToolEntry] = []
    for m in _DATA.finditer(text):
        n = int(m.group(1))
        what = f"TOOL_DATA[{n}]"
        vals = _xyzabc(_components(m.group(2), what), what)
        nm = re.search(rf'TOOL_NAME\s*\[\s*{n}\s*,\s*\]\s*=\s*"([^"]*)"', text, re.IGNORECASE)
        rot = Rotation.from_euler("ZYX", vals[3:], degrees=True).as_matrix()
        mass, cog, axes, inertia = _load(text, n)
        out.append(ToolEntry(n, nm.group(1).strip() if nm else "", vals[:3], rot,  # type: ignore[arg-type]
                             mass_kg=mass, cog_mm=cog, load_abc_deg=axes, inertia_kgm2=inertia))
    if not out:
        raise ControllerFileError("kuka: no TOOL_DATA[n]={X ..,Y ..,Z ..,A ..,B ..,C ..} found")
    return out


def _declared(text: str) -> list[tuple[str, str, str, int]]:
    """``(type, name, body, offset)`` of every position declaration of a ``.dat`` text: single
    ``DECL E6POS XP1={...}`` and the elements ``XPA[2]={...}`` of declared arrays, file order."""
    arrays = {m.group(2).upper(): m.group(1).upper() for m in _ARRAY.finditer(text)}
    found = [(m.group(1).upper(), m.group(2), m.group(3), m.start()) for m in _POSE.finditer(text)]
    found += [(m.group(1).upper(), m.group(2), m.group(3), m.start())
              for m in _AXIS.finditer(text)]
    for m in _ELEMENT.finditer(text):
        kind = arrays.get(m.group(1).upper())
        if kind is not None:
            found.append((kind, f"{m.group(1)}[{int(m.group(2))}]", m.group(3), m.start()))
    return sorted(found, key=lambda f: f[3])


def parse_poses(text: str) -> list[RecordedPose]:
    """``E6POS`` / ``POS`` / ``FRAME`` declarations of a KRL ``.dat`` file and the elements of
    such arrays (``XPA[2]={...}``), in file order (a ``FRAME`` only where it holds a whole
    pose, X to C). External axes ``E1``..``E6`` are not part
    of the pose (:func:`pose_warnings` names the points whose values are not 0)."""
    text = _code(text)
    fdat: dict[str, dict[str, str]] = {}
    for m in _FDAT.finditer(text):
        try:
            fdat[m.group(1).upper()] = _components(m.group(2), m.group(1))
        except ControllerFileError:
            continue  # an FDAT with a structure we do not read (POINT2[] " ") only informs
    out: list[RecordedPose] = []
    for kind, name, body, at in _declared(text):
        if kind in ("E6AXIS", "AXIS"):
            continue
        what = f"line {line_of(text, at)}: {kind} {name}"
        comp = _components(body, what)
        if kind == "FRAME" and not _whole_frame(comp):
            continue  # a FRAME that holds no whole pose (an offset of some components)
        vals = _xyzabc(comp, what)
        rot = Rotation.from_euler("ZYX", vals[3:], degrees=True).as_matrix()
        key = "F" + name[1:].upper() if name.upper().startswith("X") else ""
        fd = fdat.get(key, {})
        tool = int(float(fd["TOOL_NO"])) if "TOOL_NO" in fd else None
        base = int(float(fd["BASE_NO"])) if "BASE_NO" in fd else None
        out.append(RecordedPose(name, vals[:3], rot, vals[3:], tool, base,  # type: ignore[arg-type]
                                line_of(text, at)))
    return out


def parse_joint_points(text: str) -> list[JointPoint]:
    """``E6AXIS`` / ``AXIS`` declarations (``A1``..``A6`` deg) and elements of such arrays."""
    text = _code(text)
    out: list[JointPoint] = []
    for kind, name, body, at in _declared(text):
        if kind not in ("E6AXIS", "AXIS"):
            continue
        what = f"line {line_of(text, at)}: {kind} {name}"
        comp = _components(body, what)
        axes = sorted((int(k[1:]), v) for k, v in comp.items() if re.fullmatch(r"A\d", k))
        if not axes:
            raise ControllerFileError(f"kuka: {what} has no axis value A1..A6")
        out.append(JointPoint(name, tuple(to_float(v, "kuka", f"{what} A{i}") for i, v in axes),
                              line_of(text, at), kind=kind))
    return out


def pose_warnings(text: str) -> list[str]:
    """Points with external-axis values (``E1``..``E6`` not 0) and ``FRAME`` data."""
    code = _code(text)
    extax: list[str] = []
    frames: list[str] = []
    partial: list[str] = []
    for kind, name, body, at in _declared(code):
        try:
            comp = _components(body, name)
        except ControllerFileError:
            continue
        moved = [k for k in _EXTERNAL if k in comp and _nonzero(comp[k])]
        if moved:
            extax.append(f"{name} ({', '.join(f'{k} {comp[k]}' for k in moved)})")
        if kind == "FRAME":
            (frames if _whole_frame(comp) else partial).append(name)
    out = []
    if extax:
        out.append(f"{', '.join(extax)}: external-axis values are not part of the pose; tcpcal "
                   "ignores them, so the poses are right only if no external axis (a linear "
                   "track, a turntable) moves the robot or the reference between touches")
    if frames:
        out.append(f"{', '.join(frames)} read from FRAME data (X, Y, Z, A, B, C, no status "
                   "and turn): check that they are recorded flange positions, not a base or "
                   "tool frame")
    if partial:
        out.append(f"{', '.join(partial)}: FRAME data without all of X, Y, Z, A, B, C skipped "
                   "(not a pose)")
    return out


def _whole_frame(comp: dict[str, str]) -> bool:
    return all(k in comp for k in "XYZABC")


def _nonzero(token: str) -> bool:
    try:
        return float(token) != 0.0
    except ValueError:
        return False


def render_poses(poses: Sequence[RecordedPose], module: str = "touches") -> str:
    """A KRL ``.dat`` file declaring each pose as ``E6POS XPn`` with an ``FDAT`` (TOOL_NO 0,
    BASE_NO 0: the flange in WORLD). Status and turn are written as 2 and 0 (not known)."""
    lines = ["&ACCESS RVP", "&REL 1", f"DEFDAT  {module} PUBLIC",
             "; tcpcal: touch poses, X, Y, Z mm; A, B, C deg, R = Rz(A) Ry(B) Rx(C)"]
    for k, p in enumerate(poses, 1):
        x, y, z = (fixed(v, 3) for v in p.position_mm)
        a, b, c = (fixed(v, 4) for v in abc_deg_from_rotation(p.rotation))
        lines.append(f"DECL E6POS XP{k}={{X {x},Y {y},Z {z},A {a},B {b},C {c},S 2,T 0,"
                     "E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}")
        lines.append(f'DECL FDAT FP{k}={{TOOL_NO 0,BASE_NO 0,IPO_FRAME #BASE,POINT2[] " ",'
                     "TQ_STATE FALSE}")
    lines.append("ENDDAT")
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ tool data text
_TEXT_COMPONENT = re.compile(rf"^\s*([XYZABC])\s*({TEXT_NUM})\s*$", re.IGNORECASE)


def render_text(tool: Tool, slot: int = 1) -> str:
    """``TOOL_DATA[n]={X ..,Y ..,Z ..,A ..,B ..,C ..}`` and ``TOOL_NAME[n,]="name"`` (mm, deg;
    A, B, C exactly as stored in the tool)."""
    n = check_slot(slot, TOOL_NUMBERS, "kuka")
    values = (*tool.tcp_mm, *tool.abc_deg)
    body = ",".join(f"{k} {text_number(v, True)}" for k, v in zip("XYZABC", values))
    return f'TOOL_DATA[{n}]={{{body}}}\nTOOL_NAME[{n},]="{tool.name}"\n'


def parse_text(text: str, name: str | None) -> Tool:
    """One ``TOOL_DATA[n]`` (any surrounding declaration), its ``TOOL_NAME[n,]`` and
    ``LOAD_DATA[n]={M ..,CM {..},J {..}}`` load (``M <= 0``: unknown; docs/formats.md "Tool
    loads")."""
    matches = _DATA.findall(text)
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
        m = _TEXT_COMPONENT.match(piece)
        if not m:
            raise InvalidInputError(
                f"kuka: could not parse {piece.strip()!r} in TOOL_DATA[{index}]; each component "
                "is a letter X, Y, Z, A, B or C, a space and a number."
            )
        key = m.group(1).upper()
        if key in values:
            raise InvalidInputError(f"kuka: component {key} appears twice in TOOL_DATA[{index}].")
        values[key] = text_float(m.group(2), "kuka", key)
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
        rf"LOAD_DATA\s*\[\s*{int(index)}\s*\]\s*=\s*\{{\s*M\s*({TEXT_NUM})", text, re.IGNORECASE
    )
    load: dict[str, object] = {}
    if m:
        value = text_float(m.group(1), "kuka", "LOAD_DATA mass M")
        mass = value if value > 0 else None
        if mass is not None:
            _, cog, axes, inertia = _load(text, int(index))
            load = {"cog_mm": cog, "load_abc_deg": axes, "inertia_kgm2": inertia}
    return make_tool(
        "kuka", name or found_name or f"tool{int(index)}", name is not None,
        tcp_mm=(values["X"], values["Y"], values["Z"]),
        abc_deg=(values["A"], values["B"], values["C"]), mass_kg=mass, **load,
    )


def _values_to_text(values: Sequence[float]) -> str:
    """X, Y, Z mm; A, B, C deg as a ``TOOL_DATA[1]`` line."""
    v = [repr(float(x)) for x in values]
    return "TOOL_DATA[1]={" + ",".join(f"{k} {x}" for k, x in zip("XYZABC", v)) + "}"


def rotation_from_abc(abc_deg: ArrayLike) -> np.ndarray:
    """``R = Rz(A) Ry(B) Rx(C)`` of A, B, C (deg): ``(3, 3)``, or ``(N, 3, 3)`` for ``(N, 3)``."""
    return Rotation.from_euler("ZYX", np.asarray(abc_deg, dtype=float), degrees=True).as_matrix()


def _csv_rotations(values: np.ndarray, where: object) -> np.ndarray:
    return rotation_from_abc(values)


FORMAT = ControllerFormat(
    name="kuka", label="KUKA", rank=10,
    angle_convention="R = Rz(A) Ry(B) Rx(C) (A about Z, B about the new Y, C about the newest X)",
    rotation_from_angles=rotation_from_abc,
    angles_from_rotation=lambda rot: tuple(float(v) for v in abc_deg_from_rotation(rot)),
    numbers="X,Y,Z,A,B,C mm/deg", value_counts=(6,), values_to_text=_values_to_text,
    render_text=render_text, parse_text=parse_text, tool_numbers=TOOL_NUMBERS,
    name_rule=f"TOOL_NAME holds {NAME_CHARS} characters, no '\"'",
    controller="KUKA KR C ($config.dat lines)", filename="tool{n}_config.dat",
    values="TOOL_DATA[n]={X,Y,Z mm, A,B,C deg}, TOOL_NAME[n,]",
    render_file=render_tool, parse_file=parse_tool, parse_poses=parse_poses,
    render_poses=render_poses, pose_extensions=(".dat",),
    pose_warnings=pose_warnings, parse_joint_points=parse_joint_points,
    tool_file_extensions=(".dat",), tool_file_detect=re.compile(r"\bTOOL_DATA\s*\[", re.I),
    detect=re.compile(r"\b(E6POS|POS|E6AXIS|AXIS|FRAME)\s+\w+\s*=\s*\{", re.I),
    detect_text="KUKA E6POS/POS",
    csv=CsvLayout("kuka", ("a", "b", "c"), "KUKA A,B,C in deg", _csv_rotations, decimals=6,
                  rank=10),
)
