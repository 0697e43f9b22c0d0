"""The TCP check (spin test) as a wizard (methods.md "TCP check").

A technician checks a TCP by putting the tool tip on a fixed spike and reorienting the tool
about the active TCP by +-A, +-B, +-C: a correct TCP stays on the spike. This wizard takes a
library tool (made active at start), asks for one step (the tool tip on the reference tip,
Record), and on Finish shows how far the TRUE tip moved per rotation, the implied TCP error
and the correction (FLANGE, mm), with a verdict.

The state machine stays free of viser and of the controller: the six rotations are run by the
caller (``calibrate.jobs.spin_check_job``; the app runs it in a worker thread) from the
recorded pose, and the outcome is handed in with :meth:`TcpCheckWizard.give_check` (any
object shaped like ``controller.spin.SpinCheckResult``); only then can the wizard finish.
A check is not a calibration: nothing is graded against truth (no true tool at start) and
nothing can be saved (``saves_to_library`` False, :meth:`TcpCheckWizard.to_tool` refuses).
The session record stores the check's figures in the wizard's params, so a replay rebuilds
the same result without a robot (the figures are checked and bounded on load).

Units: mm and degrees throughout.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, Literal

import numpy as np

from tcpcal.tool import Tool

from tcp_pendant.json_shapes import JsonRecord
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.wizards.check_reading import CHECK_READING_MM, read_mm, reading_note, reading_verdict
from tcp_pendant.wizards.base import (
    RecordedPose,
    StartContext,
    StepSpec,
    Wizard,
    WizardError,
    WizardResult,
    WizardStateError,
    finite_number,
    mm3,
)
from tcp_pendant.wizards.describe import TOUCH, StepRole, WizardOption, WizardStart

if TYPE_CHECKING:
    from tcp_pendant.controller.spin import SpinCheckResult

__all__ = ["CheckFigures", "CheckRow", "GOOD_CHECK_MM", "TcpCheckResult", "TcpCheckWizard",
           "tcp_check_markdown"]

GOOD_CHECK_MM = 0.5
"""Implied TCP error up to which the check calls the TCP good (a careful touch's accuracy), mm."""
_MAX_TEXT = 200          # characters kept of a stored message (the record is untrusted input)


@dataclass(frozen=True)
class CheckRow:
    """One rotation of the check: label ("+A 30°"), whether it was reached, the controller's
    words when it stopped early, and how far the true tip moved (mm)."""

    label: str
    reached: bool
    message: str
    deviation_mm: float


@dataclass(frozen=True)
class CheckFigures:
    """What a TCP check found (mm, degrees); built from a ``SpinCheckResult``.

    Attributes:
        angle_deg: rotation angle used.
        rows: +A, -A, +B, -B, +C, -C.
        implied_tcp_error_mm: ``|e|``, None when the reached rotations do not determine it.
        correction_flange_mm: add it to the tool data's TCP (FLANGE axes), None as above.
        fit_rms_mm: what no TCP error explains (RMS), None as above.
        read_to_mm: None: the figures as computed; a number: a technician's reading
            (``wizards.check_reading``, an exercise): the deviations rounded to it, no implied
            error, no correction, no fit RMS.
    """

    angle_deg: float
    rows: tuple[CheckRow, ...]
    implied_tcp_error_mm: float | None
    correction_flange_mm: tuple[float, float, float] | None
    fit_rms_mm: float | None
    read_to_mm: float | None = None

    def as_reading(self) -> "CheckFigures":
        """What a technician sees (an exercise): per rotation how far the tip moved, rounded to
        ``check_reading.CHECK_READING_MM``; the implied error, correction and fit RMS dropped."""
        rows = tuple(CheckRow(r.label, r.reached, r.message, read_mm(r.deviation_mm)) for r in self.rows)
        return CheckFigures(self.angle_deg, rows, None, None, None, read_to_mm=CHECK_READING_MM)

    @classmethod
    def of(cls, spin: SpinCheckResult) -> "CheckFigures":
        """From a ``controller.spin.SpinCheckResult``."""
        rows = tuple(CheckRow(str(r.label), bool(r.reached), str(r.message or (r.stopped_by or ""))[:_MAX_TEXT],
                              float(r.deviation_mm)) for r in spin.rotations)
        off = spin.implied_offset_flange_mm
        err = spin.implied_tcp_error_mm
        return cls(float(spin.angle_deg), rows, None if err is None else float(err),
                   None if off is None else mm3(off),
                   None if spin.fit_rms_mm is None else float(spin.fit_rms_mm))

    @property
    def max_deviation_mm(self) -> float | None:
        """Largest deviation of the reached rotations (None if none was reached)."""
        devs = [r.deviation_mm for r in self.rows if r.reached]
        return max(devs) if devs else None

    @property
    def verdict(self) -> str:
        """The verdict in English (:meth:`verdict_in`)."""
        return self.verdict_in(ENGLISH)

    def verdict_in(self, tr: Translator) -> str:
        """One line: good / off by how much / not determined (plain text, in ``tr``'s language).
        "Good" needs every
        rotation: one that could not be made proves nothing about its axis, so the verdict stays
        open (an error already found among the others stands); an exercise's reading says what
        the readings say (``check_reading.reading_verdict``)."""
        _ = tr.gettext
        if self.read_to_mm is not None:
            return reading_verdict(((r.reached, r.deviation_mm) for r in self.rows), self.angle_deg, tr=tr)
        err = self.implied_tcp_error_mm
        missing = [r.label for r in self.rows if not r.reached]
        if err is not None and err > GOOD_CHECK_MM:
            return _("TCP off by {mm} mm: calibrate the tool again (or it is bent).").format(mm=f"{err:.3f}")
        if missing:
            return _("Not determined: {rotations} could not be made from this pose (joint limit or "
                     "singularity), so the check proves nothing about them. Touch the reference tip from "
                     "an orientation farther from the joint limits, record again and check again.").format(
                         rotations=", ".join(missing))
        if err is None:
            return _("Not determined: fewer than two of A, B, C were reached; move away from the joint "
                     "limits, record again and check again.")
        return _("TCP good: implied error {mm} mm (at most {good} mm).").format(
            mm=f"{err:.3f}", good=f"{GOOD_CHECK_MM:g}")

    def to_dict(self) -> dict[str, object]:
        d: dict[str, object] = {
            "angle_deg": self.angle_deg,
            "rows": [{"label": r.label, "reached": r.reached, "message": r.message,
                      "deviation_mm": r.deviation_mm} for r in self.rows],
            "implied_tcp_error_mm": self.implied_tcp_error_mm,
            "correction_flange_mm": None if self.correction_flange_mm is None else list(self.correction_flange_mm),
            "fit_rms_mm": self.fit_rms_mm}
        if self.read_to_mm is not None:
            d["read_to_mm"] = self.read_to_mm
        return d

    @classmethod
    def from_dict(cls, d: object) -> "CheckFigures":
        """Inverse of :meth:`to_dict`, checked (a record is untrusted: at most 6 rows, finite
        numbers, messages cut to 200 characters).

        Raises:
            WizardError: naming what is wrong.
        """
        if not isinstance(d, Mapping):
            raise WizardError("The TCP check's stored figures must be an object.")
        rows_in = d.get("rows")
        if not isinstance(rows_in, list) or len(rows_in) > 6:
            raise WizardError("The TCP check's stored rows must be a list of at most 6 rotations.")
        rows = []
        for r in rows_in:
            if not isinstance(r, Mapping):
                raise WizardError("Each stored TCP check row must be an object.")
            rows.append(CheckRow(str(r.get("label", ""))[:_MAX_TEXT], bool(r.get("reached")),
                                 str(r.get("message", ""))[:_MAX_TEXT],
                                 finite_number(r.get("deviation_mm"), "TCP check's deviation")))
        err = d.get("implied_tcp_error_mm")
        off = d.get("correction_flange_mm")
        rms = d.get("fit_rms_mm")
        if off is not None and not (isinstance(off, list) and len(off) == 3):
            raise WizardError("The TCP check's stored correction must be 3 numbers (mm).")
        figures = cls(finite_number(d.get("angle_deg"), "TCP check's angle"), tuple(rows),
                      None if err is None else finite_number(err, "TCP check's implied error"),
                      None if off is None else mm3([finite_number(v, "TCP check's correction") for v in off]),
                      None if rms is None else finite_number(rms, "TCP check's fit RMS"))
        return figures.as_reading() if d.get("read_to_mm") is not None else figures


@dataclass(frozen=True, eq=False, kw_only=True)
class TcpCheckResult(WizardResult):
    """The TCP check's result: ``tcp_mm`` is the checked tool data's TCP (unchanged), plus the
    check's figures and the checked tool's name and slot."""

    check: CheckFigures
    tool_name: str
    slot: int | None


class TcpCheckWizard(Wizard):
    """TCP check (spin test) of a library tool (see the module docstring).

    Args:
        tool: the library tool data checked (made active at start).
        slot: its library slot (None: not from the library).
        angle_deg: rotation angle, degrees, in (0, 90].
    """

    kind: ClassVar[str] = "tcp-check"
    title: ClassVar[str] = N_("TCP check (spin test)")
    blurb: ClassVar[str] = N_("**Checks** a tool's TCP as a technician does: with the tip on the reference "
                            "tip the controller turns the tool about its TCP by ±A, ±B, ±C; a correct TCP "
                            "stays put. Shows how far the true tip moves per rotation (mm), the implied "
                            "TCP error and the correction. Calibrates nothing, saves nothing.")
    calibrates: ClassVar[str] = N_("nothing (it checks the TCP)")
    rank: ClassVar[int] = 90
    math_view: ClassVar[str | None] = "spin_check"
    step_roles = (StepRole("touch", N_("the tool tip on the reference tip"), TOUCH),)
    options = (
        WizardOption("slot", N_("Tool data"), "library_slot", hint=N_("The library tool whose TCP is checked.")),
        WizardOption("angle_deg", N_("Check angle (deg)"), "int", default=30, minimum=1, maximum=90,
                     hint=N_("How far each of ±A, ±B, ±C turns (technicians use 10-45).")),
    )
    needs_tool = "library"
    saves_to_library: ClassVar[bool] = False
    controller_job: ClassVar[str | None] = "spin_check"
    result_view: ClassVar[Literal["touches", "spin_check", "beam_scan"]] = "spin_check"
    """No Save: a check changes no tool data (the result view hides Save, the workflow refuses)."""

    def __init__(self, tool: Tool, *, slot: int | None = None, angle_deg: float = 30.0) -> None:
        super().__init__()
        if not isinstance(tool, Tool):
            raise WizardError("The TCP check needs a tool of the library (its TCP data).")
        a = finite_number(angle_deg, "TCP check's angle")
        if not 0.0 < a <= 90.0:
            raise WizardError(f"The check angle must be above 0 and at most 90 degrees, got {angle_deg!r}.")
        self.tool = tool
        self.slot = None if slot is None else int(slot)
        self.angle_deg = a
        self._check: CheckFigures | None = None
        self._checked_pose: RecordedPose | None = None

    @classmethod
    def start(cls, ctx: StartContext, options: JsonRecord) -> WizardStart:
        """For the library tool in ``slot``, made active (the rotations turn about its TCP); no
        true tool: a check is not graded."""
        slot = int(options["slot"])
        tool = ctx.library_tool(slot)
        return WizardStart(cls(tool, slot=slot, angle_deg=options.get("angle_deg", 30)),
                           true_tool=None, active_data=(tool, slot))

    @property
    def library_tool_name(self) -> str | None:
        return self.tool.name

    # ----- steps --------------------------------------------------------------------------
    def _step_specs(self) -> list[StepSpec]:
        _ = self._tr.gettext
        return [StepSpec(role="touch", title=_("Tip on the reference tip"),
                         instruction=_("Jog the tool tip onto the reference tip (any orientation clear of "
                                       "the joint limits), then press Record. Finish runs the check: the "
                                       "controller turns the tool ±{angle}° about A, B and C "
                                       "around the active TCP and measures how far the tip moves.").format(
                                           angle=f"{self.angle_deg:g}"))]

    # ----- the check, run by the caller ---------------------------------------------------
    @property
    def recorded_pose(self) -> RecordedPose | None:
        """The recorded touch (the check starts there), or None."""
        return self._poses.get(0)

    @property
    def check_pending(self) -> bool:
        """The touch is recorded but not checked yet (Finish must run the check first)."""
        pose = self.recorded_pose
        return self._status == "in_progress" and pose is not None and self._checked_pose is not pose

    @property
    def check(self) -> CheckFigures | None:
        """The check of the recorded touch, or None (none yet, or the touch was recorded again)."""
        pose = self.recorded_pose
        return self._check if pose is not None and self._checked_pose is pose else None

    def give_check(self, spin: SpinCheckResult | CheckFigures, pose: RecordedPose | None = None) -> None:
        """Hand in the check (a ``SpinCheckResult`` or :class:`CheckFigures`) run from the
        recorded touch ``pose`` (default: the current one).

        Raises:
            WizardStateError: nothing recorded, or ``pose`` is no longer the recorded touch
                (the touch was recorded again while the check ran: check again).
        """
        current = self.recorded_pose
        if current is None:
            raise WizardStateError(self._tr.gettext("Record the touch before running the check."))
        if pose is not None and pose is not current:
            raise WizardStateError(self._tr.gettext(
                "The touch was recorded again while the check ran; press Finish again."))
        self._check = spin if isinstance(spin, CheckFigures) else CheckFigures.of(spin)
        self._checked_pose = current

    # ----- result -------------------------------------------------------------------------
    def _compute(self, poses: list[np.ndarray]) -> WizardResult:
        _ = self._tr.gettext
        check = self.check
        if check is None:
            raise WizardStateError(_("Run the check first: press Finish (the controller turns the tool)."))
        off = check.correction_flange_mm
        notes = (_("A check changes no tool data. To correct it, calibrate the tool again "
                   "(or add the correction to its TCP on the Tool tab)."),)
        return TcpCheckResult(
            wizard=self.kind, method="tcp-check", tcp_mm=mm3(self.tool.tcp_mm),
            max_error_mm=check.max_deviation_mm,
            per_touch_error_mm=tuple(r.deviation_mm for r in check.rows),
            warnings=tuple(_("{rotation} not reached: {reason}").format(rotation=r.label, reason=r.message)
                           for r in check.rows if not r.reached),
            notes=notes if off is not None and (check.implied_tcp_error_mm or 0.0) > GOOD_CHECK_MM else (),
            check=check, tool_name=self.tool.name, slot=self.slot)

    def to_tool(self, name: str) -> Tool:
        """A check saves nothing."""
        raise WizardStateError(self._tr.gettext(
            "A TCP check saves nothing to the library: it only checks the tool data."))

    # ----- serialisation ------------------------------------------------------------------
    def _params(self) -> dict[str, object]:
        check = self.check
        return {"tool": self.tool.to_dict(), "slot": self.slot, "angle_deg": self.angle_deg,
                "check": None if check is None else check.to_dict()}

    @classmethod
    def _from_params(cls, params: JsonRecord) -> "TcpCheckWizard":
        return cls(Tool.from_dict(params["tool"]), slot=params.get("slot"),
                   angle_deg=params.get("angle_deg", 30.0))

    def _load_state(self, d: JsonRecord) -> None:
        """The stored check belongs to the stored touch: hand it in before the base class
        finishes a complete wizard (a replay runs no robot)."""
        params = d.get("params")
        stored = params.get("check") if isinstance(params, Mapping) else None
        if stored is None:
            super()._load_state(d)
            return
        super()._load_state({**d, "resume_status": "in_progress", "status": "in_progress"})
        self.give_check(CheckFigures.from_dict(stored))
        if d.get("resume_status", d.get("status")) == "complete":
            self.finish()
        if d.get("status") == "cancelled":
            self.cancel()


def tcp_check_markdown(result: TcpCheckResult, *, tr: Translator = ENGLISH) -> str:
    """The check's result as markdown: per rotation the tip's deviation (mm), the implied TCP
    error, the correction (FLANGE, mm) and the verdict (the tool's name escaped), in ``tr``'s language."""
    _ = tr.gettext
    c = result.check
    name = escape_markdown(result.tool_name)
    reading = c.read_to_mm is not None
    heading = (_("**TCP check of {tool}** at ±{angle}°").format(tool=name, angle=f"{c.angle_deg:g}")
               if result.slot is None else
               _("**TCP check of slot {slot}: {tool}** at ±{angle}°").format(
                   slot=result.slot, tool=name, angle=f"{c.angle_deg:g}"))
    columns = (_("| Rotation | Tip moved (mm, by eye) | |") if reading else _("| Rotation | Tip moved (mm) | |"))
    lines = [heading, "", columns, "|---|---:|---|"]
    for r in c.rows:
        if r.reached:
            lines.append(f"| {escape_markdown(r.label)} | {r.deviation_mm:.{1 if reading else 3}f} | ✔ |")
        else:                                   # no figure: the rotation was not made
            lines.append(_("| {rotation} | not made | stopped: {reason} |").format(
                rotation=escape_markdown(r.label), reason=escape_markdown(r.message)))
    lines.append("")
    if reading:
        lines += [reading_note(tr=tr), ""]
    if c.implied_tcp_error_mm is not None and c.correction_flange_mm is not None:
        dx, dy, dz = (0.0 if abs(v) < 5e-4 else v for v in c.correction_flange_mm)
        lines.append(_("**Implied TCP error: {error} mm** · suggested correction "
                       "(add to the TCP, FLANGE): X {dx} · Y {dy} · Z {dz} mm · "
                       "what no TCP explains: {rms} mm RMS").format(
                           error=f"{c.implied_tcp_error_mm:.3f}", dx=f"{dx:+.3f}", dy=f"{dy:+.3f}",
                           dz=f"{dz:+.3f}", rms=f"{c.fit_rms_mm or 0.0:.3f}"))
        lines.append("")
    lines.append(f"**{c.verdict_in(tr)}**")
    return "\n".join(lines)
