"""The Calibrate tab, its step and result panels and the Jog tab's wizard dock in the
session's language: with the pseudo-locale every text of their handles comes from the catalogs
(the menu of every method, each step of a 4-point, its result with the estimators compared, the
save), the text functions of ``calibrate.text`` speak the translator they are given, and a
language switch in the middle of a wizard re-renders the dock, the steps and the result.

Exempt from the check, besides names and numbers: the words other modules compose and hand to
these views (a wizard's step heading, title and instruction, its warnings and blocked reason,
Auto-touch's outcome, the meter's and the tilt advisor's words, the truth's verdict) and the
wizard classes' attributes (titles, blurbs, options, variants, estimator labels) while the
catalogs still lack them: they are marked and translated by their own modules, checked by their
own tests; the spans are removed exactly, never by word.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator

import pytest
import viser

from support.calib_page import Page
from support.pseudo_text import WORD, english_words, gui_texts, untranslated_words

from tcp_pendant.calibrate.exercise_brief import default_instructions_markdown
from tcp_pendant.calibrate.pendant_rules import ExerciseRules
from tcp_pendant.calibrate.tcp_estimate import TcpEstimate
from tcp_pendant.calibrate.text import (
    empty_touches_markdown,
    meter_markdown,
    menu_markdown,
    replay_markdown,
    save_markdown,
    save_preview_markdown,
    scene_legend_markdown,
)
from tcp_pendant.controller import builtin_tools
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import ENGLISH, PSEUDO_LANGUAGE, translator
from tcp_pendant.views.wizard_dock import WizardDock
from tcp_pendant.views.wizard_menu import CalibrateView
from tcp_pendant.wizards import ESTIMATOR_LABELS, Wizard, wizard_classes
from tcp_pendant.wizards.tcp_check import tcp_check_markdown
from tcpcal.pose_quality import CandidateGain

from support.wsclient import wait_until

pytestmark = pytest.mark.app_page(cls=Page, seed=5)

QPS = translator(PSEUDO_LANGUAGE)
NAMES = (set("XYZABC") | {"TCP", "TOOL", "FLANGE", "WORLD", "BASE", "mm", "deg", "KUKA", "Rz", "Ry", "Rx",
                          "JSON", "CSV", "R", "N", "B", "s", "min", "h", "m", "Shift"}
         | {f"P{i}" for i in range(1, 21)} | {"xyz4", "lstsq", "sphere", "pairwise"})
"""Axis, frame and unit names, key names, touch names (P1...) and the result's method key."""

_HANDLES = (viser.GuiMarkdownHandle, viser.GuiButtonHandle, viser.GuiButtonGroupHandle, viser.GuiCheckboxHandle,
            viser.GuiDropdownHandle, viser.GuiSliderHandle, viser.GuiFolderHandle, viser.GuiTextHandle,
            viser.GuiUploadButtonHandle, viser.GuiHtmlHandle)


def _class_words() -> set[str]:
    """The wizard classes' attributes the catalogs do not hold yet (their module marks them)."""
    pieces: set[str] = set(ESTIMATOR_LABELS.values())
    for cls in wizard_classes():
        pieces |= {cls.title, cls.blurb, str(getattr(cls, "calibrates", ""))}
        pieces |= {label for _v, label in cls.variants}
        for opt in cls.options:
            pieces |= {opt.label, opt.hint} | {label for _v, label in opt.choices}
    return {p for p in pieces if p and QPS.gettext(p) == p}


