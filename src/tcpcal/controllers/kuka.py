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
    make_tool,
    text_float,
    text_number,
)
from tcpcal.errors import InvalidInputError
from tcpcal.tool import Tool, abc_deg_from_rotation

__all__ = ["FORMAT", "parse_poses", "parse_text", "parse_tool", "render_poses", "render_text",
           "render_tool"]

N_TOOLS = 16
TOOL_NUMBERS = range(1, N_TOOLS + 1)
NAME_CHARS = 24
_DATA = re.compile(r"TOOL_DATA\s*\[\s*(\d+)\s*\]\s*=\s*\{([^}]*)\}", re.IGNORECASE)
_POSE = re.compile(r"(?:DECL\s+)?(?:GLOBAL\s+)?\b(E6POS|POS)\s+(\w+)\s*=\s*\{([^}]*)\}",
                   re.IGNORECASE)
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


def render_tool(tool: Tool, number: int, name: str | None = None) -> str:
    """The ``$config.dat`` lines of one tool (``;`` comments name the convention)."""
    if not 1 <= number <= N_TOOLS:
        raise ControllerFileError(f"kuka: tool number must be 1..{N_TOOLS}, got {number}")
    label = tool.name if name is None else name
    if len(label) > NAME_CHARS or '"' in label:
        raise ControllerFileError(
            f"kuka: TOOL_NAME holds at most {NAME_CHARS} characters and no '\"'; {label!r} does "
            "not fit: pass a shorter name")
    x, y, z = (fixed(v, 3) for v in tool.tcp_mm)
    a, b, c = (fixed(v, 4) for v in abc_deg_from_rotation(tool.rotation))
    return (f"; tcpcal: tool {number} {label!r} for KUKA KR C $config.dat (replace the lines of\n"
            f"; TOOL_DATA[{number}] and TOOL_NAME[{number},]; set the load data on the controller)\n"
            "; X, Y, Z: TCP in FLANGE, mm; A, B, C deg: R = Rz(A) Ry(B) Rx(C) "
            "(A about Z, then B about the new Y, then C about the newest X)\n"
            f"TOOL_DATA[{number}]={{X {x},Y {y},Z {z},A {a},B {b},C {c}}}\n"
            f'TOOL_NAME[{number},]="{label}"\n')


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
        out.append(ToolEntry(n, nm.group(1).strip() if nm else "", vals[:3], rot))  # type: ignore[arg-type]
    if not out:
        raise ControllerFileError("kuka: no TOOL_DATA[n]={X ..,Y ..,Z ..,A ..,B ..,C ..} found")
    return out


def parse_poses(text: str) -> list[RecordedPose]:
    """``E6POS`` / ``POS`` declarations of a KRL ``.dat`` file, in file order."""
    text = _code(text)
    fdat: dict[str, dict[str, str]] = {}
    for m in _FDAT.finditer(text):
        try:
            fdat[m.group(1).upper()] = _components(m.group(2), m.group(1))
        except ControllerFileError:
            continue  # an FDAT with a structure we do not read (POINT2[] " ") only informs
    out: list[RecordedPose] = []
    for m in _POSE.finditer(text):
        name = m.group(2)
        what = f"line {line_of(text, m.start())}: {m.group(1).upper()} {name}"
        vals = _xyzabc(_components(m.group(3), what), what)
        rot = Rotation.from_euler("ZYX", vals[3:], degrees=True).as_matrix()
        key = "F" + name[1:].upper() if name.upper().startswith("X") else ""
        fd = fdat.get(key, {})
        tool = int(float(fd["TOOL_NO"])) if "TOOL_NO" in fd else None
        base = int(float(fd["BASE_NO"])) if "BASE_NO" in fd else None
        out.append(RecordedPose(name, vals[:3], rot, vals[3:], tool, base,  # type: ignore[arg-type]
                                line_of(text, m.start())))
    return out


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
    ``LOAD_DATA[n]={M ..}`` mass (``M <= 0``: unknown)."""
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
    if m:
        value = text_float(m.group(1), "kuka", "LOAD_DATA mass M")
        mass = value if value > 0 else None
    return make_tool(
        "kuka", name or found_name or f"tool{int(index)}", name is not None,
        tcp_mm=(values["X"], values["Y"], values["Z"]),
        abc_deg=(values["A"], values["B"], values["C"]), mass_kg=mass,
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
    detect=re.compile(r"\b(E6POS|POS)\s+\w+\s*=\s*\{", re.I), detect_text="KUKA E6POS/POS",
    csv=CsvLayout("kuka", ("a", "b", "c"), "KUKA A,B,C in deg", _csv_rotations, decimals=6,
                  rank=10),
)
