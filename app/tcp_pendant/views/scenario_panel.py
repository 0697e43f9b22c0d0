"""The "Systematic error" panel of the Calibrate tab (training).

A trainer picks a systematic error for this pendant: Off (default), Bent tool, Robot accuracy
or Moved reference tip (``controller.scenarios``), and a seed that draws its concrete errors.
The choice is the session's state, changed by its command ``Session.set_scenario`` (one change
signal); this view renders it from state. After a calibration result the scenario's
explanation (``scenarios.explain``: how it shows in the result and how the TCP check reveals
it) is shown, escaped. The panel is shown in training mode only (the Calibrate tab's "Training
mode" switch, ``CalibrationWorkflow.training``). Every word is the session's language
(``session.translator``), re-rendered on a ``language`` change; a choice is read in the language it
was shown in or in English.
"""

from __future__ import annotations

import viser

from tcp_pendant.controller.scenarios import DEFAULT_SEED_RANGE, SCENARIO_KINDS, explain
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import N_, Translator
from tcp_pendant.views.gui_util import set_value, target_of

__all__ = ["SCENARIO_CHOICES", "ScenarioPanel", "scenario_markdown"]

SCENARIO_CHOICES: dict[str, str] = {
    "off": N_("Off"),
    "bent_tool": N_("Bent tool"),
    "robot_accuracy": N_("Robot accuracy"),
    "moved_reference": N_("Moved reference tip"),
}
"""Scenario kind -> the dropdown's English words (every kind of ``scenarios.SCENARIO_KINDS``),
shown in the session's language (:func:`scenario_word`)."""
assert tuple(SCENARIO_CHOICES) == SCENARIO_KINDS


def scenario_word(kind: str, tr: Translator) -> str:
    """The dropdown's word of scenario ``kind`` in ``tr``'s language."""
    return tr.gettext(SCENARIO_CHOICES[kind])


def _kind_of(label: str, tr: Translator) -> str | None:
    """The scenario kind of the dropdown's word ``label`` (in ``tr``'s language or English)."""
    return next((k for k, v in SCENARIO_CHOICES.items() if label in (v, scenario_word(k, tr))), None)


def scenario_markdown(session: Session) -> str:
    """What the panel says: the scenario played and, after a calibration result, how it shows
    (``explain``, escaped)."""
    tr = session.translator
    _ = tr.gettext
    world = session.scenario_player.world
    if world is None:
        return _("*No systematic error: the residual reflects the touching accuracy only.*")
    s = world.scenario
    text = _("Playing **{scenario}** (seed {seed}); the trainee is not told. Calibrate, then use **Check** "
             "in the Tool tab.").format(scenario=escape_markdown(scenario_word(s.kind, tr)), seed=int(s.seed))
    wf = session.workflow
    if wf is not None and getattr(wf, "result", None) is not None:
        text += "\n\n" + _("**How this result shows it:** {explanation}").format(
            explanation=escape_markdown(explain(world, tr=tr)))
    return text


class ScenarioPanel:
    """Builds the panel in the current GUI container of ``session.target.gui``."""

    def __init__(self, session: Session) -> None:
        self.session = session
        gui = target_of(session).gui
        self.folder = gui.add_folder("Systematic error (training)", expand_by_default=False)
        with self.folder:
            tr = session.translator
            labels = [scenario_word(k, tr) for k in SCENARIO_CHOICES]
            self.kind = gui.add_dropdown("Systematic error", labels,
                                         initial_value=scenario_word(session.scenario_player.scenario.kind, tr),
                                         hint="What the physical world gets wrong (training).")
            self.seed = gui.add_number("Seed", int(session.scenario_player.scenario.seed), min=0, step=1)
            self.md = gui.add_markdown("")
        self.relabel()
        g = session.loop.on_loop
        self.kind.on_update(g(self._on_choose))
        self.seed.on_update(g(self._on_choose))
        session.subscribe(self.on_change)
        self.render()

    def on_change(self, change: SessionChange) -> None:
        """The change signal: re-render on ``tool`` (a new scenario) and ``wizard`` (a result,
        the training switch), every text on ``language``."""
        if change.language:
            self.relabel()
        if change.tool or change.wizard or change.language:
            self.render()

    def relabel(self) -> None:
        """The folder's, the dropdown's and the seed's words in the session's language."""
        tr = self.session.translator
        _ = tr.gettext
        self.folder.label = _("Systematic error (training)")
        self.kind.label = _("Systematic error")
        self.kind.hint = _("What the physical world gets wrong (training).")
        self.seed.label = _("Seed")
        self.seed.hint = _("Draws the errors; the tests check seeds {first}-{last}.").format(
            first=DEFAULT_SEED_RANGE.start, last=DEFAULT_SEED_RANGE.stop - 1)
        options = tuple(scenario_word(k, tr) for k in SCENARIO_CHOICES)
        if tuple(self.kind.options) != options:
            self.kind.options = options

    def render(self) -> None:
        """Show the session's scenario, its explanation after a result, and the panel only in
        training mode."""
        s = self.session
        wf = s.workflow
        self.folder.visible = wf is None or bool(getattr(wf, "training", True))
        label = scenario_word(s.scenario_player.scenario.kind, s.translator)
        if self.kind.value != label:
            set_value(self.kind, label)
        if int(self.seed.value or 0) != int(s.scenario_player.scenario.seed):
            set_value(self.seed, int(s.scenario_player.scenario.seed))
        self.md.content = scenario_markdown(s)

    def _on_choose(self, event: viser.GuiEvent[viser.GuiDropdownHandle[str]] | viser.GuiEvent[viser.GuiNumberHandle[int]]) -> None:
        if getattr(event, "client", None) is None:      # our own write-backs fire it too
            return
        tr = self.session.translator
        kind = _kind_of(str(self.kind.value), tr)
        if kind is None:
            raise ValueError(tr.gettext("Unknown systematic error {name}; choose one of {choices}.").format(
                name=repr(self.kind.value), choices=", ".join(scenario_word(k, tr) for k in SCENARIO_CHOICES)))
        value = self.seed.value
        seed = int(value) if isinstance(value, int | float) and float(value).is_integer() else -1
        if seed < 0:                                  # refused here, in the session's language
            self.render()                             # the widgets show the scenario still played
            raise ValueError(tr.gettext("The seed must be a whole number >= 0, got {value}.").format(
                value=repr(value)))
        if kind == self.session.scenario_player.scenario.kind and seed == self.session.scenario_player.scenario.seed:
            return
        try:
            self.session.set_scenario(kind, seed)
        except ValueError:
            self.render()            # the widgets show the scenario still played
            raise
