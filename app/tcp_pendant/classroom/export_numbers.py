"""One number format for every grade export: ``tcp-pendant grades --csv``, ``--per-trainee
--csv``, ``--moodle`` and the dashboard's "Download grades (CSV)" (no viser, no SQL).

A number cell is the number rounded to 6 decimals, written in plain decimals with the trailing
zeros cut but one kept after the point (``0.231``, ``180.0``, ``12.345679``, ``0.00001``): the
same number as ``repr(round(x, 6))``, never an exponent (``1.99562e-12`` prints ``0.0``: the
solver's round-off is not a result) and never ``-0.0``; a whole number (a count, an id) prints
as it is; no value (or not a finite one) is an empty cell. Units are the column's (mm,
degrees, seconds).
"""

from __future__ import annotations

import math

__all__ = ["DECIMALS", "export_cell"]

DECIMALS = 6
"""Decimals every exported number is rounded to."""


def export_cell(value: object) -> str:
    """``value`` as the text of one CSV cell (module docstring): None and non-finite floats
    give "", floats :data:`DECIMALS` decimals at most, anything else ``str``."""
    if value is None:
        return ""
    if isinstance(value, float):
        if not math.isfinite(value):
            return ""
        text = f"{round(value, DECIMALS) + 0.0:.{DECIMALS}f}".rstrip("0")    # + 0.0: -0.0 is 0.0
        return text + "0" if text.endswith(".") else text
    return str(value)
