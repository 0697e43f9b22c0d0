"""Words and tables of the Calibrate tab (markdown for viser's ``add_markdown``), without viser.

Every number comes from a wizard (which got it from ``tcpcal``); this module only says it in
plain words with its unit: lengths in mm, angles in degrees, as on a pendant. The error
figures are named as tcpcal names them: *mean* error, *max* error, *RMS* error (not the same
thing) and the *95 % radius* of the TCP.

Every piece of plain text that can carry what a user typed or uploaded (tool names, the
library choice, the wizards' titles, instructions, warnings and messages, which quote tool
names, and a loaded record's content) goes through
:func:`tcp_pendant.text_escape.escape_markdown` here, where the markdown is composed.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from typing import TYPE_CHECKING, Literal

from tcp_pendant.pendant.formatting import fmt_num
from tcp_pendant.text_escape import escape_markdown as _esc
from tcp_pendant.wizards import (
    ESTIMATOR_LABELS,
    BeamWizardResult,
    Wizard,
    WizardResult,
    Xyz4Result,
    wizard_class,
)
from tcp_pendant.wizards.registry import wizard_class

if TYPE_CHECKING:
    from tcp_pendant.wizards.xyz4 import Estimator
from tcp_pendant.wizards.tcp_check import tcp_check_markdown
from tcp_pendant.wizards.session_record import ReplayCheck
from tcp_pendant.wizards.truth import NUMERICAL_NOISE_MM, TruthComparison
from tcpcal.pose_quality import CandidateGain, PoseQuality

__all__ = [
    "beam_result_markdown",
    "duration_words",
    "comparison_markdown",
    "menu_markdown",
    "meter_level",
    "meter_markdown",
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
                  mounted_tool: str) -> str:
    """What Start will do with the options chosen (echoes every choice before Start), from what
    the wizard class declares (``needs_tool``, ``calibrates``, its physical-tool options).

    Args:
        kind: wizard kind.
        library_tool: the chosen library entry ("1: Pointer"), None when the library is empty.
        reference_tool: the reference tool chosen for the reference method (label).
        new_tool: the new physical tool chosen for the reference method (label).
        mounted_tool: label of the physical tool on the flange now.
    """
    cls = wizard_class(kind)
    mounted = _esc(mounted_tool.lower())
    library_tool = None if library_tool is None else _esc(library_tool)
    if cls.needs_tool == "mounted":
        return (f"Calibrates {_esc(cls.calibrates)} of the **{mounted}** now mounted; mount another "
                "tool on the Tool tab first if that is not the one.")
    if library_tool is None:
        return ("⚠ The tool library is empty: calibrate a TCP first (XYZ 4-point) and save it, or "
                "enter a tool on the Tool tab.")
    if any(o.kind == "physical_tool" for o in cls.options):
        if reference_tool == new_tool:
            return "⚠ The reference tool and the new tool must be two different physical tools."
        return (f"Touch 1 with the data **{library_tool}** on the *{_esc(reference_tool.lower())}*; then "
                f"the tool change and touch 2 with the *{_esc(new_tool.lower())}*, whose TCP is calibrated.")
    if not getattr(cls, "saves_to_library", True):         # the TCP check: calibrates nothing
        return (f"Checks the TCP of **{library_tool}** (made active; nothing is changed or saved); the "
                f"*{mounted}* is mounted: it must be the tool that data belongs to.")
    return (f"Calibrates {_esc(cls.calibrates)} of **{library_tool}** (its TCP is used as is); the "
            f"*{mounted}* is mounted: it must be the tool that data belongs to.")


def save_preview_markdown(name: str, slot_choice: str, tcp_mm: Sequence[float],
                          abc_deg: Sequence[float]) -> str:
    """What "Save to tool library" will store (echoes the name and slot as typed)."""
    x, y, z = (fmt_num(v) for v in tcp_mm)
    a, b, c = (fmt_num(v) for v in abc_deg)
    shown = f"**{_esc(name.strip())}**" if name.strip() else "*(type a name)*"
    return f"Will save {shown} · X {x} Y {y} Z {z} mm · A {a} B {b} C {c}° · slot: {_esc(slot_choice)}"


def _mm(v: float | None, decimals: int = 2) -> str:
    return "–" if v is None or not math.isfinite(v) else f"{fmt_num(v, decimals)} mm"


def _deg(v: float | None, decimals: int = 2) -> str:
    return "–" if v is None or not math.isfinite(v) else f"{fmt_num(v, decimals)}°"


def step_markdown(wizard: Wizard) -> str:
    """Heading ("**XYZ 4-point** · Step 2 of 4: Touch 2") and the step's instruction."""
    if wizard.is_complete:
        done = "The calibration is computed" if getattr(wizard, "saves_to_library", True) else "The check is done"
        return f"**{_esc(wizard.title)}** · Result\n\n{done}: see *Result* below."
    step = wizard.step
    mark = " ✔ recorded" if step.recorded else ""
    return (f"**{_esc(wizard.title)}** · {_esc(step.heading)}: {_esc(step.title)}{mark}\n\n"
            f"{_esc(step.instruction)}")


