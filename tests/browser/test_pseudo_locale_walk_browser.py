"""Nothing left untranslated: the whole app in the pseudo-locale, walked in chromium at 1400x900.

A class pendant started with ``--language qps`` (every message of the catalogs shows wrapped and
accented, ``⟦Ŕéçöŕð⟧``; a plain ASCII word outside such a span bypassed the catalogs). One
trainee page and one trainer page; at each state the test waits for the page to have applied
everything the server sent (``support.page_barrier``), then collects what a person reads
(``support.visible_text``): the visible text of the DOM, placeholders and titles, the 3D labels
(canvas-drawn: read from the session's label handles), the notifications sent, and the hints of
the GUI's controls and the options of its dropdowns. Each text is listed once, under the first state that showed it.

The states: the name prompt; each tab (Jog, Tool, Calibrate); every wizard of the Calibrate menu,
started as the menu starts it, each of its steps (Auto-touch, a tool change where the method
needs one, Finish where the controller runs the step) and its result; presenter mode with a
wizard running, and its math board ("The math" over the whole screen); the trainer's dashboard
with the trainee's calibration replayed in 3D, and a message it sends on the trainee's screen.
The server-side commands (``session.wizard_commands``) reach the states quickly; the page then
shows them, and its texts are what is checked.

Exempt (``NAMES``): names that stay untranslated by design (axis, joint and frame names, TCP,
units, key names, language names, robot and tool names, the HOME position), the trainee's name,
numbers and file names, the product's name and the selector's English word "(Language)"
(``BY_DESIGN``); and viser's own client chrome (``VISER_CHROME``: its connection badge and canvas buttons,
not the app's texts). Every other word fails the test, listed by state; the list is also written
to the test's folder (``leftovers.txt``).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from support.app_page import truth_tool
from support.guiclick import choose, click
from support.page_barrier import Barrier, show_tab
from support.pendant_page import wait_until
from support.pseudo_text import untranslated_words
from support.visible_text import TEXTS_JS, gui_hints, record_notifications, scene_labels

from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.controller import builtin_tools
from tcp_pendant.translation import LANGUAGE_NAMES
from tcp_pendant.wizards.base import WizardError
from tcp_pendant.wizards.registry import wizard_classes

pytestmark = pytest.mark.browser

TOKEN = "trainer-walk-token-4242"
TRAINEE = "Ada Trainee"
TOOL_NAME = "Walker7"
"""The tool data in slot 1 (user text: stays as typed)."""
FILE_NAME = re.compile(r"\b[\w.-]+\.(?:json|csv|urdf|xacro|xml|dat|src|mod|tp|ls|jbi|sqlite3|png|txt)\b", re.I)
BY_DESIGN = re.compile(r"\bTCP Pendant\b|\(Language\)")
"""The product's name, and the English word the language selector keeps beside its translated
label ("⟦Ļåñĝûåĝé⟧ (Language)": a trainee shown a language they cannot read finds the way back)."""
EQUATION_TAG = re.compile(r"\b[A-Z]{2,}-\d+\b")
"""An equation's tag from docs/methods.md ("(ZX-1)", "(BEAM-2)"): a name, as in the docs."""
MATH_SYMBOL = re.compile(r"[A-Za-z]|[A-Za-z]\d+|sin|cos|tan|pinv|R[xyz]")
"""A symbol of an equation or a name with a number: one letter (``t``, ``R_i``), a letter and a
number (touch ``P1``, joint ``A6``), a function, the pseudo-inverse's subscript (``t_pinv``), KUKA's
rotations ``Rz(A) Ry(B) Rx(C)``."""
NAMES = {
    *"X Y Z A B C".split(), *(f"A{i}" for i in range(1, 7)), *(f"J{i}" for i in range(1, 7)),
    "WORLD", "BASE", "TOOL", "FLANGE", "TCP", "HOME", "UTC", "mm", "deg", "rad", "s", "ms",
    "Shift", "Ctrl", "Esc", "Enter", "Space",                 # key names
    *(w for name in LANGUAGE_NAMES.values() for w in re.findall(r"[A-Za-z]+", name)),
    "KUKA", "KR", "R900", "sixx", "Yaskawa", "GP12", "ABB", "FANUC", "UR",   # robots and vendors
    *TRAINEE.split(), TOOL_NAME,
}
"""Words that stay as they are in every language (module docstring)."""
VISER_CHROME = {"Connected", "Save Canvas", "Reset View", "Software WebGL rendering detected",
                "WebGL is running in software mode, not on your GPU. Performance may be degraded. If this is "
                "unexpected, check that hardware acceleration is enabled in your browser settings."}
