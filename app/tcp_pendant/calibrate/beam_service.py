"""The TCP service with the beam sensor: "Check with beam" and "Update".

The industrial loop after a crash: the tool is bent, the stored tool data is stale. "Check
with beam" runs the automatic scan (``controller.beam_scan``) with the tool data the
controller believes, measures the TCP (``tcpcal.solve_beam``) and the tool direction
(``tcpcal.solve_beam_axis``) of the tool the beam really sees, and compares them with the
stored data; "Update" writes the measured TCP into the tool's library slot (calibration method
``"beam"``, date now). The spin test (``controller.spin``) then verifies the updated data.

Threads: :func:`beam_check_job` takes a snapshot on viser's event loop, under the session lock
(the robot model copied with its own pinocchio data, joints, sensor, tool data, physical tool);
:meth:`BeamCheckJob.run` is pure and runs in a worker thread. No viser here.

Units: the controller's metres inside the job, mm and degrees in :class:`BeamCheck` (the
pendant's units).
"""

from __future__ import annotations

import math
import secrets
from dataclasses import dataclass, replace

import numpy as np

from tcp_pendant.controller.words import in_language
from tcp_pendant.controller import RobotKinematics, T_flange_tool_m, VirtualController
from tcp_pendant.controller.beam import BeamSensor, ToolShape
from tcp_pendant.controller.beam_scan import BeamScan, BeamScanConfig, run_beam_scan, scan_arrays_mm, tool_shape
from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.calibrate.pendant_rules import UNRESTRICTED, LibraryRights
from tcpcal.beam import BeamAxisResult, BeamResult, solve_beam, solve_beam_axis
from tcpcal.errors import TcpcalError
from tcpcal.library import ToolLibrary
from tcpcal.origin import SIGMA_RANGE
from tcpcal.tool import Calibration, Tool
from tcpcal.validation import read_only_array

__all__ = [
    "BEAM_METHOD",
    "GOOD_BEAM_MM",
    "BeamCheck",
    "BeamCheckJob",
    "BeamServiceError",
    "beam_check_job",
    "beam_check_markdown",
    "beam_verdict",
    "update_tool_from_beam",
]

GOOD_BEAM_MM = 0.5
"""Deviation of the measured TCP from the stored one up to which the check calls the TCP good
(the spin test's tolerance, ``views.tool_check.GOOD_CHECK_MM``)."""
DIRECTION_NOTE_DEG = 0.5
CONSISTENT_FACTOR = 3.0
"""The tip events agree when their RMS distance from the beam line is at most this many times
their repeatability (``BeamScan.tip_sigma_m``); beyond, the verdict names the robot's absolute
accuracy (methods.md section 11)."""
"""Above this the verdict says that the tool direction differs from the stored X axis."""
BEAM_METHOD = "beam"
"""The calibration method :func:`update_tool_from_beam` writes."""


class BeamServiceError(ControllerError):
    """The TCP service refused (a check that cannot be written, a slot that changed)."""


def _angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    """Angle between two vectors, degrees (accurate for tiny angles)."""
    return math.degrees(math.atan2(float(np.linalg.norm(np.cross(a, b))), float(np.dot(a, b))))