def where_to_jog_markdown(wizard: Wizard) -> str:
    """Where a step that is jogged to is done, for the Calibrate tab (the trainee is there
    after Start, the jog keys are on the Jog tab): "" on the result and on a step the
    controller runs itself (a beam scan: Finish is pressed here)."""
    if wizard.is_complete or wizard.auto_role(wizard.step).by_controller:
        return ""
    return ("→ **Jog on the Jog tab** to do this step. Then press **Record** there, in the "
            "*Calibration step* box above the jog keys (key R), or here.")


def scene_legend_markdown(*, computed: bool, true: bool, sphere: bool, radius_mm: float | None = None) -> str:
    """What the result draws in 3D, named (the labels there are short): the COMPUTED and TRUE
    triads and, for a 4-point result, the fitted sphere (radius mm), its flange points and
    approach lines. "" when the result draws none of them."""
    items = []
    if computed:
        items.append("**COMPUTED**: the TOOL frame of this result (thick triad)")
    if true:
        items.append("**TRUE**: the hidden true TOOL frame (thin, longer triad; training)")
    if sphere:
        r = "" if radius_mm is None else f", radius {fmt_num(radius_mm, 1)} mm = |TCP|"
        items.append(f"**blue wire sphere**: the sphere the flange origins were fitted to (centre: the "
                     f"reference tip{r}); dots: the flange origins of the touches (red: outlier, grey: "
                     "dropped); blue lines: from each flange origin toward its TCP")
    return "" if not items else "**In 3D:** " + " · ".join(items) + "."


def steps_list_markdown(wizard: Wizard) -> str:
    """The steps in one line: ✔ recorded, ▶ current, · to do."""
    parts = []
    for s in wizard.steps:
        here = s.index == wizard.step_index and not wizard.is_complete
        sym = "▶" if here else ("✔" if s.recorded else "·")
        parts.append(f"{sym} {_esc(s.title)}")
    if wizard.is_complete:
        parts.append("▶ Result")
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
                   measured: str = "") -> str:
    """Live advice while jogging toward the next touch (all figures predicted by tcpcal from the
    orientations alone, for an operator error of ``sigma_mm`` per axis). While recording here
    would still not make the TCP determinable (``gain.predicted_after`` infinite) the advice is
    ``advice_before_determinable`` (``tcp_pendant.calibrate.diversity``: the angle to the
    nearest touch and the axis still missing, in words) or else ``quality.message`` (tcpcal's).
    ``tilt_hint`` (``tilt_advice.TiltAdvice.text``: which way to tilt for the next touch) ends it.
    ``measured``: whose scatter ``sigma_mm`` is ("your touches", "your last calibration"; ""
    assumed)."""
    basis = (f"{measured}: scatter {fmt_num(sigma_mm, 2)} mm" if measured
             else f"operator error {fmt_num(sigma_mm, 1)} mm")
    head = f"**Pose diversity** (if you recorded here, {basis}):"
    if gain.too_close:
        advice = (f"⚠ **Too close** to an earlier touch: {_deg(gain.angle_to_nearest_deg, 0)} apart. "
                  "Tilt the tool further, about another axis, before recording.")
    elif math.isinf(gain.predicted_after):
        extra = advice_before_determinable or ("" if quality is None else quality.message)
        advice = "Not determinable yet." + (f" {extra}" if extra else "")
    elif math.isinf(gain.predicted_before):
        advice = (f"✔ Recording here makes the TCP determinable: predicted RMS error "
                  f"**{_mm(gain.predicted_after)}**.")
    else:
        word = "✔ Good pose" if gain.reduction >= 0.1 else "This pose adds little"
        advice = (f"{word}: predicted TCP RMS error {_mm(gain.predicted_before)} → "
                  f"**{_mm(gain.predicted_after)}** ({-100.0 * gain.reduction:+.0f} %).")
    near = ("" if math.isinf(gain.angle_to_nearest_deg) or advice_before_determinable else
            f"\n\nNearest recorded orientation: {_deg(gain.angle_to_nearest_deg, 0)} away.")
    hint = f"\n\n{tilt_hint}" if tilt_hint else ""
    return f"{head}\n\n{advice}{near}{hint}"