def _foreign(session: object, wiz: Wizard | None) -> set[str]:
    """The texts other modules hand to these views now, escaped as shown (module docstring)."""
    pieces = set(_class_words())
    if wiz is not None:
        for step in wiz.steps:
            pieces |= {step.heading, step.title, step.instruction}
        if not wiz.is_complete:
            pieces |= {wiz.step.heading, wiz.step.title, wiz.step.instruction, wiz.blocked_reason or ""}
        res = wiz.finished_result
        if res is not None:
            pieces |= set(res.warnings) | set(res.notes)
            pieces.add(f" {escape_markdown(res.method)} |")      # the method's key in the figures table
            if type(wiz).result_view == "spin_check":          # the TCP check's own words (its module's)
                pieces.add(tcp_check_markdown(res))  # type: ignore[arg-type]
    if wiz is not None and wiz.is_complete:                  # the default save name: the tool's label as data
        pieces.add(session.controller.mounted_tool.label)    # type: ignore[attr-defined]
    wf = session.workflow                                    # type: ignore[attr-defined]
    truth = wf.truth() if wf.result is not None else None
    if truth is not None:
        pieces.add(truth.verdict)
    pieces |= {part for _i, label in wf.resumable() for part in (label, label.rsplit(", ", 1)[0])}
    return {p for p in pieces if p} | {escape_markdown(p) for p in pieces if p}


def _without(text: str, pieces: Iterable[str]) -> str:
    """``text`` without the exempt ``pieces`` and without HTML entities (``&nbsp;``: a space)."""
    text = text.replace("&nbsp;", " ")
    for piece in sorted(pieces, key=len, reverse=True):
        text = text.replace(piece, " ")
    return text


def _handles(*owners: object) -> Iterator[tuple[str, object]]:
    for owner in owners:
        for name, value in vars(owner).items():
            items = value.values() if isinstance(value, dict) else value if isinstance(value, list) else (value,)
            for item in items:
                if isinstance(item, _HANDLES):
                    yield f"{type(owner).__name__}.{name}", item


# Auto-touch's outcome is composed by calibrate.autotouch (another module's words, checked there)
_OTHERS = {"WizardStepsView.auto_md"}


def _untranslated(session: object, view: CalibrateView, dock: WizardDock) -> list[tuple[str, list[str]]]:
    wiz = view.workflow.wizard
    foreign = _foreign(session, wiz)
    names = set(NAMES)
    names |= {w for t in view._library.values() for w in WORD.findall(str(t.name))}
    bad = []
    shown = [o for o in (view.steps, view.result, dock) if o.folder.visible]   # a hidden panel: not on screen
    for name, handle in _handles(view, *shown):
        if name in _OTHERS or not getattr(handle, "visible", True):
            continue
        for text in gui_texts(handle):
            if text in foreign:
                continue
            words = untranslated_words(_without(text, foreign), names)
            if words:
                bad.append((name, words))
    return bad


def test_with_the_pseudo_locale_the_menu_of_every_method_is_from_the_catalogs(page) -> None:
    p = page(language=PSEUDO_LANGUAGE)
    v, s = p.view, p.session
    dock = s.views["dock"]
    assert v.training.label == QPS.gettext("Training mode") != "Training mode"
    for label in tuple(v.method.options):
        p.choose(v.method, label)
        assert _untranslated(s, v, dock) == [], label
    assert v.menu_folder.label == QPS.gettext("Calibrate")


def test_with_the_pseudo_locale_a_4point_its_steps_dock_and_result_are_from_the_catalogs(page) -> None:
    p = page(language=PSEUDO_LANGUAGE)
    v, s = p.view, p.session
    dock: WizardDock = s.views["dock"]
    p.click(v.start)
    assert v.steps.folder.visible and dock.folder.visible
    for k in range(4):
        assert _untranslated(s, v, dock) == [], f"step {k + 1}"
        assert v.steps.next.label == QPS.gettext("Finish" if k == 3 else "Next")
        assert tuple(dock.nav.options)[0] == QPS.gettext("◀ Back")
        p.click(v.steps.auto_touch)
    assert v.result.folder.visible
    assert v.steps.cancel.label == QPS.gettext("Close (not saved)")
    assert tuple(dock.nav.options) == (QPS.gettext("◀ Back"), QPS.gettext("Close"))
    p.choose(v.result.compare, True)
    assert v.result.compare_md.visible
    assert _untranslated(s, v, dock) == []
    assert QPS.gettext("| figure | value |") in v.result.result_md.content
    assert v.result.chart.title == QPS.gettext("Error per touch (mm)")
    p.choose(v.result.estimator, tuple(v.result.estimator.options)[1])    # a translated option is read
    assert v.workflow.result.estimator == "sphere"
    p.click(v.result.save)
    assert v.workflow.last_save is not None
    assert v.result.save_md.content.startswith("⟦✔")
    assert _untranslated(s, v, dock) == []


