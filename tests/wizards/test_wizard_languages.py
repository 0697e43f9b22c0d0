"""The wizards' per-instance texts in the session's language (issue 47): every step of every
wizard kind, the refusals and the result's own warnings come from the catalogs (the
pseudo-locale shows every word of them wrapped), English stays as it was, and a language switch
re-renders the step on show."""

from __future__ import annotations

import numpy as np
import pytest

from support.calib_helpers import make_session
from support.pseudo_text import untranslated_words
from tcpcal.tool import Calibration, Tool
from tcp_pendant.calibrate.autotouch import MOVED_DURING_PROBE
from tcp_pendant.calibrate.finish_checks import wrong_tool_touch
from tcp_pendant.calibrate.record_words import recorded_words
from tcp_pendant.controller import builtin_tools
from tcp_pendant.translation import ENGLISH, PSEUDO_LANGUAGE, translator
from tcp_pendant.wizards import (
    AbcWorldWizard,
    ReferenceWizard,
    ThreePointWizard,
    Wizard,
    WizardError,
    Xyz4Wizard,
    wizard_classes,
)
from tcp_pendant.wizards.beam import BeamWizard
from tcp_pendant.wizards.check_reading import reading_verdict
from tcp_pendant.wizards.session_record import WizardRun
from tcp_pendant.wizards.tcp_check import TcpCheckWizard
from tcp_pendant.wizards.tcp_zx import TcpZxWizard

QPS = translator(PSEUDO_LANGUAGE)
NAMES = {"ref", "tool"}               # tool names: user text, shown as given


def library_tool(tcp_mm=(0.0, 0.0, 180.0), name="tool", *, calibrated=True) -> Tool:
    cal = Calibration("xyz4-lstsq", "2026-01-01T00:00:00Z", {"ci95_mm": 0.3}) if calibrated else None
    return Tool(name=name, tcp_mm=tuple(float(v) for v in tcp_mm), calibration=cal)


def every_wizard() -> list[Wizard]:
    """One wizard of every kind, both three-point and ABC world variants, the 4-point with an
    extra touch (its fifth step's own instruction)."""
    tool = library_tool()
    return [
        Xyz4Wizard(n_points=5),
        TcpZxWizard(n_points=5),
        ReferenceWizard(library_tool(name="ref"), reference_tool_key="pointer", new_tool_key="torch",
                        new_tool_label="the torch"),
        ReferenceWizard(library_tool(name="ref")),
        ThreePointWizard(tool, variant=1),
        ThreePointWizard(tool, variant=2),
        AbcWorldWizard(tool, variant="6d"),
        AbcWorldWizard(tool, variant="5d"),
        TcpCheckWizard(tool, slot=1),
        BeamWizard(),
    ]


def own_warnings(res) -> list[str]:
    """The result's warnings: tcpcal's first (said again from the catalogs,
    ``wizards.solver_words``), then the wizard's."""
    return list(res.warnings)


def assert_pseudo(text: str | None, names: set[str] = NAMES) -> None:
    assert text, "no text"
    assert untranslated_words(text, names) == [], text


def test_every_wizard_kind_is_covered() -> None:
    assert {type(w) for w in every_wizard()} == set(wizard_classes())


@pytest.mark.parametrize("wiz", every_wizard(), ids=lambda w: f"{w.kind}-{w.variant}")
def test_every_step_of_every_wizard_is_from_the_catalogs(wiz: Wizard) -> None:
    english = [(s.heading, s.title, s.instruction) for s in wiz.steps]
    wiz.set_translator(QPS)
    assert len(wiz.steps) == len(english)
    for step, (heading, title, instruction) in zip(wiz.steps, english):
        for text, source in ((step.heading, heading), (step.title, title), (step.instruction, instruction)):
            assert_pseudo(text)
            assert text != source
    wiz.set_translator(ENGLISH)
    assert [(s.heading, s.title, s.instruction) for s in wiz.steps] == english


@pytest.mark.parametrize("wiz", every_wizard(), ids=lambda w: f"{w.kind}-{w.variant}")
def test_refusals_of_every_wizard_are_from_the_catalogs(wiz: Wizard) -> None:
    wiz.set_translator(QPS)
    with pytest.raises(WizardError) as next_refused:
        wiz.finish()                      # nothing recorded (the beam wizard: no scan)
    assert_pseudo(str(next_refused.value))
    with pytest.raises(WizardError) as no_step:
        wiz.go_to(wiz.n_steps + 3)
    assert_pseudo(str(no_step.value))
    wiz.cancel()
    assert_pseudo(wiz.blocked_reason)
    with pytest.raises(WizardError) as cancelled:
        wiz.record(np.eye(4))
    assert_pseudo(str(cancelled.value))
    if type(wiz).variants:
        wiz.resume()
    else:
        with pytest.raises(WizardError) as no_variant:
            wiz.set_variant(1)
        assert_pseudo(str(no_variant.value))
    if not type(wiz).supports_add_point:
        with pytest.raises(WizardError) as no_add:
            wiz.add_point()
        assert_pseudo(str(no_add.value))