def result_markdown(result: WizardResult, truth: TruthComparison | None = None) -> str:
    """What the result panel shows of ``result``, by how its wizard class shows results
    (``Wizard.result_view``): the calibrated frame and its quality figures (what a pendant shows
    after a calibration); a check's rotations, implied error, correction and verdict
    (:func:`tcp_check_markdown`); a scan's events and lesson (:func:`beam_result_markdown`;
    ``truth``: its comparison with the true tool, given only where the truth may be shown).
    """
    view = wizard_class(result.wizard).result_view
    if view == "spin_check":
        return tcp_check_markdown(result)  # type: ignore[arg-type]  # its wizard's result type
    if view == "beam_scan":
        return beam_result_markdown(result, truth)  # type: ignore[arg-type]  # its wizard's result type
    return touches_result_markdown(result)


def touches_result_markdown(result: WizardResult) -> str:
    """A result computed from recorded touches: the TCP (and orientation) with its figures."""
    x, y, z = (fmt_num(v) for v in result.tcp_mm)
    lines = [f"**TCP** X {x} · Y {y} · Z {z} mm"]
    if result.abc_deg is not None:
        a, b, c = (fmt_num(v) for v in result.abc_deg)
        lines.append(f"**Orientation** A {a} · B {b} · C {c}° (KUKA: Rz(A) Ry(B) Rx(C))")
    rows: list[tuple[str, str]] = [("method", _esc(result.method))]
    tcp = result.tcp_result
    if tcp is not None:
        n = len(result.per_touch_error_mm)
        errs = ", ".join(f"P{i + 1} {fmt_num(e)}" for i, e in zip(_touch_numbers(result), result.per_touch_error_mm))
        rows += [
            ("error per touch (mm)", errs if n else "–"),
            ("mean error", _mm(result.mean_error_mm)),
            ("max error", _mm(result.max_error_mm)),
            ("RMS error", _mm(result.rms_error_mm)),
            ("95 % radius of the TCP", _mm(result.ci95_mm)),
        ]
        if result.wizard == "reference":
            # one touch per tool: no redundancy, so the noise is assumed, and the angle between
            # the two touches (two different tools) says nothing about the result
            rows.append(("assumed touch error (per axis)", _mm(float(tcp.noise_sigma))))
        else:
            rows.append(("touch noise estimate (per axis)", _mm(float(tcp.noise_sigma))))
            if tcp.n_touches >= 2:
                rows += [("angle between touches",
                          f"{_deg(tcp.min_angle_deg, 1)} to {_deg(tcp.max_angle_deg, 1)}"),
                         ("condition number", f"{tcp.condition_number:.1f}")]
    if result.orthogonality_defect_deg is not None:
        rows.append(("orthogonality defect", _deg(result.orthogonality_defect_deg, 3)))
    if result.displacements_mm:
        rows.append(("displacement lengths Δ", ", ".join(_mm(d, 1) for d in result.displacements_mm)))
    table = "| figure | value |\n|---|---|\n" + "\n".join(f"| {k} | {v} |" for k, v in rows)
    return "\n\n".join(lines) + "\n\n" + table


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