@dataclass(frozen=True, eq=False)
class BeamCheck:
    """The result of a beam check (mm, degrees; FLANGE coordinates).

    Attributes:
        tool_name: the checked tool data's name (user text: escape it for markdown).
        slot: its library slot, or None (tool data not from the library).
        stored_tool: the tool data as it was when checked (Update refuses if the slot differs).
        stored_tcp_mm: (3,) the stored TCP.
        measured_tcp_mm: (3,) the TCP the beam measured.
        deviation_mm: (3,) ``measured - stored``, FLANGE.
        deviation_norm_mm: its length.
        ci95_mm: 95 % radius of the measured TCP (``solve_beam`` with the tip events'
            repeatability, ``BeamScan.tip_sigma_m``).
        residual_rms_mm: RMS distance of the computed tip from the beam line over the tip
            events (``BeamResult.rms_error``): about the repeatability when the events agree.
        consistent: the residual is at most :data:`CONSISTENT_FACTOR` times the repeatability.
        direction_deviation_deg: angle between the measured tool direction and the stored tool
            X axis, or None when the axis events did not determine it.
        measured_direction: (3,) the measured unit tool direction in FLANGE, or None.
        scan: the scan (events, moves, time on a real robot).
        beam_result: tcpcal's result of the tip events.
        axis_result: tcpcal's result of the axis events, or None.
        verdict: plain text: good, or off by how much and what to do (English; in another
            language :func:`beam_verdict`).
        good: the deviation is at most :data:`GOOD_BEAM_MM`.
        seed: the random seed of the repeatability noise (a check is reproducible from it).
        tip_sigma_mm: the tip events' repeatability the residual is judged against, mm.
    """

    tool_name: str
    slot: int | None
    stored_tool: Tool
    stored_tcp_mm: np.ndarray
    measured_tcp_mm: np.ndarray
    deviation_mm: np.ndarray
    deviation_norm_mm: float
    ci95_mm: float
    residual_rms_mm: float
    consistent: bool
    direction_deviation_deg: float | None
    measured_direction: np.ndarray | None
    scan: BeamScan
    beam_result: BeamResult
    axis_result: BeamAxisResult | None
    verdict: str
    good: bool
    seed: int
    tip_sigma_mm: float = math.nan


@dataclass(frozen=True, eq=False)
class BeamCheckJob:
    """Everything one beam check needs, detached from the session (metres, radians).

    Attributes:
        tool: the tool data checked (what the controller plans with).
        slot: its library slot, or None.
        kinematics: the nominal robot model (own pinocchio data).
        true_kinematics: the physical robot (the same object when there is no accuracy error).
        q_rad: joint values where the scan starts.
        sensor: the beam sensor.
        shape: the physical tool as the beam sees it (its true frame).
        mounted_label: the physical tool's name (plain text).
        config: the scan's configuration.
        seed: random seed of the repeatability noise.
        tr: the language of a refusal (too few tip events).
    """

    tool: Tool
    slot: int | None
    kinematics: RobotKinematics
    true_kinematics: RobotKinematics
    q_rad: np.ndarray
    sensor: BeamSensor
    shape: ToolShape
    mounted_label: str
    config: BeamScanConfig
    seed: int
    tr: Translator = ENGLISH

    @property
    def T_flange_tool_plan(self) -> np.ndarray:
        """The checked tool data as ``T_flange_tool`` (4, 4), m."""
        return T_flange_tool_m(self.tool)

    def run(self) -> BeamCheck:
        """The scan and the two solves (pure; for a worker thread).

        Raises:
            ControllerError: nothing could be scanned, or too few tip events for a TCP
                (the reasons in plain words).
        """
        rng = np.random.default_rng(self.seed)
        true_kin = None if self.true_kinematics is self.kinematics else self.true_kinematics
        scan = run_beam_scan(self.kinematics, self.q_rad, self.sensor, self.T_flange_tool_plan,
                             self.shape, true_kinematics=true_kin, config=self.config, rng=rng)
        return evaluate_check(self.tool, self.slot, scan, self.seed, tr=self.tr)