def _walk(p: Page, dock: WizardDock) -> list[str]:
    """The open wizard through its steps to its result (Auto-touch, Mount, Next / Finish),
    checking every text at each step and on the result; returns what was checked."""
    v, s = p.view, p.session
    seen = []
    for _i in range(40):
        wiz = v.workflow.wizard
        assert wiz is not None
        where = "result" if wiz.is_complete else f"step {wiz.step_index + 1}"
        assert _untranslated(s, v, dock) == [], f"{wiz.kind} {where}"
        seen.append(where)
        if wiz.is_complete:
            return seen
        if v.steps.mount.visible:
            p.click(v.steps.mount)
        elif v.steps.record.visible and not wiz.step.recorded and v.steps.auto_folder.visible:
            p.click(v.steps.auto_touch)
            wait_until(lambda: not v.steps._auto_touching, what="Auto-touch")
        elif not v.steps.next.disabled:
            p.click(v.steps.next)
            wait_until(lambda: not v.steps._checking, what="the controller job")
        else:
            raise AssertionError(f"{wiz.kind} {where}: nothing to click")
    raise AssertionError("no result after 40 clicks")


def test_with_the_pseudo_locale_every_wizard_walks_to_its_result_in_the_catalogs_words(page) -> None:
    """Each method of the menu, started with its defaults (the tool library holds the 4-point
    just saved), through its steps to its result; then Close brings the menu back."""
    p = page(language=PSEUDO_LANGUAGE)
    v, s = p.view, p.session
    dock: WizardDock = s.views["dock"]
    walked = {}
    for cls in [c for c in v._classes.values() if c.kind == "xyz4"] + [c for c in v._classes.values()
                                                                          if c.kind != "xyz4"]:
        p.choose(v.method, QPS.gettext(cls.title))
        assert _untranslated(s, v, dock) == [], f"menu of {cls.kind}"
        p.click(v.start)
        assert v.workflow.wizard is not None and v.workflow.wizard.kind == cls.kind, cls.kind
        walked[cls.kind] = _walk(p, dock)
        if cls.kind == "xyz4":
            p.click(v.result.save)
            assert v.workflow.last_save is not None
        p.click(v.steps.cancel)                       # Close
        assert v.menu_folder.visible and _untranslated(s, v, dock) == []
    assert set(walked) == {c.kind for c in wizard_classes()}
    assert all(w[-1] == "result" and len(w) >= 2 for w in walked.values()), walked