def test_a_step_for_another_tool_says_so_in_the_language() -> None:
    wiz = ReferenceWizard(library_tool(name="ref"), reference_tool_key="pointer", new_tool_key="torch")
    wiz.set_translator(QPS)
    wiz.note_mounted_tool("torch", {"pointer": "Pointer", "torch": "Torch"})
    assert_pseudo(wiz.blocked_reason, NAMES | {"pointer", "torch"})
    with pytest.raises(WizardError) as refused:
        wiz.record(np.eye(4))
    assert_pseudo(str(refused.value), NAMES | {"pointer", "torch"})


def test_the_four_point_warnings_notes_and_plurals(synth) -> None:
    tool = synth.tools["pointer"]
    wiz = Xyz4Wizard(n_points=6)
    wiz.set_translator(QPS)
    for d in synth.directions[:6]:
        wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(*d)))
        out = wiz.next()
    assert wiz.is_complete and out is wiz.result
    with pytest.raises(WizardError) as too_many:
        wiz.set_excluded([0, 1, 2])
    assert_pseudo(str(too_many.value))
    one = wiz.set_excluded([1])
    two = wiz.set_excluded([1, 2])
    assert one is not None and two is not None
    assert own_warnings(one) and own_warnings(two)
    for text in (*own_warnings(one), *one.notes, *own_warnings(two), *two.notes):
        assert_pseudo(text)
    wiz.set_translator(ENGLISH)                    # the result is recomposed: same figures, English words
    res = wiz.result
    assert res is not None and res.tcp_mm == two.tcp_mm and res.computed_at == two.computed_at
    assert "Touches 2, 3 were dropped by you and are not used." in res.warnings
    wiz.set_excluded([1])
    assert wiz.result is not None and "Touch 2 was dropped by you and is not used." in wiz.result.warnings


@pytest.mark.parametrize("make, offsets", [
    (lambda t: ThreePointWizard(t, variant=1), [(0, 0, 0), (-60.0, 0, 0), (0.0, 60.0, 0.0)]),
    (lambda t: ThreePointWizard(t, variant=2), [(0, 0, 0), (-60.0, 0, 0), (-20.0, 60.0, 0.0)]),
    (lambda t: AbcWorldWizard(t, variant="5d"), None),
])
def test_orientation_warnings_are_from_the_catalogs(synth, make, offsets) -> None:
    truth = synth.tools["torch"]
    wiz = make(library_tool(truth.tcp_mm, calibrated=False))
    wiz.set_translator(QPS)
    if offsets is None:
        R = synth.tool_orientation(0.0, 0.0, 0.0)
        wiz.record(synth.flange_pose_m(truth, R))
        wiz.next()
    else:
        R = synth.tool_orientation(15.0, 30.0, 20.0)
        for off in offsets:
            wiz.record(synth.flange_pose_m(truth, R, offset_tool_mm=off))
            wiz.next()
    assert wiz.result is not None and own_warnings(wiz.result)
    for text in own_warnings(wiz.result):
        assert_pseudo(text)
    english = wiz.result_in(ENGLISH)        # a session record keeps English words
    assert english is not None and any("no calibration record" in w or "5D: only" in w for w in english.warnings)
    assert wiz.result.warnings != english.warnings


def test_the_reference_wizard_notes_are_from_the_catalogs(synth) -> None:
    ref, new = synth.tools["pointer"], synth.tools["torch"]
    wiz = ReferenceWizard(library_tool(ref.tcp_mm, "ref"))
    wiz.set_translator(QPS)
    wiz.record(synth.flange_pose_m(ref, synth.tool_orientation(30.0, 40.0, 10.0)))
    wiz.next()
    wiz.record(synth.flange_pose_m(new, synth.tool_orientation(20.0, 200.0, -30.0)))
    res = wiz.next()
    own = own_warnings(res)
    assert own and res.notes
    for text in (*own, *res.notes):
        assert_pseudo(text)


