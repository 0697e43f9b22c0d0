"""Numeric entry of a tool (X, Y, Z in mm; A, B, C in deg; a name), validated field by field.

Nothing is built unless every field is valid: :func:`parse_tool_entry` returns either a
:class:`tcpcal.Tool` (``calibration.method == "numeric"``) or the errors per field, so the view
can show each error next to its field and save nothing half-way.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from tcpcal.tool import Calibration, Tool
from tcp_pendant.pendant.formatting import fmt_num
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import ENGLISH, Translator

__all__ = [
    "FIELDS",
    "MAX_ABS_MM",
    "ToolEntry",
    "ToolEntryResult",
    "entry_preview_markdown",
    "parse_number",
    "parse_tool_entry",
]

FIELDS: tuple[str, ...] = ("X", "Y", "Z", "A", "B", "C")
MAX_ABS_MM = 5000.0
"""A TCP farther than 5 m from the flange is a typing error, not a tool."""


def parse_number(text: str, what: str, *, tr: Translator = ENGLISH) -> float:
    """A finite number from a text field; accepts a decimal comma (``"12,5"``). The error is
    in ``tr``'s language (``what``: the field's label, e.g. ``X (mm)``).

    Raises:
        ValueError: with a message naming the field and what to type.
    """
    t = str(text).strip().replace(",", ".") if text is not None else ""
    if not t:
        raise ValueError(tr.gettext("{what}: enter a number").format(what=what))
    try:
        v = float(t)
    except ValueError:
        raise ValueError(tr.gettext("{what}: '{text}' is not a number").format(what=what, text=text)) from None
    if not math.isfinite(v):
        raise ValueError(tr.gettext("{what}: '{text}' is not a finite number").format(what=what, text=text))
    return v


@dataclass(frozen=True)
class ToolEntry:
    """Raw text of the entry form."""

    name: str
    values: Mapping[str, str]          # "X".."C" -> text


@dataclass(frozen=True)
class ToolEntryResult:
    """Outcome of :func:`parse_tool_entry`: a tool, or the errors by field ("name", "X".."C")."""

    tool: Tool | None
    errors: Mapping[str, str] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        """True when every field is valid."""
        return self.tool is not None and not self.errors


def parse_tool_entry(entry: ToolEntry, *, tr: Translator = ENGLISH) -> ToolEntryResult:
    """Validate the form: a non-empty name, X/Y/Z in mm within +-5000, A/B/C in deg within
    +-360 (A, B, C are KUKA angles, ``R = Rz(A) Ry(B) Rx(C)``); the errors in ``tr``'s language."""
    errors: dict[str, str] = {}
    name = (entry.name or "").strip()
    if not name:
        errors["name"] = tr.gettext("Name: enter a tool name")
    nums: dict[str, float] = {}
    for f in FIELDS:
        unit = "mm" if f in "XYZ" else "deg"
        try:
            v = parse_number(entry.values.get(f, ""), f"{f} ({unit})", tr=tr)
        except ValueError as exc:
            errors[f] = str(exc)
            continue
        limit = MAX_ABS_MM if f in "XYZ" else 360.0
        if abs(v) > limit:
            errors[f] = tr.gettext("{field} ({unit}): {value} is out of range (within ±{limit} {unit})").format(
                field=f, unit=unit, value=f"{v:g}", limit=f"{limit:g}")
            continue
        nums[f] = v
    if errors:
        return ToolEntryResult(None, errors)
    try:
        tool = Tool(name=name, tcp_mm=(nums["X"], nums["Y"], nums["Z"]),
                    abc_deg=(nums["A"], nums["B"], nums["C"]),
                    calibration=Calibration.now("numeric", {}))
    except ValueError as exc:                       # tcpcal's own validation (e.g. the name)
        return ToolEntryResult(None, {"name": tr.gettext("Name: {problem}").format(problem=exc)})
    return ToolEntryResult(tool, {})


def entry_preview_markdown(entry: ToolEntry, *, tr: Translator = ENGLISH) -> str:
    """The form's live preview: what "Save" would store, as the server has received it.

    One line with the name and every field as it will be stored (two decimals, mm and deg;
    ``?`` for a field that is not a valid number), then either "ready to save" or the errors.
    A decimal comma typed in a field shows here as the number it means, so the user sees
    what the controller will hold before saving.
    """

    name = escape_markdown((entry.name or "").strip())
    shown: list[str] = []
    for f in FIELDS:
        try:
            v = parse_number(entry.values.get(f, ""), f)
            text = fmt_num(v) if abs(v) <= (MAX_ABS_MM if f in "XYZ" else 360.0) else "?"
        except ValueError:
            text = "?"
        shown.append(f"{f} {text}")
    head = (f"**{name}**" if name else tr.gettext("*(no name)*")) + \
        f" · {' '.join(shown[:3])} mm · {' '.join(shown[3:])} deg"
    res = parse_tool_entry(entry, tr=tr)
    status = tr.gettext("✔ ready to save") if res.ok else "⚠ " + "; ".join(escape_markdown(e) for e in res.errors.values())
    return f"{head}\n\n{status}"
