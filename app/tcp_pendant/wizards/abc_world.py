"""ABC world (parallel axes) wizard (methods.md section 4, paper eqs. 4-6), 6D and 5D variants.

The operator jogs until the tool axes are parallel to WORLD as prescribed by (PA-1): tool X
along WORLD -Z (down), tool Y along WORLD +Y, tool Z along WORLD +X; then one flange pose gives
``R_flange_tool`` by (PA-2), computed by ``tcpcal.orientation.solve_abc_world``. The 5D variant
fixes only tool X; the rotation about it is kept from the tool's current data.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import ClassVar, Literal

import numpy as np
import numpy.typing as npt

from tcpcal.orientation import R_WORLD_TOOL_PARALLEL, solve_abc_world
from tcpcal.tool import Tool

from tcp_pendant.json_shapes import JsonRecord
from tcp_pendant.translation import N_
from tcp_pendant.wizards.base import (
    StepSpec,
    Wizard,
    WizardError,
    WizardResult,
    check_pose_m,
    StepInfo,
    mm3,
)
from tcp_pendant.wizards.solver_words import solver_warnings
from tcp_pendant.wizards.describe import (
    ALIGN_WORLD,
    AutoRole,
    StartContext,
    StepRole,
    WizardOption,
    WizardStart,
)

R_WORLD_TOOL_TARGET: np.ndarray = R_WORLD_TOOL_PARALLEL
"""(PA-1): the prescribed tool orientation in WORLD (columns: tool X, Y, Z in WORLD), tcpcal's."""


class AbcWorldWizard(Wizard):
    """ABC world: align the tool with WORLD as prescribed, record once.

    Args:
        tool: the tool from the library (its TCP is kept; for 5D its current orientation gives
            the rotation about tool X).
        variant: "6d" (all three axes aligned) or "5d" (only tool X, pointing down).
    """

    kind: ClassVar[str] = "abc-world"
    title: ClassVar[str] = N_("ABC world (parallel axes)")
    blurb: ClassVar[str] = N_("Calibrates the **orientation** (A, B, C): align the tool with WORLD (X down, Y "
                            "along WORLD Y, Z along WORLD X) and record once. 5D: tool X only.")
    calibrates: ClassVar[str] = N_("the orientation")
    rank: ClassVar[int] = 50
    math_view: ClassVar[str | None] = "abc_world"
    step_roles = (StepRole("parallel", N_("the tool axes parallel to WORLD as (PA-1) prescribes"), ALIGN_WORLD),)
    options = (WizardOption("slot", N_("Tool data"), "library_slot",
                            hint=N_("A tool of the library whose TCP is calibrated.")),)
    variants = (("6d", N_("6D: X down, Y along WORLD Y")), ("5d", N_("5D: tool X down only")))
    needs_tool = "library"

    @classmethod
    def start(cls, ctx: StartContext, options: JsonRecord) -> WizardStart:
        """For the library tool in ``slot``; its data is made active so rotations A, B, C turn
        about its TCP."""
        tool = ctx.library_tool(options["slot"])
        return WizardStart(cls(tool, variant=options.get("variant", "6d")), true_tool=ctx.mounted_tool,
                           active_data=(tool, int(options["slot"])))

    def auto_role(self, step: StepInfo) -> AutoRole:
        """5D: only tool X is prescribed, so auto-touch turns the tool about X at random."""
        role = super().auto_role(step)
        return replace(role, free_turn_about_x=True) if self._variant == "5d" else role

    @property
    def library_tool_name(self) -> str | None:
        return self.tool.name

    def scene_target_T_world_tool_m(self, T_world_flange_m: np.ndarray) -> np.ndarray | None:
        """The (PA-1) target triad while the wizard is in progress."""
        return self.target_T_world_tool_m(T_world_flange_m) if self.status == "in_progress" else None

    def __init__(self, tool: Tool, *, variant: Literal["6d", "5d"] = "6d") -> None:
        super().__init__()
        if not isinstance(tool, Tool):
            raise WizardError("Pick the tool to orient from the tool library (a tcpcal Tool), "
                              f"got {type(tool).__name__}.")
        self._check_variant(variant)
        self.tool = tool
        self._variant: Literal["6d", "5d"] = variant

    @staticmethod
    def _check_variant(variant: object) -> Literal["6d", "5d"]:
        if variant == "6d":
            return "6d"
        if variant == "5d":
            return "5d"
        raise WizardError(f"The ABC world variant is '6d' or '5d', got {variant!r}.")

    @property
    def variant(self) -> Literal["6d", "5d"]:
        return self._variant

    def set_variant(self, variant: int | str) -> None:
        """Choose 6D or 5D; the recorded pose is valid for both; a finished wizard is recomputed."""
        variant = self._check_variant(variant)
        self._variant = variant
        if self.is_complete:
            self.finish()

    def _step_specs(self) -> list[StepSpec]:
        _ = self._tr.gettext
        if self._variant == "6d":
            text = _("Jog (rotations A, B, C in WORLD) until the tool's working direction (tool X) "
                    "points straight down, tool Y along WORLD +Y and tool Z along WORLD +X, as the "
                    "target triad shows; then press Record.")
        else:
            text = _("Jog (rotations in WORLD) until the tool's working direction (tool X) points "
                    "straight down, along WORLD -Z, as the target triad shows; the rotation about "
                    "it does not matter. Then press Record.")
        return [StepSpec(role="parallel", title=_("Align the tool with WORLD"), instruction=text)]

    def target_T_world_tool_m(self, T_world_flange_m: npt.ArrayLike) -> np.ndarray:
        """Pose of the target triad for the scene (4x4, metres): the prescribed orientation
        (PA-1) placed at the tool's TCP as currently believed (``tool.tcp_mm``)."""
        T = check_pose_m(T_world_flange_m)
        out = np.eye(4)
        out[:3, :3] = R_WORLD_TOOL_TARGET
        out[:3, 3] = T[:3, :3] @ (np.asarray(self.tool.tcp_mm, dtype=float) / 1000.0) + T[:3, 3]
        return out

    def _compute(self, poses: list[np.ndarray]) -> WizardResult:
        (T,) = poses
        res = solve_abc_world(T[:3, :3], variant=self._variant,
                              current_rotation=self.tool.rotation if self._variant == "5d" else None)
        rot = np.asarray(res.rotation, dtype=float)
        warnings = solver_warnings(res.warnings, tr=self._tr)
        if self._variant == "5d":
            warnings.append(self._tr.gettext("5D: only the tool X direction was calibrated; the rotation "
                                             "about X is kept from '{tool}'.").format(tool=self.tool.name))
        return WizardResult(
            wizard=self.kind, method=f"abc-world-{self._variant}",
            tcp_mm=mm3(self.tool.tcp_mm), abc_deg=mm3(res.kuka_abc_deg), rotation=rot,
            orientation_result=res,
            orthogonality_defect_deg=float(res.orthogonality_defect_deg),
            displacements_mm=tuple(float(d) for d in res.displacements),
            warnings=tuple(warnings),
        )

    def to_tool(self, name: str) -> Tool:
        """The tool with its TCP unchanged and the calibrated orientation (TCP figures kept with
        a ``tcp_`` prefix)."""
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
    def _from_params(cls, params: JsonRecord) -> "AbcWorldWizard":
        return cls(Tool.from_dict(params["tool"]), variant=params.get("variant", "6d"))
