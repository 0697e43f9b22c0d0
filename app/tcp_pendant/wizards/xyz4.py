"""XYZ 4-point wizard (methods.md section 2): touch one reference tip from N >= 4 orientations.

All calibration math is ``tcpcal.origin.solve_xyz4`` ((4P-1) to (4P-3)) and, for the live
pose-diversity meter, ``tcpcal.pose_quality.candidate_gain`` / ``assess_touches``. Poses come
in metres and are handed to tcpcal in millimetres, so every figure of the result is in mm.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import ClassVar, Literal, TypedDict

import numpy as np
import numpy.typing as npt

from tcpcal.errors import TcpcalError
from tcpcal.origin import TcpResult, solve_xyz4
from tcpcal.pose_quality import CandidateGain, PoseQuality, assess_touches, candidate_gain
from tcpcal.tool import Tool

from tcp_pendant.json_shapes import JsonRecord
from tcp_pendant.translation import N_, Translator
from tcp_pendant.wizards.base import (
    StartContext,
    StepSpec,
    Wizard,
    WizardError,
    WizardResult,
    WizardStateError,
    check_pose_m,
    mm3,
    rotation_and_position_mm,
)
from tcp_pendant.wizards.solver_words import solver_warning, solver_warnings
from tcp_pendant.wizards.describe import TOUCH, StepRole, WizardOption, WizardStart

Estimator = Literal["lstsq", "sphere", "pairwise"]
ESTIMATORS: tuple[Estimator, ...] = ("lstsq", "sphere", "pairwise")
ESTIMATOR_LABELS: dict[Estimator, str] = {
    "lstsq": N_("joint least squares (default)"),
    "sphere": N_("best-fit sphere"),
    "pairwise": N_("pairwise differences"),
}
"""The estimators in words for the trainee's Calibrate tab (English msgids: the views show
``tr.gettext(label)``); their equations, (4P-3), (4P-1a) and
(4P-2) of methods.md, are shown in "The math" (``calibrate.math_view``)."""

RESIDUAL_CAVEAT = N_(
    "A small residual does not prove an accurate TCP: systematic errors (a bent tip, a "
    "reference that moved, a wrong robot model) hide in it. Check the TCP by rotating about it."
)
"""A result's standing note (an English msgid; the wizards add it as ``tr.gettext(RESIDUAL_CAVEAT)``)."""


def outlier_warning(touches: list[int], advice: str, *, tr: Translator) -> str:
    """The words that ``touches`` (1-based numbers) stand out from the others as outliers;
    ``advice`` "drop" (recompute without them) or "re-record"."""
    listed = ", ".join(str(n) for n in touches)
    if advice == "drop":
        return tr.ngettext(
            "Touch {touches} stands out from the others (outlier): drop it to recompute without it.",
            "Touches {touches} stand out from the others (outliers): drop them to recompute without them.",
            len(touches)).format(touches=listed)
    return tr.ngettext("Touch {touches} stands out from the others (outlier): re-record it.",
                       "Touches {touches} stand out from the others (outliers): re-record them.",
                       len(touches)).format(touches=listed)


class EstimatorRow(TypedDict, total=False):
    """One estimator's line of :meth:`Xyz4Result.comparison_rows` (figures in mm): ``error``
    when it could not solve (``ok`` false), the figures when it could."""

    estimator: str
    label: str
    ok: bool
    error: str
    tcp_mm: tuple[float, float, float]
    mean_error_mm: float
    max_error_mm: float
    rms_error_mm: float
    ci95_mm: float
    chosen: bool


