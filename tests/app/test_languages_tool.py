"""The Tool tab (tool table, library, export, TCP check, numeric entry, the beam sensor's TCP
service), the Calibrate tab's systematic-error panel and the beam stand's 3D label in the
session's language: with the pseudo-locale every text of their handles is from the catalogs
(tool names, formats, axis names, units and numbers aside), in each state they show (an empty
library, a selected tool, a TCP check, an entry refused and saved, the exercise's lock, a beam
check and its Update, each systematic error); a live switch relabels everything and back to
English gives the very same texts; the files sent to the browser are the same bytes in every
language. In-process server, headless websocket clients as browsers (``guiclick``)."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from typing import Any

import pytest
import viser

from support.app_page import AppPage, true_tip_at, truth_tool
from support.pseudo_text import WORD, gui_texts, untranslated_words
from support.wsclient import wait_until

from tcp_pendant.calibrate.beam_service import beam_check_markdown, beam_verdict
from tcp_pendant.calibrate.pendant_rules import LibraryRights
from tcp_pendant.calibrate.touches_export import wizard_touches_csv
from tcp_pendant.classroom.exercise_rules import class_rules
from tcp_pendant.controller import builtin_tools
from tcp_pendant.controller.scenarios import SCENARIO_KINDS, Scenario, explain
from tcp_pendant.pendant.tool_entry import ToolEntry, entry_preview_markdown, parse_tool_entry
from tcp_pendant.job_pool import JobPool
from tcp_pendant.translation import PSEUDO_LANGUAGE, languages, translator
from tcpcal.controllers import CONTROLLER_FORMATS
from tcpcal.formats import FORMATS, text_format

QPS = translator(PSEUDO_LANGUAGE)
HANDLES = (viser.GuiMarkdownHandle | viser.GuiButtonHandle | viser.GuiButtonGroupHandle | viser.GuiCheckboxHandle
           | viser.GuiDropdownHandle | viser.GuiSliderHandle | viser.GuiFolderHandle | viser.GuiTextHandle
           | viser.GuiNumberHandle)


class Page(AppPage):
    """One browser: its Tool tab, beam check and scenario panel, the notifications it got."""

    def __init__(self, app: Any) -> None:
        super().__init__(app)
        self.sent: list[tuple[str, bytes]] = []
        self.client.send_file_download = lambda name, data, *a, **k: self.sent.append((name, data))  # type: ignore
        self.tools = self.session.views["tools"]
        self.beam = self.session.views["beam_check"]
        self.scenario = self.session.views["scenario"]
        self.session.views["beam_player"].rate_hz = 400.0                  # the film, fast

    def select(self, slot: int) -> None:
        self.choose(self.tools.slots, next(o for o in self.tools.slots.options if o.startswith(f"{slot}:")))

    def views(self) -> tuple[object, ...]:
        return self.tools, self.beam, self.scenario


pytestmark = [pytest.mark.app_page(cls=Page, seed=7), pytest.mark.shares_cpu]  # asserts no time, latency or load (tests/conftest.py)

TOOLS = {1: truth_tool("pointer", "Pointer"), 2: truth_tool("pointer", "Skewed", (0.0, 1.0, 0.0))}
NAMES = ({"X", "Y", "Z", "A", "B", "C", "mm", "deg", "TCP", "FLANGE", "RMS", "Pointer", "Skewed", "Mine",
          "numeric", "beam"}
         | {w for f in FORMATS for w in WORD.findall(text_format(f).label)}
         | {w for f in CONTROLLER_FORMATS.values() for w in WORD.findall(f.label)})
"""What stays as it is in every language: axis names, units, frame names, tool names (the test's;
the built-in tool models' labels are translated), controller formats, calibration methods (the tool file's values)."""


def _handles(view: object) -> Iterator[tuple[str, object]]:
    for name, value in vars(view).items():
        items = value.values() if isinstance(value, dict) else value if isinstance(value, list) else (value,)
        for item in items:
            if isinstance(item, HANDLES):
                yield name, item


def _texts(page: Page) -> dict[tuple[str, str, int], str]:
    """Every text of every handle of the page's three views, by (view, handle, index)."""
    out = {}
    for view in page.views():
        for name, handle in _handles(view):
            for i, text in enumerate(gui_texts(handle)):
                out[(type(view).__name__, name, i)] = text
    return out


