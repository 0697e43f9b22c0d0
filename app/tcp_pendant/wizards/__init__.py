"""Calibration wizards as state machines (no viser): XYZ 4-point, XYZ reference, TCP & Z, X,
three-point orientation and ABC world (methods.md sections 2-5, 8). Views render them; all math
is tcpcal's. Each wizard class describes itself and is registered here (``registry``): the
Calibrate menu, auto-touch, the session record and the workflow read only the registry.

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

from tcp_pendant.wizards.tcp_zx import TcpZxWizard
from tcp_pendant.wizards.tcp_check import TcpCheckResult, TcpCheckWizard
from tcp_pendant.wizards.beam import BeamWizard, BeamWizardResult, ManualComparison
from tcp_pendant.wizards.registry import WIZARD_TYPES, register, unregister, wizard_class, wizard_classes

for _cls in (Xyz4Wizard, ReferenceWizard, TcpZxWizard, ThreePointWizard, AbcWorldWizard, BeamWizard, TcpCheckWizard):
    register(_cls)

__all__ = [
    "AbcWorldWizard", "BeamWizard", "BeamWizardResult", "CalibrationFailedError", "ESTIMATORS", "ESTIMATOR_LABELS",
    "InvalidPoseError", "MIN_DISPLACEMENT_MM", "ManualComparison", "R_WORLD_TOOL_TARGET", "RecordedPose",
    "ReferenceWizard", "StepInfo", "StepSpec", "TcpCheckResult", "TcpCheckWizard", "TcpZxWizard", "ThreePointWizard", "WIZARD_TYPES",
    "Wizard", "WizardError", "WizardResult", "WizardStateError", "Xyz4Result", "Xyz4Wizard",
    "register", "unregister", "wizard_class", "wizard_classes",
]