def beam_result_markdown(result: BeamWizardResult, truth: TruthComparison | None = None) -> str:
    """An Automatic (beam) result: the TCP with its 95 % radius, the measured tool direction,
    the TOOL frame to save (and that it is the planning orientation turned onto the measured
    direction), the figures, the events with their residuals, the time the scan takes on a real
    robot, and the lesson: automatic vs the trainee's last manual calibration of the same tool
    (times; errors against the true tool only with ``truth``, the beam run's own comparison,
    which the caller gives only where the truth may be shown).
    """
    x, y, z = (fmt_num(v) for v in result.tcp_mm)
    lines = [f"**TCP** X {x} · Y {y} · Z {z} mm (FLANGE) · 95 % radius {_mm(result.ci95_mm, 3)}"]
    if result.direction_flange is not None:
        dx, dy, dz = (f"{v:+.4f}" for v in result.direction_flange)
        cone = result.direction_ci95_deg
        lines.append(f"**Tool direction** (TOOL X in FLANGE) {dx} · {dy} · {dz} · 95 % cone "
                     + (_deg(cone, 3) if cone is not None and math.isfinite(cone) else "– (no redundancy)"))
    else:
        lines.append("**Tool direction** not measured (see the warnings)")
    if result.abc_deg is not None:
        a, b, c = (fmt_num(v) for v in result.abc_deg)
        how = (f"the planning orientation turned by {_deg(result.direction_turn_deg, 3)} so that its X is the "
               "measured direction" if result.direction_turn_deg is not None else "the planning orientation as it is")
        lines.append(f"**TOOL frame to save** A {a} · B {b} · C {c}° (KUKA): {how}; the beam does not see the "
                     "turn about the tool's X, which is kept from the planning data.")
    beam = result.beam_result
    rows = [("method", _esc(result.method)),
            ("tip events (TCP)", str(len(result.tip_event_indices))),
            ("sideways crossings used (direction)", str(len(result.axis_event_indices))),
            ("mean error (tip off the beam line)", _mm(result.mean_error_mm, 3)),
            ("max error", _mm(result.max_error_mm, 3)),
            ("RMS error", _mm(result.rms_error_mm, 3)),
            ("95 % radius of the TCP", _mm(result.ci95_mm, 3)),
            ("event noise estimate (per axis)", _mm(float(beam.noise_sigma), 4)),
            ("scan on a real robot", f"{duration_words(result.duration_s)} (path {fmt_num(result.path_length_m, 2)} m)")]
    table = "| figure | value |\n|---|---|\n" + "\n".join(f"| {k} | {v} |" for k, v in rows)
    return "\n\n".join([*lines, table, _beam_events_markdown(result), _beam_lesson_markdown(result, truth)])


def _beam_events_markdown(result: BeamWizardResult) -> str:
    """The events: orientation, kind, beam, and the residual of each event used (mm)."""
    tips = dict(zip(result.tip_event_indices, result.beam_result.residuals))
    axes = {} if result.axis_result is None else dict(zip(result.axis_event_indices,
                                                          (abs(float(r)) for r in result.axis_result.residuals)))
    rows = []
    for i, e in enumerate(result.events):
        kind = "tip on the beam" if e.kind == "tip" else "shaft crossed sideways"
        if i in tips:
            used = f"{fmt_num(float(tips[i]), 4)} mm from the beam line"
        elif i in axes:
            used = f"axis {fmt_num(axes[i], 4)} mm from the beam line"
        else:
            used = "not used" + ("" if e.on_shaft else " (off the shaft)")
        rows.append(f"| {i + 1} | {e.orientation + 1} | {kind} | {e.beam + 1} | {used} |")
    return (f"**Events** ({len(result.events)})\n\n| # | orientation | event | beam | residual |\n"
            "|---|---|---|---|---|\n" + "\n".join(rows))


def _beam_lesson_markdown(result: BeamWizardResult, truth: TruthComparison | None) -> str:
    """Automatic vs by hand, on the same tool: time (and errors against the truth, with it)."""
    manual = result.manual
    if manual is None:
        return ("**Automatic vs by hand:** no manual calibration of this tool in this session yet. "
                f"The scan takes {duration_words(result.duration_s)} on a real robot; calibrate the tool by hand "
                "(e.g. XYZ 4-point) and scan again to compare.")
    if manual.auto_touches == 0:
        who, whose = "by hand", "your time"
    elif manual.auto_touches >= manual.touches:
        who, whose = "by Auto-touch", "Auto-touch's clicks"
    else:
        who, whose = f"{manual.auto_touches} of {manual.touches} touches by Auto-touch", "your time"
    name = f"{manual.run_number}: {_esc(manual.title)} ({who})"
    if truth is None:
        return ("**Automatic vs by hand** (same tool)\n\n| calibration | time |\n|---|---|\n"
                f"| Automatic (beam) | {duration_words(result.duration_s)} on a real robot |\n"
                f"| {name} | {duration_words(manual.wall_time_s)} ({whose}) |")
    head = ("**Automatic vs by hand** (same tool, against the true tool)\n\n"
            "| calibration | time | TCP error | direction error |\n|---|---|---|---|")
    beam = (f"| Automatic (beam) | {duration_words(result.duration_s)} on a real robot | "
            f"{_mm(truth.position_error_mm, 3)} | {_deg(truth.x_axis_error_deg, 3)} |")
    hand = (f"| {name} | {duration_words(manual.wall_time_s)} ({whose}) | {_mm(manual.position_error_mm, 3)} | "
            f"{_deg(manual.direction_error_deg, 3)} |")
    return "\n".join([head, beam, hand])


def _touch_numbers(result: WizardResult) -> Sequence[int]:
    """0-based recorded-touch index of each per-touch error (a result that leaves touches out,
    the 4-point's, says which it used: ``used_indices``)."""
    used = getattr(result, "used_indices", None)
    return range(len(result.per_touch_error_mm)) if used is None else used