LOOP_TITLES = {"Not done", "Internal error"}
"""The titles ``session_loop`` gives a refused click (its owner wraps them); the bodies are ours."""


def _note_texts(page: Page) -> list[str]:
    """The titles (not the loop's) and bodies of the notifications the page was shown."""
    return [t for title, body in page.notes for t in ((body,) if title in LOOP_TITLES else (title, body))]


def _assert_pseudo(page: Page, state: str) -> None:
    _assert_pseudo_names(page, set(), state)


def _assert_pseudo_names(page: Page, names: set[str], state: str) -> None:
    """Every text of the page's views from the catalogs but :data:`NAMES` and ``names``."""
    bad = {key: (text, words) for key, text in _texts(page).items()
           if (words := untranslated_words(text, NAMES | names))}
    assert bad == {}, state


def test_with_the_pseudo_locale_every_text_of_the_tool_tab_and_the_scenario_panel_is_from_the_catalogs(page) -> None:
    p = page(language=PSEUDO_LANGUAGE)
    assert p.session.language == PSEUDO_LANGUAGE
    _assert_pseudo(p, "an empty library")
    assert p.tools.slots.options[0].startswith("⟦")                      # "(library empty)"
    p.click(p.tools.activate)                                            # nothing to activate
    p.click(p.tools.check_active)                                        # no active tool data
    p.click(p.beam.check)                                                # no active tool data
    p.click(p.tools.entry_save)                                          # every field: name missing
    _assert_pseudo(p, "an entry refused")
    assert p.tools.entry_name_err.visible and p.tools.entry_name_err.content.startswith("**⚠ ⟦")
    for field, text in (("X", "abc"), ("Y", "9999"), ("Z", "")):
        p.choose(p.tools.entry_fields[field], text)
    p.click(p.tools.entry_save)
    _assert_pseudo(p, "fields refused")
    for field in "XYZ":
        p.choose(p.tools.entry_fields[field], "1,5")
    p.choose(p.tools.entry_name, "Mine")
    p.click(p.tools.entry_save)                                          # saved in the first free slot
    assert p.session.library.get(1).name == "Mine"
    _assert_pseudo(p, "a tool saved")
    p.choose(p.tools.entry_name, "Mine")
    p.click(p.tools.entry_save)                                          # the name is taken
    assert "Mine" in p.tools.entry_name_err.content
    _assert_pseudo(p, "a name taken")
    notes = _note_texts(p)
    assert len(notes) >= 3 and all(untranslated_words(t, NAMES) == [] for t in notes), p.notes


def test_with_the_pseudo_locale_the_beam_service_is_from_the_catalogs(page) -> None:
    """Check with beam (a bent tool) and its Update: the folder, the result, the update's
    words and the notifications. A session of its own: one job, as a trainee would start it
    (checks before it would spend the session's share of the server's time)."""
    p = page(TOOLS, language=PSEUDO_LANGUAGE)
    s = p.session
    p.select(1)
    p.click(p.tools.activate)
    s.set_scenario("bent_tool", 6)
    _assert_pseudo(p, "the bent tool played")
    p.click(p.beam.check)
    wait_until(lambda: not s.views["beam_player"].playing, timeout=60, what="the scan's film")
    assert p.beam.last_check is not None, p.notes
    _assert_pseudo(p, "a beam check")
    p.click(p.beam.update)
    assert s.library.get(1).calibration.method == "beam"
    _assert_pseudo(p, "a beam update")
    notes = _note_texts(p)
    assert len(notes) >= 4 and all(untranslated_words(t, NAMES) == [] for t in notes), p.notes