def test_the_language_switched_mid_wizard_re_renders_dock_steps_and_result(page) -> None:
    p = page()
    v, s = p.view, p.session
    dock: WizardDock = s.views["dock"]
    p.click(v.start)
    p.click(v.steps.auto_touch)
    wizard = v.workflow.wizard
    assert dock.record.label == "Record" and v.steps.next.label == "Next"
    assert any(name == "WizardDock.record" for name, _w in _untranslated(s, v, dock))   # the check bites
    with s.lock:
        s.set_language(PSEUDO_LANGUAGE)
    assert v.workflow.wizard is wizard and wizard is not None and len(wizard.recorded_poses) == 1
    assert dock.record.label == QPS.gettext("Record") and dock.folder.label == QPS.gettext("Calibration step")
    assert tuple(dock.nav.options) == tuple(QPS.gettext(t) for t in ("◀ Back", "Next ▶", "Cancel"))
    assert v.steps.next.label == QPS.gettext("Next") and v.steps.record.hint == QPS.gettext(
        "Store the current flange pose for this step.")
    assert tuple(v.steps.auto_direction.options) == (QPS.gettext("random"), QPS.gettext("chosen (tilt, azimuth)"))
    assert _untranslated(s, v, dock) == []
    # a click on a button shown in the old language (English) is still read: Back
    p.choose(dock.nav, "◀ Back")
    assert wizard.step_index == 0
    for _k in range(4):
        p.click(v.steps.auto_touch)
    assert v.result.folder.visible and _untranslated(s, v, dock) == []
    with s.lock:
        s.set_language("en")
    assert v.result.save.label == "Save to tool library" and v.steps.cancel.label == "Close (not saved)"
    assert "| figure | value |" in v.result.result_md.content
    assert v.result.chart.title == "Error per touch (mm)"
    assert tuple(dock.nav.options) == ("◀ Back", "Close")


def test_the_text_functions_speak_the_translator_they_are_given() -> None:
    names = NAMES | {"Pointer", "pointer", "Torch", "torch", "Tool"}
    for cls in wizard_classes():
        text = menu_markdown(cls.kind, library_tool="1: Pointer", reference_tool="Pointer", new_tool="Torch",
                             mounted_tool="Pointer", tr=QPS)
        assert untranslated_words(_without(text, _class_words()), names) == [], cls.kind
    assert untranslated_words(save_preview_markdown("Tool", "2: Torch", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0), tr=QPS),
                              names) == []
    assert untranslated_words(save_preview_markdown(" ", "2: Torch", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0), tr=QPS),
                              names) == []
    assert untranslated_words(save_markdown(3, "Tool", tr=QPS), names) == []
    legend = scene_legend_markdown(computed=True, true=True, sphere=True, radius_mm=150.0, tr=QPS)
    assert untranslated_words(legend, names) == [] and "150.0" in legend
    assert untranslated_words(replay_markdown([], tr=QPS), names) == []
    assert untranslated_words(empty_touches_markdown(None, tr=QPS), names) == []
    brief = default_instructions_markdown(ExerciseRules(exercise="e1", min_touches=6, distance_locked=True,
                                                        auto_touch_allowed=False), tr=QPS)
    assert brief and untranslated_words(_without(brief, _class_words()), names) == []
    assert TcpEstimate((0.0, 0.0, 150.0), 3).tool(tr=QPS).name.startswith("⟦")
    # English stays as it was
    assert TcpEstimate((0.0, 0.0, 150.0), 3).tool().name == "Estimate, 3 touches"
    assert save_markdown(3, "Tool") == "✔ Saved **Tool** in slot 3; it is now the active tool."
    assert save_markdown(3, "Tool", tr=ENGLISH) == save_markdown(3, "Tool")


@pytest.mark.parametrize("gain", [
    CandidateGain(float("inf"), float("inf"), 0.0, float("inf"), False, ""),
    CandidateGain(float("inf"), float("inf"), 0.0, 12.0, True, ""),
    CandidateGain(float("inf"), 0.8, 1.0, 50.0, False, ""),
    CandidateGain(0.8, 0.5, 0.375, 50.0, False, ""),
    CandidateGain(0.8, 0.78, 0.025, 50.0, False, ""),
])
def test_the_meter_speaks_the_translator_it_is_given(gain: CandidateGain) -> None:
    for measured in ("", "your touches"):
        text = meter_markdown(gain, None, 0.5, measured=measured, tr=QPS)
        assert english_words(text, NAMES) == [], text
        assert meter_markdown(gain, None, 0.5, measured=measured) == meter_markdown(gain, None, 0.5,
                                                                                   measured=measured, tr=ENGLISH)
    assert meter_markdown(CandidateGain(0.8, 0.5, 0.375, 50.0, False, ""), None, 0.5) == (
        "**Pose diversity** (if you recorded here, operator error 0.5 mm):\n\n✔ Good pose: predicted TCP RMS "
        "error 0.80 mm → **0.50 mm** (-38 %).\n\nNearest recorded orientation: 50° away.")


