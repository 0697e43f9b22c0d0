"""The Tool tab's TCP service with the beam sensor: "Check with beam" measures
the ACTIVE tool's TCP now, "Update" writes the measured TCP into the library.

The industrial loop after a crash: the tool is bent, "Check with beam" finds the deviation
between the stored TCP and the tip the beam sees, "Update" stores the measured TCP (calibration
method "beam", today's date) and makes it the active tool data, and the spin test ("TCP
check" above) verifies it.

Check: the job (``calibrate.beam_service.beam_check_job``: a snapshot of the robot model, the
joints, the sensor, the active tool data and its slot, the physical tool) is taken on viser's
event loop under the session lock; the scan (a few hundred milliseconds of geometry and two
solves) runs in the server's job pool (``SessionLoop.run_job``); its result is shown on the loop and the scan is replayed
in the scene (``views.beam_replay``), the robot going back to where it was, the camera turned
to the sensor. One check at a
time per session. Update: ``beam_service.update_tool_from_beam`` (it refuses when the slot
changed since the check), then ``SessionTools.apply_saved`` (the library re-read, the updated tool
the active data); refused when the active tool is no longer the one checked. Tool names reach
the markdown escaped (``beam_check_markdown`` escapes its own), notifications as plain text.

Language: every word is the session's (``session.translator``); a ``language`` change relabels
the folder and the buttons and says the result again (:meth:`BeamCheckView.relabel`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

import numpy as np

from tcp_pendant.controller.words import error_text
from tcp_pendant.calibrate.beam_service import (
    BeamCheck,
    beam_check_job,
    beam_check_markdown,
    update_tool_from_beam,
)
from tcp_pendant.calibrate.jobs import EXERCISE_REFUSAL
from tcp_pendant.job_pool import JobRefused
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import ENGLISH, N_, SOURCE_LANGUAGE, Translator
from tcp_pendant.views.beam_replay import ScanPlayer, beam_view_direction, scan_spheres
from tcp_pendant.views.framing import Framing
from tcp_pendant.views.scene import frame_cameras
from tcp_pendant.views.gui_util import ButtonEvent, clients_of, refused_before_job, target_of
from tcpcal.tool import Tool

if TYPE_CHECKING:
    from tcp_pendant.controller.beam_scan import BeamScan
    from tcp_pendant.wizards.beam import RecordedScan

__all__ = ["BeamCheckView", "update_markdown"]

log = logging.getLogger(__name__)

INTRO = N_("The robot moves the ACTIVE tool through the beam sensor by itself and measures its TCP. "
           "After a crash: **Check with beam**, then **Update** stores the measured TCP.")
_FOLDER = N_("TCP service (beam sensor)")
_CHECK = N_("Check with beam")


def _fmt3(v: Iterable[float]) -> str:
    return ", ".join(f"{0.0 if abs(float(x)) < 5e-4 else float(x):.3f}" for x in v)


def update_markdown(slot: int, before: Tool, after: Tool, *, tr: Translator = ENGLISH) -> str:
    """What Update did (tool name escaped), in ``tr``'s language."""
    return tr.gettext("✔ **Updated slot {slot}: {name}**: TCP ({tcp}) mm (was ({before}) mm), calibration method "
                      "{method}. It is the active tool data now; verify it with the TCP check (spin test) "
                      "above.").format(
        slot=slot, name=escape_markdown(after.name), tcp=_fmt3(after.tcp_mm), before=_fmt3(before.tcp_mm),
        method=escape_markdown(after.calibration.method if after.calibration else 'beam'))