def test_with_the_pseudo_locale_the_check_the_lock_and_the_scenarios_are_from_the_catalogs(page) -> None:
    p = page(TOOLS, language=PSEUDO_LANGUAGE)
    s = p.session
    p.select(2)
    _assert_pseudo(p, "a tool selected")
    p.click(p.tools.check)                                               # the TCP check of slot 2
    assert p.tools.last_check is not None
    _assert_pseudo(p, "a TCP check")
    p.select(1)
    p.click(p.tools.activate)
    p.click(p.tools.check_active)
    _assert_pseudo(p, "a check of the active tool")
    for kind in SCENARIO_KINDS:
        s.set_scenario(kind, 3)
        _assert_pseudo(p, kind)
    with s.lock:
        s.tools.set_exercise_tool(builtin_tools()["torch"])
    assert p.tools.mounted_lock_md.visible
    _assert_pseudo(p, "the exercise's lock")
    label = s.views["scene"].beam_stand.label
    assert label is not None and untranslated_words(label.text, NAMES) == []
    notes = _note_texts(p)
    assert notes and all(untranslated_words(t, NAMES) == [] for t in notes), p.notes


def test_with_the_pseudo_locale_an_exercises_check_reading_and_its_refusal_are_from_the_catalogs(page) -> None:
    p = page(TOOLS, language=PSEUDO_LANGUAGE)
    s = p.session
    s.set_rules(class_rules("mystery"))
    p.select(2)
    p.click(p.tools.check)                   # no reference tip to read the swing against: refused
    assert p.tools.last_check is None and p.notes
    true_tip_at(s, (0.0, 0.0, 2.0))
    p.click(p.tools.check)
    assert p.tools.last_check is not None and "Implied" not in p.tools.check_md.content
    _assert_pseudo(p, "an exercise's reading")
    notes = _note_texts(p)
    assert notes and all(untranslated_words(t, NAMES) == [] for t in notes), p.notes
    with s.lock:
        s.set_language("en")                 # said again in English: still the reading, no answer
    md = p.tools.check_md.content
    assert "by eye" in md and "Implied" not in md and "FLANGE axes" not in md


def test_with_the_pseudo_locale_the_scenario_panel_is_chosen_in_its_words_and_explains_a_result(page) -> None:
    """The trainer picks "Robot accuracy" by its pseudo-locale word; after an XYZ 4-point
    result the panel explains it, every word from the catalogs."""
    p = page(language=PSEUDO_LANGUAGE)
    s, panel = p.session, p.scenario
    word = next(o for o in panel.kind.options if o == QPS.gettext("Robot accuracy"))
    assert word.startswith("⟦") and len(set(panel.kind.options)) == len(SCENARIO_KINDS)
    p.choose(panel.seed, -3)                                     # refused in words, the seed put back
    assert p.notes and untranslated_words(p.notes[-1][1], NAMES) == [] and panel.seed.value == 0
    p.choose(panel.seed, 7)
    p.choose(panel.kind, word)
    assert s.scenario_player.scenario.kind == "robot_accuracy" and s.scenario_player.scenario.seed == 7
    v = s.views["calibrate"]
    p.click(v.start)
    for _ in range(4):
        p.click(v.steps.auto_touch)
    assert v.workflow.result is not None
    md = panel.md.content
    assert md.count("\n\n") >= 1 and untranslated_words(md, NAMES) == [], md
    _assert_pseudo(p, "a result explained")
    with s.lock:
        s.set_language("en")
    assert panel.kind.value == "Robot accuracy" and "**How this result shows it:** The robot differs" in panel.md.content


