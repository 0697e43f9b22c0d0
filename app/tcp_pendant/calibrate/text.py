"""Words and tables of the Calibrate tab (markdown for viser's ``add_markdown``), without viser.

Every number comes from a wizard (which got it from ``tcpcal``); this module only says it in
plain words with its unit: lengths in mm, angles in degrees, as on a pendant. The error
figures are named as tcpcal names them: *mean* error, *max* error, *RMS* error (not the same
thing) and the *95 % radius* of the TCP.

Every piece of plain text that can carry what a user typed or uploaded (tool names, the
library choice, the wizards' titles, instructions, warnings and messages, which quote tool
names, and a loaded record's content) goes through
:func:`tcp_pendant.text_escape.escape_markdown` here, where the markdown is composed.

Every function that composes words takes ``tr`` (the session's :class:`Translator`, English by
default): one catalog message per sentence or table cell, with named placeholders; the wizard
classes' titles and ``calibrates`` (``N_`` msgids of ``tcp_pendant.wizards``) are translated
here, where they are shown. Numbers keep their form (``fmt_num``), units and axis names stay.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from typing import TYPE_CHECKING, Literal

from tcp_pendant.pendant.formatting import fmt_num
from tcp_pendant.text_escape import escape_markdown as _esc
from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.wizards import (
    ESTIMATOR_LABELS,
    BeamWizardResult,
    Wizard,
    WizardResult,
    Xyz4Result,
    wizard_class,
)
from tcp_pendant.wizards.registry import wizard_class

from tcp_pendant.wizards.tcp_check import tcp_check_markdown
from tcp_pendant.wizards.session_record import ReplayCheck
from tcp_pendant.wizards.truth import NUMERICAL_NOISE_MM, TruthComparison
from tcpcal.pose_quality import CandidateGain, PoseQuality

if TYPE_CHECKING:
    from tcp_pendant.wizards.xyz4 import Estimator

__all__ = [
    "beam_result_markdown",
    "duration_words",
    "comparison_markdown",
    "menu_markdown",
    "meter_level",
    "meter_markdown",
    "method_words",
    "replay_markdown",
    "result_markdown",
    "save_markdown",
    "save_preview_markdown",
    "step_markdown",
    "scene_legend_markdown",
    "steps_list_markdown",
    "where_to_jog_markdown",
    "truth_markdown",
    "empty_touches_markdown",
    "warnings_markdown",
]



def menu_markdown(kind: str, *, library_tool: str | None, reference_tool: str, new_tool: str,
                  mounted_tool: str, tr: Translator = ENGLISH) -> str:
    """What Start will do with the options chosen (echoes every choice before Start), from what
    the wizard class declares (``needs_tool``, ``calibrates``, its physical-tool options).

    Args:
        kind: wizard kind.
        library_tool: the chosen library entry ("1: Pointer"), None when the library is empty.
        reference_tool: the reference tool chosen for the reference method (label).
        new_tool: the new physical tool chosen for the reference method (label).
        mounted_tool: label of the physical tool on the flange now.
    """
    _ = tr.gettext
    cls = wizard_class(kind)
    mounted = _esc(mounted_tool.lower())
    library_tool = None if library_tool is None else _esc(library_tool)
    what = _esc(_(cls.calibrates))
    if cls.needs_tool == "mounted":
        return _("Calibrates {what} of the **{tool}** now mounted; mount another "
                 "tool on the Tool tab first if that is not the one.").format(what=what, tool=mounted)
    if library_tool is None:
        return _("⚠ The tool library is empty: calibrate a TCP first (XYZ 4-point) and save it, or "
                 "enter a tool on the Tool tab.")
    if any(o.kind == "physical_tool" for o in cls.options):
        if reference_tool == new_tool:
            return _("⚠ The reference tool and the new tool must be two different physical tools.")
        return _("Touch 1 with the data **{data}** on the *{reference}*; then the tool change and "
                 "touch 2 with the *{new}*, whose TCP is calibrated.").format(
                     data=library_tool, reference=_esc(reference_tool.lower()), new=_esc(new_tool.lower()))
    if not getattr(cls, "saves_to_library", True):         # the TCP check: calibrates nothing
        return _("Checks the TCP of **{data}** (made active; nothing is changed or saved); the "
                 "*{tool}* is mounted: it must be the tool that data belongs to.").format(
                     data=library_tool, tool=mounted)
    return _("Calibrates {what} of **{data}** (its TCP is used as is); the "
             "*{tool}* is mounted: it must be the tool that data belongs to.").format(
                 what=what, data=library_tool, tool=mounted)


def save_preview_markdown(name: str, slot_choice: str, tcp_mm: Sequence[float],
                          abc_deg: Sequence[float], *, tr: Translator = ENGLISH) -> str:
    """What "Save to tool library" will store (echoes the name and slot as typed)."""
    x, y, z = (fmt_num(v) for v in tcp_mm)
    a, b, c = (fmt_num(v) for v in abc_deg)
    shown = f"**{_esc(name.strip())}**" if name.strip() else tr.gettext("*(type a name)*")
    return tr.gettext("Will save {name} · X {x} Y {y} Z {z} mm · A {a} B {b} C {c}° · slot: {slot}").format(
        name=shown, x=x, y=y, z=z, a=a, b=b, c=c, slot=_esc(slot_choice))


def _mm(v: float | None, decimals: int = 2) -> str:
    return "–" if v is None or not math.isfinite(v) else f"{fmt_num(v, decimals)} mm"


def _deg(v: float | None, decimals: int = 2) -> str:
    return "–" if v is None or not math.isfinite(v) else f"{fmt_num(v, decimals)}°"


def step_markdown(wizard: Wizard, *, tr: Translator = ENGLISH) -> str:
    """Heading ("**XYZ 4-point** · Step 2 of 4: Touch 2") and the step's instruction (the
    step's words come in the session's language from the wizard)."""
    _ = tr.gettext
    title = _esc(_(wizard.title))
    if wizard.is_complete:
        if getattr(wizard, "saves_to_library", True):
            return _("**{title}** · Result\n\nThe calibration is computed: see *Result* below.").format(title=title)
        return _("**{title}** · Result\n\nThe check is done: see *Result* below.").format(title=title)
    step = wizard.step
    mark = _(" ✔ recorded") if step.recorded else ""
    head = _("**{title}** · {heading}: {step}").format(title=title, heading=_esc(step.heading), step=_esc(step.title))
    return f"{head}{mark}\n\n{_esc(step.instruction)}"


def where_to_jog_markdown(wizard: Wizard, *, tr: Translator = ENGLISH) -> str:
    """Where a step that is jogged to is done, for the Calibrate tab (the trainee is there
    after Start, the jog keys are on the Jog tab): "" on the result and on a step the
    controller runs itself (a beam scan: Finish is pressed here)."""
    if wizard.is_complete or wizard.auto_role(wizard.step).by_controller:
        return ""
    return tr.gettext("→ **Jog on the Jog tab** to do this step. Then press **Record** there, in the "
                      "*Calibration step* box above the jog keys (key R), or here.")


def scene_legend_markdown(*, computed: bool, true: bool, sphere: bool, radius_mm: float | None = None,
                          tr: Translator = ENGLISH) -> str:
    """What the result draws in 3D, named (the labels there are short): the COMPUTED and TRUE
    triads and, for a 4-point result, the fitted sphere (radius mm), its flange points and
    approach lines. "" when the result draws none of them."""
    _ = tr.gettext
    items = []
    if computed:
        items.append(_("**COMPUTED**: the TOOL frame of this result (thick triad)"))
    if true:
        items.append(_("**TRUE**: the hidden true TOOL frame (thin, longer triad; training)"))
    if sphere:
        if radius_mm is None:
            items.append(_("**blue wire sphere**: the sphere the flange origins were fitted to (centre: the "
                           "reference tip); dots: the flange origins of the touches (red: outlier, grey: "
                           "dropped); blue lines: from each flange origin toward its TCP"))
        else:
            items.append(_("**blue wire sphere**: the sphere the flange origins were fitted to (centre: the "
                           "reference tip, radius {radius} mm = |TCP|); dots: the flange origins of the "
                           "touches (red: outlier, grey: dropped); blue lines: from each flange origin "
                           "toward its TCP").format(radius=fmt_num(radius_mm, 1)))
    return "" if not items else _("**In 3D:** {items}.").format(items=" · ".join(items))


def steps_list_markdown(wizard: Wizard, *, tr: Translator = ENGLISH) -> str:
    """The steps in one line: ✔ recorded, ▶ current, · to do."""
    parts = []
    for s in wizard.steps:
        here = s.index == wizard.step_index and not wizard.is_complete
        sym = "▶" if here else ("✔" if s.recorded else "·")
        parts.append(f"{sym} {_esc(s.title)}")
    if wizard.is_complete:
        parts.append(tr.gettext("▶ Result"))
    return " &nbsp; ".join(parts)


FULL_DIVERSITY_DEG = 45.0
"""The meter's bar is full when the nearest recorded orientation is this far (methods.md
section 7: touches 45 degrees apart about different axes give several times smaller errors)."""


def meter_level(gain: CandidateGain) -> tuple[float, Literal["red", "yellow", "green"]]:
    """The pose-diversity meter as a bar: (0..100, colour).

    The bar is the angle from the current orientation to the nearest recorded one, full at
    ``FULL_DIVERSITY_DEG`` (full before the first touch); the colour is tcpcal's verdict on the
    predicted TCP uncertainty: red when the orientation is too close to an earlier touch
    (``gain.too_close``), yellow when recording would not yet make the TCP determinable or would
    cut its predicted error by less than 10 %, green otherwise.
    """
    angle = gain.angle_to_nearest_deg
    value = 100.0 if math.isinf(angle) else 100.0 * min(max(angle / FULL_DIVERSITY_DEG, 0.0), 1.0)
    if gain.too_close:
        return value, "red"
    if math.isinf(gain.predicted_after) or gain.reduction < 0.1:
        return value, "yellow"
    return value, "green"


def meter_markdown(gain: CandidateGain, quality: PoseQuality | None, sigma_mm: float,
                   advice_before_determinable: str | None = None, tilt_hint: str | None = None, *,
                   measured: str = "", tr: Translator = ENGLISH) -> str:
    """Live advice while jogging toward the next touch (all figures predicted by tcpcal from the
    orientations alone, for an operator error of ``sigma_mm`` per axis). While recording here
    would still not make the TCP determinable (``gain.predicted_after`` infinite) the advice is
    ``advice_before_determinable`` (``tcp_pendant.calibrate.diversity``: the angle to the
    nearest touch and the axis still missing, in words) or else ``quality.message`` (tcpcal's).
    ``tilt_hint`` (``tilt_advice.TiltAdvice.text``: which way to tilt for the next touch) ends it.
    ``measured``: whose scatter ``sigma_mm`` is (msgids "your touches", "your last calibration"; ""
    assumed)."""
    _ = tr.gettext
    if measured:
        head = _("**Pose diversity** (if you recorded here, {whose}: scatter {sigma} mm):").format(
            whose=_(measured), sigma=fmt_num(sigma_mm, 2))
    else:
        head = _("**Pose diversity** (if you recorded here, operator error {sigma} mm):").format(
            sigma=fmt_num(sigma_mm, 1))
    if gain.too_close:
        advice = _("⚠ **Too close** to an earlier touch: {angle} apart. "
                   "Tilt the tool further, about another axis, before recording.").format(
                       angle=_deg(gain.angle_to_nearest_deg, 0))
    elif math.isinf(gain.predicted_after):
        extra = advice_before_determinable or ("" if quality is None else quality.message)
        advice = _("Not determinable yet.") + (f" {extra}" if extra else "")
    elif math.isinf(gain.predicted_before):
        advice = _("✔ Recording here makes the TCP determinable: predicted RMS error **{error}**.").format(
            error=_mm(gain.predicted_after))
    else:
        good = (_("✔ Good pose: predicted TCP RMS error {before} → **{after}** ({change} %).")
                if gain.reduction >= 0.1 else
                _("This pose adds little: predicted TCP RMS error {before} → **{after}** ({change} %)."))
        advice = good.format(before=_mm(gain.predicted_before), after=_mm(gain.predicted_after),
                             change=f"{-100.0 * gain.reduction:+.0f}")
    near = ("" if math.isinf(gain.angle_to_nearest_deg) or advice_before_determinable else
            "\n\n" + _("Nearest recorded orientation: {angle} away.").format(angle=_deg(gain.angle_to_nearest_deg, 0)))
    hint = f"\n\n{tilt_hint}" if tilt_hint else ""
    return f"{head}\n\n{advice}{near}{hint}"


def result_markdown(result: WizardResult, truth: TruthComparison | None = None, *,
                    tr: Translator = ENGLISH) -> str:
    """What the result panel shows of ``result``, by how its wizard class shows results
    (``Wizard.result_view``): the calibrated frame and its quality figures (what a pendant shows
    after a calibration); a check's rotations, implied error, correction and verdict
    (:func:`tcp_check_markdown`); a scan's events and lesson (:func:`beam_result_markdown`;
    ``truth``: its comparison with the true tool, given only where the truth may be shown).
    """
    view = wizard_class(result.wizard).result_view
    if view == "spin_check":
        return tcp_check_markdown(result, tr=tr)  # type: ignore[arg-type]  # its wizard's result type
    if view == "beam_scan":
        return beam_result_markdown(result, truth, tr=tr)  # type: ignore[arg-type]  # its wizard's result type
    return touches_result_markdown(result, tr=tr)


def _figures_table(rows: Sequence[tuple[str, str]], tr: Translator) -> str:
    """The two-column table of a result's figures (names already in ``tr``'s language)."""
    head = tr.gettext("| figure | value |")
    return head + "\n|---|---|\n" + "\n".join(f"| {k} | {v} |" for k, v in rows)


def method_words(result: WizardResult, *, tr: Translator = ENGLISH) -> str:
    """The method of ``result`` in words: its wizard's title, and the estimator or variant its
    method id names (``xyz4-lstsq`` → "XYZ 4-point · joint least squares (default)"); the id
    itself only for a method the wizard does not describe."""
    cls = wizard_class(result.wizard)
    title = tr.gettext(cls.title)
    suffix = result.method.removeprefix(f"{result.wizard}-") if result.method != result.wizard else ""
    if result.wizard == "xyz4" and suffix in ESTIMATOR_LABELS:
        return f"{title} · {tr.gettext(ESTIMATOR_LABELS[suffix])}"
    variant = next((label for value, label in cls.variants if str(value) == suffix), None)
    if variant is not None:
        return f"{title} · {tr.gettext(variant)}"
    return title if not suffix or result.method == cls.kind else f"{title} ({result.method})"


def touches_result_markdown(result: WizardResult, *, tr: Translator = ENGLISH) -> str:
    """A result computed from recorded touches: the TCP (and orientation) with its figures."""
    _ = tr.gettext
    x, y, z = (fmt_num(v) for v in result.tcp_mm)
    lines = [f"**TCP** X {x} · Y {y} · Z {z} mm"]
    if result.abc_deg is not None:
        a, b, c = (fmt_num(v) for v in result.abc_deg)
        lines.append(_("**Orientation** A {a} · B {b} · C {c}° (KUKA: Rz(A) Ry(B) Rx(C))").format(a=a, b=b, c=c))
    rows: list[tuple[str, str]] = [(_("method"), _esc(method_words(result, tr=tr)))]
    tcp = result.tcp_result
    if tcp is not None:
        n = len(result.per_touch_error_mm)
        errs = ", ".join(f"P{i + 1} {fmt_num(e)}" for i, e in zip(_touch_numbers(result), result.per_touch_error_mm))
        rows += [
            (_("error per touch (mm)"), errs if n else "–"),
            (_("mean error"), _mm(result.mean_error_mm)),
            (_("max error"), _mm(result.max_error_mm)),
            (_("RMS error"), _mm(result.rms_error_mm)),
            (_("95 % radius of the TCP"), _mm(result.ci95_mm)),
        ]
        if result.wizard == "reference":
            # one touch per tool: no redundancy, so the noise is assumed, and the angle between
            # the two touches (two different tools) says nothing about the result
            rows.append((_("assumed touch error (per axis)"), _mm(float(tcp.noise_sigma))))
        else:
            rows.append((_("touch noise estimate (per axis)"), _mm(float(tcp.noise_sigma))))
            if tcp.n_touches >= 2:
                rows += [(_("angle between touches"),
                          _("{low} to {high}").format(low=_deg(tcp.min_angle_deg, 1), high=_deg(tcp.max_angle_deg, 1))),
                         (_("condition number"), f"{tcp.condition_number:.1f}")]
    if result.orthogonality_defect_deg is not None:
        rows.append((_("orthogonality defect"), _deg(result.orthogonality_defect_deg, 3)))
    if result.displacements_mm:
        rows.append((_("displacement lengths Δ"), ", ".join(_mm(d, 1) for d in result.displacements_mm)))
    return "\n\n".join(lines) + "\n\n" + _figures_table(rows, tr)


def duration_words(seconds: float) -> str:
    """A duration as a pendant says it: "23.4 s", "3 min 12 s", "1 h 02 min"."""
    if not math.isfinite(seconds) or seconds < 0.0:
        return "–"
    if seconds < 60.0:
        return f"{seconds:.1f} s"
    whole = int(round(seconds))
    if whole < 3600:
        return f"{whole // 60} min {whole % 60:02d} s"
    return f"{whole // 3600} h {whole % 3600 // 60:02d} min"


def beam_result_markdown(result: BeamWizardResult, truth: TruthComparison | None = None, *,
                         tr: Translator = ENGLISH) -> str:
    """An Automatic (beam) result: the TCP with its 95 % radius, the measured tool direction,
    the TOOL frame to save (and that it is the planning orientation turned onto the measured
    direction), the figures, the events with their residuals, the time the scan takes on a real
    robot, and the lesson: automatic vs the trainee's last manual calibration of the same tool
    (times; errors against the true tool only with ``truth``, the beam run's own comparison,
    which the caller gives only where the truth may be shown).
    """
    _ = tr.gettext
    x, y, z = (fmt_num(v) for v in result.tcp_mm)
    lines = [_("**TCP** X {x} · Y {y} · Z {z} mm (FLANGE) · 95 % radius {radius}").format(
        x=x, y=y, z=z, radius=_mm(result.ci95_mm, 3))]
    if result.direction_flange is not None:
        dx, dy, dz = (f"{v:+.4f}" for v in result.direction_flange)
        cone = result.direction_ci95_deg
        lines.append(_("**Tool direction** (TOOL X in FLANGE) {dx} · {dy} · {dz} · 95 % cone {cone}").format(
            dx=dx, dy=dy, dz=dz,
            cone=_deg(cone, 3) if cone is not None and math.isfinite(cone) else _("– (no redundancy)")))
    else:
        lines.append(_("**Tool direction** not measured (see the warnings)"))
    if result.abc_deg is not None:
        a, b, c = (fmt_num(v) for v in result.abc_deg)
        if result.direction_turn_deg is not None:
            frame = _("**TOOL frame to save** A {a} · B {b} · C {c}° (KUKA): the planning orientation turned by "
                      "{turn} so that its X is the measured direction; the beam does not see the turn about "
                      "the tool's X, which is kept from the planning data.")
        else:
            frame = _("**TOOL frame to save** A {a} · B {b} · C {c}° (KUKA): the planning orientation as it is; "
                      "the beam does not see the turn about the tool's X, which is kept from the planning data.")
        lines.append(frame.format(a=a, b=b, c=c, turn=_deg(result.direction_turn_deg, 3)))
    beam = result.beam_result
    rows = [(_("method"), _esc(method_words(result, tr=tr))),
            (_("tip events (TCP)"), str(len(result.tip_event_indices))),
            (_("sideways crossings used (direction)"), str(len(result.axis_event_indices))),
            (_("mean error (tip off the beam line)"), _mm(result.mean_error_mm, 3)),
            (_("max error"), _mm(result.max_error_mm, 3)),
            (_("RMS error"), _mm(result.rms_error_mm, 3)),
            (_("95 % radius of the TCP"), _mm(result.ci95_mm, 3)),
            (_("event noise estimate (per axis)"), _mm(float(beam.noise_sigma), 4)),
            (_("scan on a real robot"), _("{duration} (path {length} m)").format(
                duration=duration_words(result.duration_s), length=fmt_num(result.path_length_m, 2)))]
    return "\n\n".join([*lines, _figures_table(rows, tr), _beam_events_markdown(result, tr),
                        _beam_lesson_markdown(result, truth, tr)])


def _beam_events_markdown(result: BeamWizardResult, tr: Translator = ENGLISH) -> str:
    """The events: orientation, kind, beam, and the residual of each event used (mm)."""
    tips = dict(zip(result.tip_event_indices, result.beam_result.residuals))
    axes = {} if result.axis_result is None else dict(zip(result.axis_event_indices,
                                                          (abs(float(r)) for r in result.axis_result.residuals)))
    _ = tr.gettext
    rows = []
    for i, e in enumerate(result.events):
        kind = _("tip on the beam") if e.kind == "tip" else _("shaft crossed sideways")
        if i in tips:
            used = _("{distance} mm from the beam line").format(distance=fmt_num(float(tips[i]), 4))
        elif i in axes:
            used = _("axis {distance} mm from the beam line").format(distance=fmt_num(axes[i], 4))
        else:
            used = _("not used") if e.on_shaft else _("not used (off the shaft)")
        rows.append(f"| {i + 1} | {e.orientation + 1} | {kind} | {e.beam + 1} | {used} |")
    return (_("**Events** ({n})").format(n=len(result.events)) + "\n\n"
            + _("| # | orientation | event | beam | residual |") + "\n|---|---|---|---|---|\n" + "\n".join(rows))


def _beam_lesson_markdown(result: BeamWizardResult, truth: TruthComparison | None,
                          tr: Translator = ENGLISH) -> str:
    """Automatic vs by hand, on the same tool: time (and errors against the truth, with it)."""
    _ = tr.gettext
    manual = result.manual
    if manual is None:
        return _("**Automatic vs by hand:** no manual calibration of this tool in this session yet. "
                 "The scan takes {duration} on a real robot; calibrate the tool by hand "
                 "(e.g. XYZ 4-point) and scan again to compare.").format(duration=duration_words(result.duration_s))
    if manual.auto_touches == 0:
        who, whose = _("by hand"), _("your time")
    elif manual.auto_touches >= manual.touches:
        who, whose = _("by Auto-touch"), _("Auto-touch's clicks")
    else:
        who = tr.ngettext("{k} of {n} touch by Auto-touch", "{k} of {n} touches by Auto-touch",
                          manual.touches).format(k=manual.auto_touches, n=manual.touches)
        whose = _("your time")
    name = f"{manual.run_number}: {_esc(_(manual.title))} ({who})"
    beam_time = _("{duration} on a real robot").format(duration=duration_words(result.duration_s))
    hand_time = f"{duration_words(manual.wall_time_s)} ({whose})"
    automatic = _("Automatic (beam)")
    if truth is None:
        return (_("**Automatic vs by hand** (same tool)") + "\n\n" + _("| calibration | time |") + "\n|---|---|\n"
                f"| {automatic} | {beam_time} |\n"
                f"| {name} | {hand_time} |")
    head = (_("**Automatic vs by hand** (same tool, against the true tool)") + "\n\n"
            + _("| calibration | time | TCP error | direction error |") + "\n|---|---|---|---|")
    beam = (f"| {automatic} | {beam_time} | "
            f"{_mm(truth.position_error_mm, 3)} | {_deg(truth.x_axis_error_deg, 3)} |")
    hand = (f"| {name} | {hand_time} | {_mm(manual.position_error_mm, 3)} | "
            f"{_deg(manual.direction_error_deg, 3)} |")
    return "\n".join([head, beam, hand])


def _touch_numbers(result: WizardResult) -> Sequence[int]:
    """0-based recorded-touch index of each per-touch error (a result that leaves touches out,
    the 4-point's, says which it used: ``used_indices``)."""
    used = getattr(result, "used_indices", None)
    return range(len(result.per_touch_error_mm)) if used is None else used


def empty_touches_markdown(wizard: Wizard | None, *, tr: Translator = ENGLISH) -> str:
    """What the Touches list says with no free touch (Record point): "No touch recorded", or,
    while a wizard on show has recorded steps, that they are its (our words and numbers)."""
    n = 0 if wizard is None or wizard.status == "cancelled" else len(wizard.recorded_poses)
    if wizard is None or n == 0:
        return tr.gettext("*No touch recorded.*")
    return tr.ngettext("*No touch recorded with Record point. The {title} wizard has {n} touch of its own: "
                       "they are in its step list above.*",
                       "*No touch recorded with Record point. The {title} wizard has {n} touches of its own: "
                       "they are in its step list above.*", n).format(title=_esc(tr.gettext(wizard.title)), n=n)


def warnings_markdown(result: WizardResult) -> str:
    """Warnings (⚠) then standing notes (ℹ), one per line; empty when there are none."""
    lines = [f"⚠ {_esc(w)}" for w in result.warnings] + [f"ℹ {_esc(n)}" for n in result.notes]
    return "\n\n".join(lines)


def comparison_markdown(result: Xyz4Result, *, tr: Translator = ENGLISH) -> str:
    """The three 4-point estimators side by side on the same touches (mm)."""
    _ = tr.gettext
    head = _("| estimator | X | Y | Z | mean | max | RMS | 95 % |") + "\n|---|---|---|---|---|---|---|---|"
    rows = []
    for r in result.comparison_rows():
        label = (_("{estimator} ◀ reported") if r.get("chosen") else "{estimator}").format(estimator=_(r["label"]))
        if not r["ok"]:
            cannot = _("cannot solve: {error}").format(error=_esc(r["error"]))
            rows.append(f"| {label} | {cannot} ||||||| ")
            continue
        x, y, z = (fmt_num(v) for v in r["tcp_mm"])
        rows.append(f"| {label} | {x} | {y} | {z} | {fmt_num(r['mean_error_mm'])} | "
                    f"{fmt_num(r['max_error_mm'])} | {fmt_num(r['rms_error_mm'])} | {fmt_num(r['ci95_mm'])} |")
    return (head + "\n" + "\n".join(rows) + "\n\n" + _("All figures in mm. Same touches, three estimators: "
            "the joint least squares is the maximum-likelihood one (their equations: The math)."))


def truth_markdown(cmp: TruthComparison, *, tr: Translator = ENGLISH) -> str:
    """Training mode: the result against the hidden true TOOL frame, with the verdict (the
    verdict's words are ``wizards.truth``'s)."""
    _ = tr.gettext
    icon = {"good": "✔", "fair": "●", "poor": "✘"}[cmp.grade]
    lines = [_("{icon} **Against the true TOOL frame: {verdict}**").format(icon=icon, verdict=cmp.verdict_in(tr)),
             _("Position error of the TCP: **{error}**").format(error=_mm(cmp.position_error_mm, 3))]
    if cmp.orientation_error_deg is not None:
        lines.append(_("Orientation error: **{error}** (tool X: {x_error})").format(
            error=_deg(cmp.orientation_error_deg, 3), x_error=_deg(cmp.x_axis_error_deg, 3)))
    if cmp.inside_ci95 is not None:
        if cmp.position_error_mm < NUMERICAL_NOISE_MM:
            lines.append(_("The touches were exact (no operator error): the computed TCP is the true one."))
        elif cmp.inside_ci95:
            lines.append(_("The true TCP is inside the 95 % radius."))
        else:
            lines.append(_("The true TCP is **outside** the 95 % radius."))
    return "\n\n".join(lines)


def save_markdown(slot: int, name: str, *, tr: Translator = ENGLISH) -> str:
    """Confirmation after "Save to tool library"."""
    return tr.gettext("✔ Saved **{name}** in slot {slot}; it is now the active tool.").format(name=_esc(name), slot=slot)


def replay_markdown(checks: Sequence[ReplayCheck], *, tr: Translator = ENGLISH) -> str:
    """A loaded session record, recomputed: one row per wizard (how a trainer grades)."""
    _ = tr.gettext
    if not checks:
        return _("The record holds no calibration.")
    head = _("| # | calibration | replay | against truth |") + "\n|---|---|---|---|"
    rows = []
    for c in checks:
        truth = "–" if c.truth is None else _esc(c.truth.verdict_in(tr))
        ok = "✔ " if c.matches else "✘ "
        rows.append(f"| {c.index + 1} | {_esc(_(c.wizard.title))} | {ok}{_esc(c.message)} | {truth} |")
    return head + "\n" + "\n".join(rows)


def estimator_options(*, tr: Translator = ENGLISH) -> dict[str, Estimator]:
    """Dropdown label -> estimator key, in the wizard's order (labels in ``tr``'s language)."""
    return {tr.gettext(label): key for key, label in ESTIMATOR_LABELS.items()}


def hidden_touches_markdown(result: WizardResult, distance_mm: Mapping[int, float],
                            hidden: Collection[int], *, tr: Translator = ENGLISH) -> str:
    """The lesson of \"Hide distance\": for each touch recorded with the distance hidden, how far
    the tool tip really was from the reference tip then (mm), next to that touch's error in the
    result (mm; \"not used\" for a touch left out). Empty when no touch was recorded hidden.

    Args:
        result: the wizard's result.
        distance_mm: distance-at-record by 0-based step (``WizardRun.distance_mm``).
        hidden: steps recorded while \"Hide distance\" was on (``WizardRun.distance_hidden``).
    """
    steps = sorted(i for i in hidden if i in distance_mm)
    if not steps:
        return ""
    _ = tr.gettext
    errors = dict(zip(_touch_numbers(result), result.per_touch_error_mm))
    rows = [f"| P{i + 1} | {_mm(distance_mm[i])} | {_mm(errors[i]) if i in errors else _('not used')} |"
            for i in steps]
    return (_("**Recorded with the distance hidden**: how far each tip really was") + "\n\n"
            + _("| touch | distance at record | error in the result |") + "\n|---|---|---|\n" + "\n".join(rows))