def test_the_check_and_the_composed_words_outside_the_wizards() -> None:
    assert_pseudo(reading_verdict([(True, 0.0)], 30.0, tr=QPS))
    assert_pseudo(reading_verdict([(True, 1.5)], 30.0, tr=QPS))
    assert_pseudo(reading_verdict([(False, 0.0)], 30.0, tr=QPS))
    assert_pseudo(recorded_words(1, 0.31, hidden=False, in_exercise=False, feedback="", tr=QPS))
    assert_pseudo(recorded_words(1, 0.31, hidden=True, in_exercise=True, feedback="", tr=QPS))
    assert QPS.gettext(MOVED_DURING_PROBE) != MOVED_DURING_PROBE
    assert recorded_words(1, 0.31, hidden=False, in_exercise=False, feedback="") == \
        "✔ Step 2 recorded, 0.31 mm from the tip."


def test_a_touch_made_with_the_wrong_tool_is_refused_in_the_language() -> None:
    wiz = Xyz4Wizard()
    wiz.record(np.eye(4))
    run = WizardRun(wiz, "torch", None, touch_tools={0: "pointer"})
    words = wrong_tool_touch(run, builtin_tools(), tr=QPS)
    labels = {w for t in builtin_tools().values() for w in t.label.lower().split()}
    assert_pseudo(words, NAMES | labels)
    assert (wrong_tool_touch(run, builtin_tools()) or "").startswith("Step 1 was recorded with the ")


def test_plural_forms_come_from_the_catalog() -> None:
    """ngettext picks the catalog's form by the count: the pseudo-locale's plural form keeps the
    English ending (``touchéš``), its singular has none."""
    one = QPS.ngettext("Dropping {n} touch leaves fewer than {min}; add points first.",
                       "Dropping {n} touches leaves fewer than {min}; add points first.", 1).format(n=1, min=4)
    many = QPS.ngettext("Dropping {n} touch leaves fewer than {min}; add points first.",
                        "Dropping {n} touches leaves fewer than {min}; add points first.", 2).format(n=2, min=4)
    assert "ţöûçĥ " in one and "ţöûçĥéš" not in one and "ţöûçĥéš " in many
    assert ENGLISH.ngettext("Touch {touches} was dropped by you and is not used.",
                            "Touches {touches} were dropped by you and are not used.", 1).startswith("Touch ")


def test_switching_the_session_language_mid_wizard_rerenders_the_step(tmp_path) -> None:
    s = make_session(tmp_path / "tools.json")
    changes = []
    s.subscribe(changes.append)
    s.wizard_commands.start("xyz4", n_points=4)
    s.wizard_commands.record_step()
    s.wizard_commands.next_step()
    wiz = s.workflow.wizard
    assert wiz is not None and wiz.step.heading == "Step 2 of 4"
    english = wiz.step.instruction
    changes.clear()
    s.set_language(PSEUDO_LANGUAGE)
    assert changes and changes[-1].language and changes[-1].wizard     # the views re-render the step
    step = s.workflow.wizard.step
    assert step.index == 1 and step.instruction != english
    for text in (step.heading, step.title, step.instruction):
        assert_pseudo(text)
    for _i, label in s.workflow.resumable():
        assert_pseudo(label)
    s.wizard_commands.cancel()
    (index, label), = s.workflow.resumable()
    assert_pseudo(label)
    s.wizard_commands.resume(index)
    s.set_language("en")
    assert s.workflow.wizard.step.instruction == english
    with pytest.raises(WizardError, match="There are no recorded points"):
        s.workflow.start_from_touches([])
    s.set_language(PSEUDO_LANGUAGE)
    with pytest.raises(WizardError) as no_points:
        s.workflow.start_from_touches([])
    assert_pseudo(str(no_points.value))


def test_a_wizard_started_after_the_switch_speaks_the_language(tmp_path) -> None:
    s = make_session(tmp_path / "tools.json")
    s.set_language(PSEUDO_LANGUAGE)
    wiz = s.wizard_commands.start("tcp-zx", n_points=4)
    assert wiz.translator is s.translator
    for step in wiz.steps:
        assert_pseudo(step.instruction)


def test_the_verdict_against_the_truth_in_the_language(synth) -> None:
    from tcp_pendant.wizards.truth import compare_with_truth

    tool = synth.tools["torch"]
    wiz = AbcWorldWizard(library_tool(tool.tcp_mm + 0.3), variant="6d")
    wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(0.0, 0.0, 0.0)))
    res = wiz.next()
    cmp = compare_with_truth(res, tool.T_flange_tool_true_m)
    assert cmp.verdict == cmp.verdict_in(ENGLISH) and cmp.verdict.startswith("good: orientation error ")
    assert "(TCP used is 0.52 mm off the true one)" in cmp.verdict
    assert_pseudo(cmp.verdict_in(QPS))