def evaluate_check(tool: Tool, slot: int | None, scan: BeamScan, seed: int = 0, *,
                   tr: Translator = ENGLISH) -> BeamCheck:
    """Solve a scan's events and compare with the stored tool data (mm, FLANGE); a refusal in
    ``tr``'s language (the verdict is English: :func:`beam_verdict` says it in another).

    Raises:
        ControllerError: fewer than two orientations gave a tip event (the skip reasons).
    """
    rot, pos, b, u = scan_arrays_mm(scan.events)
    ti, ai = list(scan.tip_indices), list(scan.axis_indices)
    lo, hi = SIGMA_RANGE
    tip_sigma_mm = scan.tip_sigma_m * 1000.0  # the sensor's repeatability and the aiming error
    axis_sigma_mm = scan.sensor.sigma * 1000.0 / math.sqrt(2.0)  # entry and exit averaged
    tip_sigma = tip_sigma_mm if lo <= tip_sigma_mm <= hi else None
    axis_sigma = axis_sigma_mm if lo <= axis_sigma_mm <= hi else None
    if len(ti) < 2:
        raise ControllerError(" ".join((
            tr.ngettext("The beam check found too few tip events for a TCP: {n} of {count} orientation could "
                        "be scanned, at least 2 are needed.",
                        "The beam check found too few tip events for a TCP: {n} of {count} orientations could "
                        "be scanned, at least 2 are needed.",
                        scan.n_orientations_planned).format(n=len(ti), count=scan.n_orientations_planned),
            *(in_language(why, tr) for why in scan.skipped),
            tr.gettext("Place the beam sensor where the robot reaches it with the tool turned about its own axis "
                       "(nearer the robot, or lower), or start from another pose."))))
    try:
        beam = solve_beam(rot[ti], pos[ti], b[ti], u[ti], sigma=tip_sigma)
    except TcpcalError as exc:
        raise ControllerError(tr.gettext("The beam check's tip events do not determine a TCP: {problem}").format(
            problem=exc)) from None
    axis: BeamAxisResult | None
    try:
        axis = solve_beam_axis(rot[ai], pos[ai], b[ai], u[ai], beam.tcp, sigma=axis_sigma)
    except TcpcalError:
        axis = None
    stored = np.asarray(tool.tcp_mm, dtype=float)
    measured = np.asarray(beam.tcp, dtype=float)
    dev = measured - stored
    norm = float(np.linalg.norm(dev))
    direction = None if axis is None else np.asarray(axis.direction, dtype=float)
    dir_dev = None if direction is None else _angle_deg(direction, tool.rotation[:, 0])
    good = norm <= GOOD_BEAM_MM
    consistent = beam.rms_error <= CONSISTENT_FACTOR * max(tip_sigma_mm, 1e-4)
    check = BeamCheck(
        tool_name=tool.name, slot=slot, stored_tool=tool, stored_tcp_mm=read_only_array(stored),
        measured_tcp_mm=read_only_array(measured), deviation_mm=read_only_array(dev),
        deviation_norm_mm=norm, ci95_mm=float(beam.ci95_radius),
        residual_rms_mm=float(beam.rms_error), consistent=consistent, direction_deviation_deg=dir_dev,
        measured_direction=None if direction is None else read_only_array(direction), scan=scan,
        beam_result=beam, axis_result=axis, verdict="", good=good, seed=int(seed), tip_sigma_mm=tip_sigma_mm)
    return replace(check, verdict=beam_verdict(check))


def beam_verdict(check: BeamCheck, *, tr: Translator = ENGLISH) -> str:
    """The check's verdict in ``tr``'s language (plain text): good, or off by how much and what to
    do; then whether the direction differs, the tip events disagree, orientations were skipped."""
    _ = tr.gettext
    norm = check.deviation_norm_mm
    if check.good:
        verdict = _("TCP good: the beam measured it {deviation} mm from the stored data (at most {limit} mm).").format(
            deviation=f"{norm:.3f}", limit=f"{GOOD_BEAM_MM:g}")
    else:
        verdict = _("TCP off by {deviation} mm: the tool is bent or its data is stale. Update writes the measured "
                    "TCP into the library; verify it with the TCP check.").format(deviation=f"{norm:.3f}")
    dir_dev = check.direction_deviation_deg
    if dir_dev is not None and dir_dev > DIRECTION_NOTE_DEG:
        verdict += " " + _("The tool direction differs by {angle} deg from the stored X axis; Update keeps the "
                           "stored orientation (calibrate it with TCP & Z, X if the work depends on it).").format(
            angle=f"{dir_dev:.2f}")
    if not check.consistent:
        verdict += " " + _("The tip events disagree by {rms} mm RMS, far more than the sensor's repeatability "
                           "({sigma} mm): the robot's absolute accuracy (its model is not the real arm) or a moved "
                           "sensor limits this measurement, and an Update would store part of that error in the "
                           "tool data.").format(rms=f"{check.residual_rms_mm:.3f}", sigma=f"{check.tip_sigma_mm:.3f}")
    scan = check.scan
    if scan.skipped:
        verdict += " " + tr.ngettext("{n} of {count} orientation was skipped.",
                                     "{n} of {count} orientations were skipped.",
                                     scan.n_orientations_planned).format(
            n=len(scan.skipped), count=scan.n_orientations_planned)
    return verdict