"""viser's own client texts (its connection badge, canvas buttons and the software-WebGL notice of
this test machine): not the app's, outside its catalogs."""


class Walk:
    """The pages walked and the words found outside the pseudo-locale, by state."""

    def __init__(self) -> None:
        self.found: dict[str, list[str]] = {}
        self.notes: dict[int, list[str]] = {}
        self.hints: set[tuple[str, str]] = set()
        self.seen: set[str] = set()

    def check(self, state: str, texts: list[tuple[str, str]]) -> None:
        """Each (where, text) with words outside the pseudo-locale, listed under the first state
        that showed it."""
        for where, text in dict.fromkeys(texts):
            if text in VISER_CHROME:
                continue
            plain = BY_DESIGN.sub(" ", EQUATION_TAG.sub(" ", FILE_NAME.sub(" ", text)))
            words = [w for w in untranslated_words(plain, NAMES)
                     if not MATH_SYMBOL.fullmatch(w)]
            entry = f"{where}: {' '.join(dict.fromkeys(words))}  <=  {text[:160]!r}"
            if words and entry not in self.seen:
                self.seen.add(entry)
                self.found.setdefault(state, []).append(entry)

    def look(self, state: str, page: Any, session: Any, barrier: Barrier) -> None:
        """Wait for the page to show the session's state, then check what it shows."""
        barrier.sync(page)
        texts = [("page", str(t)) for t in page.evaluate(TEXTS_JS)] + [("3D label", t) for t in scene_labels(session)]
        notes = self.notes.setdefault(id(session), [])
        texts += [("notification", t) for t in notes]
        notes.clear()
        self.hints.update(gui_hints(session))
        self.check(state, texts)

    def report(self) -> str:
        self.check("hints (tooltips) and dropdown options of the GUI's controls, all states", sorted(self.hints))
        return "\n".join(f"== {state}\n" + "\n".join(f"  {e}" for e in entries)
                         for state, entries in self.found.items() if entries)


WIZARD_OPTIONS: dict[str, dict[str, object]] = {
    "reference": {"slot": 1, "reference_tool_key": "pointer", "new_tool_key": "torch"},
}


def start_options(cls: Any) -> dict[str, object]:
    """The options the Calibrate menu would send for ``cls`` (slot 1: the pointer's tool data)."""
    return WIZARD_OPTIONS.get(cls.kind, {"slot": 1} if cls.needs_tool == "library" else {})


def walk_wizard(walk: Walk, page: Any, s: Any, barrier: Barrier, cls: Any) -> None:
    """Start ``cls`` and go through its steps to its result, looking at each state."""
    s.tools.mount_tool(builtin_tools()["pointer"])           # the reference method left the torch on
    wiz = s.wizard_commands.start(cls.kind, **start_options(cls))
    name = f"wizard {cls.kind}"
    show_tab(page, 0)
    walk.look(f"{name}: step 1 in the Jog tab's dock", page, s, barrier)
    show_tab(page, 2)
    for _ in range(3 * wiz.n_steps + 4):
        if s.workflow.result is not None:
            break
        walk.look(f"{name}: step {wiz.step_index + 1} of {wiz.n_steps}", page, s, barrier)
        before = wiz.step_index
        try:
            outcome = s.wizard_commands.auto_touch(AutoTouchRequest())
        except WizardError:                    # the controller runs this step itself: Finish
            s.wizard_commands.next_step()
            continue
        if not outcome.ok and wiz.step.mount_tool_key is not None:
            walk.look(f"{name}: step {wiz.step_index + 1}, another tool needed", page, s, barrier)
            s.wizard_commands.mount_required_tool()
        elif wiz.step_index == before and s.workflow.result is None:
            s.wizard_commands.next_step()      # its last step recorded: Finish computes
    assert s.workflow.result is not None, f"{cls.kind}: no result after its steps"
    walk.look(f"{name}: result", page, s, barrier)


