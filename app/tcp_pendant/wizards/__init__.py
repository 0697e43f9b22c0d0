"""Calibration wizards as state machines (no viser): XYZ 4-point, XYZ reference, three-point
orientation and ABC world (methods.md sections 2-5). Views render them; all math is tcpcal's.

Public API: see each module. Poses are fed in metres (``T_world_flange_m``, from the virtual
controller) and handed to tcpcal in millimetres; every ``*_mm`` figure is in mm.
"""

from __future__ import annotations

from tcp_pendant.wizards.abc_world import R_WORLD_TOOL_TARGET, AbcWorldWizard
from tcp_pendant.wizards.base import (
    CalibrationFailedError,
    InvalidPoseError,
    RecordedPose,
    StepInfo,
    StepSpec,
    Wizard,
    WizardError,
    WizardResult,
    WizardStateError,
)
from tcp_pendant.wizards.reference import ReferenceWizard
from tcp_pendant.wizards.three_point import MIN_DISPLACEMENT_MM, ThreePointWizard
from tcp_pendant.wizards.xyz4 import ESTIMATORS, ESTIMATOR_LABELS, Xyz4Result, Xyz4Wizard

WIZARD_TYPES: dict[str, type[Wizard]] = {
    Xyz4Wizard.kind: Xyz4Wizard,
    ReferenceWizard.kind: ReferenceWizard,
    ThreePointWizard.kind: ThreePointWizard,
    AbcWorldWizard.kind: AbcWorldWizard,
}
"""Wizard kind (as in ``Wizard.to_dict()["kind"]``) -> class."""

__all__ = [
    "AbcWorldWizard", "CalibrationFailedError", "ESTIMATORS", "ESTIMATOR_LABELS",
    "InvalidPoseError", "MIN_DISPLACEMENT_MM", "R_WORLD_TOOL_TARGET", "RecordedPose",
    "ReferenceWizard", "StepInfo", "StepSpec", "ThreePointWizard", "WIZARD_TYPES", "Wizard",
    "WizardError", "WizardResult", "WizardStateError", "Xyz4Result", "Xyz4Wizard",
]