class BeamCheckView:
    """The "TCP service (beam sensor)" folder of the Tool tab (see the module docstring)."""

    def __init__(self, session: Session, player: ScanPlayer) -> None:
        self.session = session
        self.player = player
        gui = target_of(session).gui
        self.folder = gui.add_folder(_FOLDER)
        with self.folder:
            self.intro_md = gui.add_markdown(INTRO)
            self.check = gui.add_button(_CHECK, color="blue",
                                        hint="Measure the active tool's TCP with the beam sensor now.")
            self.update = gui.add_button("Update", color="green", disabled=True,
                                         hint="Write the measured TCP into the library slot of the active tool.")
            self.replay = gui.add_button("Replay scan", disabled=True,
                                         hint="Show the last check's scan again in the 3D view.")
            self.result_md = gui.add_markdown("")
        self._checking = False
        self._said: Callable[[Translator], str] | None = None   # result_md's text in a language
        self.last_check: BeamCheck | None = None
        """The last check's result (None before one, and after its Update)."""
        self._q_before: np.ndarray | None = None
        self.framing: Framing | None = None
        """The camera framing of the last check's scan (None before one), for tests."""
        self.check.on_click(self._on_check)
        g = session.loop.on_loop
        self.update.on_click(g(self._on_update))
        self.replay.on_click(g(self._on_replay))
        if session.language != SOURCE_LANGUAGE:
            self.relabel()
        session.subscribe(self.on_change)

    @property
    def tr(self) -> Translator:
        """The session's language."""
        return self.session.translator

    def on_change(self, change: SessionChange) -> None:
        """The change signal: Update is offered only while the active tool is the one checked;
        every text again on ``language``."""
        if change.language:
            self.relabel()
        if change.tool or change.library:
            self._render_buttons()

    def relabel(self) -> None:
        """The folder, the intro, the buttons and the result in the session's language."""
        _ = self.tr.gettext
        self.folder.label = _(_FOLDER)
        self.intro_md.content = _(INTRO)
        self.check.label = _(_CHECK)
        self.check.hint = _("Measure the active tool's TCP with the beam sensor now.")
        self.update.label = _("Update")
        self.update.hint = _("Write the measured TCP into the library slot of the active tool.")
        self.replay.label = _("Replay scan")
        self.replay.hint = _("Show the last check's scan again in the 3D view.")
        self._show_said()

    def _say(self, said: Callable[[Translator], str]) -> None:
        """Show ``said`` (the result's text as a function of the language) and keep it for a switch."""
        self._said = said
        self._show_said()

    def _show_said(self) -> None:
        if self._said is not None:
            self.result_md.content = self._said(self.tr)

    def _still_checked(self) -> bool:
        chk = self.last_check
        s = self.session
        tool = s.controller.active_tool
        return chk is not None and tool is not None and s.tools.active_slot == chk.slot and tool == chk.stored_tool

    def _render_buttons(self) -> None:
        self.check.disabled = self._checking
        checked = self.last_check
        self.update.disabled = self._checking or not self._still_checked() or checked is None or checked.slot is None
        self.replay.disabled = self._checking or self.last_check is None

    # ------------------------------------------------------------ Check with beam
    async def _on_check(self, _event: ButtonEvent) -> None:
        try:
            await self.run_check()
        except Exception as exc:           # a browser's click must never kill the server
            log.exception("beam check failed")
            self._failed(N_("Beam check failed"), f"{type(exc).__name__}: {exc}", kind="error")

    async def run_check(self) -> None:
        """The check of the active tool: job on the loop, scan in the worker, result on the loop;
        refused at once while this session's job runs or its share is used up
        (``SessionLoop.admit_job``)."""
        s, _ = self.session, self.tr.gettext
        if refused_before_job(s, running=self._checking, what=_("beam check"),
                              not_started=_("Beam check not started")):
            return
        try:
            with s.lock:
                tool = s.controller.active_tool
                if s.workflow.hide_truth:
                    raise ValueError(_(EXERCISE_REFUSAL).format(what=_(_CHECK)))
                if tool is None:
                    raise ValueError(_("No tool data is active (TCP = flange): activate the tool to check in the "
                                       "Tool library first."))
                player = self.player
                if not (player.playing and player.owner is self):   # a check during our film: back to
                    self._q_before = s.controller.q_rad             # where the first one started
                player.stop()                                       # the robot stays where the job sees it
                job = beam_check_job(s.controller, s.tools.active_slot, tool, rng_seed=int(s.rng.integers(2**31)),
                                     tr=self.tr)
                self._checking = True
                name = escape_markdown(tool.name)
                self._say(lambda tr: tr.gettext("Scanning **{name}** with the beam sensor ...").format(name=name))
                self._render_buttons()
        except ValueError as exc:          # ControllerError and tcpcal's errors are ValueErrors
            s.notify(_("Not done"), error_text(exc, self.tr), kind="warning")
            return
        try:
            check = await s.loop.run_job(job.run, what="a beam check")
        except JobRefused as exc:          # another job of this session, or a full queue: nothing ran
            self._failed(N_("Beam check not started"), error_text(exc, self.tr), kind="warning")
            return
        except ValueError as exc:          # nothing could be scanned: plain words from the controller
            self._failed(N_("Beam check not done"), error_text(exc, self.tr), kind="warning")
            return
        except Exception as exc:           # a browser's click must never kill the server
            log.exception("beam check failed")
            self._failed(N_("Beam check failed"), f"{type(exc).__name__}: {exc}", kind="error")
            return
        with s.lock:
            self._checking = False
            if s.closed:
                return
            self.last_check = check
            self._say(lambda tr: beam_check_markdown(check, tr=tr))
            self._render_buttons()
            self.player.play(check.scan, owner=self, return_to=self._q_before)
            self.frame_scan(check.scan)
        s.notify(_("Beam check done"), _("{name}: deviation {deviation} mm").format(
            name=check.tool_name, deviation=f"{check.deviation_norm_mm:.3f}"), kind="info")

    def frame_scan(self, scan: BeamScan | RecordedScan) -> None:
        """Turn the session's camera(s) to the beam sensor, the scan's events and the flange
        there, seen across the beam (as the wizard's result is framed)."""
        if not len(scan.events):
            return
        centres, radii = scan_spheres(scan)
        direction = beam_view_direction(scan.events[0].beam_point, scan.events[0].beam_dir)
        self.framing = frame_cameras(clients_of(self.session), centres, radii, direction=direction, margin=1.4)

    def _failed(self, title: str, body: str, *, kind: str) -> None:
        """``title``: an English message (translated here); ``body``: already in its words."""
        s = self.session
        with s.lock:
            self._checking = False
            if s.closed:
                return
            shown = f"⚠ {escape_markdown(body)}"
            self._say(lambda _tr: shown)
            self._render_buttons()
        s.notify(self.tr.gettext(title), body, kind=kind)

    # ------------------------------------------------------------ Update
    def _on_update(self, _event: ButtonEvent) -> None:
        s, _ = self.session, self.tr.gettext
        check = self.last_check
        if check is None:
            raise ValueError(_("Check with beam first: Update writes the TCP the check measured."))
        if check.slot is None:
            raise ValueError(_("The checked tool data is not in the library (typed in or an unsaved result): "
                               "save it to a slot first, then check again."))
        if not self._still_checked():
            raise ValueError(_("The active tool changed since the check; check the active tool again before "
                               "Update."))
        before = check.stored_tool
        tool = update_tool_from_beam(s.library, check.slot, check, s.tools.library_rights)
        self.last_check = None
        s.tools.apply_saved(check.slot, tool)                    # one signal: library re-read, active data
        slot = check.slot
        self._say(lambda tr: beam_check_markdown(check, tr=tr) + "\n\n" + update_markdown(slot, before, tool, tr=tr))
        self._render_buttons()
        s.notify(_("TCP updated"), _("Slot {slot}: {name} now has the TCP the beam measured.").format(
            slot=slot, name=tool.name), kind="success")

    def _on_replay(self, _event: ButtonEvent) -> None:
        check = self.last_check
        player = self.player
        if check is None:
            raise ValueError(self.tr.gettext("No beam check to replay: press Check with beam first."))
        player.play(check.scan, owner=self, return_to=self._q_before)
