"""Pendant panel logic without viser: jog settings, jog commands, readout formatting and
numeric tool entry. The viser views (``tcp_pendant.views``) only wire widgets to these.

Modules, one job each:

* ``jogging``: :class:`JogSettings` (mode, frame, increment, override) and :class:`Jogger`,
  which turns a -/+ key press (or one hold tick) into a controller command.
* ``formatting``: the text of the TCP/joint readouts, the touch indicator and the touch list.
* ``tool_entry``: parse and validate the numeric tool entry (X, Y, Z mm; A, B, C deg).

The robot's state after a move (``PoseState``) and the hot path's rotation conversions are
controller math: ``tcp_pendant.controller.pose_state`` and ``tcp_pendant.controller.rotations``.
"""

from tcp_pendant.pendant.formatting import (
    dropped_presses_text,
    joint_label,
    joint_readout_markdown,
    tcp_readout_markdown,
    tool_data_markdown,
    touch_indicator_markdown,
    touch_label,
)
from tcp_pendant.pendant.jogging import (
    CARTESIAN_AXES,
    INCREMENTS,
    JOG_FRAMES,
    JogMode,
    Jogger,
    JogSettings,
)
from tcp_pendant.controller.pose_state import PoseState, pose_state
from tcp_pendant.pendant.tool_entry import FIELDS, ToolEntry, ToolEntryResult, parse_number, parse_tool_entry

__all__ = [
    "CARTESIAN_AXES",
    "FIELDS",
    "INCREMENTS",
    "JOG_FRAMES",
    "JogMode",
    "JogSettings",
    "Jogger",
    "ToolEntry",
    "ToolEntryResult",
    "dropped_presses_text",
    "joint_label",
    "joint_readout_markdown",
    "parse_number",
    "parse_tool_entry",
    "tcp_readout_markdown",
    "tool_data_markdown",
    "touch_indicator_markdown",
    "touch_label",
]
