"""Text of the pendant's readouts (markdown for viser's ``add_markdown``), without viser.

Units as on a pendant: positions in mm, angles in degrees, two decimals. The TCP readout
shows the active TCP (the tool data the controller believes) as X, Y, Z and KUKA A, B, C
(``R = Rz(A) Ry(B) Rx(C)``) in the named frame; ``-0.00`` is printed as ``0.00``.

The words of the Jog tab's readouts are in the session's language (a
:class:`~tcp_pendant.translation.Translator`, English by default); axis names, frame names
(WORLD, BASE, TOOL, FLANGE), units and the numbers' fixed layout stay as they are in every
language.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping

import numpy as np

from tcpcal.tool import Tool
from tcp_pendant.controller import PoseReadout, TouchGeometry
from tcp_pendant.controller.touch import TOUCH_TOLERANCE_MM
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import ENGLISH, Translator, translator

"""The source language's translator: the default of the readouts' ``tr``."""

__all__ = [
    "dropped_presses_text",
    "fmt_num",
    "joint_label",
    "readout_rows",
    "readout_text",
    "joint_readout_markdown",
    "tcp_readout_markdown",
    "tool_data_markdown",
    "touch_indicator_markdown",
    "touch_label",
]


def fmt_num(value: float, decimals: int = 2) -> str:
    """``value`` with ``decimals`` decimals; ``-0.00`` becomes ``0.00``; non-finite as text."""
    v = float(value)
    if not math.isfinite(v):
        return str(v)
    text = "%.*f" % (decimals, v)                # f"{v:.{decimals}f}" without the nested spec
    # fixed-point text is zero when it has no digit but 0 (no exponent in the "f" format)
    return text[1:] if text[0] == "-" and not text.strip("-0.") else text


def readout_rows(readout: PoseReadout, decimals: int = 2) -> tuple[tuple[str, str, str], ...]:
    """``(label, value, unit)`` rows of a readout, e.g. ``("X", "525.00", "mm")`` (values with
    ``decimals`` decimals, ``-0.00`` shown as ``0.00``)."""
    r = readout
    return (("X", fmt_num(r.x_mm, decimals), "mm"), ("Y", fmt_num(r.y_mm, decimals), "mm"),
            ("Z", fmt_num(r.z_mm, decimals), "mm"), ("A", fmt_num(r.a_deg, decimals), "deg"),
            ("B", fmt_num(r.b_deg, decimals), "deg"), ("C", fmt_num(r.c_deg, decimals), "deg"))


def readout_text(readout: PoseReadout, decimals: int = 2) -> str:
    """One line, e.g. ``"WORLD X 525.00 Y 0.00 Z 890.00 mm  A 0.00 B 90.00 C 0.00 deg"``."""
    r = readout_rows(readout, decimals)
    pos = " ".join(f"{lab} {val}" for lab, val, _ in r[:3])
    rot = " ".join(f"{lab} {val}" for lab, val, _ in r[3:])
    return f"{readout.frame} {pos} mm  {rot} deg"


def _two_decimals(values: tuple[float, ...]) -> list[str]:
    """``fmt_num(v)`` of each value (two decimals, ``-0.00`` as ``0.00``, non-finite as text) in
    one formatting pass: the readouts' numbers on every jog step.

    ``"%.2f"`` text is ``-?digits.dd``, ``nan``, ``inf`` or ``-inf``: ``-0.00`` can only be a
    whole number, so one ``replace`` over the joined texts is the per-number rule."""
    return (_SEP.join(("%.2f",) * len(values)) % values).replace("-0.00", "0.00").split(_SEP)


_SEP = "\x1f"                      # never in a formatted number
_SIX = _SEP.join(("%.2f",) * 6)
_TABLE = ("\n\n```\nX %*s mm   A %*s deg\nY %*s mm   B %*s deg\nZ %*s mm   C %*s deg\n```")


@functools.lru_cache(maxsize=64)
def _tcp_table(language: str) -> str:
    """The TCP readout's ``%`` template in ``language``: its title (``**TCP in %s** · %s``,
    frame and tool title) in words, the table in the fixed layout of every language."""
    title = translator(language).gettext("**TCP in {frame}** · {tool}").replace("%", "%%")
    return title.format(frame="%s", tool="%s") + _TABLE


@functools.lru_cache(maxsize=64)
def _tool_title(tool_name: str | None, mounted: str | None = None, tr: Translator = ENGLISH) -> str:
    """The TCP readout's tool: the tool data really active, ``Active tool data: TOOL <name>`` or
    ``Active tool data: none (FLANGE)`` (the TCP is the flange), and the tool mounted on the
    flange, ``· mounted: <label>``, so a pointer on the flange with no data active is not read
    as "no tool" (names escaped; a pure function of the names)."""
    _ = tr.gettext
    data = _("none (FLANGE)") if tool_name is None else f"TOOL {escape_markdown(tool_name)}"
    on = "" if not mounted else _(" · mounted: {tool}").format(tool=escape_markdown(mounted))
    return _("Active tool data: {data}").format(data=data) + on


def tcp_readout_markdown(readout: PoseReadout, tool_name: str | None, mounted: str | None = None,
                         tr: Translator = ENGLISH) -> str:
    """The TCP readout: a title with frame, the active tool data and the mounted tool
    (:func:`_tool_title`), then a monospace table ``X 525.00 mm | A 0.00 deg`` (one line per
    pair), the numbers right-aligned to the widest."""
    r = readout
    x, y, z, a, b, c = (_SIX % (r.x_mm, r.y_mm, r.z_mm, r.a_deg, r.b_deg, r.c_deg)).replace(
        "-0.00", "0.00").split(_SEP)
    w = max(len(x), len(y), len(z), len(a), len(b), len(c))
    return _tcp_table(tr.language) % (r.frame, _tool_title(tool_name, mounted, tr), w, x, w, a, w, y, w, b, w, z, w, c)


@functools.lru_cache(maxsize=32)
def _joint_table(names: tuple[str, ...], tr: Translator = ENGLISH) -> str | None:
    """The joint readout of :func:`joint_readout_markdown` for one robot's joints with a
    ``%8.2f`` slot per angle (the names' own ``%`` doubled); None when a name holds ``-0.00``.

    A negative zero fills its slot as ``   -0.00`` (always padded: 5 of 8 characters), so
    ``" -0.00"`` in the filled text is exactly such a slot unless a name holds it (the text
    around the slots is fixed, and a slot is preceded by a space and followed by a space or a
    line end): one ``replace`` of ``" -0.00"`` by ``"  0.00"`` is the per-number rule."""
    if any("-0.00" in str(n) for n in names):
        return None
    items = [f"{str(n).replace('%', '%%')} %8.2f" for n in names]
    lines = ["  ".join(items[i:i + 3]) for i in range(0, len(items), 3)]
    return _joints_title(tr) + "\n\n```\n" + "\n".join(lines) + "\n```"


def _joints_title(tr: Translator) -> str:
    return tr.gettext("**Joints (deg)**")


def joint_readout_markdown(angles_deg: Mapping[str, float], tr: Translator = ENGLISH) -> str:
    """Joint angles in degrees, three per line: ``A1 0.00  A2 -90.00  A3 90.00`` (each angle
    right-aligned in 8 characters; ``-0.00`` as ``0.00``)."""
    table = _joint_table(tuple(angles_deg), tr)
    if table is not None:
        return (table % tuple(angles_deg.values())).replace(" -0.00", "  0.00")
    values = _two_decimals(tuple(angles_deg.values()))
    items = [f"{n} {v:>8}" for n, v in zip(angles_deg, values)]
    lines = ["  ".join(items[i:i + 3]) for i in range(0, len(items), 3)]
    return _joints_title(tr) + "\n\n```\n" + "\n".join(lines) + "\n```"


def joint_label(name: str, lower_deg: float, upper_deg: float) -> str:
    """Slider label with the axis name and its limits, e.g. ``A1 [-170, +170]°``."""
    return f"{name} [{lower_deg:+.0f}, {upper_deg:+.0f}]°"


def touch_indicator_markdown(touch: TouchGeometry, *, hide_distance: bool, tr: Translator = ENGLISH) -> str:
    """The touch indicator.

    * crash (tool tip driven through the reference tip): always shown, with the depth;
    * otherwise, unless ``hide_distance``: "TOUCHING" within 0.5 mm, else the distance (mm).
    """
    _ = tr.gettext
    if touch.crashed:
        return _("✖ **CRASH**: the tool tip went {depth} mm through the reference tip. Jog back out."
                 ).format(depth=fmt_num(touch.penetration_mm, 1))
    if hide_distance:
        return _("Distance to reference tip: *hidden (judge by eye)*")
    if touch.touching:
        return _("✔ **TOUCHING** the reference tip ({distance} mm ≤ {tolerance} mm)").format(
            distance=fmt_num(touch.distance_mm), tolerance=TOUCH_TOLERANCE_MM)
    return _("Distance to reference tip: **{distance} mm**").format(distance=fmt_num(touch.distance_mm))


def dropped_presses_text(n: int, tr: Translator = ENGLISH) -> str:
    """What the trainee is told when ``n`` jog presses (or hold starts, or joint-slider moves)
    came too late to be carried out (``pendant.jogging.PressGate``)."""
    return tr.ngettext("{n} jog press dropped: the server was busy",
                       "{n} jog presses dropped: the server was busy", n).format(n=n)


def touch_label(index: int, T_world_flange: np.ndarray) -> str:
    """Label of a recorded touch: ``P1  X 525.0 Y 0.0 Z 400.0 mm`` (flange origin, WORLD).

    Args:
        index: 0-based index; shown 1-based.
        T_world_flange: (4,4) flange pose, metres.
    """
    p = np.asarray(T_world_flange, dtype=float)[:3, 3] * 1000.0
    return f"P{index + 1}  X {fmt_num(p[0], 1)} Y {fmt_num(p[1], 1)} Z {fmt_num(p[2], 1)} mm"


def tool_data_markdown(tool: Tool | None, slot: int | None = None, *, selected: bool = False,
                       tr: Translator = ENGLISH) -> str:
    """Active tool data: name (slot), TCP X, Y, Z mm and A, B, C deg, calibration method, in
    ``tr``'s language; ``selected``: headed "Selected:" (the library's selection) instead of
    "Active tool:"."""

    _ = tr.gettext
    if tool is None:
        return _("**Selected:** none (TCP = flange)") if selected else _("**Active tool:** none (TCP = flange)")
    name = escape_markdown(tool.name)
    if slot is None:
        head = (_("**Selected:** {name}") if selected else _("**Active tool:** {name}")).format(name=name)
    else:
        head = (_("**Selected:** {name} (slot {slot})") if selected
                else _("**Active tool:** {name} (slot {slot})")).format(name=name, slot=slot)
    x, y, z = (fmt_num(v) for v in tool.tcp_mm)
    a, b, c = (fmt_num(v) for v in tool.abc_deg)
    cal = "" if tool.calibration is None else "\n\n" + _("calibrated by {method}").format(
        method=escape_markdown(tool.calibration.method))
    return f"{head}\n\n```\nX {x}  Y {y}  Z {z} mm\nA {a}  B {b}  C {c} deg\n```{cal}"
