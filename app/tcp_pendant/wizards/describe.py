"""What a wizard class declares about itself: its step roles with the way the
robot performs each in auto-touch, the options it takes at start with their choices, and what
starting it needs. No viser, no controller: plain frozen data read by the menu, the steps view,
auto-touch, the session record and the workflow (``tcp_pendant.wizards.registry``).

Units: auto-touch distances in mm (``reference_per_distance`` is multiplied by the auto-touch
distance, 60 mm by default; ``reference_fixed_mm`` is added), tilt ranges in degrees.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, Protocol

from tcp_pendant.translation import ENGLISH, Translator

if TYPE_CHECKING:
    from tcp_pendant.controller.tools import ToolModel
    from tcp_pendant.wizards.base import Wizard
    from tcpcal.tool import Tool

__all__ = [
    "AHEAD_PLUS_X", "AHEAD_PLUS_Z", "ALIGN_WORLD", "AutoRole", "BY_CONTROLLER", "IN_PLUS_Y_HALF", "ON_MINUS_X",
    "ON_PLUS_Y", "OptionError", "StartContext", "StepRole", "TOUCH", "TOUCH_KEEP_ORIENTATION",
    "WizardOption", "WizardStart",
]


class OptionError(ValueError):
    """A start option is unknown or out of its choices; the message names it and the choices."""


@dataclass(frozen=True)
class AutoRole:
    """How the robot performs a step in training-mode auto-touch (``calibrate.autotouch``).

    Attributes:
        reference_per_distance: where the reference tip ends up in true TOOL coordinates, per mm
            of the auto-touch distance ((0, 0, 1): on the tool's +Z axis, ``distance_mm`` ahead of
            the TCP).
        reference_fixed_mm: added to that (mm, TOOL coordinates).
        tilt_range_deg: tilt of tool X from straight down of a random direction (deg).
        keeps_orientation: after the wizard's first step, reuse the direction of its previous
            auto-touch (the operator jogs along tool axes and keeps the orientation).
        align_world: move the tool to the (PA-1) orientation above the reference tip instead.
        free_turn_about_x: with ``align_world``: a random turn about tool X (5D).
        any_orientation_solves: the solve uses each pose's own rotation (TCP & Z, X,
            methods.md (ZX-1), (ZX-2)), so when the kept orientation is out of reach, auto-touch
            may draw a new direction in ``tilt_range_deg``; False where the method needs the orientation kept (three-point).
        by_controller: the controller performs the step itself (the beam wizard's scan): no
            Record and no auto-touch; Finish runs the wizard's controller job
            (``CalibrationWorkflow.controller_job``).
    """

    reference_per_distance: tuple[float, float, float] = (0.0, 0.0, 0.0)
    reference_fixed_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    tilt_range_deg: tuple[float, float] = (20.0, 50.0)
    keeps_orientation: bool = False
    align_world: bool = False
    free_turn_about_x: bool = False
    any_orientation_solves: bool = False
    by_controller: bool = False

    def reference_in_tool_mm(self, distance_mm: float) -> tuple[float, float, float]:
        """The reference tip in true TOOL coordinates (mm) for an auto-touch ``distance_mm``."""
        x, y, z = (p * distance_mm + f for p, f in zip(self.reference_per_distance, self.reference_fixed_mm))
        return (float(x), float(y), float(z))


TOUCH = AutoRole()
"""The tool tip on the reference tip, from a random direction tilted 20-50 degrees."""
TOUCH_KEEP_ORIENTATION = AutoRole(tilt_range_deg=(5.0, 30.0), keeps_orientation=True)
"""A touch from a gentle direction whose orientation the following axis steps keep."""
ON_MINUS_X = AutoRole((-1.0, 0.0, 0.0), tilt_range_deg=(5.0, 30.0), keeps_orientation=True)
ON_PLUS_Y = AutoRole((0.0, 1.0, 0.0), tilt_range_deg=(5.0, 30.0), keeps_orientation=True)
IN_PLUS_Y_HALF = AutoRole((0.0, 1.0, 0.0), (-20.0, 0.0, 0.0), tilt_range_deg=(5.0, 30.0),
                          keeps_orientation=True)
AHEAD_PLUS_Z = AutoRole((0.0, 0.0, 1.0), tilt_range_deg=(5.0, 30.0), keeps_orientation=True,
                        any_orientation_solves=True)
"""The reference tip on the tool's +Z axis ahead of the TCP (backed off along tool -Z)."""
AHEAD_PLUS_X = AutoRole((1.0, 0.0, 0.0), tilt_range_deg=(5.0, 30.0), keeps_orientation=True,
                        any_orientation_solves=True)
"""The reference tip on the tool's +X axis ahead of the TCP (moved along tool -X)."""
ALIGN_WORLD = AutoRole(align_world=True)
"""Tool axes parallel to WORLD as (PA-1) prescribes, hovering above the reference tip."""
BY_CONTROLLER = AutoRole(by_controller=True)
"""No touch: the controller runs the step itself (a beam scan); nothing to record by hand."""


@dataclass(frozen=True)
class StepRole:
    """A step role a wizard uses: its name (``StepSpec.role``), what it means, how auto-touch
    performs it."""

    name: str
    meaning: str
    auto: AutoRole


@dataclass(frozen=True)
class WizardOption:
    """An option a wizard takes at start, shown by the Calibrate menu while the method is chosen.

    Attributes:
        name: keyword of the start options (``CalibrationWorkflow.start(kind, **options)``);
            wizards that declare the same name share one menu widget.
        label: menu label.
        kind: "int" (a slider ``minimum..maximum``), "choice" (a dropdown of ``choices``),
            "library_slot" (a tool of the library: its slot) or "physical_tool" (a physical
            tool's key; ``default`` "mounted" or "other": the mounted one or another).
        default: value when not given ("int", "choice") or the physical tool proposed.
        choices: (value, label) pairs of a "choice".
        minimum, maximum: range of an "int".
        hint: tooltip.
    """

    name: str
    label: str
    kind: Literal["int", "choice", "library_slot", "physical_tool"]
    default: int | str | None = None
    choices: tuple[tuple[object, str], ...] = ()
    minimum: int | None = None
    maximum: int | None = None
    hint: str = ""

    @property
    def required(self) -> bool:
        """The start needs a value (no default to fall back on)."""
        return self.kind in ("library_slot", "physical_tool")

    def parse(self, value: object, *, tr: Translator = ENGLISH) -> object:
        """``value`` checked against the option's kind and choices.

        Raises:
            OptionError: naming the option, the value and what is allowed (in ``tr``'s language).
        """
        _, label = tr.gettext, tr.gettext(self.label)
        if self.kind in ("int", "library_slot"):
            try:
                number = float(value)  # type: ignore[arg-type]  # any value: what float() refuses is refused
            except (TypeError, ValueError):
                raise OptionError(_("{option}: {value} is not a whole number.").format(
                    option=label, value=repr(value))) from None
            if not math.isfinite(number) or number != int(number):
                raise OptionError(_("{option}: {value} is not a whole number.").format(option=label, value=repr(value)))
            n = int(number)
            lo = 1 if self.kind == "library_slot" else self.minimum
            hi = self.maximum
            if (lo is not None and n < lo) or (hi is not None and n > hi):
                raise OptionError(_("{option}: {n} is out of range {low}..{high}.").format(
                    option=label, n=n, low=lo, high=hi))
            return n
        if self.kind == "choice":
            values = [v for v, _choice in self.choices]
            if value not in values:
                raise OptionError(_("{option}: {value} is not one of {values}.").format(
                    option=label, value=repr(value), values=values))
            return value
        if not isinstance(value, str) or not value:
            raise OptionError(_("{option}: give the key of a physical tool, got {value}.").format(
                option=label, value=repr(value)))
        return value


class StartContext(Protocol):
    """What a wizard class may read when it is started (the workflow provides it)."""

    @property
    def tools(self) -> Mapping[str, ToolModel]:
        """Physical tools (``ToolModel``) by key."""

    @property
    def mounted_tool(self) -> ToolModel:
        """The physical tool on the flange now (``ToolModel``)."""

    def library_tool(self, slot: int) -> "Tool":
        """The library's tool in ``slot`` (a ``WizardError`` when empty)."""


@dataclass(frozen=True)
class WizardStart:
    """What starting a wizard produced.

    Attributes:
        wizard: the new wizard.
        true_tool: the physical tool (``ToolModel``) whose hidden true frame grades the result
            (None: no grading).
        active_data: (tool, slot) of library tool data made active at start (the steps jog
            with it), or None.
    """

    wizard: "Wizard"
    true_tool: "ToolModel | None" = None
    active_data: "tuple[Tool, int] | None" = None