def test_with_the_pseudo_locale_whose_slot_it_is_is_said_in_the_catalogs_words(page) -> None:
    """A class's library: the selected slot is the trainee's own, another trainee's or the
    trainer's (no classmate's name); unrestricted, who saved it (a trainee's name)."""
    p = page(TOOLS, language=PSEUDO_LANGUAGE)
    s = p.session
    s.library.save(3, truth_tool("pointer", "AnnaPointer"), owner="Anna")
    s.library.save(4, truth_tool("pointer", "BenPointer"), owner="Ben")
    s.tools.reload_library()
    lines = {}
    for rights in (LibraryRights(), LibraryRights(restricted=True, owner="Anna")):
        with s.lock:
            s.tools.set_library_rights(rights)
        for slot in (1, 3, 4):
            p.select(slot)
            lines[(rights.restricted, slot)] = p.tools.slot_md.content.split("\n\n")[-1]
            _assert_pseudo_names(p, {"Anna", "Ben", "AnnaPointer", "BenPointer"}, f"slot {slot}, restricted {rights.restricted}")
    assert len(set(lines.values())) == 6, lines   # no owner, saved by Anna, by Ben; the trainer's, Anna's own, another's
    assert "Anna" in lines[(False, 3)] and "Ben" not in lines[(True, 4)]


def test_a_live_switch_relabels_every_text_and_english_comes_back_the_same(page) -> None:
    p = page(TOOLS)
    s = p.session
    p.select(2)
    p.click(p.tools.check)
    p.click(p.tools.entry_save)                                          # the entry's errors shown
    english = _texts(p)
    assert english[("ToolPanel", "mounted", 0)] == "Mounted tool"
    assert "TCP check of slot 2: Skewed" in p.tools.check_md.content
    label = s.views["scene"].beam_stand.label
    assert label is not None and label.text == "beam sensor"
    with s.lock:
        s.set_language(PSEUDO_LANGUAGE)
    _assert_pseudo(p, "after the switch")
    assert label.text != "beam sensor" and untranslated_words(label.text, NAMES) == []
    assert s.library.get(2).name == "Skewed" and p.tools.last_check is not None
    with s.lock:
        s.set_language("en")
    assert _texts(p) == english
    assert label.text == "beam sensor"


def test_the_files_sent_and_the_controller_text_are_the_same_bytes_in_every_language(page) -> None:
    p = page(TOOLS)
    s = p.session
    p.select(2)
    by_language = {}
    for language in languages(include_pseudo=True):
        with s.lock:
            s.set_language(language)
        p.sent.clear()
        for fmt in CONTROLLER_FORMATS.values():
            p.choose(p.tools.file_fmt, fmt.label)
            p.click(p.tools.download)
        texts = []
        for fmt in FORMATS:
            p.choose(p.tools.export_fmt, text_format(fmt).label)
            p.click(p.tools.export)
            texts.append(str(p.tools.export_text.value))
        by_language[language] = (list(p.sent), texts)
    english = by_language["en"]
    assert len(english[0]) == len(CONTROLLER_FORMATS) and all(data for _, data in english[0])
    assert all(sent == english for sent in by_language.values())


def test_the_text_functions_speak_the_pseudo_locale_and_english_by_default(page) -> None:
    """The tool entry's errors and preview, the scenarios' explanations and the beam check's
    words with ``translator("qps")``; without a translator they stay English."""
    for entry in (ToolEntry("", {"X": "x", "Y": "", "Z": "inf", "A": "400", "B": "0", "C": "0"}),
                  ToolEntry("T", {f: "1" for f in "XYZABC"})):
        res = parse_tool_entry(entry, tr=QPS)
        assert all(untranslated_words(e, NAMES) == [] for e in res.errors.values()), res.errors
        assert untranslated_words(entry_preview_markdown(entry, tr=QPS), NAMES | {"T"}) == []
    assert parse_tool_entry(ToolEntry("", {})).errors["name"] == "Name: enter a tool name"
    for kind in SCENARIO_KINDS:
        assert untranslated_words(explain(Scenario(kind, 1), tr=QPS), NAMES) == []
    assert explain(Scenario("off", 1)) == "No systematic error: the residual reflects only your touching accuracy."
    p = page(TOOLS, language=PSEUDO_LANGUAGE)
    p.select(1)
    p.click(p.tools.activate)
    p.session.set_scenario("bent_tool", 6)
    p.click(p.beam.check)
    check = p.beam.last_check
    assert check is not None and not check.good
    assert untranslated_words(beam_check_markdown(check, tr=QPS), NAMES) == []
    assert beam_verdict(check) == check.verdict and check.verdict.startswith("TCP off by")
    assert beam_check_markdown(check).startswith("**Beam check of Pointer** (slot 1)")