def empty_touches_markdown(wizard: Wizard | None) -> str:
    """What the Touches list says with no free touch (Record point): "No touch recorded", or,
    while a wizard on show has recorded steps, that they are its (our words and numbers)."""
    n = 0 if wizard is None or wizard.status == "cancelled" else len(wizard.recorded_poses)
    if wizard is None or n == 0:
        return "*No touch recorded.*"
    return (f"*No touch recorded with Record point. The {_esc(wizard.title)} wizard has {n} "
            f"touch{'es' if n != 1 else ''} of its own: they are in its step list above.*")


def warnings_markdown(result: WizardResult) -> str:
    """Warnings (⚠) then standing notes (ℹ), one per line; empty when there are none."""
    lines = [f"⚠ {_esc(w)}" for w in result.warnings] + [f"ℹ {_esc(n)}" for n in result.notes]
    return "\n\n".join(lines)


def comparison_markdown(result: Xyz4Result) -> str:
    """The three 4-point estimators side by side on the same touches (mm)."""
    head = "| estimator | X | Y | Z | mean | max | RMS | 95 % |\n|---|---|---|---|---|---|---|---|"
    rows = []
    for r in result.comparison_rows():
        label = r["label"] + (" ◀ reported" if r.get("chosen") else "")
        if not r["ok"]:
            rows.append(f"| {label} | cannot solve: {_esc(r['error'])} ||||||| ")
            continue
        x, y, z = (fmt_num(v) for v in r["tcp_mm"])
        rows.append(f"| {label} | {x} | {y} | {z} | {fmt_num(r['mean_error_mm'])} | "
                    f"{fmt_num(r['max_error_mm'])} | {fmt_num(r['rms_error_mm'])} | {fmt_num(r['ci95_mm'])} |")
    return (head + "\n" + "\n".join(rows) + "\n\nAll figures in mm. Same touches, three estimators: "
            "the joint least squares is the maximum-likelihood one (their equations: The math).")


def truth_markdown(cmp: TruthComparison) -> str:
    """Training mode: the result against the hidden true TOOL frame, with the verdict."""
    icon = {"good": "✔", "fair": "●", "poor": "✘"}[cmp.grade]
    lines = [f"{icon} **Against the true TOOL frame: {cmp.verdict}**",
             f"Position error of the TCP: **{_mm(cmp.position_error_mm, 3)}**"]
    if cmp.orientation_error_deg is not None:
        lines.append(f"Orientation error: **{_deg(cmp.orientation_error_deg, 3)}** "
                     f"(tool X: {_deg(cmp.x_axis_error_deg, 3)})")
    if cmp.inside_ci95 is not None:
        if cmp.position_error_mm < NUMERICAL_NOISE_MM:
            lines.append("The touches were exact (no operator error): the computed TCP is the true one.")
        else:
            lines.append("The true TCP is " + ("inside" if cmp.inside_ci95 else "**outside**")
                         + " the 95 % radius.")
    return "\n\n".join(lines)


def save_markdown(slot: int, name: str) -> str:
    """Confirmation after "Save to tool library"."""
    return f"✔ Saved **{_esc(name)}** in slot {slot}; it is now the active tool."


def replay_markdown(checks: Sequence[ReplayCheck]) -> str:
    """A loaded session record, recomputed: one row per wizard (how a trainer grades)."""
    if not checks:
        return "The record holds no calibration."
    head = "| # | calibration | replay | against truth |\n|---|---|---|---|"
    rows = []
    for c in checks:
        truth = "–" if c.truth is None else _esc(c.truth.verdict)
        ok = "✔ " if c.matches else "✘ "
        rows.append(f"| {c.index + 1} | {_esc(c.wizard.title)} | {ok}{_esc(c.message)} | {truth} |")
    return head + "\n" + "\n".join(rows)


def estimator_options() -> dict[str, Estimator]:
    """Dropdown label -> estimator key, in the wizard's order."""
    return {label: key for key, label in ESTIMATOR_LABELS.items()}


def hidden_touches_markdown(result: WizardResult, distance_mm: Mapping[int, float],
                            hidden: Collection[int]) -> str:
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
    errors = dict(zip(_touch_numbers(result), result.per_touch_error_mm))
    rows = [f"| P{i + 1} | {_mm(distance_mm[i])} | {_mm(errors[i]) if i in errors else 'not used'} |"
            for i in steps]
    return ("**Recorded with the distance hidden**: how far each tip really was\n\n"
            "| touch | distance at record | error in the result |\n|---|---|---|\n" + "\n".join(rows))