def beam_check_job(controller: VirtualController, slot: int | None, tool: Tool, *,
                   rng_seed: int | None = None, config: BeamScanConfig | None = None,
                   tr: Translator = ENGLISH) -> BeamCheckJob:
    """A :class:`BeamCheckJob` of ``tool`` from the controller's current state (on the loop).

    Args:
        controller: the session's controller (read only).
        slot: the tool data's library slot (1..16), or None.
        tool: the tool data to check (usually the active one).
        rng_seed: seed of the repeatability noise; None: a fresh random one.
        config: the scan's configuration (default :class:`BeamScanConfig`).

    Raises:
        ControllerError: not a tool, or a mounted tool the beam cannot measure (the gripper).
    """
    if not isinstance(tool, Tool):
        raise ControllerError(f"The beam check needs tcpcal tool data, got {type(tool).__name__}.")
    if slot is not None and (isinstance(slot, bool) or not isinstance(slot, (int, np.integer))
                             or not 1 <= slot <= ToolLibrary.N_SLOTS):
        raise ControllerError(f"slot must be 1..{ToolLibrary.N_SLOTS} or None, got {slot!r}.")
    if rng_seed is None:
        seed = secrets.randbits(32)
    elif isinstance(rng_seed, bool) or not isinstance(rng_seed, (int, np.integer)) or rng_seed < 0:
        raise ControllerError(f"rng_seed must be an integer >= 0 or None, got {rng_seed!r}.")
    else:
        seed = int(rng_seed)
    c = controller
    nominal, physical = c.kinematics_for_worker()
    shape = tool_shape(c.mounted_tool)
    return BeamCheckJob(tool=tool, slot=None if slot is None else int(slot), kinematics=nominal,
                        true_kinematics=physical, q_rad=c.q_rad, sensor=c.beam_sensor, shape=shape,
                        mounted_label=c.mounted_tool.label,
                        config=BeamScanConfig() if config is None else config, seed=seed, tr=tr)


def _fmt3(v: np.ndarray) -> str:
    return ", ".join(f"{0.0 if abs(float(x)) < 5e-4 else float(x):.3f}" for x in v)