def test_the_touches_export_speaks_the_pseudo_locale_and_its_csv_is_the_same_in_every_language(page) -> None:
    """"Export touches (CSV)" (the wizard panel): its label, hint and refusal from the catalogs,
    relabelled on a switch; the POSES.csv it sends the same bytes in every language."""
    p = page(language=PSEUDO_LANGUAGE)
    s = p.session
    export = s.views["calibrate"].steps.export
    p.click(export.button)                                       # no calibration open: refused
    assert p.notes and untranslated_words(p.notes[-1][1], NAMES) == [], p.notes
    with pytest.raises(ValueError) as refused:
        wizard_touches_csv(s.wizard_commands.start("xyz4"), tr=QPS)
    assert untranslated_words(str(refused.value), NAMES) == []
    for _ in range(4):
        p.click(s.views["calibrate"].steps.auto_touch)
    assert export.button.visible
    texts = [t for t in gui_texts(export.button)]
    assert len(texts) == 2 and all(untranslated_words(t, NAMES) == [] for t in texts)
    sent = {}
    for language in languages(include_pseudo=True):
        with s.lock:
            s.set_language(language)
        p.sent.clear()
        p.click(export.button)
        (sent[language],) = p.sent
    with s.lock:
        s.set_language("en")
    assert export.button.label == "Export touches (CSV)"
    assert all(data == sent["en"] for data in sent.values()) and sent["en"][1].startswith(b"# tcpcal solve")


def test_with_the_pseudo_locale_a_check_refused_by_the_job_pool_is_said_in_the_catalogs_words(page) -> None:
    """The TCP check while this session's other job runs: the job pool's refusal (its data,
    worded by ``controller.words.error_text``) in the session's language, not its English text."""
    p = page(TOOLS, language=PSEUDO_LANGUAGE)
    s = p.session
    s.tools.activate(1)
    gate = threading.Event()
    s.jobs = pool = JobPool()
    running = pool.submit(s, lambda: gate.wait(10), what="a beam check")
    try:
        p.click(p.tools.check_active)
        assert p.notes == [(QPS.gettext("Check not started"),
                            QPS.gettext("{what} is still running here; wait for its result, then try again.").format(
                                what="A beam check"))]
        assert untranslated_words(p.notes[0][1], NAMES) == [] and p.tools.last_check is None
    finally:
        gate.set()
    assert running.result(10) is True
    pool.shutdown()


def test_with_the_pseudo_locale_the_mounted_tool_is_chosen_by_its_translated_label(page) -> None:
    """The built-in tools' labels are translated in the Mounted tool dropdown (a tool library's
    saved names are not: data); a choice in the session's words mounts that tool, and a click
    in English (one that crossed a switch) still does."""
    p = page(TOOLS, language=PSEUDO_LANGUAGE)
    s = p.session
    models = builtin_tools()
    assert tuple(p.tools.mounted.options) == tuple(QPS.gettext(t.label) for t in models.values())
    p.choose(p.tools.mounted, QPS.gettext(models["torch"].label))
    assert s.controller.mounted_tool.key == "torch"
    assert p.tools.mounted.value == QPS.gettext(models["torch"].label)
    p.choose(p.tools.mounted, models["pointer"].label)
    assert s.controller.mounted_tool.key == "pointer"
    with s.lock:
        s.set_language("en")
    assert tuple(p.tools.mounted.options) == tuple(t.label for t in models.values())
    assert p.tools.mounted.value == "Straight pointer"
