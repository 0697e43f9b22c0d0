"""Training mode's Auto-touch on the run on show (no viser).

An :class:`AutoTouchDriver` belongs to one ``CalibrationWorkflow`` and lets its controller
perform the current step (``autotouch.auto_touch_steps``: reach the pose, mounting the tool the
step needs), record it in the workflow's run and, after the last step, finish the run - unless
the exercise asks for more touches or a touch was made with another tool. It decides when
Auto-touch is refused (training mode off, the exercise's rules, a step the controller runs
itself) and drops a probe's answer when the run on show changed meanwhile.
"""

from __future__ import annotations

from collections.abc import Generator
from typing import TYPE_CHECKING

from tcp_pendant.calibrate.autotouch import AutoTouchOutcome, PoseProbe, auto_touch_steps
from tcp_pendant.calibrate.jobs import POSE_CHECKS
from tcp_pendant.translation import N_
from tcp_pendant.wizards import CalibrationFailedError, WizardStateError

if TYPE_CHECKING:
    from tcp_pendant.calibrate.workflow import AutoTouchRequest, CalibrationWorkflow

__all__ = ["AutoTouchDriver"]

_TRAINING_ONLY = N_("Auto-touch is a training-mode tool; switch training mode on.")


class AutoTouchDriver:
    """Auto-touch on the runs of ``workflow`` (module docstring)."""

    def __init__(self, workflow: CalibrationWorkflow) -> None:
        self._workflow = workflow

    @property
    def allowed(self) -> bool:
        """Auto-touch may be offered: training mode, and the exercise's rules allow it."""
        rules = getattr(self._workflow.state, "rules", None)
        return self._workflow.training and (rules is None or bool(rules.auto_touch_allowed))

    def refusal(self) -> str | None:
        """``CalibrationWorkflow.auto_touch_refusal``: why Auto-touch is refused as things are."""
        _ = self._workflow.translator.gettext
        if not self._workflow.training:
            return _(_TRAINING_ONLY)
        rules = getattr(self._workflow.state, "rules", None)
        if rules is not None:
            try:
                rules.check_auto_touch()
            except ValueError:          # the exercise's refusal comes first: trying says it
                return None
        w = self._workflow.wizard
        if w is not None and w.status != "in_progress":
            return _("Cannot auto-touch: {reason}").format(reason=w.blocked_reason)
        return None

    def steps(self, request: AutoTouchRequest) -> Generator[PoseProbe, str | None, AutoTouchOutcome]:
        """``CalibrationWorkflow.auto_touch_steps``: yields each pose probe, must be sent its
        answer, returns the outcome.

        Raises:
            WizardStateError: training mode is off, or no wizard is in progress.
            RuleRefusal: the trainer's exercise does not allow Auto-touch (the owner's ``rules``).
            CalibrationFailedError: the touches cannot determine the result.
        """
        wf = self._workflow
        _ = wf.translator.gettext
        if not wf.training:
            raise WizardStateError(_(_TRAINING_ONLY))
        rules = getattr(wf.state, "rules", None)     # the session's exercise rules, when it has them
        if rules is not None:
            rules.check_auto_touch()
        w = wf.require_wizard()
        if w.status == "in_progress" and w.auto_role(w.step).by_controller:
            raise WizardStateError(_("The {method} wizard has nothing to touch: the controller runs this "
                                     "step itself; press Finish.").format(method=_(w.title)))
        run_index = wf.run_index
        wf.note_mounted_tool()
        had_pose = set(w.recorded_poses) if w.status == "in_progress" else set()
        job = type(w).controller_job
        pose_check = POSE_CHECKS[job](wf, w) if job in POSE_CHECKS else None
        steps = auto_touch_steps(w, wf.controller, direction_deg=request.direction_deg,
                                 sigma_mm=request.sigma_mm, rng=wf.rng, tools=wf.tools,
                                 previous_direction_deg=wf.touches.direction(run_index),
                                 mount=wf.state.mount_step_tool, pose_check=pose_check)
        try:
            probe = next(steps)
            while True:
                answer = yield probe
                if wf.wizard is not w or wf.run_index != run_index:   # left while the probe ran
                    steps.close()
                    raise WizardStateError(_("The calibration on show changed while Auto-touch checked the pose "
                                             "it reached; nothing was recorded."))
                probe = steps.send(answer)
        except StopIteration as stop:
            out: AutoTouchOutcome = stop.value
        wf.note_mounted_tool()
        if out.ok:                            # the robot stands at the touch it recorded
            wf.note_recorded(out.step_index, auto=True, had_pose=out.step_index in had_pose)
        if out.direction_deg is not None and run_index is not None:
            wf.touches.note_direction(run_index, out.direction_deg)
        if type(w).controller_job is not None:    # Finish runs the controller's job (off the loop in the app)
            return out
        if out.ok and w.on_last_step and all(s.recorded for s in w.steps) and wf.touches_short() is None:
            wrong = wf.wrong_tool_touch()
            if wrong is not None:
                raise WizardStateError(wrong)
            try:
                wf.log.finished(w, w.finish())
            except CalibrationFailedError as exc:
                raise wf.log.failed(exc) from exc
        return out