def test_the_session_record_keeps_english_words(synth) -> None:
    from tcp_pendant.wizards.session_record import run_entry

    truth = synth.tools["torch"]
    wiz = AbcWorldWizard(library_tool(truth.tcp_mm), variant="5d")
    wiz.record(synth.flange_pose_m(truth, synth.tool_orientation(0.0, 0.0, 0.0)))
    wiz.next()
    english = run_entry(WizardRun(wiz))
    wiz.set_translator(QPS)
    shown = wiz.result
    assert shown is not None and any("⟦" in w for w in shown.warnings)
    entry = run_entry(WizardRun(wiz))
    assert entry["result"] == english["result"]
    assert any(w.startswith("5D: only the tool X direction was calibrated") for w in entry["result"]["warnings"])
    assert wiz.result is shown                     # the record's English words leave the shown result alone


def test_tcpcals_remarks_are_said_again_from_the_catalogs(synth) -> None:
    from tcp_pendant.wizards.solver_words import solver_warning

    tool = synth.tools["pointer"]
    wiz = Xyz4Wizard(n_points=4)
    for d in synth.directions[:4]:
        wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(*d)))
        wiz.next()
    res = wiz.result
    assert res is not None and res.tcp_result is not None
    solver = res.tcp_result.warnings
    assert any(w.startswith("with only 4 touches") for w in solver) and res.warnings[:len(solver)] == solver
    wiz.set_translator(QPS)
    assert wiz.result is not None
    for text in wiz.result.warnings:
        assert_pseudo(text)
    weak = ("the TCP along flange [0.00, -0.71, 0.71] is 12 times less certain than across it: the touches "
            "tilt little about a second axis; add a touch tilted about another axis.")
    said = solver_warning(weak, tr=QPS)
    assert_pseudo(said)
    assert "[0.00, -0.71, 0.71]" in said and " 12 " in said
    assert solver_warning(weak) == weak
    assert solver_warning("a remark no table knows", tr=QPS) == "a remark no table knows"


def test_tcpcals_refusal_of_the_touches_reaches_the_trainee_in_the_language(synth) -> None:
    from tcp_pendant.calibrate.finish_checks import failure_in_trainee_words
    from tcp_pendant.wizards import CalibrationFailedError

    tool = synth.tools["pointer"]
    wiz = Xyz4Wizard(n_points=4)
    R = synth.tool_orientation(20.0, 30.0, 0.0)
    for k in range(4):                        # one orientation, four places: nothing to solve
        wiz.record(synth.flange_pose_m(tool, R, offset_tool_mm=(0.0, 10.0 * k, 0.0)))
        if k < 3:
            wiz.next()
    with pytest.raises(CalibrationFailedError) as failed:
        wiz.next()
    english = str(failed.value)
    assert english.startswith("all 4 touches have the same orientation")
    said = failure_in_trainee_words(failed.value, wiz, np.eye(3), tr=QPS)
    assert_pseudo(str(said))
    assert said.cause is failed.value.cause
    assert failure_in_trainee_words(failed.value, wiz, np.eye(3)) is failed.value    # English: as tcpcal said


def test_start_options_are_refused_in_the_language(tmp_path) -> None:
    s = make_session(tmp_path / "tools.json")
    s.set_language(PSEUDO_LANGUAGE)
    for kind, options in (("xyz4", {"colour": 1}), ("xyz4", {"n_points": 2.5}), ("xyz4", {"n_points": 99}),
                          ("xyz4", {"estimator": "median"}), ("three-point", {"variant": 3, "slot": 1}),
                          ("three-point", {}), ("three-point", {"slot": 7})):
        with pytest.raises(WizardError) as refused:
            s.wizard_commands.start(kind, **options)
        option_keys = {"colour", "median", "estimator", "n", "points", "slot", "variant", "lstsq", "sphere", "pairwise"}
        assert_pseudo(str(refused.value), option_keys)
    with pytest.raises(WizardError, match=r"^Touches: 99 is out of range 4\.\.20\.$"):
        Xyz4Wizard.parse_options({"n_points": 99})


def test_a_failed_finish_is_told_again_in_the_new_language(tmp_path) -> None:
    s = make_session(tmp_path / "tools.json")
    s.wizard_commands.start("xyz4")
    for k in range(4):                        # four records without moving: one orientation
        s.wizard_commands.record_step()
        if k < 3:
            s.wizard_commands.next_step()
    with pytest.raises(WizardError):
        s.wizard_commands.next_step()
    english = s.workflow.finish_failure
    assert english is not None and english.startswith("all 4 touches have the same orientation")
    s.set_language(PSEUDO_LANGUAGE)
    assert_pseudo(s.workflow.finish_failure)
    s.set_language("en")
    assert s.workflow.finish_failure == english