@dataclass(frozen=True, eq=False, kw_only=True)
class Xyz4Result(WizardResult):
    """Result of the XYZ 4-point wizard. Lengths in mm, directions unit vectors in WORLD.

    Attributes:
        estimator: the estimator of ``tcp_mm`` ("lstsq" | "sphere" | "pairwise").
        used_indices: 0-based indices of the recorded touches used (all but the excluded).
        excluded: touches the user dropped.
        outliers: touches tcpcal flags as outliers, as 0-based indices of the *recorded*
            touches (not of the used subset).
        sphere_centre_mm: fitted reference point ``r`` in WORLD (the sphere's centre).
        sphere_radius_mm: ``|t|``, distance flange origin to TCP (the sphere's radius).
        flange_positions_mm: (N,3) flange origins ``f_i`` in WORLD of every recorded touch.
        approach_directions_world: (N,3) tool direction at each touch in WORLD: the unit
            vector from the flange origin towards the computed TCP, ``R_i t / |t|``.
        estimators: the tcpcal result of each estimator on the same touches (side by side).
        estimator_errors: estimator -> tcpcal's message, for those that could not solve.
    """

    estimator: Estimator
    used_indices: tuple[int, ...]
    excluded: tuple[int, ...]
    outliers: tuple[int, ...]
    sphere_centre_mm: tuple[float, float, float]
    sphere_radius_mm: float
    flange_positions_mm: np.ndarray
    approach_directions_world: np.ndarray
    estimators: Mapping[str, TcpResult] = field(default_factory=dict)
    estimator_errors: Mapping[str, str] = field(default_factory=dict)

    def comparison_rows(self) -> list[EstimatorRow]:
        """One row per estimator for the side-by-side table (mm), in ``ESTIMATORS`` order."""
        rows: list[EstimatorRow] = []
        for name in ESTIMATORS:
            res = self.estimators.get(name)
            if res is None:
                rows.append({"estimator": name, "label": ESTIMATOR_LABELS[name], "ok": False,
                             "error": self.estimator_errors.get(name, "not computed")})
                continue
            rows.append({
                "estimator": name, "label": ESTIMATOR_LABELS[name], "ok": True,
                "tcp_mm": mm3(res.tcp), "mean_error_mm": float(res.mean_error),
                "max_error_mm": float(res.max_error), "rms_error_mm": float(res.rms_error),
                "ci95_mm": float(res.ci95_radius), "chosen": name == self.estimator,
            })
        return rows


