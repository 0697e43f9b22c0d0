"""Why a run's Finish is refused or failed, in the trainee's words (no viser).

Three checks the workflow makes around a Finish: too few touches for the exercise
(:func:`touches_short`), a touch made with another physical tool than its step measures
(:func:`wrong_tool_touch`), and tcpcal's failure told as step numbers and a FLANGE axis with
what to do (:func:`failure_in_trainee_words`, the axis from ``diversity.failure_in_words``).
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import numpy as np

from tcp_pendant.calibrate.diversity import failure_in_words
from tcp_pendant.calibrate.pendant_rules import ExerciseRules
from tcp_pendant.controller import ToolModel
from tcp_pendant.controller.tools import shown_tool_label
from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.wizards import CalibrationFailedError, Wizard
from tcp_pendant.wizards.session_record import WizardRun
from tcp_pendant.wizards.solver_words import solver_warning

__all__ = ["failure_in_trainee_words", "touches_short", "wrong_tool_touch"]

_ANGLE_APART = re.compile(r"\(([0-9.]+) deg apart\)")
"""The angle in tcpcal's "touches i and j (0-based) have the same orientation (x deg apart)"."""


def touches_short(rules: ExerciseRules | None, wizard: Wizard | None) -> str | None:
    """Why the exercise's ``rules`` refuse Finish of ``wizard`` (open, not cancelled): on the
    last step of a method whose touch count the trainee chooses (an ``n_points`` start option
    or Add point), fewer touch steps than ``rules.min_touches``. None when Finish is not
    refused; a method with a fixed number of poses never is."""
    w = wizard
    if (rules is None or not getattr(rules, "min_touches", 0) or w is None or w.status == "cancelled"
            or w.is_complete or not w.on_last_step):
        return None
    cls = type(w)
    if not (cls.supports_add_point or any(o.name == "n_points" for o in cls.options)):
        return None
    refusal: str | None = rules.touches_refusal(len(w.solver_touch_steps()), can_add_point=cls.supports_add_point)
    return refusal


def wrong_tool_touch(run: WizardRun | None, tools: Mapping[str, ToolModel], *,
                     tr: Translator = ENGLISH) -> str | None:
    """Why ``run`` cannot be filed as it is: a touch recorded with another physical tool than
    the one its step measures (the step's tool change, else the tool the run calibrates), in
    words with what to do; None when every touch whose tool is known was made with the right
    one. A calibration is graded and filed under the tool it measured, so touches of two tools
    cannot make one."""
    if run is None or run.true_tool_key is None:
        return None

    def label(key: str) -> str:
        tool = tools.get(key)
        return shown_tool_label(key if tool is None else tool.label, tr, in_sentence=True)

    w = run.wizard
    for step in sorted(w.recorded_poses):
        used = run.touch_tools.get(step)
        spec = w.steps[step] if 0 <= step < w.n_steps else None
        need = run.true_tool_key if spec is None or spec.mount_tool_key is None else spec.mount_tool_key
        if used is None or used == need:
            continue
        return tr.gettext("Step {k} was recorded with the {used}, but it measures the {needed}: "
                          "a calibration is filed under the tool it measured. Mount the {needed} and record "
                          "step {k} again (or start a new calibration for the {used}).").format(
                              k=step + 1, used=label(used), needed=label(need))
    return None


def failure_in_trainee_words(exc: CalibrationFailedError, wizard: Wizard | None,
                             R_world_flange: np.ndarray, *, tr: Translator = ENGLISH) -> CalibrationFailedError:
    """tcpcal's failure of ``wizard``'s Finish in the trainee's words, with what to do: the
    touches it is about as step numbers (two with the same orientation: go back to the later
    one), or its unobservable FLANGE axis in words (the robot's ``R_world_flange`` now, 3x3);
    ``exc`` itself when it is about neither."""
    w, cause = wizard, exc.cause
    axis = getattr(cause, "unobservable_axis", None)
    pair = tuple(getattr(cause, "indices", ()))
    steps = () if w is None else w.solver_touch_steps()
    if len(pair) == 2 and all(0 <= k < len(steps) for k in pair):
        a, b = (steps[k] + 1 for k in pair)
        _ = tr.gettext
        angle = _ANGLE_APART.search(str(exc))
        here = w is not None and w.step_index == b - 1
        if angle:
            text = (_("Touches {a} and {b} have the same orientation ({angle}° apart): the method needs clearly "
                      "different orientations. Tilt the tool 30-60° about another axis and record step {b} again.")
                    if here else
                    _("Touches {a} and {b} have the same orientation ({angle}° apart): the method needs clearly "
                      "different orientations. Tilt the tool 30-60° about another axis and go Back to step {b} "
                      "and record it again.")).format(a=a, b=b, angle=angle.group(1))
        else:
            text = (_("Touches {a} and {b} have the same orientation: the method needs clearly "
                      "different orientations. Tilt the tool 30-60° about another axis and record step {b} again.")
                    if here else
                    _("Touches {a} and {b} have the same orientation: the method needs clearly "
                      "different orientations. Tilt the tool 30-60° about another axis and go Back to step {b} "
                      "and record it again.")).format(a=a, b=b)
        return CalibrationFailedError(text, cause)
    if axis is not None:
        return CalibrationFailedError(
            tr.gettext("{failure} Go Back to a step and record it tilted about that axis.").format(
                failure=failure_in_words(str(exc), axis, R_world_flange)), cause)
    said = solver_warning(str(exc), tr=tr)       # tcpcal's words from the catalogs, when it knows them
    return exc if said == str(exc) else CalibrationFailedError(said, cause)
