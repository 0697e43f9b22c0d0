"""The step panel of the open wizard (viser GUI): "Step k of n", a progress bar, the step's
instruction, the list of steps, Record / Back / Next (Finish) / Cancel, the tool change a step
asks for, the variant choice (the wizard class's ``variants``: three-point, ABC world), "Add
point" (``supports_add_point``: 4-point) and the live pose-diversity meter (``meter_active``:
the touch steps of 4-point and TCP & Z, X), and in training mode the Auto-touch controls. No
wizard class is named here: what is shown is what the wizard declares. A step the controller
runs itself (its role's ``AutoRole.by_controller``: the beam wizard's scan) shows neither Record
nor Auto-touch; its Finish runs the wizard's controller job (``WizardCommands.take_controller_job``: the
job its class names) in a worker thread, as a TCP check's Finish runs its six rotations. Every
click is a command of the session (``WizardCommands.record_step``, ``back``, ``next_step``, ...).

Record is enabled only when the wizard can record (``Wizard.can_record``); Next only when the
step is recorded. The pose-diversity meter is updated on every move of the robot (a motion
listener of the session) with the wizard's ``preview`` of the current flange pose: the TCP
uncertainty tcpcal predicts if the user recorded here.
"""

from __future__ import annotations

import logging
import math
from typing import TYPE_CHECKING, cast

from tcp_pendant.controller.tools import shown_tool_label
from tcp_pendant.controller.words import error_text
from tcp_pendant.calibrate import AUTO_SIGMA_MAX_MM, AutoTouchRequest
from tcp_pendant.calibrate.diversity import diversity_advice
from tcp_pendant.calibrate.tilt_advice import TiltAdvisor, meter_gain
from tcp_pendant.calibrate.jobs import POSE_CHECKS
from tcp_pendant.calibrate.text import (
    meter_level,
    meter_markdown,
    step_markdown,
    steps_list_markdown,
    where_to_jog_markdown,
)
from tcp_pendant.job_pool import JobRefused
from tcp_pendant.pendant.guidance import tip_offset_mm
from tcp_pendant.pendant.touch_feedback import touch_feedback
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import N_
from tcp_pendant.views.gui_util import ButtonEvent, DropdownEvent, set_content, set_value, target_of
from tcp_pendant.views.touches_export import TouchesExport
from tcp_pendant.wizards import Wizard, WizardStateError

if TYPE_CHECKING:
    from tcp_pendant.calibrate.autotouch import AutoTouchOutcome
    from tcp_pendant.calibrate.workflow import ControllerJob
    from tcp_pendant.views.wizard_menu import CalibrateView
    from tcp_pendant.wizards.base import MeterWizard

__all__ = ["RANDOM", "WizardStepsView"]

RANDOM, CHOSEN = N_("random"), N_("chosen (tilt, azimuth)")
"""Auto-touch's directions (msgids; the dropdown shows them translated)."""
log = logging.getLogger(__name__)