class Xyz4Wizard(Wizard):
    """XYZ 4-point: touch the reference tip with the tool tip from N clearly different orientations.

    Args:
        n_points: number of touch steps to start with (4..20); "Add point" adds more.
        estimator: tcpcal estimator of the reported TCP ("lstsq" is the default and the best).
        assumed_sigma_mm: operator jogging error assumed by the pose-diversity meter.
        base_tool: when re-calibrating an existing tool, its orientation (A, B, C) is kept by
            ``to_tool``; otherwise A = B = C = 0.
    """

    kind: ClassVar[str] = "xyz4"
    title: ClassVar[str] = N_("XYZ 4-point")
    blurb: ClassVar[str] = N_("Calibrates the **TCP** (X, Y, Z): touch the reference tip with the tool tip "
                            "from 4 to 20 clearly different orientations.")
    calibrates: ClassVar[str] = N_("the TCP")
    rank: ClassVar[int] = 10
    result_extras: ClassVar[frozenset[str]] = frozenset({"estimators", "sphere"})
    math_view: ClassVar[str | None] = "xyz4"
    MIN_POINTS: ClassVar[int] = 4
    MAX_POINTS: ClassVar[int] = 20
    step_roles = (StepRole("touch", N_("the tool tip on the reference tip"), TOUCH),)
    options = (
        WizardOption("n_points", N_("Touches"), "int", default=4, minimum=MIN_POINTS, maximum=MAX_POINTS,
                     hint=N_("Touches to start with; Add point adds more (up to 20).")),
        WizardOption("estimator", N_("Estimator"), "choice", default="lstsq",
                     choices=tuple(ESTIMATOR_LABELS.items())),
    )
    needs_tool = "mounted"
    supports_add_point = True
    diversity_meter = True

    @classmethod
    def start(cls, ctx: StartContext, options: JsonRecord) -> WizardStart:
        """A 4-point wizard for the mounted tool (its truth grades the result)."""
        return WizardStart(cls(n_points=options["n_points"], estimator=options["estimator"]),
                           true_tool=ctx.mounted_tool)

    def __init__(self, *, n_points: int = 4, estimator: Estimator = "lstsq",
                 assumed_sigma_mm: float = 0.5, base_tool: Tool | None = None) -> None:
        super().__init__()
        if not self.MIN_POINTS <= int(n_points) <= self.MAX_POINTS:
            raise WizardError(f"n_points must be between {self.MIN_POINTS} and {self.MAX_POINTS}, got {n_points}.")
        if not (np.isfinite(assumed_sigma_mm) and assumed_sigma_mm > 0):
            raise WizardError(f"assumed_sigma_mm must be a positive number of mm, got {assumed_sigma_mm}.")
        self._check_estimator(estimator)
        self._n_points = int(n_points)
        self._estimator: Estimator = estimator
        self.assumed_sigma_mm = float(assumed_sigma_mm)
        self.base_tool = base_tool
        self._excluded: tuple[int, ...] = ()

    @staticmethod
    def _check_estimator(estimator: str) -> None:
        if estimator not in ESTIMATORS:
            raise WizardError(f"Unknown estimator {estimator!r}; choose one of {list(ESTIMATORS)}.")

    # ----- steps --------------------------------------------------------------------------
    def _step_specs(self) -> list[StepSpec]:
        _ = self._tr.gettext
        specs = []
        for i in range(self._n_points):
            if i == 0:
                text = _("Jog the tool tip onto the reference tip, approaching from any direction; "
                        "then press Record.")
            elif i == 1:
                text = _("Back off, tilt 45 to 60° about A, B or C (\"Reachable 45° tilts\" below names "
                        "those that work from here) and touch the reference tip again (touch 2); then "
                        "Record.")
            elif i == 2:
                text = _("Back off, tilt 45 to 60° about another axis than for touch 2 and touch the "
                        "reference tip again (touch 3); then Record.")
            elif i == 3:
                text = _("Back off and touch the reference tip from an orientation 45 to 60° away from all "
                        "three earlier ones, e.g. tilted the other way than touch 2 (touch 4); then Record.")
            else:
                text = _("Extra touch {k}: touch the reference tip from an orientation unlike "
                         "the earlier ones (watch the pose-diversity meter); then press Record.").format(k=i + 1)
            specs.append(StepSpec(role="touch", title=_("Touch {k}").format(k=i + 1), instruction=text))
        return specs

    @property
    def n_points(self) -> int:
        return self._n_points

    @property
    def can_add_point(self) -> bool:
        return self.status != "cancelled" and self._n_points < self.MAX_POINTS

    def add_point(self) -> None:
        """Add one touch step at the end (up to 20) and go to it (a finished wizard reopens)."""
        if not self.can_add_point:
            if self.status == "cancelled":
                raise self._cancelled_refusal()
            raise WizardStateError(self._tr.gettext("At most {n} touches.").format(n=self.MAX_POINTS))
        self._n_points += 1
        self._status = "in_progress"
        self._result = None
        self._index = self._n_points - 1 if all(i in self._poses for i in range(self._n_points - 1)) \
            else self._index

    def remove_point(self, index: int) -> None:
        """Delete touch ``index`` (0-based) and its step, keeping at least 4 steps."""
        _ = self._tr.gettext
        if self.status == "cancelled":
            raise self._cancelled_refusal()
        if self._n_points <= self.MIN_POINTS:
            raise WizardStateError(_("At least {n} touches are needed; re-record instead.").format(n=self.MIN_POINTS))
        if not 0 <= index < self._n_points:
            raise WizardStateError(_("There is no touch {k}.").format(k=index + 1))
        self._poses = {(i if i < index else i - 1): p for i, p in self._poses.items() if i != index}
        self._n_points -= 1
        self._excluded = ()
        self._status = "in_progress"
        self._result = None
        self._index = min(self._index, self._n_points - 1)

    # ----- estimator and outliers ---------------------------------------------------------
    @property
    def estimator(self) -> Estimator:
        return self._estimator

    def set_estimator(self, estimator: Estimator) -> WizardResult | None:
        """Choose the estimator of the reported TCP; a finished wizard is recomputed."""
        self._check_estimator(estimator)
        self._estimator = estimator
        return self.finish() if self.is_complete else None

    @property
    def excluded(self) -> tuple[int, ...]:
        """0-based indices of recorded touches left out of the computation."""
        return self._excluded

    def solver_touch_steps(self) -> tuple[int, ...]:
        """The touches tcpcal is given: every step but the ones dropped."""
        return tuple(i for i in range(self.n_steps) if i not in self._excluded)

    def set_excluded(self, indices: Iterable[int]) -> WizardResult | None:
        """Leave these touches out (0-based); recompute if finished. At least 4 must remain."""
        idx = tuple(sorted({int(i) for i in indices}))
        _ = self._tr.gettext
        if any(not 0 <= i < self._n_points for i in idx):
            raise WizardError(_("Touch indices {indices} out of range 0..{last}.").format(
                indices=list(idx), last=self._n_points - 1))
        if self._n_points - len(idx) < self.MIN_POINTS:
            raise WizardError(self._tr.ngettext(
                "Dropping {n} touch leaves fewer than {min}; add points first.",
                "Dropping {n} touches leaves fewer than {min}; add points first.", len(idx),
            ).format(n=len(idx), min=self.MIN_POINTS))
        old = self._excluded
        self._excluded = idx
        if self.is_complete:
            try:
                return self.finish()
            except WizardError:
                self._excluded = old
                self.finish()
                raise
        return None

    def drop_outliers(self) -> WizardResult:
        """Exclude the touches flagged as outliers in the current result and recompute."""
        res = self.result
        if not isinstance(res, Xyz4Result):
            raise WizardStateError(self._tr.gettext("Finish the wizard first."))
        if not res.outliers:
            raise WizardStateError(self._tr.gettext("No touch is flagged as an outlier."))
        out = self.set_excluded(set(self._excluded) | set(res.outliers))
        assert out is not None
        return out

    def restore_all(self) -> WizardResult | None:
        """Use every recorded touch again."""
        return self.set_excluded(())

    # ----- live pose-diversity meter ------------------------------------------------------
    def _other_rotations(self) -> np.ndarray:
        rots = [p.T_world_flange_m[:3, :3] for i, p in sorted(self._poses.items())
                if i != self._index or self.is_complete]
        return np.array(rots, dtype=float).reshape(-1, 3, 3)

    def other_rotations(self) -> np.ndarray:
        """(N, 3, 3) ``R_world_flange`` of the touches a recording now would keep (all but the
        current step's own): what :meth:`preview` compares the candidate with."""
        return self._other_rotations()

    def preview(self, T_world_flange_m: npt.ArrayLike, *, min_angle_deg: float = 15.0) -> CandidateGain:
        """Predicted TCP uncertainty if the current pose were recorded (tcpcal.candidate_gain).

        Compares the candidate flange orientation with the touches recorded so far (except the
        current step's own, which a new recording would replace), for an operator error of
        ``assumed_sigma_mm`` per axis. Figures in mm; ``too_close`` flags an orientation within
        ``min_angle_deg`` of an earlier one. Before the TCP is observable the predicted figures
        are inf and ``message`` says what is still needed.
        """
        T = check_pose_m(T_world_flange_m, what="candidate flange pose")
        others = self._other_rotations()
        return candidate_gain(others, T[:3, :3], sigma=self.assumed_sigma_mm,
                              min_angle_deg=min_angle_deg)

    def quality(self) -> PoseQuality:
        """tcpcal's verdict on the touches recorded so far (observable? predicted uncertainty)."""
        rots = np.array([p.T_world_flange_m[:3, :3] for _, p in sorted(self._poses.items())],
                        dtype=float).reshape(-1, 3, 3)
        return assess_touches(rots, sigma=self.assumed_sigma_mm)

    # ----- result -------------------------------------------------------------------------
    def _compute(self, poses: list[np.ndarray]) -> Xyz4Result:
        used = tuple(i for i in range(len(poses)) if i not in self._excluded)
        R_all = np.array([T[:3, :3] for T in poses])
        f_all_mm = np.array([T[:3, 3] for T in poses]) * 1000.0  # metres -> mm for tcpcal
        R, f = R_all[list(used)], f_all_mm[list(used)]
        chosen = solve_xyz4(R, f, method=self._estimator)   # TcpcalError propagates: no result
        estimators: dict[str, TcpResult] = {self._estimator: chosen}
        errors: dict[str, str] = {}
        for name in ESTIMATORS:
            if name == self._estimator:
                continue
            try:
                estimators[name] = solve_xyz4(R, f, method=name)
            except TcpcalError as exc:
                errors[name] = solver_warning(str(exc), tr=self._tr)
        t = np.asarray(chosen.tcp, dtype=float)
        radius = float(np.linalg.norm(t))
        directions = (R_all @ t) / radius if radius > 0 else np.zeros((len(poses), 3))
        outliers = tuple(used[i] for i in chosen.outliers)
        warnings = solver_warnings(chosen.warnings, tr=self._tr)
        if outliers:
            warnings.append(outlier_warning([i + 1 for i in outliers], "drop", tr=self._tr))
        if self._excluded:
            warnings.append(self._tr.ngettext(
                "Touch {touches} was dropped by you and is not used.",
                "Touches {touches} were dropped by you and are not used.", len(self._excluded),
            ).format(touches=", ".join(str(i + 1) for i in self._excluded)))
        return Xyz4Result(
            wizard=self.kind, method=f"xyz4-{self._estimator}", tcp_mm=mm3(t),
            tcp_result=chosen,
            per_touch_error_mm=tuple(float(e) for e in chosen.residuals),
            mean_error_mm=float(chosen.mean_error), max_error_mm=float(chosen.max_error),
            rms_error_mm=float(chosen.rms_error), ci95_mm=float(chosen.ci95_radius),
            warnings=tuple(warnings), notes=(self._tr.gettext(RESIDUAL_CAVEAT),),
            estimator=self._estimator, used_indices=used, excluded=self._excluded,
            outliers=outliers, sphere_centre_mm=mm3(chosen.reference), sphere_radius_mm=radius,
            flange_positions_mm=f_all_mm, approach_directions_world=directions,
            estimators=estimators, estimator_errors=errors,
        )

    def to_tool(self, name: str) -> Tool:
        """The tool with the calibrated TCP; orientation from ``base_tool`` (or A = B = C = 0)."""
        res = self._require_result()
        tool = Tool(name=name, tcp_mm=res.tcp_mm, calibration=self._calibration(res, res.figures))
        if self.base_tool is None:
            return tool
        a, b, c = (float(v) for v in self.base_tool.abc_deg)
        return replace(tool, abc_deg=(a, b, c), notes=self.base_tool.notes, **self.base_tool.load_fields())

    # ----- serialisation ------------------------------------------------------------------
    def _params(self) -> dict[str, object]:
        return {"n_points": self._n_points, "estimator": self._estimator,
                "assumed_sigma_mm": self.assumed_sigma_mm,
                "base_tool": None if self.base_tool is None else self.base_tool.to_dict(),
                "excluded": list(self._excluded)}

    @classmethod
    def _from_params(cls, params: JsonRecord) -> "Xyz4Wizard":
        base = params.get("base_tool")
        wiz = cls(n_points=int(params.get("n_points", 4)),
                  estimator=params.get("estimator", "lstsq"),
                  assumed_sigma_mm=float(params.get("assumed_sigma_mm", 0.5)),
                  base_tool=None if base is None else Tool.from_dict(base))
        wiz._excluded = tuple(int(i) for i in params.get("excluded", ()))
        return wiz
