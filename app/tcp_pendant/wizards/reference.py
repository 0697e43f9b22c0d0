"""XYZ reference wizard (methods.md section 3): one touch with a calibrated tool, one with the new.

Math: ``tcpcal.origin.solve_reference`` (REF-1), ``t_2 = R_2^T (r - f_2)`` with
``r = R_1 t_1 + f_1``. Poses come in metres and go to tcpcal in mm.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import ClassVar

import numpy as np

from tcpcal.origin import solve_reference
from tcpcal.tool import Tool

from tcp_pendant.json_shapes import JsonRecord
from tcp_pendant.translation import N_
from tcp_pendant.wizards.base import StartContext, StepSpec, Wizard, WizardError, WizardResult, mm3
from tcp_pendant.wizards.solver_words import solver_warnings
from tcp_pendant.wizards.describe import TOUCH, StepRole, WizardOption, WizardStart

ERRORS_ADD_UP = N_(
    "The reference method uses one touch per tool: the new TCP carries the error of both "
    "touches plus the reference tool's own calibration error. Check it, or use the 4-point "
    "method for a tool that matters."
)
"""Said in the result's warnings unless tcpcal already says that the errors add up."""


class ReferenceWizard(Wizard):
    """XYZ reference: touch a fixed tip with a calibrated tool, swap tools, touch it again.

    Args:
        reference_tool: calibrated tool data of the reference tool (from the library).
        reference_tool_key: physical tool (ToolModel key) that the reference data belongs to;
            the app mounts it for step 1 (None: whatever is mounted).
        new_tool_key: physical tool to calibrate; the app mounts it for step 2.
        new_tool_label: how the instructions call the new tool (default: its key).
        assumed_sigma_mm: operator touch error per axis assumed for the 95 % radius (one touch
            per tool leaves no residual to estimate it from); None: no radius.
    """

    kind: ClassVar[str] = "reference"
    title: ClassVar[str] = N_("XYZ reference")
    blurb: ClassVar[str] = N_("Calibrates the **TCP** of a new tool from one touch with an already calibrated "
                            "tool and one with the new tool. Fast; errors add up.")
    calibrates: ClassVar[str] = N_("the TCP of the new tool")
    rank: ClassVar[int] = 20
    math_view: ClassVar[str | None] = "reference"
    step_roles = (StepRole("touch", N_("the tool tip on the reference tip"), TOUCH),)
    options = (
        WizardOption("slot", N_("Tool data"), "library_slot",
                     hint=N_("A tool of the library whose TCP is calibrated.")),
        WizardOption("reference_tool_key", N_("Its physical tool"), "physical_tool", default="mounted",
                     hint=N_("The tool that the reference data belongs to: it is mounted for the first touch.")),
        WizardOption("new_tool_key", N_("New tool"), "physical_tool", default="other",
                     hint=N_("The tool to calibrate: it is mounted for the second touch.")),
    )
    needs_tool = "library"

    @classmethod
    def start(cls, ctx: StartContext, options: JsonRecord) -> WizardStart:
        """The reference tool's data from the library slot (made active: "mounted and active"
        for step 1); the new physical tool's truth grades the result."""
        ref = ctx.library_tool(options["slot"])
        for key in (options["reference_tool_key"], options["new_tool_key"]):
            if key not in ctx.tools:
                raise WizardError(f"Unknown physical tool {key!r}; choose one of {', '.join(ctx.tools)}.")
        new = ctx.tools[options["new_tool_key"]]
        wiz = cls(ref, reference_tool_key=options["reference_tool_key"], new_tool_key=options["new_tool_key"],
                  new_tool_label=f"the {new.label.lower()}")
        return WizardStart(wiz, true_tool=new, active_data=(ref, int(options["slot"])))

    def __init__(self, reference_tool: Tool, *, reference_tool_key: str | None = None,
                 new_tool_key: str | None = None, new_tool_label: str | None = None,
                 assumed_sigma_mm: float | None = 0.5) -> None:
        super().__init__()
        if assumed_sigma_mm is not None and not (np.isfinite(assumed_sigma_mm) and assumed_sigma_mm > 0):
            raise WizardError(f"assumed_sigma_mm must be a positive number of mm or None, got {assumed_sigma_mm}.")
        self.assumed_sigma_mm = None if assumed_sigma_mm is None else float(assumed_sigma_mm)
        if not isinstance(reference_tool, Tool):
            raise WizardError("Pick the calibrated reference tool from the tool library "
                              f"(a tcpcal Tool), got {type(reference_tool).__name__}.")
        if (reference_tool_key is not None and new_tool_key is not None
                and reference_tool_key == new_tool_key):
            raise WizardError("The reference tool and the new tool are the same physical tool; "
                              "pick the tool you want to calibrate as the new tool.")
        self.reference_tool = reference_tool
        self.reference_tool_key = reference_tool_key
        self.new_tool_key = new_tool_key
        self.new_tool_label = new_tool_label or new_tool_key or "the new tool"

    def _step_specs(self) -> list[StepSpec]:
        _ = self._tr.gettext
        ref = self.reference_tool.name
        return [
            StepSpec(role="touch", title=_("Touch with the reference tool"),
                     instruction=_("With the reference tool '{tool}' mounted and active, jog its tip "
                                   "onto the reference tip, from any direction; then press Record. "
                                   "Do not move the reference tip afterwards.").format(tool=ref),
                     mount_tool_key=self.reference_tool_key),
            StepSpec(role="touch", title=_("Touch with the new tool"),
                     instruction=_("Change the tool: mount {tool}. Jog its tip onto "
                                   "the same reference tip, from any direction; then press Record.").format(
                                       tool=self._new_tool_words()),
                     mount_tool_key=self.new_tool_key),
        ]

    def _new_tool_words(self) -> str:
        """The new tool as the instruction names it: its label (a name, not translated) after the
        article the start gave it ("the pointed tool"), in the wizard's language."""
        label = self.new_tool_label
        if label == "the new tool":
            return self._tr.gettext("the new tool")
        if label.startswith("the "):
            return self._tr.gettext("the {tool}").format(tool=label[4:])
        return label

    @property
    def tool_to_mount(self) -> str | None:
        """Physical tool key the current step needs mounted (the app swaps the tool model)."""
        return self.step.mount_tool_key

    def _compute(self, poses: list[np.ndarray]) -> WizardResult:
        T1, T2 = poses
        res = solve_reference(np.asarray(self.reference_tool.tcp_mm, dtype=float),
                              T1[:3, :3], T1[:3, 3] * 1000.0,   # metres -> mm for tcpcal
                              T2[:3, :3], T2[:3, 3] * 1000.0, sigma=self.assumed_sigma_mm)
        warnings = solver_warnings(res.warnings, tr=self._tr)
        _ = self._tr.gettext
        if not any("sum of" in w or "add up" in w for w in res.warnings):
            warnings.append(_(ERRORS_ADD_UP))
        cal = self.reference_tool.calibration
        if cal is None:
            warnings.append(_("The reference tool '{tool}' has no calibration "
                              "record: its TCP may never have been measured.").format(tool=self.reference_tool.name))
        elif "ci95_mm" in cal.figures:
            warnings.append(_("The reference tool's own TCP is uncertain by about "
                              "{ci95} mm (95 %); the new TCP inherits it.").format(
                                  ci95=f"{float(cal.figures['ci95_mm']):.2f}"))
        return WizardResult(
            wizard=self.kind, method="reference", tcp_mm=mm3(res.tcp), tcp_result=res,
            per_touch_error_mm=tuple(float(e) for e in res.residuals),
            mean_error_mm=float(res.mean_error), max_error_mm=float(res.max_error),
            rms_error_mm=float(res.rms_error),
            ci95_mm=float(res.ci95_radius) if np.isfinite(res.ci95_radius) else None,
            warnings=tuple(warnings),
            notes=(() if self.assumed_sigma_mm is None else
                   (_("The 95 % radius is predicted from an assumed touch error of "
                      "{sigma} mm per axis, not measured.").format(sigma=f"{self.assumed_sigma_mm:g}"),)),
        )

    def to_tool(self, name: str) -> Tool:
        """The new tool with the TCP from (REF-1); orientation A = B = C = 0 (not calibrated)."""
        res = self._require_result()
        return Tool(name=name, tcp_mm=res.tcp_mm, calibration=self._calibration(res, res.figures))

    def _params(self) -> dict[str, object]:
        return {"reference_tool": self.reference_tool.to_dict(),
                "reference_tool_key": self.reference_tool_key,
                "new_tool_key": self.new_tool_key, "new_tool_label": self.new_tool_label,
                "assumed_sigma_mm": self.assumed_sigma_mm}

    @classmethod
    def _from_params(cls, params: JsonRecord) -> "ReferenceWizard":
        return cls(Tool.from_dict(params["reference_tool"]),
                   reference_tool_key=params.get("reference_tool_key"),
                   new_tool_key=params.get("new_tool_key"),
                   new_tool_label=params.get("new_tool_label"),
                   assumed_sigma_mm=params.get("assumed_sigma_mm", 0.5))
