"""The "Systematic error" panel of the Calibrate tab (training).

A trainer picks a systematic error for this pendant: Off (default), Bent tool, Robot accuracy
or Moved reference tip (``controller.scenarios``), and a seed that draws its concrete errors.
The choice is the session's state, changed by its command ``Session.set_scenario`` (one change
signal); this view renders it from state. After a calibration result the scenario's
explanation (``scenarios.explain``: how it shows in the result and how the TCP check reveals
it) is shown, escaped. The panel is shown in training mode only (the Calibrate tab's "Training
mode" switch, ``CalibrationWorkflow.training``).
"""

from __future__ import annotations

import viser

from tcp_pendant.controller.scenarios import DEFAULT_SEED_RANGE, SCENARIO_KINDS, explain
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.gui_util import set_value, target_of

__all__ = ["SCENARIO_CHOICES", "ScenarioPanel", "scenario_markdown"]

SCENARIO_CHOICES: dict[str, str] = {
    "off": "Off",
    "bent_tool": "Bent tool",
    "robot_accuracy": "Robot accuracy",
    "moved_reference": "Moved reference tip",
}
"""Scenario kind -> the dropdown's words (every kind of ``scenarios.SCENARIO_KINDS``)."""
assert tuple(SCENARIO_CHOICES) == SCENARIO_KINDS


def scenario_markdown(session: Session) -> str:
    """What the panel says: the scenario played and, after a calibration result, how it shows
    (``explain``, escaped)."""
    world = session.scenario_player.world
    if world is None:
        return "*No systematic error: the residual reflects the touching accuracy only.*"
    s = world.scenario
    text = (f"Playing **{escape_markdown(SCENARIO_CHOICES[s.kind])}** (seed {int(s.seed)}); the trainee is "
            "not told. Calibrate, then use **Check** in the Tool tab.")
    wf = session.workflow
    if wf is not None and getattr(wf, "result", None) is not None:
        text += "\n\n**How this result shows it:** " + escape_markdown(explain(world))
    return text


class ScenarioPanel:
    """Builds the panel in the current GUI container of ``session.target.gui``."""

    def __init__(self, session: Session) -> None:
        self.session = session
        gui = target_of(session).gui
        self.folder = gui.add_folder("Systematic error (training)", expand_by_default=False)
        with self.folder:
            labels = list(SCENARIO_CHOICES.values())
            self.kind = gui.add_dropdown("Systematic error", labels,
                                         initial_value=SCENARIO_CHOICES[session.scenario_player.scenario.kind],
                                         hint="What the physical world gets wrong (training).")
            self.seed = gui.add_number("Seed", int(session.scenario_player.scenario.seed), min=0, step=1,
                                       hint=f"Draws the errors; the tests check seeds "
                                            f"{DEFAULT_SEED_RANGE.start}-{DEFAULT_SEED_RANGE.stop - 1}.")
            self.md = gui.add_markdown("")
        g = session.loop.on_loop
        self.kind.on_update(g(self._on_choose))
        self.seed.on_update(g(self._on_choose))
        session.subscribe(self.on_change)
        self.render()

    def on_change(self, change: SessionChange) -> None:
        """The change signal: re-render on ``tool`` (a new scenario) and ``wizard`` (a result,
        the training switch)."""
        if change.tool or change.wizard:
            self.render()

    def render(self) -> None:
        """Show the session's scenario, its explanation after a result, and the panel only in
        training mode."""
        s = self.session
        wf = s.workflow
        self.folder.visible = wf is None or bool(getattr(wf, "training", True))
        label = SCENARIO_CHOICES[s.scenario_player.scenario.kind]
        if self.kind.value != label:
            set_value(self.kind, label)
        if int(self.seed.value or 0) != int(s.scenario_player.scenario.seed):
            set_value(self.seed, int(s.scenario_player.scenario.seed))
        self.md.content = scenario_markdown(s)

    def _on_choose(self, event: viser.GuiEvent[viser.GuiDropdownHandle[str]] | viser.GuiEvent[viser.GuiNumberHandle[int]]) -> None:
        if getattr(event, "client", None) is None:      # our own write-backs fire it too
            return
        kind = next((k for k, v in SCENARIO_CHOICES.items() if v == str(self.kind.value)), None)
        if kind is None:
            raise ValueError(f"Unknown systematic error {self.kind.value!r}; choose one of "
                             f"{', '.join(SCENARIO_CHOICES.values())}.")
        try:
            seed = int(self.seed.value)
        except (TypeError, ValueError):
            raise ValueError(f"The seed must be a whole number >= 0, got {self.seed.value!r}.") from None
        if kind == self.session.scenario_player.scenario.kind and seed == self.session.scenario_player.scenario.seed:
            return
        try:
            self.session.set_scenario(kind, seed)
        except ValueError:
            self.render()            # the widgets show the scenario still played
            raise
