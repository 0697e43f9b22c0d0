"""Training mode: compare a wizard result with the hidden true TOOL frame of the mounted tool.

The truth is ``ToolModel.T_flange_tool_true`` (4x4, metres, FLANGE -> true TOOL). Errors are
reported in mm and degrees:

- position error: ``|t_result - t_true|`` (mm), the TCP in FLANGE coordinates;
- orientation error: the angle of ``R_true^T R_result`` (deg, the geodesic distance between the
  two tool orientations, via ``scipy.spatial.transform.Rotation.magnitude``); for the methods
  that calibrate only the direction of tool X (``X_AXIS_METHODS``: the 5D ABC world variant and
  the automatic beam scan, which cannot see a turn about the tool's axis), the angle between the
  true and the computed tool X axes is the graded figure (``x_axis_error_deg``).

Verdict thresholds (``POSITION_THRESHOLDS_MM``, ``ORIENTATION_THRESHOLDS_DEG``):
good below 0.5 mm / 0.5 deg, fair below 2 mm / 2 deg, poor otherwise. Only what the wizard
calibrated is graded (position for the XYZ wizards, orientation for the orientation wizards,
both for TCP & Z, X, whose result has a TCP result and an orientation: the worse grade counts);
the other figure is still reported.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt
from scipy.spatial.transform import Rotation

from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.wizards.base import WizardError, WizardResult, check_pose_m

Grade = Literal["good", "fair", "poor"]
POSITION_THRESHOLDS_MM: tuple[float, float] = (0.5, 2.0)
ORIENTATION_THRESHOLDS_DEG: tuple[float, float] = (0.5, 2.0)
_ORDER: dict[Grade, int] = {"good": 0, "fair": 1, "poor": 2}


@dataclass(frozen=True, eq=False)
class TruthComparison:
    """A result against the true TOOL frame.

    Attributes:
        position_error_mm: ``|t_result - t_true|``.
        position_error_vector_mm: ``t_result - t_true`` in FLANGE, mm.
        orientation_error_deg: angle of ``R_true^T R_result``, None when the result has no
            orientation.
        x_axis_error_deg: angle between true and computed tool X (working direction), or None.
        inside_ci95: whether the position error is within the result's 95 % radius (None when
            the result has no 95 % radius).
        graded: which figures the grade is based on ("position", "orientation", "x_axis").
        grade: "good" | "fair" | "poor".
        verdict: short words in English (the record's), e.g. "good: position error 0.21 mm < 0.5 mm";
            :meth:`verdict_in` says them in a session's language.
    """

    position_error_mm: float
    position_error_vector_mm: tuple[float, float, float]
    orientation_error_deg: float | None
    x_axis_error_deg: float | None
    inside_ci95: bool | None
    graded: tuple[str, ...]
    grade: Grade
    verdict: str

    def verdict_in(self, tr: Translator) -> str:
        """:attr:`verdict` in ``tr``'s language (the same figures and grade)."""
        return _verdict(self.graded, self.position_error_mm, self.orientation_error_deg, self.x_axis_error_deg,
                        tr=tr)[1]

    def to_dict(self) -> dict[str, object]:
        return {"position_error_mm": self.position_error_mm,
                "position_error_vector_mm": list(self.position_error_vector_mm),
                "orientation_error_deg": self.orientation_error_deg,
                "x_axis_error_deg": self.x_axis_error_deg, "inside_ci95": self.inside_ci95,
                "graded": list(self.graded), "grade": self.grade, "verdict": self.verdict}


def _grade(value: float, thresholds: tuple[float, float]) -> Grade:
    return "good" if value < thresholds[0] else "fair" if value < thresholds[1] else "poor"


GRADE_WORDS: dict[str, str] = {"good": N_("good"), "fair": N_("fair"), "poor": N_("poor")}
"""The grades in words (English msgids; ``tr.gettext(GRADE_WORDS[grade])``)."""

_BELOW = {"position": N_("position error {value} mm < {limit} mm"),
          "x_axis": N_("tool X error {value} deg < {limit} deg"),
          "orientation": N_("orientation error {value} deg < {limit} deg")}
_NOT_BELOW = {"position": N_("position error {value} mm >= {limit} mm"),
              "x_axis": N_("tool X error {value} deg >= {limit} deg"),
              "orientation": N_("orientation error {value} deg >= {limit} deg")}


def _phrase(grade: Grade, figure: str, value: float, thresholds: tuple[float, float], tr: Translator) -> str:
    limit = thresholds[0] if grade == "good" else thresholds[1]
    words = _NOT_BELOW[figure] if grade == "poor" else _BELOW[figure]
    return tr.gettext(words).format(value=f"{value:.2f}", limit=f"{limit:g}")


def _verdict(graded: tuple[str, ...], pos_err: float, ori_err: float | None, x_err: float | None, *,
             tr: Translator = ENGLISH) -> tuple[Grade, str]:
    """The grade and the verdict of the ``graded`` figures (position mm, orientation and tool X deg)."""
    parts: list[tuple[Grade, str]] = []
    for figure in graded:
        value, thresholds = ((pos_err, POSITION_THRESHOLDS_MM) if figure == "position" else
                             (x_err if figure == "x_axis" else ori_err, ORIENTATION_THRESHOLDS_DEG))
        assert value is not None
        g = _grade(value, thresholds)
        parts.append((g, _phrase(g, figure, value, thresholds, tr)))
    grade = max((g for g, _ in parts), key=_ORDER.__getitem__)
    verdict = tr.gettext("{grade}: {errors}").format(grade=tr.gettext(GRADE_WORDS[grade]),
                                                      errors="; ".join(p for _, p in parts))
    if "position" not in graded:
        verdict = tr.gettext("{verdict} (TCP used is {mm} mm off the true one)").format(
            verdict=verdict, mm=f"{pos_err:.2f}")
    return grade, verdict


X_AXIS_METHODS: frozenset[str] = frozenset({"abc-world-5d", "beam"})
"""Methods whose orientation is only the direction of tool X (graded on ``x_axis_error_deg``)."""


NUMERICAL_NOISE_MM = 1e-6
"""Lengths below this are the solver's rounding, not a measurement (exact touches, sigma 0)."""


def compare_with_truth(result: WizardResult, T_flange_tool_true_m: npt.ArrayLike) -> TruthComparison:
    """Errors of ``result`` against the true TOOL frame (see the module docstring).

    Args:
        result: a finished wizard's result (mm, deg).
        T_flange_tool_true_m: (4,4) true FLANGE -> TOOL transform in metres.
    """
    if not isinstance(result, WizardResult):
        raise WizardError(f"compare_with_truth needs a wizard result, got {type(result).__name__}.")
    T_true = check_pose_m(T_flange_tool_true_m, what="true tool frame")
    t_true_mm = T_true[:3, 3] * 1000.0
    dvec = np.asarray(result.tcp_mm, dtype=float) - t_true_mm
    pos_err = float(np.linalg.norm(dvec))
    ori_err = x_err = None
    if result.rotation is not None:
        R_true = T_true[:3, :3]
        ori_err = float(np.degrees(Rotation.from_matrix(R_true.T @ result.rotation).magnitude()))
        a, b = R_true[:, 0], result.rotation[:, 0]  # atan2 form: accurate near 0 deg too
        x_err = float(np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b)), float(a @ b))))
    # within numerical noise (exact touches: a 95 % radius and an error of ~1e-12 mm) is inside
    inside = None if result.ci95_mm is None else bool(pos_err <= result.ci95_mm + NUMERICAL_NOISE_MM)

    graded: list[str] = []
    calibrates_tcp = result.tcp_result is not None or not result.orientation_calibrated
    if calibrates_tcp:          # XYZ wizards, and TCP & Z, X (TCP and orientation both graded)
        graded.append("position")
    if not result.orientation_calibrated:
        pass
    elif result.method in X_AXIS_METHODS:
        graded.append("x_axis")
    else:
        graded.append("orientation")
    grade, verdict = _verdict(tuple(graded), pos_err, ori_err, x_err)
    return TruthComparison(position_error_mm=pos_err,
                           position_error_vector_mm=(float(dvec[0]), float(dvec[1]), float(dvec[2])),
                           orientation_error_deg=ori_err, x_axis_error_deg=x_err,
                           inside_ci95=inside, graded=tuple(graded), grade=grade, verdict=verdict)