class WizardStepsView:
    """Builds the step panel in the current GUI container (see the module docstring)."""

    def __init__(self, parent: CalibrateView) -> None:
        self.advisor = TiltAdvisor()          # the tilt hint given on this tab
        self.parent = parent
        gui = target_of(parent.session).gui
        keep = parent.words.keep                  # the tab's fixed words, relabelled per language
        _ = parent.gettext
        self.folder = keep(gui.add_folder(N_("Wizard"), visible=False))
        with self.folder:
            self.head_md = gui.add_markdown("")
            self.progress = gui.add_progress_bar(0.0, color="blue")
            self.steps_md = gui.add_markdown("")
            self.variant = keep(gui.add_dropdown(N_("Variant"), ("-",), visible=False))
            self.blocked_md = gui.add_markdown("", visible=False)
            self.mount = gui.add_button(N_("Mount the tool"), color="orange", visible=False,
                                        hint=N_("The tool change this step asks for (the app swaps the tool)."))
            keep(self.mount)            # its label is set per step (the tool's name), its hint kept
            self.record = keep(gui.add_button(N_("Record"), color="green",
                                              hint=N_("Store the current flange pose for this step.")))
            self.record_md = gui.add_markdown("")
            self.next = gui.add_button(_("Next"), color="blue")
            self.back = keep(gui.add_button(N_("Back"), color="gray"))
            self.add_point = keep(gui.add_button(N_("Add point"), visible=False,
                                                 hint=N_("One more touch (up to 20): more touches, smaller error.")))
            self.cancel = gui.add_button(N_("Cancel"), color="red",
                                         hint=N_("Leave the wizard; nothing recorded is lost, Resume brings it back."))
            keep(self.cancel)           # its label is set per state (Cancel, Close), its hint kept
            self.export = TouchesExport(parent)          # "Export touches (CSV)" for tcpcal solve
            self.meter_bar = gui.add_progress_bar(0.0, color="gray", visible=False)
            self.meter_md = gui.add_markdown("", visible=False)
            self.auto_folder = keep(gui.add_folder(N_("Auto-touch (training)"), expand_by_default=True))
            with self.auto_folder:
                directions = (_(RANDOM), _(CHOSEN))
                self.auto_direction = keep(gui.add_dropdown(N_("Direction"), directions, initial_value=directions[0]))
                self.auto_tilt = keep(gui.add_slider(N_("Tilt (deg)"), min=0.0, max=60.0, step=1.0,
                                                     initial_value=35.0, visible=False))
                self.auto_azimuth = keep(gui.add_slider(N_("Azimuth (deg)"), min=0.0, max=355.0, step=5.0,
                                                        initial_value=0.0, visible=False))
                self.auto_sigma = keep(gui.add_slider(N_("Operator error σ (mm)"), min=0.0, max=AUTO_SIGMA_MAX_MM,
                                                      step=0.05, initial_value=0.0))
                self.auto_touch = keep(gui.add_button(
                    N_("Auto-touch"), color="violet",
                    hint=N_("The robot performs this step itself, with the operator error σ.")))
                self.auto_md = gui.add_markdown("")
        act = parent.action
        session = parent.session
        self.record.on_click(act(self._on_record))
        self.next.on_click(self._on_next)
        self._checking = False
        self._busy_text = ""
        self.back.on_click(act(lambda _e: session.wizard_commands.back()))
        self.cancel.on_click(act(self._on_cancel))
        self.add_point.on_click(act(self._on_add_point))
        self.mount.on_click(act(lambda _e: session.wizard_commands.mount_required_tool(), sync=True))
        self.variant.on_update(act(self._on_variant, user_only=True))
        self.auto_direction.on_update(act(lambda _e: None, user_only=True))
        self.auto_touch.on_click(self._on_auto_touch)
        self._auto_touching = False
        self._auto_line: tuple[tuple[object, ...], str, object] | None = None  # (where it belongs, text, poses)
        self._record_line: tuple[tuple[object, ...], str, object] | None = None  # the same, for Record

    def relabel(self) -> None:
        """A ``language`` change (the tab relabelled the kept handles): the Direction options
        in the new language, the chosen one kept; the lines of the last clicks are dropped (they
        were said in the old language); ``render`` shows the rest."""
        chosen = self._direction()
        _ = self.parent.gettext
        options = (_(RANDOM), _(CHOSEN))
        if tuple(self.auto_direction.options) != options:
            self.auto_direction.options = options
        set_value(self.auto_direction, _(chosen))
        self._auto_line = self._record_line = None

    def _direction(self) -> str:
        """The Auto-touch direction chosen (:data:`RANDOM` or :data:`CHOSEN`), read in any
        language the option may come in."""
        return CHOSEN if str(self.auto_direction.value) in self.parent.said_as(CHOSEN) else RANDOM

    # ------------------------------------------------------------ callbacks
    def _on_record(self, _event: ButtonEvent) -> None:
        """Record the step. In free practice with the distance hidden the line below says how
        far the touch really was (``touch_feedback``, the dock's words); never in an exercise."""
        s = self.parent.session
        wiz = self.parent.workflow.wizard
        index = None if wiz is None else wiz.step.index
        frame = s.jogger.settings.frame
        delta = tip_offset_mm(s.pose_state(), s.controller.reference_tip_world_m, frame)
        s.wizard_commands.record_step()
        self._record_line = None
        if s.hide_distance and not s.rules.in_exercise:
            wiz = self.parent.workflow.wizard
            self._record_line = (self._auto_where(),
                                 self.parent.gettext("✔ Step {n} recorded: {feedback}.").format(
                                     n=index + 1 if index is not None else "?", feedback=touch_feedback(delta, frame, tr=s.translator)),
                                 None if wiz is None else wiz.recorded_poses)

    def _on_cancel(self, _event: ButtonEvent) -> None:
        if self.parent.session.wizard_commands.cancel():
            _ = self.parent.gettext
            self.parent.session.notify(_("Calibration cancelled"),
                                       _("Nothing recorded is lost: Resume it from the Calibrate menu."))

    async def _on_next(self, event: ButtonEvent) -> None:
        """Next / Finish. A wizard waiting for its controller job (a TCP check's rotations, a
        beam scan) runs it on Finish: the job is taken on the loop (under the session lock), run
        in the server's job pool (``SessionLoop.run_job``: a TCP check's six rotations 0.1-0.3 s, a
        beam scan of 3 to 5 orientations well under a second), its outcome handed to the wizard
        on the loop; one job at a time."""
        session, act = self.parent.session, self.parent.action
        _ = self.parent.gettext
        jobs: list[ControllerJob] = []

        def take(_e: ButtonEvent) -> None:
            if self._checking:
                raise WizardStateError(_("The controller is still at work; wait for its result."))
            job = session.wizard_commands.take_controller_job()
            if job is None:
                session.wizard_commands.next_step()
            else:
                jobs.append(job)
                self._busy_text = job.busy_text
                self._checking = True                  # render shows the busy text and disables Finish

        await act(take)(event)
        if not jobs:
            return
        title = jobs[0].wizard.title
        shown = _(title)
        try:
            result = await session.loop.run_job(jobs[0].run, what=f"the {title} wizard's controller job")
        except Exception as exc:  # a browser's click must never kill the server
            self._checking = False
            if isinstance(exc, JobRefused):            # another job of this session, or a full queue
                self.parent.session.notify(_("{title}: not started").format(title=shown),
                                           error_text(exc, session.translator), kind="warning")
            elif isinstance(exc, ValueError):            # the controller's words (ControllerError)
                self.parent.session.notify(_("{title}: not possible").format(title=shown),
                                           error_text(exc, session.translator), kind="error")
            else:
                log.exception("%s: controller job failed", title)
                self.parent.session.notify(_("{title} failed").format(title=shown), f"{type(exc).__name__}: {exc}",
                                           kind="error")
            await act(lambda _e: None)(event)          # re-render the step as it was
            return
        finally:
            self._checking = False
        await act(lambda _e: session.wizard_commands.hand_in_controller_job(jobs[0], result), sync=True)(event)

    def _on_add_point(self, _event: ButtonEvent) -> None:
        self.parent.session.wizard_commands.add_point()

    def _on_variant(self, event: DropdownEvent) -> None:
        wiz = self.parent.workflow.wizard
        label = str(event.target.value)
        values = {} if wiz is None else {said: v for v, lab in type(wiz).variants for said in self.parent.said_as(lab)}
        if wiz is None or label not in values:
            raise ValueError(self.parent.gettext("Unknown variant {label!r}.").format(label=label))
        self.parent.session.wizard_commands.set_variant(values[label])

    def auto_request(self) -> AutoTouchRequest:
        """The Auto-touch settings as a request (random or chosen direction, operator error)."""
        sigma = float(self.auto_sigma.value)
        if self._direction() == CHOSEN:
            return AutoTouchRequest(float(self.auto_tilt.value), float(self.auto_azimuth.value), sigma)
        return AutoTouchRequest(sigma_mm=sigma)

    async def _on_auto_touch(self, _event: ButtonEvent) -> None:
        """Auto-touch (``WizardCommands.auto_touch_in_pool``: the probes of a TCP check's poses run in
        the job pool); one at a time per
        session, refused at once while the session's job runs or its share is used up
        (``SessionLoop.admit_job``), the outcome shown in one signal at the end."""
        session = self.parent.session
        if session.closed:
            return
        _ = self.parent.gettext
        not_started = _("Auto-touch not started")
        wiz = self.parent.workflow.wizard
        probes = wiz is not None and type(wiz).controller_job in POSE_CHECKS    # its poses are probed in the pool
        running = session.jobs.pending(session) if probes else None
        if self._auto_touching or running is not None:
            what = _("Auto-touch") if self._auto_touching else str(running)
            session.notify_refusal(not_started, _("{job} is still running here; wait for its result, then try "
                                                  "again.").format(job=f"{what[:1].upper()}{what[1:]}"))
            return
        try:                                    # refused at once, before anything moves
            session.loop.admit_job()
        except JobRefused as exc:
            session.notify_refusal(not_started, error_text(exc, session.translator))
            return
        try:
            request = self.auto_request()
        except ValueError as exc:
            session.notify(_("Not done"), error_text(exc, session.translator), kind="warning")
            return
        self._auto_touching = True
        try:
            await session.wizard_commands.auto_touch_in_pool(request, shown=lambda out: self._show_auto_touch(out, request))
        except JobRefused as exc:
            session.notify_refusal(not_started, error_text(exc, session.translator))
            return
        except ValueError as exc:               # the wizard's words
            session.notify_refusal(_("Not done"), error_text(exc, session.translator))
            return
        except Exception as exc:                # a browser's click must never kill the server
            log.exception("Auto-touch failed")
            session.notify(_("Internal error"), f"{type(exc).__name__}: {exc}", kind="error")
            return
        finally:
            self._auto_touching = False

    def _show_auto_touch(self, out: AutoTouchOutcome, request: AutoTouchRequest) -> None:
        if not out.ok:
            raise ValueError(out.message)
        wiz = self.parent.workflow.wizard
        self._auto_line = (self._auto_where(),       # the poses are kept alive: their ids stay unique
                           escape_markdown(out.message) + " " + self.parent.gettext("Operator error σ {sigma} mm.").format(
                               sigma=f"{request.sigma_mm:.2f}"),
                           None if wiz is None else wiz.recorded_poses)

    def _auto_where(self) -> tuple[object, ...]:
        """Where the Auto-touch line belongs: the wizard on show, its step and status and its
        recorded poses (a new record, a step change or another wizard makes the line stale)."""
        wiz = self.parent.workflow.wizard
        if wiz is None:
            return ()
        poses = wiz.recorded_poses
        return (id(wiz), wiz.step_index, wiz.status, tuple((i, id(poses[i])) for i in sorted(poses)))

    def _render_auto_line(self) -> None:
        """The Auto-touch line, only while it still describes the wizard's state (no
        \"Recorded touch 3\" after touch 4, nothing carried into another wizard)."""
        line = self._auto_line
        if line is not None and line[0] != self._auto_where():
            self._auto_line = line = None
        set_content(self.auto_md, "" if line is None else line[1])
        said = self._record_line
        if said is not None and said[0] != self._auto_where():
            self._record_line = said = None
        set_content(self.record_md, "" if said is None else said[1])

    # ------------------------------------------------------------ render
    def render(self) -> None:
        """Show the open wizard's step (hide the panel when no wizard is open)."""
        wf = self.parent.workflow
        wiz = wf.wizard
        self.folder.visible = wf.is_open
        if wiz is None or not wf.is_open:
            return
        tr = self.parent.session.translator
        _ = tr.gettext
        where = where_to_jog_markdown(wiz, tr=tr)
        set_content(self.head_md, step_markdown(wiz, tr=tr) + (f"\n\n{where}" if where else "")
                    + (f"\n\n{self._busy_text}" if self._checking else ""))
        set_value(self.progress, round(100.0 * wiz.progress, 1))
        set_content(self.steps_md, steps_list_markdown(wiz, tr=tr))
        self._render_variant(wiz)
        needed = wf.required_tool()
        reason = wiz.blocked_reason if not wiz.is_complete and not wiz.auto_role(wiz.step).by_controller else None
        failure = wf.finish_failure
        if failure is not None:                  # Finish could not compute: why, and what to do
            reason = (_("Finish not possible: {why}").format(why=failure) if reason is None
                      else f"{reason}\n\n{failure}")
        short = self.parent.session.wizard_commands.finish_refusal()   # the exercise asks for more touches
        if short is not None:
            reason = short if reason is None else f"{reason}\n\n{short}"
        self.blocked_md.visible = reason is not None
        if reason is not None:
            set_content(self.blocked_md, f"⚠ {escape_markdown(reason)}")
        self.mount.visible = needed is not None
        if needed is not None:
            self.mount.label = _("Mount the {tool}").format(
                tool=shown_tool_label(needed.label, self.parent.session.translator, in_sentence=True))
        stepping = not wiz.is_complete           # on the result only Back, Add point and Close remain
        by_controller = stepping and wiz.auto_role(wiz.step).by_controller   # no Record, no Auto-touch
        self.record.visible = stepping and not by_controller
        self.next.visible = stepping
        self.record.disabled = not wiz.can_record
        self.next.disabled = not wiz.can_next or self._checking
        next_label = _("Finish") if wiz.on_last_step else _("Next")
        if self.next.label != next_label:
            self.next.label = next_label
        self.back.disabled = not wiz.can_back
        cancel_label = _("Cancel") if stepping else (_("Close") if wf.result_saved else _("Close (not saved)"))
        if self.cancel.label != cancel_label:
            self.cancel.label = cancel_label
        self.add_point.visible = wiz.supports_add_point
        self.export.render(wiz)
        self.add_point.disabled = not wiz.can_add_point
        self.auto_folder.visible = wf.auto_touch_allowed and stepping and not by_controller
        chosen = self._direction() == CHOSEN
        self.auto_tilt.visible = self.auto_azimuth.visible = chosen
        self._render_auto_line()
        self.update_meter()

    def _render_variant(self, wiz: Wizard) -> None:
        variants = type(wiz).variants
        if not variants:
            self.variant.visible = False
            return
        tr = self.parent.gettext
        labels = tuple(tr(label) for _v, label in variants)
        label = next(tr(lab) for v, lab in variants if v == wiz.variant)
        if tuple(self.variant.options) != labels:    # our own assignments: the on_update
            self.variant.options = labels            # they fire has no client and is ignored
        if self.variant.value != label:
            set_value(self.variant, label)
        self.variant.visible = True
        self.variant.disabled = wiz.status != "in_progress"

    def update_meter(self) -> None:
        """The live pose-diversity meter (while a touch is to be recorded, for the wizards that
        declare it: ``Wizard.meter_active``)."""
        wf = self.parent.workflow
        shown = wf.wizard
        show = shown is not None and shown.meter_active
        self.meter_bar.visible = self.meter_md.visible = show
        if not show:
            return
        wiz = cast("MeterWizard", shown)              # meter_active: a wizard that declares the meter
        T_world_flange = self.parent.session.controller.T_world_flange()
        meter = meter_gain(wiz, T_world_flange[:3, :3], [r.wizard for r in wf.runs])
        gain = meter.gain
        value, color = meter_level(gain)
        set_value(self.meter_bar, round(value, 1))
        self.meter_bar.color = color
        s = self.parent.session
        advice = (diversity_advice(wiz.other_rotations(), T_world_flange[:3, :3], gain.angle_to_nearest_deg,
                                   tr=s.translator)
                  if math.isinf(gain.predicted_after) else None)               # only then shown
        tilt = self.advisor.advise(wiz.other_rotations(), T_world_flange[:3, :3], s.jogger, meter.sigma_mm,
                                   tr=s.translator)
        set_content(self.meter_md, meter_markdown(gain, None, meter.sigma_mm, advice,
                                                  None if tilt is None else tilt.text, measured=meter.source,
                                                  tr=s.translator))
