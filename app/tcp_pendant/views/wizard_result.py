"""The result panel of a finished wizard (viser GUI).

Shows the calibrated frame (X, Y, Z mm; A, B, C deg when orientation is calibrated) and the
quality figures from tcpcal (per-touch error, mean, max and RMS error, 95 % radius,
orthogonality defect, displacement lengths), the warnings in words, and "Save to tool
library" (name and slot; saving also makes it the active tool). For the 4-point wizard: a bar
chart of the per-touch errors with outliers in red, "Drop outliers" / "Use all touches", the
estimator the TCP is reported from, and a switch that compares the three estimators side by
side. In training mode: the result against the hidden true TOOL frame with a verdict.
Touches recorded with "Hide distance" on are listed with their distance-at-record next to
their error (``hidden_touches_markdown``: the lesson of judging by eye).
A TCP check's result (``saves_to_library`` False) shows no Save; a saved calibration's result
offers "Check this TCP", which starts the TCP check wizard on the slot just saved.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, cast

from tcp_pendant.controller.words import error_text
from tcp_pendant.calibrate.chart import error_axis_top_mm, error_bars
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.calibrate.text import (
    comparison_markdown,
    estimator_options,
    hidden_touches_markdown,
    result_markdown,
    save_markdown,
    scene_legend_markdown,
    save_preview_markdown,
    truth_markdown,
    warnings_markdown,
)
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.views.gui_util import (
    CHART_LEGEND,
    ButtonEvent,
    DropdownEvent,
    number_of_option,
    set_content,
    set_options,
    set_value,
    slot_option,
    target_of,
)
from tcp_pendant.wizards import (
    ESTIMATOR_LABELS,
    Wizard,
    WizardStateError,
    Xyz4Result,
    Xyz4Wizard,
)
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

if TYPE_CHECKING:
    from viser import uplot

    from tcp_pendant.wizards.session_record import WizardRun

    from tcp_pendant.views.wizard_menu import CalibrateView

__all__ = ["AUTO_SLOT", "WizardResultView", "slot_options"]

AUTO_SLOT = N_("same name, else first free")
"""The Save slot list's first option (a msgid: shown in the session's language)."""


def slot_options(tools: dict[int, Tool], *, tr: Translator = ENGLISH) -> tuple[str, ...]:
    """The Save slot list: automatic, then every slot with the tool it holds."""
    return (tr.gettext(AUTO_SLOT), *(slot_option(s, tools[s].name if s in tools else tr.gettext("(empty)"))
                                     for s in range(1, ToolLibrary.N_SLOTS + 1)))


def _chart_series(*, has_outliers: bool, tr: Translator = ENGLISH) -> tuple[uplot.Series, ...]:
    """uPlot series of the error bars: touch number, errors (blue), outliers (red, shown only
    when there are some), the mean (dashed); no point markers on the bar outlines."""
    _ = tr.gettext
    no_points: uplot.Series_Points = {"show": False}
    return ({"label": _("touch")},
            {"label": _("error (mm)"), "stroke": "#3b6fd6", "fill": "rgba(59,111,214,0.55)", "width": 1,
             "points": no_points},
            {"label": _("outlier (mm)"), "stroke": "#d62020", "fill": "rgba(214,32,32,0.6)", "width": 1,
             "points": no_points, "show": has_outliers},
            {"label": _("mean (mm)"), "stroke": "#444444", "dash": (4.0, 4.0), "width": 1, "points": no_points})


class WizardResultView:
    """Builds the result panel in the current GUI container (see the module docstring)."""

    def __init__(self, parent: CalibrateView) -> None:
        self.parent = parent
        gui = target_of(parent.session).gui
        keep = parent.words.keep                  # the tab's fixed words, relabelled per language
        tr = parent.session.translator
        _ = tr.gettext
        self.folder = keep(gui.add_folder(N_("Result"), visible=False))
        with self.folder:
            self.result_md = gui.add_markdown("")
            self.truth_md = gui.add_markdown("", visible=False)
            self.legend_md = gui.add_markdown("", visible=False)   # what the 3D view shows of it
            self.replay_scan = keep(gui.add_button(N_("Replay scan"), visible=False,   # a beam result's scan
                                                   hint=N_("Show the robot going through the beam scan again.")))
            self.warnings_md = gui.add_markdown("")
            self.hidden_md = gui.add_markdown("", visible=False)   # touches recorded with the distance hidden
            bars = error_bars([1], [0.0])
            self.chart = gui.add_uplot(
                bars.columns, _chart_series(has_outliers=False, tr=tr),
                title=_("Error per touch (mm)"), height=170, visible=False,
                scales={"x": {"time": False}, "y": {"range": (0.0, 1.0)}},
                axes=({"label": _("touch")}, {"label": "mm"}), legend=CHART_LEGEND,
            )
            self.drop = keep(gui.add_button(N_("Drop outliers"), color="red", visible=False,
                                            hint=N_("Recompute without the touches flagged as outliers.")))
            self.restore = keep(gui.add_button(N_("Use all touches"), visible=False))
            labels = tuple(estimator_options(tr=tr))
            self.estimator = keep(gui.add_dropdown(N_("Report TCP from"), labels, initial_value=labels[0],
                                                   visible=False))
            self.compare = keep(gui.add_checkbox(N_("Compare the three estimators"), False, visible=False))
            self.compare_md = gui.add_markdown("", visible=False)
            self.save_name = keep(gui.add_text(N_("Tool name"), ""))
            slots = slot_options({}, tr=tr)
            self.save_slot = keep(gui.add_dropdown(N_("Slot"), slots, initial_value=slots[0]))
            self.save_preview = gui.add_markdown("")
            self.save = keep(gui.add_button(N_("Save to tool library"), color="green",
                                            hint=N_("Store the tool in the library and make it the active tool.")))
            self.save_md = gui.add_markdown("")
            self.check_tcp = keep(gui.add_button(N_("Check this TCP"), color="violet", visible=False,
                                                 hint=N_("Start the TCP check (spin test) on the tool just saved.")))
        act = parent.action
        self.drop.on_click(act(self._on_drop))
        self.restore.on_click(act(self._on_restore))
        self.estimator.on_update(act(self._on_estimator, user_only=True))
        self.compare.on_update(act(lambda _e: None, user_only=True))
        self.save.on_click(act(self._on_save, sync=True))
        self.check_tcp.on_click(act(self._on_check_tcp, sync=True))
        self.replay_scan.on_click(act(lambda _e: self.parent.scene.replay_scan()))
        self.save_name.on_update(act(lambda _e: None, user_only=True))
        self.save_slot.on_update(act(lambda _e: None, user_only=True))
        self._named_run: WizardRun | None = None
        self._refused: tuple[WizardRun | None, str] | None = None   # (run, why its last Save was refused)
        self._charted: Xyz4Result | None = None
        self._tools: dict[int, Tool] = {}

    def relabel(self) -> None:
        """A ``language`` change (the tab relabelled the kept handles): the chart's words, the
        estimator and slot options in the new language (the choices kept); ``render`` shows the
        rest."""
        tr = self.parent.session.translator
        self.chart.title = tr.gettext("Error per touch (mm)")
        self.chart.axes = ({"label": tr.gettext("touch")}, {"label": "mm"})
        self.chart.series = _chart_series(has_outliers=bool(self._charted is not None and self._charted.outliers),
                                          tr=tr)
        labels = tuple(estimator_options(tr=tr))
        if tuple(self.estimator.options) != labels:
            self.estimator.options = labels        # render sets the result's estimator
        auto = str(self.save_slot.value) in self.parent.said_as(AUTO_SLOT)
        options = slot_options(self._tools, tr=tr)
        set_options(self.save_slot, options, keep=options[0] if auto else str(self.save_slot.value))

    # ------------------------------------------------------------ callbacks
    def _with_estimators(self, fn: Callable[[Xyz4Wizard], object]) -> None:
        """``fn(wizard)`` on the result on show, for the wizards whose result panel offers the
        estimators (``Wizard.result_extras``), as one command of the session."""
        def edit(wiz: Wizard) -> object:
            if "estimators" not in type(wiz).result_extras:
                raise WizardStateError(self.parent.gettext("The {title} result has no estimators to choose.").format(
                    title=self.parent.gettext(wiz.title)))
            return fn(cast("Xyz4Wizard", wiz))       # the 4-point's, the one that offers them
        self.parent.session.wizard_commands.edit_result(edit)

    def _on_drop(self, _event: ButtonEvent) -> None:
        self._with_estimators(lambda wiz: wiz.drop_outliers())

    def _on_restore(self, _event: ButtonEvent) -> None:
        self._with_estimators(lambda wiz: wiz.restore_all())

    def _on_estimator(self, event: DropdownEvent) -> None:
        tr = self.parent.session.translator
        key = (estimator_options(tr=tr) | estimator_options()).get(str(event.target.value))
        if key is None:
            raise ValueError(tr.gettext("Unknown estimator {value!r}.").format(value=event.target.value))
        self._with_estimators(lambda wiz: wiz.set_estimator(key))

    def _on_save(self, _event: ButtonEvent) -> None:
        """Save; a refusal is said in the panel (it stays until the next Save or another
        result), not only in the toast the session's guard shows."""
        run = self.parent.workflow.run
        try:
            slot, tool = self.parent.session.wizard_commands.save_result(str(self.save_name.value),
                                                         number_of_option(self.save_slot.value))
        except ValueError as exc:
            self._refused = (run, error_text(exc, self.parent.session.translator))
            raise
        self._refused = None
        self.parent.saved(slot, tool)

    def _on_check_tcp(self, _event: ButtonEvent) -> None:
        wf = self.parent.workflow
        if wf.last_save is None:
            raise WizardStateError(self.parent.gettext("Save the tool first: the TCP check works on a tool of the library."))
        self.parent.session.wizard_commands.start("tcp-check", slot=wf.last_save[0])

    # ------------------------------------------------------------ render
    def refresh_slots(self, tools: dict[int, Tool]) -> None:
        """Re-list the slots after the library changed."""
        self._tools = dict(tools)
        set_options(self.save_slot, slot_options(tools, tr=self.parent.session.translator), keep=self.save_slot.value)

    def render(self) -> None:
        """Show the result of the wizard on show (hide the panel when there is none)."""
        wf = self.parent.workflow
        res = wf.result
        self.folder.visible = res is not None
        if res is None:
            return
        tr = self.parent.session.translator
        saves = wf.wizard is not None and wf.wizard.saves_to_library
        for h in (self.save_name, self.save_slot, self.save_preview, self.save, self.save_md):
            h.visible = saves                          # a TCP check saves nothing
        self.check_tcp.visible = saves and wf.last_save is not None and wf.result_saved
        if wf.run is not self._named_run:              # another calibration: its name, no old message
            self._named_run = wf.run
            set_value(self.save_name, wf.default_save_name(tr=tr))
            set_content(self.save_md, "")
        truth = None if wf.hide_truth else wf.truth()   # an exercise: no answer shown
        set_content(self.result_md, result_markdown(res, truth, tr=tr))   # a beam result: errors of both vs truth
        self.replay_scan.visible = bool(getattr(getattr(res, "scan", None), "moves", ()))   # a stored scan: none
        set_content(self.warnings_md, warnings_markdown(res))
        hidden = hidden_touches_markdown(res, *wf.distances_shown(), tr=tr)
        self.hidden_md.visible = bool(hidden)
        if hidden:
            set_content(self.hidden_md, hidden)
        self.truth_md.visible = truth is not None
        if truth is not None:
            set_content(self.truth_md, truth_markdown(truth, tr=tr))
        tool = wf.preview_tool()
        if tool is not None:
            set_content(self.save_preview, save_preview_markdown(str(self.save_name.value), str(self.save_slot.value),
                                                                 tool.tcp_mm, tool.abc_deg, tr=tr))
        if wf.last_save is not None:
            set_content(self.save_md, save_markdown(wf.last_save[0], wf.last_save[1].name, tr=tr))
        refused = self._refused
        if refused is not None and refused[0] is wf.run and wf.last_save is None:
            set_content(self.save_md, tr.gettext("⚠ **Not saved:** {why}").format(why=escape_markdown(refused[1])))
        extras = set() if wf.wizard is None else type(wf.wizard).result_extras
        legend = scene_legend_markdown(computed=wf.T_flange_tool_computed_m() is not None,
                                       true=truth is not None and wf.T_flange_tool_true_m() is not None,
                                       sphere="sphere" in extras,
                                       radius_mm=getattr(res, "sphere_radius_mm", None), tr=tr)
        self.legend_md.visible = bool(legend)
        if legend:
            set_content(self.legend_md, legend)
        self._render_estimators(cast("Xyz4Result", res) if "estimators" in extras else None, tr)

    def _render_estimators(self, res: Xyz4Result | None, tr: Translator) -> None:
        """The 4-point's estimator parts (``result_extras`` "estimators"): the per-touch chart,
        outlier drop and restore, the estimator choice and their comparison."""
        for h in (self.chart, self.drop, self.restore, self.estimator, self.compare):
            h.visible = res is not None
        if res is None:
            self.compare_md.visible = False
            return
        if res is not self._charted:                   # arrays and dicts: viser re-sends every assignment
            self._charted = res
            bars = error_bars([i + 1 for i in res.used_indices], res.per_touch_error_mm,
                              [i + 1 for i in res.outliers])
            self.chart.data = bars.columns
            self.chart.series = _chart_series(has_outliers=bool(res.outliers), tr=tr)
            self.chart.scales = {"x": {"time": False},
                                 "y": {"range": (0.0, error_axis_top_mm(res.per_touch_error_mm))}}
        self.drop.disabled = not res.outliers
        self.restore.disabled = not res.excluded
        label = tr.gettext(ESTIMATOR_LABELS[res.estimator])
        if self.estimator.value != label:
            set_value(self.estimator, label)
        self.compare_md.visible = bool(self.compare.value)
        if self.compare.value:
            set_content(self.compare_md, comparison_markdown(res, tr=tr))
