"""The wizard dock of the Jog tab (viser GUI): the running wizard's step beside the jog keys.

While a calibration wizard is open, the top of the Jog tab shows its current step ("Step k
of N", what to do), **Record** (the step's, checked: ``pendant.record_check``), a row
"◀ Back · Next ▶ (Finish) · Cancel", the tool change a step asks for, and the pose-diversity
meter (bar, one line, and below it the tilt that helps most and the tilts reachable from here,
``calibrate.tilt_advice`` and ``pendant.tilts``, wrapped in full and at least three lines high),
so a trainee jogs, watches and records on one screen; the Calibrate
tab stays the place to choose a method and review the result. Outside a wizard the dock is
hidden and the touch list's "Record point" records into the free list (one Record concept).
A step the controller runs itself (``AutoRole.by_controller``: the beam wizard's scan) shows no
Record; its Finish runs the wizard's controller job in the server's job pool, off the loop
(``WizardCommands.next_step_in_pool``).

The dock renders from the session's workflow (``Session.workflow``) on the change signal and
changes it only through the session's commands (``session.wizard_commands``: ``record_step``,
``next_step``, ``back``, ``cancel``, ``mount_required_tool``); it never calls another view. Each click runs through ``SessionLoop.on_loop`` inside ``Session.batch`` and ends in one
change signal with ``wizard`` (as the Calibrate tab's clicks), so the Calibrate tab, the scene
and the classroom recorder see it too. Every text from a wizard goes through the escaping
``calibrate.text`` helpers.

Language: the dock's words are the session's (``session.translator``); a ``language`` change
relabels its handles (``views.gui_words``) and re-renders the step; a Step click is read in the
language it was shown in or in English (a click that crossed a switch).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Coroutine
from typing import TYPE_CHECKING, TypeVar, cast

from tcp_pendant.controller.tools import shown_tool_label
from tcp_pendant.controller.words import error_text
from tcp_pendant.calibrate.record_words import recorded_words
from tcp_pendant.calibrate.tilt_advice import TiltAdvisor, meter_gain
from tcp_pendant.calibrate.text import meter_level, step_markdown
from tcp_pendant.pendant.guidance import direction_words, tip_offset_mm
from tcp_pendant.text_escape import escape_html, escape_markdown
from tcp_pendant.pendant.record_check import RecordCheck
from tcp_pendant.pendant.tilts import reachable_line
from tcp_pendant.pendant.touch_feedback import touch_feedback
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.translation import N_
from tcp_pendant.views.gui_util import ButtonEvent, ButtonGroupEvent, set_content, set_value, target_of
from tcp_pendant.views.gui_words import GuiWords

if TYPE_CHECKING:
    from tcp_pendant.calibrate import CalibrationWorkflow
    from tcp_pendant.wizards.base import MeterWizard

__all__ = ["BACK", "CANCEL", "CLOSE", "FINISH", "NEXT", "RECORD", "WizardDock", "tilt_line_html"]

_E = TypeVar("_E")
"""The event a dock action's callback takes (viser's, of the widget it is attached to)."""

log = logging.getLogger(__name__)

BACK, NEXT, FINISH, CANCEL, CLOSE = N_("◀ Back"), N_("Next ▶"), N_("Finish ▶"), N_("Cancel"), N_("Close")
"""The Step row's buttons (msgids: shown in the session's language; a click is read in any
language it may come in)."""
RECORD = N_("Record")
"""The wizard step's Record button (key R: the page's script finds it by this label)."""


TILT_LINE_STYLE = "min-height:4.2em;line-height:1.4em;white-space:normal;font-size:0.875em;padding:0 0.75em"
"""Wrapped in full (never cut), at least three lines high (an empty hint keeps them): the jog
keys below stay put while the hint is three lines or less."""


def tilt_line_html(hint: str | None, reachable: str = "") -> str:
    """The dock's tilt lines: ``hint`` (``tilt_advice.TiltAdvice.text``) and the reachable tilts
    (``tilts.reachable_line``), markdown bold dropped, escaped, wrapped; none: the same lines,
    empty."""
    parts = [escape_html(t.replace("**", "")) for t in (hint or "", reachable) if t]
    return f'<div style="{TILT_LINE_STYLE}">{"<br>".join(parts) or "&nbsp;"}</div>'


PIVOT_LABEL = N_("Tilt about the wizard's estimate")
PIVOT_HINT = N_("Make the TCP your touches so far give (the wizard's estimate, never the truth) the active "
                "tool data: the A, B, C keys then turn about it, so a tilt keeps the tip near the "
                "reference tip. Offered from two touches in different orientations; press again after "
                "a touch for a better estimate.")
"""The dock's button of ``WizardCommands.pivot_on_estimate``: shown through an XYZ 4-point's
steps, enabled while it has an estimate to offer. It takes the row of the meter's bar (the
meter's line says the same in words), so the jog keys stay above the fold at 1024x768 and do not
move when the estimate comes."""


class WizardDock:
    """Builds the dock in the current GUI container (the top of the Jog tab)."""

    def __init__(self, session: Session, *, check: RecordCheck | None = None) -> None:
        self.session = session
        self.check = RecordCheck() if check is None else check
        self.advisor = TiltAdvisor()          # the tilt hint given to this browser
        self._note = ""                       # the last click's line, for this run and step only
        self._note_at: tuple[int, int, int] | None = None
        gui = target_of(session).gui
        self.words = GuiWords(session.translator)     # the fixed labels and hints, relabelled per language
        self._shown_in = session.translator           # the language of the Step options on show
        keep, _ = self.words.keep, session.translator.gettext
        self.folder = keep(gui.add_folder(N_("Calibration step"), visible=False))
        with self.folder:
            self.step_md = gui.add_markdown("")
            self.note_md = gui.add_markdown("", visible=False)
            self.mount = keep(gui.add_button(N_("Mount the tool"), color="orange", visible=False,
                                             hint=N_("The tool change this step asks for (the app swaps the tool).")))
            self.record = keep(gui.add_button(RECORD, color="green",
                                              hint=N_("Record this step at the current pose (a touch farther than "
                                                      "0.5 mm asks first, unless the distance is hidden); key R.")))
            self.nav = keep(gui.add_button_group(N_("Step"), (_(BACK), _(NEXT), _(CANCEL)),
                                                 hint=N_("Keys: N Next (Finish on the last step), B Back.")))
            self.meter_bar = gui.add_progress_bar(0.0, color="gray", visible=False)
            self.meter_md = gui.add_markdown("", visible=False)
            self.tilt_html = gui.add_html(tilt_line_html(None), visible=False)
            self.pivot = keep(gui.add_button(PIVOT_LABEL, visible=False, hint=PIVOT_HINT))
        self.record.on_click(self._action(self._on_record))
        self.nav.on_click(self._on_nav_click)
        self.mount.on_click(self._action(lambda _e: self.session.wizard_commands.mount_required_tool(), sync=True))
        self.pivot.on_click(self._action(lambda _e: self.session.wizard_commands.pivot_on_estimate(), sync=True))
        session.subscribe(self.on_change)

    # ------------------------------------------------------------ plumbing
    def _action(self, fn: Callable[[_E], object], *,
                sync: bool = False) -> Callable[[_E], Coroutine[object, object, None]]:
        s = self.session

        def run(event: _E) -> None:
            with s.batch():
                try:
                    fn(event)
                finally:
                    s.changed(wizard=True, pose=sync)

        run.__qualname__ = getattr(fn, "__qualname__", "dock action")
        return s.loop.on_loop(run)

    def _where(self) -> tuple[int, int, int]:
        wf = self.session.workflow
        wiz = wf.wizard
        if wiz is None:
            return (-1, -1, -1)
        return (id(wiz), wiz.step.index if not wiz.is_complete else -2, len(wf.runs))

    def _say(self, text: str) -> None:
        self._note, self._note_at = text, self._where()

    def _command(self, value: str) -> str | None:
        """The Step command (:data:`BACK`, ...) a click's ``value`` names, in the session's
        language, in the one the buttons were shown in (a click that crossed a switch) or in
        English; None for none."""
        tr = self.session.translator
        return next((c for c in (BACK, NEXT, FINISH, CANCEL, CLOSE)
                     if value in (c, tr.gettext(c), self._shown_in.gettext(c))), None)

    # ------------------------------------------------------------ callbacks
    def _on_record(self, _event: ButtonEvent) -> None:
        wf = self.session.workflow
        s = self.session
        state = s.pose_state()
        frame = s.jogger.settings.frame
        delta = tip_offset_mm(state, s.controller.reference_tip_world_m, frame)
        decision = self.check.decide(state.touch.distance_mm, hidden=s.hide_distance, q_rad=state.q_rad,
                                     where=direction_words(delta, frame), tr=s.translator)
        if not decision.record:
            self._say(decision.message)
            return
        wiz = wf.wizard
        index = None if wiz is None else wiz.step.index
        s.wizard_commands.record_step()
        self._say(recorded_words(index, state.touch.distance_mm, hidden=s.hide_distance,
                                 in_exercise=s.rules.in_exercise,
                                 feedback=touch_feedback(delta, frame, tr=s.translator), tr=s.translator))

    async def _on_nav_click(self, event: ButtonGroupEvent) -> None:
        """Back and Cancel as every click; Next / Finish through ``WizardCommands.next_step_in_pool``
        (a controller job runs in the job pool), its errors one notification."""
        s = self.session
        if self._command(str(event.target.value)) not in (NEXT, FINISH):
            await self._action(self._on_nav)(event)
            return
        if s.closed:
            return
        self.check.clear()
        try:
            await s.wizard_commands.next_step_in_pool()
        except ValueError as exc:          # the wizard's words, or the pool's (JobRefused)
            s.notify(s.translator.gettext("Not done"), error_text(exc, s.translator), kind="warning")
        except Exception as exc:           # a browser's click must never kill the server
            log.exception("Next / Finish failed")
            s.notify(s.translator.gettext("Internal error"), f"{type(exc).__name__}: {exc}", kind="error")

    def _on_nav(self, event: ButtonGroupEvent) -> None:
        s = self.session
        _ = s.translator.gettext
        choice = self._command(str(event.target.value))
        self.check.clear()
        if choice == BACK:
            s.wizard_commands.back()
        elif choice in (NEXT, FINISH):
            s.wizard_commands.next_step()
        elif choice in (CANCEL, CLOSE):
            if s.wizard_commands.cancel():
                self.session.notify(_("Calibration cancelled"),
                                    _("Nothing recorded is lost: Resume it from the Calibrate menu."))
        else:
            raise ValueError(_("Unknown step command {choice!r}; use {back}, {next} or {cancel}.").format(
                choice=str(event.target.value), back=_(BACK), next=_(NEXT), cancel=_(CANCEL)))

    # ------------------------------------------------------------ render
    def on_change(self, change: SessionChange) -> None:
        """The change signal: the whole dock after a wizard, tool or touches change (and every
        label after a ``language`` change); the meter after a move."""
        if change.language:
            self.words.relabel(self.session.translator)
            self._note, self._note_at = "", None      # said in the old language
        if change.wizard or change.tool or change.touches or change.language:
            self.render()
        elif change.pose and self.folder.visible:
            self.update_meter()

    def render(self) -> None:
        """Show the open wizard's step (hide the dock when no wizard is open)."""
        if self.session.closed:
            return
        wf = self.session.workflow
        wiz = wf.wizard
        open_ = wiz is not None and wf.is_open
        self.folder.visible = open_
        if wf is None or wiz is None or not open_:
            self._note, self._note_at = "", None
            return
        tr = self.session.translator
        _ = tr.gettext
        set_content(self.step_md, step_markdown(wiz, tr=tr))
        note = self._note if self._note_at == self._where() else ""
        failure = wf.finish_failure
        if failure is not None:                  # Finish could not compute: why, and what to do
            note = _("⚠ Finish not possible: {why}").format(why=escape_markdown(failure)) + (f"\n\n{note}" if note else "")
        self.note_md.visible = bool(note)
        if note:
            set_content(self.note_md, note)
        stepping = not wiz.is_complete
        needed = wf.required_tool() if stepping else None
        self.mount.visible = needed is not None
        if needed is not None:
            self.mount.label = _("Mount the {tool}").format(
                tool=shown_tool_label(needed.label, self.session.translator, in_sentence=True))
        self.record.visible = stepping and not wiz.auto_role(wiz.step).by_controller   # a scan: no Record
        self.record.disabled = not wiz.can_record
        # the button keeps its row through the whole XYZ 4-point (disabled until two touches give
        # an estimate, and once it is active), so the jog keys below never move when it comes
        self.pivot.visible = stepping and wiz.kind == "xyz4" and bool(getattr(wiz, "meter_active", False))
        self.pivot.disabled = self.session.wizard_commands.estimate_offer() is None
        options: tuple[str, ...]
        if stepping:
            options = (_(BACK), _(FINISH) if wiz.on_last_step else _(NEXT), _(CANCEL))
        else:
            options = (_(BACK), _(CLOSE))
        if tuple(self.nav.options) != options:
            self.nav.options = options
        self._shown_in = tr
        self.update_meter()

    def update_meter(self) -> None:
        """The pose-diversity meter (the wizards that declare it: ``Wizard.meter_active``)."""
        wf = self.session.workflow
        shown = wf.wizard
        show = shown is not None and bool(shown.meter_active)
        self.meter_md.visible = self.tilt_html.visible = show
        self.meter_bar.visible = show and not self.pivot.visible   # its row goes to the button (PIVOT_LABEL)
        if not show:
            return
        wiz = cast("MeterWizard", shown)              # meter_active: a wizard that declares the meter
        T_world_flange = self.session.controller.T_world_flange()
        meter = meter_gain(wiz, T_world_flange[:3, :3], [r.wizard for r in wf.runs])
        gain = meter.gain
        value, color = meter_level(gain)
        set_value(self.meter_bar, round(value, 1))
        self.meter_bar.color = color
        angle = gain.angle_to_nearest_deg
        _ = self.session.translator.gettext
        if math.isinf(angle):
            text = _("Pose diversity: first touch, any orientation.")
        elif gain.too_close:
            text = _("Pose diversity: ⚠ **too close**, {angle}°: tilt further.").format(angle=f"{angle:.0f}")
        elif math.isinf(gain.predicted_after):
            text = _("Pose diversity: {angle}° from the nearest touch; not yet determinable.").format(
                angle=f"{angle:.0f}")
        else:
            text = _("Pose diversity: {angle}° from the nearest touch; predicted TCP error {error} mm if "
                     "recorded here ({basis}).").format(angle=f"{angle:.0f}", error=f"{gain.predicted_after:.2f}",
                                                        basis=meter.basis_words(self.session.translator))
        set_content(self.meter_md, text)              # numbers and our words only
        s = self.session
        others = wiz.other_rotations()
        advice = self.advisor.advise(others, T_world_flange[:3, :3], s.jogger, meter.sigma_mm, tr=s.translator)
        reach = ""
        if len(others):
            from_mode = s.jogger.settings.mode.value == "Joint"
            reach = reachable_line(s.jogger.tilts.options(s.jogger.settings.frame),
                                   frame=s.jogger.settings.frame, joint_mode=from_mode, tr=s.translator)
        set_content(self.tilt_html, tilt_line_html(None if advice is None else advice.text, reach))