def test_every_text_of_the_app_is_from_the_catalogs(app_factory, new_page: Callable[..., Any],
                                                   tmp_path: Path) -> None:
    """Long because it walks the whole app in one page and one trainer page (module docstring)."""
    app = app_factory({1: truth_tool("pointer", TOOL_NAME)}, active_slot=1, language="qps",
                      class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, seed=11)
    walk = Walk()
    page = new_page(app.url, wait_for="")
    wait_until(lambda: len(app.sessions) == 1 and "identity" in next(iter(app.sessions.values())).views,
               "the trainee's name prompt")
    (s,) = app.sessions.values()
    record_notifications(s, walk.notes.setdefault(id(s), []))
    barrier = Barrier(s)
    walk.look("name prompt", page, s, barrier)
    prompt = s.views["identity"]
    choose(prompt.name_field, TRAINEE, s.client)
    click(prompt.start, s.client)
    wait_until(lambda: "calibrate" in s.views, "the trainee's pendant")
    for index, tab in enumerate(("Jog", "Tool", "Calibrate")):
        show_tab(page, index)
        walk.look(f"{tab} tab", page, s, barrier)
    for cls in wizard_classes():
        walk_wizard(walk, page, s, barrier, cls)
    # presenter mode with a wizard running
    choose(s.views["presenter"].toggle, True, s.client)
    s.wizard_commands.start("xyz4")
    walk.look("presenter mode: XYZ 4-point step 1", page, s, barrier)
    for _ in range(2):
        s.wizard_commands.auto_touch(AutoTouchRequest())      # touches for the board and the dashboard
    choose(s.views["presenter"].board.toggle, True, s.client)
    walk.look("presenter mode: the math board, XYZ 4-point step 3", page, s, barrier)
    choose(s.views["presenter"].board.toggle, False, s.client)
    choose(s.views["presenter"].toggle, False, s.client)

    # the trainer's dashboard, the trainee's calibration replayed in 3D
    trainer_page = new_page(app.trainer_url, wait_for="")
    wait_until(lambda: any("trainer" in t.views for t in app.sessions.values()), "the trainer's dashboard")
    trainer = next(t for t in app.sessions.values() if "trainer" in t.views)
    record_notifications(trainer, walk.notes.setdefault(id(trainer), []))
    trainer_barrier = Barrier(trainer)
    walk.look("trainer dashboard", trainer_page, trainer, trainer_barrier)
    dash = trainer.views["trainer"]
    option = next((o for o in dash.trainee.options if TRAINEE in str(o)), None)
    assert option is not None, f"the dashboard offers no {TRAINEE!r}: {dash.trainee.options}"
    choose(dash.trainee, option, trainer.client)
    walk.look("trainer dashboard: trainee chosen", trainer_page, trainer, trainer_barrier)
    click(dash.replay_button, trainer.client)
    walk.look("trainer dashboard: replay in 3D", trainer_page, trainer, trainer_barrier)

    # a message from the trainer to the class, on the trainee's screen (its text is the trainer's:
    # written in the pseudo-locale's brackets, so only the app's words around it count)
    messages = next(x for x in dash.class_extras if hasattr(x, "send") and hasattr(x, "text"))
    choose(messages.text, "⟦message 1⟧", trainer.client)
    click(messages.send, trainer.client)
    walk.look("trainer dashboard: message sent", trainer_page, trainer, trainer_barrier)
    page.get_by_text("⟦message 1⟧").first.wait_for(timeout=60_000)    # delivered to the trainee's screen
    walk.look("trainee: the trainer's message", page, s, barrier)

    report = walk.report()
    (tmp_path / "leftovers.txt").write_text(report + "\n", encoding="utf-8")
    assert not report, f"texts outside the pseudo-locale (also in {tmp_path / 'leftovers.txt'}):\n{report}"
