"""Three-point orientation wizard (methods.md section 5, paper eqs. 7-30), variants 1 and 2.

Requires a tool whose TCP is already calibrated. Math: ``tcpcal.orientation.solve_three_point``
(rows: touch, tip on tool -X axis, tip on +Y axis / in the +Y half of the XY plane). Poses come
in metres and go to tcpcal in mm, so displacement lengths are in mm.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import ClassVar, Literal

import numpy as np

from tcpcal.orientation import solve_three_point
from tcpcal.tool import Tool

from tcp_pendant.json_shapes import JsonRecord
from tcp_pendant.translation import N_
from tcp_pendant.wizards.base import (
    StepSpec,
    Wizard,
    WizardError,
    WizardResult,
    WizardStateError,
    mm3,
)
from tcp_pendant.wizards.solver_words import solver_warnings
from tcp_pendant.wizards.describe import (
    IN_PLUS_Y_HALF,
    ON_MINUS_X,
    ON_PLUS_Y,
    TOUCH_KEEP_ORIENTATION,
    StartContext,
    StepRole,
    WizardOption,
    WizardStart,
)

MIN_DISPLACEMENT_MM = 20.0
"""Displacements shorter than this give a poor orientation; the wizard warns."""


class ThreePointWizard(Wizard):
    """Three-point orientation: touch, tip on the tool's -X axis, tip on +Y axis or +Y half-plane.

    Args:
        tool: the tool from the library whose TCP (``tcp_mm``) is calibrated; its TCP is used
            as is and kept by ``to_tool``.
        variant: 1 (step 3: tip on the +Y axis) or 2 (tip anywhere in the +Y half of the tool XY
            plane); can be changed with ``set_variant``.
    """

    kind: ClassVar[str] = "three-point"
    title: ClassVar[str] = N_("Three-point orientation")
    blurb: ClassVar[str] = N_("Calibrates the **orientation** (A, B, C) of a tool whose TCP is calibrated: "
                            "a touch, then the tip on the tool's -X axis and on its +Y side.")
    calibrates: ClassVar[str] = N_("the orientation")
    rank: ClassVar[int] = 40
    math_view: ClassVar[str | None] = "three_point"
    step_roles = (
        StepRole("touch", N_("the tool tip on the reference tip"), TOUCH_KEEP_ORIENTATION),
        StepRole("minus_x", N_("the reference tip on the tool's -X axis"), ON_MINUS_X),
        StepRole("plus_y", N_("the reference tip on the tool's +Y axis"), ON_PLUS_Y),
        StepRole("plus_y_half", N_("the reference tip in the +Y half of the tool XY plane"), IN_PLUS_Y_HALF),
    )
    options = (WizardOption("slot", N_("Tool data"), "library_slot",
                            hint=N_("A tool of the library whose TCP is calibrated.")),)
    variants = ((1, N_("Variant 1: tip on the +Y axis")), (2, N_("Variant 2: tip in the +Y half-plane")))
    needs_tool = "library"

    @classmethod
    def start(cls, ctx: StartContext, options: JsonRecord) -> WizardStart:
        """For the library tool in ``slot`` (its TCP must be calibrated); its data is made
        active so jogs along tool X/Y use it."""
        tool = ctx.library_tool(options["slot"])
        return WizardStart(cls(tool, variant=options.get("variant", 1)), true_tool=ctx.mounted_tool,
                           active_data=(tool, int(options["slot"])))

    @property
    def library_tool_name(self) -> str | None:
        return self.tool.name

    def __init__(self, tool: Tool, *, variant: Literal[1, 2] = 1) -> None:
        super().__init__()
        if not isinstance(tool, Tool):
            raise WizardError("Pick a tool with a calibrated TCP from the tool library "
                              f"(a tcpcal Tool), got {type(tool).__name__}.")
        self._check_variant(variant)
        self.tool = tool
        self._variant: Literal[1, 2] = variant

    @staticmethod
    def _check_variant(variant: object) -> Literal[1, 2]:
        if variant == 1:
            return 1
        if variant == 2:
            return 2
        raise WizardError(f"The three-point variant is 1 or 2, got {variant!r}.")

    @property
    def variant(self) -> Literal[1, 2]:
        return self._variant

    def set_variant(self, variant: int | str) -> None:
        """Choose variant 1 or 2. A step-3 pose recorded for variant 2 is dropped when switching
        to variant 1 (a point in the half-plane is not on the +Y axis); a finished wizard reopens."""
        variant = self._check_variant(variant)
        if self.status == "cancelled":
            raise self._cancelled_refusal()
        if variant == self._variant:
            return
        if self._variant == 2 and variant == 1:
            self._poses.pop(2, None)
        self._variant = variant
        if self.is_complete:
            self._status = "in_progress"
            self._result = None

    def _step_specs(self) -> list[StepSpec]:
        _ = self._tr.gettext
        name = self.tool.name
        step3 = (StepSpec(role="plus_y", title=_("Tip on the tool's +Y axis"),
                          instruction=_("Go back to the touch, then jog along tool -Y (at least 20 mm, "
                                       "more is better) so that the reference tip lies on the tool's "
                                       "positive Y axis; then press Record."))
                 if self._variant == 1 else
                 StepSpec(role="plus_y_half", title=_("Tip in the tool's +Y half-plane"),
                          instruction=_("Jog in the tool's XY plane (no tool Z motion) so that the "
                                       "reference tip lies on the +Y side of the tool X axis, at "
                                       "least 20 mm from it; then press Record.")))
        return [
            StepSpec(role="touch", title=_("Touch the reference tip"),
                     instruction=_("With '{tool}' active, jog its TCP onto the reference tip from "
                                   "a comfortable orientation; then press Record. Keep this "
                                   "orientation for the next steps.").format(tool=name),),
            StepSpec(role="minus_x", title=_("Tip on the tool's -X axis"),
                     instruction=_("Jog along tool +X only (at least 20 mm, more is better) so that "
                                  "the reference tip lies on the tool's negative X axis; then press "
                                  "Record.")),
            step3,
        ]

    def _compute(self, poses: list[np.ndarray]) -> WizardResult:
        R = np.array([T[:3, :3] for T in poses])
        f_mm = np.array([T[:3, 3] for T in poses]) * 1000.0   # metres -> mm for tcpcal
        tcp = np.asarray(self.tool.tcp_mm, dtype=float)
        # tcpcal warns about every displacement shorter than MIN_DISPLACEMENT_MM (mm here).
        res = solve_three_point(R, f_mm, tcp, variant=self._variant,
                                min_displacement=MIN_DISPLACEMENT_MM)
        warnings = solver_warnings(res.warnings, tr=self._tr)
        if self.tool.calibration is None:
            warnings.append(self._tr.gettext("The TCP of '{tool}' has no calibration record; the "
                                             "orientation is only as good as that TCP.").format(tool=self.tool.name))
        rot = np.asarray(res.rotation, dtype=float)
        return WizardResult(
            wizard=self.kind, method=f"three-point-{self._variant}", tcp_mm=mm3(tcp),
            abc_deg=mm3(res.kuka_abc_deg), rotation=rot, orientation_result=res,
            orthogonality_defect_deg=float(res.orthogonality_defect_deg),
            displacements_mm=tuple(float(d) for d in res.displacements),
            warnings=tuple(warnings),
        )

    def to_tool(self, name: str) -> Tool:
        """The tool with its TCP unchanged and the calibrated orientation; the TCP's own figures
        are kept with a ``tcp_`` prefix."""
        res = self._require_result()
        figures = dict(res.figures)
        if self.tool.calibration is not None:
            for k, v in self.tool.calibration.figures.items():
                figures.setdefault(f"tcp_{k}" if not k.startswith("tcp_") else k, float(v))
        assert res.abc_deg is not None
        return Tool(name=name, tcp_mm=res.tcp_mm, abc_deg=res.abc_deg, notes=self.tool.notes,
                    **self.tool.load_fields(), calibration=self._calibration(res, figures))

    def _params(self) -> dict[str, object]:
        return {"tool": self.tool.to_dict(), "variant": self._variant}

    @classmethod
    def _from_params(cls, params: JsonRecord) -> "ThreePointWizard":
        return cls(Tool.from_dict(params["tool"]), variant=int(params.get("variant", 1)))  # type: ignore[arg-type]
