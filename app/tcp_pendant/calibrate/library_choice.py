"""Which library tool the orientation wizards (three-point, ABC world) and the reference
wizard offer first, without viser.

Orientation is calibrated for the tool data of the tool on the flange, so the menu proposes,
in this order: the session's active slot (the tool data in use); else the slot holding the
controller's active tool data (same name); else a slot named like the mounted physical tool
(its label or key, case ignored); else the lowest slot.
"""

from __future__ import annotations

from collections.abc import Mapping

from tcpcal.tool import Tool

__all__ = ["default_library_slot"]


def default_library_slot(tools: Mapping[int, Tool], *, active_slot: int | None,
                         active_tool_name: str | None, mounted_label: str,
                         mounted_key: str) -> int | None:
    """The slot to propose (see the module docstring); None when the library is empty.

    Args:
        tools: the library, slot -> tool.
        active_slot: the session's active slot (None: no library tool is active).
        active_tool_name: name of the controller's active tool data (None: none).
        mounted_label: the mounted physical tool's label.
        mounted_key: the mounted physical tool's key.
    """
    if not tools:
        return None
    if active_slot is not None and active_slot in tools:
        return int(active_slot)
    slots = sorted(tools)
    names = {s: str(tools[s].name).strip().casefold() for s in slots}
    if active_tool_name:
        for s in slots:
            if names[s] == active_tool_name.strip().casefold():
                return s
    mounted = {mounted_label.strip().casefold(), mounted_key.strip().casefold()}
    for s in slots:
        if names[s] in mounted:
            return s
    return slots[0]