def test_the_menu_keeps_its_choice_across_a_switch_and_reads_a_click_in_the_old_language(page) -> None:
    p = page()
    v, s = p.view, p.session
    titles = {c.kind: c.title for c in wizard_classes()}
    p.choose(v.method, titles["tcp-zx"])
    assert v.method.label == "Method"
    with s.lock:
        s.set_language(PSEUDO_LANGUAGE)
    assert v.method.label == QPS.gettext("Method") != "Method"
    assert v.method.value == QPS.gettext(titles["tcp-zx"])            # the choice kept, in the new words
    assert tuple(v.method.options) == tuple(QPS.gettext(c.title) for c in wizard_classes())
    assert v.start.label == QPS.gettext("Start") and v.record_folder.label == QPS.gettext("Session record")
    assert v.library_tool is not None and v.library_tool.value == QPS.gettext("(library empty)")
    # a click sent before the browser saw the switch names the method in English: still read
    p.choose(v.method, titles["xyz4"])
    p.click(v.start)
    assert v.workflow.wizard is not None and v.workflow.wizard.kind == "xyz4"
    assert _untranslated(s, v, s.views["dock"]) == []


def test_with_the_pseudo_locale_the_docks_record_lines_tilt_line_and_meter_are_from_the_catalogs(page) -> None:
    """What the dock and the steps say while a 4-point runs: the meter with the scatter's
    basis and the diversity advice, the tilt advisor's and the reachable tilts' line, and the
    line after the dock's Record (distance shown, hidden in practice, and the question before a
    far touch), each in the session's language."""
    p = page(language=PSEUDO_LANGUAGE)
    v, s = p.view, p.session
    dock: WizardDock = s.views["dock"]
    p.click(v.start)
    wizard = v.workflow.wizard
    assert wizard is not None
    p.click(v.steps.auto_touch)
    p.click(v.steps.auto_touch)                # two touches: the meter and the tilt line have their say
    with s.lock:
        s.motion.jog("B", 1)
    assert dock.tilt_html.visible and dock.meter_md.visible and v.steps.meter_md.visible
    for handle in (dock.tilt_html, dock.meter_md, v.steps.meter_md):
        text = handle.content
        assert text and english_words(text, NAMES) == [], text
    assert QPS.gettext("Pose diversity: first touch, any orientation.") not in dock.meter_md.content
    notes = []
    for hide in (False, True):
        with s.lock:
            s.set_hide_distance(hide)
        p.click(dock.record)
        notes.append(dock.note_md.content)
    assert len(set(notes)) == 2, notes
    for note in notes:
        assert note.count("⟦") >= 1 and english_words(note, NAMES) == [], note
    assert _untranslated(s, v, dock) == []


def test_the_physical_tool_choices_are_in_the_sessions_words_and_kept_across_a_switch(page) -> None:
    """The reference method's physical tools (built-in models' labels) in the pseudo-locale; a
    choice made there is the same tool after a switch to English, and read as its key."""
    p = page(language=PSEUDO_LANGUAGE)
    v, s = p.view, p.session
    new = v.new_physical
    assert new is not None
    labels = {t.key: t.label for t in builtin_tools().values()}
    assert set(new.options) == {QPS.gettext(label) for label in labels.values()}
    p.choose(new, QPS.gettext(labels["torch"]))
    assert v._physical_key(labels["gripper"]) == "gripper"                  # English is read too
    with s.lock:
        s.set_language("en")
    assert new.value == labels["torch"] and set(new.options) == set(labels.values())
    assert v._physical_key(str(new.value)) == "torch"
