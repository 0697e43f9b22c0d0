"""ABB "TCP & Z, X" wizard (methods.md section 8): the TCP and the TOOL frame in one wizard.

Steps: N >= 4 touches of the reference tip from clearly different orientations (as the XYZ
4-point), then one pose with the reference tip on the tool's **+Z** axis ahead of the TCP (from
the last touch, keep the orientation and back off straight along the tool's Z), then one with it
on the tool's **+X** axis. All math is ``tcpcal.tcp_zx.solve_tcp_zx`` (roles touch, z, x); the
live pose-diversity meter on the touches is tcpcal's ``candidate_gain``. Poses come in metres
and go to tcpcal in millimetres, so every figure is in mm (angles in degrees).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import ClassVar

import numpy as np
import numpy.typing as npt

from tcpcal.pose_quality import CandidateGain, candidate_gain
from tcpcal.tcp_zx import solve_tcp_zx
from tcpcal.tool import Tool

from tcp_pendant.json_shapes import JsonRecord
from tcp_pendant.translation import N_
from tcp_pendant.wizards.base import (
    StartContext,
    StepSpec,
    Wizard,
    WizardError,
    WizardResult,
    check_pose_m,
    mm3,
)
from tcp_pendant.wizards.solver_words import solver_warnings
from tcp_pendant.wizards.describe import (
    AHEAD_PLUS_X,
    AHEAD_PLUS_Z,
    TOUCH,
    StepRole,
    WizardOption,
    WizardStart,
)
from tcp_pendant.wizards.xyz4 import RESIDUAL_CAVEAT, outlier_warning

__all__ = ["MIN_AXIS_DISTANCE_MM", "TcpZxWizard"]

MIN_AXIS_DISTANCE_MM = 20.0
"""z / x distances shorter than this give a warning (the angular error grows as they shrink)."""


class TcpZxWizard(Wizard):
    """TCP & Z, X: N touches give the TCP; a pose on the tool's +Z axis and one on its +X axis
    give the orientation (Z defines, X completes, as ABB).

    Args:
        n_points: number of touch steps (4..20).
        assumed_sigma_mm: operator jogging error assumed by the pose-diversity meter (mm).
    """

    kind: ClassVar[str] = "tcp-zx"
    title: ClassVar[str] = N_("TCP & Z, X (ABB)")
    blurb: ClassVar[str] = N_("Calibrates the **TCP and the orientation** (X, Y, Z, A, B, C) in one go, as "
                            "ABB's TCP & Z, X: 4 to 20 touches, then the reference tip on the tool's +Z "
                            "axis ahead of the TCP, then on its +X axis.")
    calibrates: ClassVar[str] = N_("the TCP and the orientation")
    rank: ClassVar[int] = 30
    math_view: ClassVar[str | None] = "tcp_zx"
    MIN_POINTS: ClassVar[int] = 4
    MAX_POINTS: ClassVar[int] = 20
    step_roles = (
        StepRole("touch", N_("the tool tip on the reference tip"), TOUCH),
        StepRole("z", N_("the reference tip on the tool's +Z axis, ahead of the TCP"), AHEAD_PLUS_Z),
        StepRole("x", N_("the reference tip on the tool's +X axis, ahead of the TCP"), AHEAD_PLUS_X),
    )
    options = (WizardOption("n_points", N_("Touches"), "int", default=4, minimum=MIN_POINTS, maximum=MAX_POINTS,
                            hint=N_("Touches of the reference tip before the Z and X poses.")),)
    needs_tool = "mounted"
    diversity_meter = True

    def __init__(self, *, n_points: int = 4, assumed_sigma_mm: float = 0.5) -> None:
        super().__init__()
        if not self.MIN_POINTS <= int(n_points) <= self.MAX_POINTS:
            raise WizardError(f"n_points must be between {self.MIN_POINTS} and {self.MAX_POINTS}, got {n_points}.")
        if not (np.isfinite(assumed_sigma_mm) and assumed_sigma_mm > 0):
            raise WizardError(f"assumed_sigma_mm must be a positive number of mm, got {assumed_sigma_mm}.")
        self._n_points = int(n_points)
        self.assumed_sigma_mm = float(assumed_sigma_mm)

    @classmethod
    def start(cls, ctx: StartContext, options: JsonRecord) -> WizardStart:
        """For the mounted tool (its truth grades the TCP and the frame)."""
        return WizardStart(cls(n_points=options["n_points"]), true_tool=ctx.mounted_tool)

    @property
    def n_points(self) -> int:
        return self._n_points

    # ----- steps --------------------------------------------------------------------------
    def _step_specs(self) -> list[StepSpec]:
        _ = self._tr.gettext
        specs = []
        for i in range(self._n_points):
            text = (_("Jog the tool tip onto the reference tip, approaching from any direction; then "
                      "press Record.") if i == 0 else
                    _("Back off, tilt 45 to 60° about A, B or C (\"Reachable 45° tilts\" below names "
                      "those that work from here) and touch the reference tip again (touch 2); then "
                      "Record.") if i == 1 else
                    _("Back off, tilt 45 to 60° about another axis than for the earlier touches and touch "
                      "the reference tip again (touch {k}); then Record.").format(k=i + 1))
            specs.append(StepSpec(role="touch", title=_("Touch {k}").format(k=i + 1), instruction=text))
        specs.append(StepSpec(
            role="z", title=_("Reference on the tool's +Z axis"),
            instruction=_("From the last touch keep the orientation and back off straight along the "
                         "tool's Z axis (jog along tool -Z only, at least 20 mm, more is better), so "
                         "that the reference tip lies on the tool's +Z axis ahead of the TCP; then "
                         "press Record.")))
        specs.append(StepSpec(
            role="x", title=_("Reference on the tool's +X axis"),
            instruction=_("Go back to the touch and jog along tool -X only (at least 20 mm), so that "
                         "the reference tip lies on the tool's +X axis ahead of the TCP; then press "
                         "Record.")))
        return specs

    def _roles(self) -> list[str]:
        return [s.role for s in self._step_specs()]

    # ----- live pose-diversity meter (touch steps) ----------------------------------------
    def other_rotations(self) -> np.ndarray:
        """(N, 3, 3) ``R_world_flange`` of the recorded touches other than the current step's."""
        roles = self._roles()
        rots = [p.T_world_flange_m[:3, :3] for i, p in sorted(self._poses.items())
                if roles[i] == "touch" and (i != self._index or self.is_complete)]
        return np.array(rots, dtype=float).reshape(-1, 3, 3)

    def preview(self, T_world_flange_m: npt.ArrayLike, *, min_angle_deg: float = 15.0) -> CandidateGain:
        """Predicted TCP uncertainty (mm) if the current pose were recorded as a touch
        (``tcpcal.candidate_gain`` against the other touches, operator error ``assumed_sigma_mm``)."""
        T = check_pose_m(T_world_flange_m, what="candidate flange pose")
        return candidate_gain(self.other_rotations(), T[:3, :3], sigma=self.assumed_sigma_mm,
                              min_angle_deg=min_angle_deg)

    # ----- result -------------------------------------------------------------------------
    def _compute(self, poses: list[np.ndarray]) -> WizardResult:
        R = np.array([T[:3, :3] for T in poses])
        f_mm = np.array([T[:3, 3] for T in poses]) * 1000.0      # metres -> mm for tcpcal
        res = solve_tcp_zx(R, f_mm, self._roles(), min_distance=MIN_AXIS_DISTANCE_MM)
        origin = res.origin
        warnings = solver_warnings(res.warnings, tr=self._tr)
        if origin.outliers:
            warnings.append(outlier_warning([res.touch_rows[i] + 1 for i in origin.outliers], "re-record",
                                            tr=self._tr))
        rot = np.asarray(res.rotation, dtype=float)
        return WizardResult(
            wizard=self.kind, method="tcp-zx", tcp_mm=mm3(res.tcp), abc_deg=mm3(res.kuka_abc_deg),
            rotation=rot, tcp_result=origin,
            per_touch_error_mm=tuple(float(e) for e in origin.residuals),
            mean_error_mm=float(origin.mean_error), max_error_mm=float(origin.max_error),
            rms_error_mm=float(origin.rms_error), ci95_mm=float(origin.ci95_radius),
            orthogonality_defect_deg=float(res.orthogonality_defect_deg),
            displacements_mm=tuple(float(d) for d in (*res.z_distances, *res.x_distances)),
            warnings=tuple(warnings), notes=(self._tr.gettext(RESIDUAL_CAVEAT),),
        )

    def to_tool(self, name: str) -> Tool:
        """The tool with the calibrated TCP and orientation."""
        res = self._require_result()
        assert res.abc_deg is not None
        return Tool(name=name, tcp_mm=res.tcp_mm, abc_deg=res.abc_deg,
                    calibration=self._calibration(res, res.figures))

    # ----- serialisation ------------------------------------------------------------------
    def _params(self) -> dict[str, object]:
        return {"n_points": self._n_points, "assumed_sigma_mm": self.assumed_sigma_mm}

    @classmethod
    def _from_params(cls, params: JsonRecord) -> "TcpZxWizard":
        return cls(n_points=int(params.get("n_points", 4)),
                   assumed_sigma_mm=float(params.get("assumed_sigma_mm", 0.5)))