def beam_check_markdown(check: BeamCheck, *, tr: Translator = ENGLISH) -> str:
    """The check's text for the Tool tab (markdown; the tool name and words escaped), in ``tr``'s
    language."""
    _ = tr.gettext
    name = escape_markdown(check.tool_name)
    head = (_("**Beam check of {name}** (not in the library)").format(name=name) if check.slot is None
            else _("**Beam check of {name}** (slot {slot})").format(name=name, slot=check.slot))
    lines = [
        head,
        "",
        "| | X | Y | Z |",
        "|---|---:|---:|---:|",
        "| " + _("stored TCP (mm)") + " | " + " | ".join(f"{v:.3f}" for v in check.stored_tcp_mm) + " |",
        "| " + _("measured TCP (mm)") + " | " + " | ".join(f"{v:.3f}" for v in check.measured_tcp_mm) + " |",
        "| " + _("deviation (mm)") + " | " + " | ".join(f"{v:+.3f}" for v in check.deviation_mm) + " |",
        "",
        _("Deviation **{deviation} mm** (95 % radius of the measurement {ci95} mm), FLANGE coordinates, "
          "measured - stored.").format(deviation=f"{check.deviation_norm_mm:.3f}", ci95=f"{check.ci95_mm:.3f}"),
        "",
        "- " + _("the tip events fit the beam to {rms} mm RMS").format(rms=f"{check.residual_rms_mm:.3f}"),
    ]
    if check.direction_deviation_deg is not None:
        lines.append("- " + _("tool direction: {angle} deg from the stored X axis").format(
            angle=f"{check.direction_deviation_deg:.2f}"))
    s = check.scan
    lines.append("- " + _("{tips} tip and {axes} axis events at {n} orientations; the scan takes {seconds} s on "
                          "the robot ({path} mm of path)").format(
        tips=len(s.tip_indices), axes=len(s.axis_indices), n=s.n_orientations_done, seconds=f"{s.duration_s:.1f}",
        path=f"{s.path_length_m * 1000.0:.0f}"))
    for reason in s.skipped:
        lines.append(f"- {escape_markdown(in_language(reason, tr))}")
    verdict = check.verdict if tr.language == ENGLISH.language else beam_verdict(check, tr=tr)
    lines += ["", ("✔ " if check.good else "⚠ ") + escape_markdown(verdict)]
    return "\n".join(lines)


def update_tool_from_beam(library: ToolLibrary, slot: int, check: BeamCheck,
                          rights: LibraryRights = UNRESTRICTED) -> Tool:
    """Write the measured TCP into ``slot`` of ``library`` (the orientation kept).

    The new tool data: the stored tool with ``tcp_mm`` = the measured TCP and a calibration
    ``method="beam"``, date now, figures ``deviation_mm`` (length of measured - stored),
    ``ci95_mm``, ``n_events`` (tip events), ``n_axis_events``, ``direction_deviation_deg`` (when
    measured). The library's active slot is not changed (that is the session's).

    Args:
        library: the tool library.
        slot: the slot to write (must be the checked one).
        check: the check whose measured TCP is written.
        rights: whose write it is (a class's trainee: only a slot of their own;
            ``calibrate.pendant_rules``).

    Returns:
        The tool as saved.

    Raises:
        BeamServiceError: the check is not of that slot, or the slot changed since the check
            (another tool, other data, or emptied): check again.
        tcpcal.TcpcalError: the library refused (bad slot, unreadable file, another trainee's
            slot).
    """
    if not isinstance(check, BeamCheck):
        raise BeamServiceError(f"update_tool_from_beam needs a BeamCheck, got {type(check).__name__}.")
    if check.slot is None:
        raise BeamServiceError("The checked tool data is not in the library: save it to a slot first, "
                               "then check it again with the beam.")
    if slot != check.slot:
        raise BeamServiceError(f"The check was of slot {check.slot}, not slot {slot}: check slot {slot} "
                               "with the beam first.")
    current = library.get(slot)
    if current is None:
        raise BeamServiceError(f"Slot {slot} is empty now: the tool checked as {check.tool_name!r} was "
                               "removed since the check; nothing was written.")
    if current != check.stored_tool:
        raise BeamServiceError(f"Slot {slot} changed since the check (now {current.name!r}, checked "
                               f"{check.tool_name!r}): check it again with the beam before Update; "
                               "nothing was written.")
    figures = {"deviation_mm": check.deviation_norm_mm, "ci95_mm": check.ci95_mm,
               "n_events": float(len(check.scan.tip_indices)),
               "n_axis_events": float(len(check.scan.axis_indices))}
    if check.direction_deviation_deg is not None:
        figures["direction_deviation_deg"] = check.direction_deviation_deg
    x, y, z = (float(v) for v in check.measured_tcp_mm)
    measured = (x, y, z)
    tool = Tool(name=current.name, tcp_mm=measured, abc_deg=current.abc_deg,
                notes=current.notes, **current.load_fields(),
                calibration=Calibration.now(BEAM_METHOD, figures))
    with rights.in_words():
        library.save(slot, tool, activate=False, **rights.save_kwargs())
    return tool
