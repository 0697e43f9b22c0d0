"""The Tool tab's "Check" (TCP check, spin test) without the wizard: the job and its words.

:func:`check_job` takes what the check needs from the session's controller (under the session
lock, on viser's event loop) into a :class:`CheckJob` with its OWN pinocchio data (copies of
the nominal and the physical robot model's ``RobotKinematics``), so :meth:`CheckJob.run` (six
sub-stepped rotations, 0.1-0.3 s) can run in a worker thread while the loop keeps jogging;
the controller is not moved. :func:`check_markdown` makes the result's text (the tool's name
escaped: it is user text). No viser here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tcp_pendant.controller.tools import shown_tool_label
from tcp_pendant.controller import RobotKinematics, T_flange_tool_m, VirtualController
from tcp_pendant.controller.jog import JogSettings
from tcp_pendant.controller.words import in_language
from tcp_pendant.controller.spin import MAX_SPIN_ANGLE_DEG, SpinCheckResult, spin_check
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.wizards.check_reading import read_mm, reading_note, reading_verdict
from tcpcal.tool import Tool

__all__ = ["CheckJob", "check_job", "check_markdown", "check_verdict"]

GOOD_CHECK_MM = 0.5
"""Implied TCP error up to which the check calls the TCP good (a careful touch's accuracy)."""


@dataclass(frozen=True, eq=False)
class CheckJob:
    """Everything one TCP check needs, detached from the session (metres, radians).

    Attributes:
        title: what is checked, plain text (e.g. "slot 2: Torch").
        tool: the tool data checked.
        mounted_label: the physical tool on the flange (plain text).
        angle_deg: the rotation angle, degrees.
    """

    title: str
    tool: Tool
    mounted_label: str
    angle_deg: float
    kinematics: RobotKinematics
    true_kinematics: RobotKinematics
    q_rad: np.ndarray
    T_flange_tool_true: np.ndarray
    settings: JogSettings

    def run(self) -> SpinCheckResult:
        """The check (``spin.spin_check``): the nominal model plans the motion about the tool
        data's TCP, the physical robot and tool say where the true tip goes."""
        return spin_check(self.kinematics, self.q_rad, T_flange_tool_m(self.tool), self.T_flange_tool_true, angle_deg=self.angle_deg,
                          true_kinematics=self.true_kinematics, settings=self.settings)


def check_job(controller: VirtualController, tool: Tool, title: str, angle_deg: float, *,
              tr: Translator = ENGLISH) -> CheckJob:
    """A :class:`CheckJob` of ``tool`` from the controller's current state (a refusal in ``tr``'s
    language).

    Raises:
        ValueError: an angle outside (0, 90] degrees (names the range).
    """
    try:
        angle = float(angle_deg)
    except (TypeError, ValueError):
        raise ValueError(tr.gettext("The check angle must be a number of degrees, got {value}.").format(
            value=repr(angle_deg))) from None
    if not math.isfinite(angle) or not 0.0 < angle <= MAX_SPIN_ANGLE_DEG:
        raise ValueError(tr.gettext("The check angle must be above 0 and at most {max} degrees "
                                    "(technicians use 10-45), got {value}.").format(
            max=f"{MAX_SPIN_ANGLE_DEG:g}", value=repr(angle_deg)))
    c = controller
    nominal, physical = c.kinematics_for_worker()
    return CheckJob(title=title, tool=tool, mounted_label=c.mounted_tool.label, angle_deg=angle,
                    kinematics=nominal, true_kinematics=physical, q_rad=c.q_rad,
                    T_flange_tool_true=np.array(c.mounted_tool.T_flange_tool_true, dtype=float),
                    settings=c.settings)


def check_verdict(result: SpinCheckResult, *, tr: Translator = ENGLISH) -> str:
    """One line: good / off by how much / undetermined (plain text, ``tr``'s language)."""
    _ = tr.gettext
    err = result.implied_tcp_error_mm
    if err is None:
        return _("Not determined: fewer than two of A, B, C were reached; move away from limits and check again.")
    if err <= GOOD_CHECK_MM:
        return _("TCP good: implied error {error} mm (at most {limit} mm).").format(
            error=f"{err:.3f}", limit=f"{GOOD_CHECK_MM:g}")
    return _("TCP off by {error} mm: calibrate again (or the tool is bent).").format(error=f"{err:.3f}")


def check_markdown(job: CheckJob, result: SpinCheckResult, *, reading: bool = False,
                   tr: Translator = ENGLISH) -> str:
    """The result as markdown: per rotation the tip's deviation (mm), then the implied TCP
    error and the correction (user text escaped). ``reading`` (an exercise): what a technician
    sees instead - per rotation how far the tip moved, read by eye (``wizards.check_reading``),
    and a verdict from those readings; no implied error vector, no correction."""
    _ = tr.gettext
    lines = [_("**TCP check of {title}** at ±{angle}° (mounted: {mounted})").format(
                 title=escape_markdown(job.title), angle=f"{result.angle_deg:g}",
                 mounted=escape_markdown(shown_tool_label(job.mounted_label, tr))), "",
             "| {rotation} | {moved} | |".format(rotation=_("Rotation"),
                                                 moved=_("Tip moved (mm, by eye)") if reading else _("Tip moved (mm)")),
             "|---|---:|---|"]
    readings = []
    for r in result.rotations:
        status = "✔" if r.reached else _("stopped: {why}").format(why=escape_markdown(in_language(r.message, tr) or str(r.stopped_by)))
        moved = f"{read_mm(r.deviation_mm):.1f}" if reading else f"{r.deviation_mm:.3f}"
        readings.append((r.reached, read_mm(r.deviation_mm)))
        lines.append(f"| {r.label} | {moved} | {status} |")
    lines.append("")
    if reading:
        lines += [reading_note(tr=tr), "", f"**{reading_verdict(readings, result.angle_deg, tr=tr)}**"]
        return "\n".join(lines)
    err = result.implied_tcp_error_mm
    if err is not None and result.implied_offset_flange_mm is not None:
        dx, dy, dz = (0.0 if abs(v) < 5e-4 else float(v) for v in result.implied_offset_flange_mm)  # no "-0.000"
        lines.append(_("**Implied TCP error: {error} mm** (the true tip is at TCP + "
                       "({dx}, {dy}, {dz}) mm in FLANGE axes); what no TCP explains: {rms} mm RMS.").format(
            error=f"{err:.3f}", dx=f"{dx:+.3f}", dy=f"{dy:+.3f}", dz=f"{dz:+.3f}", rms=f"{result.fit_rms_mm:.3f}"))
    lines.append("")
    lines.append(f"**{check_verdict(result, tr=tr)}**")             # our own words, no user text
    return "\n".join(lines)
