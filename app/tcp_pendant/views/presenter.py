"""Presenter mode: the lecture's view of a pendant, readable on a projector.

A "Presenter mode" checkbox on top of the panel (per session; in ``--shared`` mode the shared
GUI's, so every browser follows it; ``tcp-pendant --presenter`` starts with it on) shows the
"Presenter" folder above the tabs:

* the TCP readout in large monospace numbers (``READOUT_FONT_PX``, 28 px): X Y Z mm, A B C deg
  in WORLD, and the distance to the reference tip (unless "Hide distance" is on);
* the running wizard's steps in a few wrapped lines, the current one marked;
* the per-touch error chart of a 4-point result, ``CHART_HEIGHT_PX`` high;
* the "Math board" checkbox: "The math" over the whole screen (``views.math_board_view``).

The folder is pinned at the top of the panel while the rest scrolls under it (the page script,
``serve/static/pendant.js``, makes it ``position: sticky``: viser 1.1 has no sticky GUI element), so
it is sized to leave room below it: at 1024x768 the whole block, chart included, is above the
fold (about 500 px of the 713 px panel). It narrows the panel to ``PRESENTER_WIDTH_PX`` (the
scene keeps about 70 % of a 1024 px wide projector) and puts it back to ``NORMAL_WIDTH_PX``
when switched off; the scene's labels (``session.views.labels``) are drawn
``LABEL_SCALE`` times larger.

The readout is raw HTML inside viser markdown (a ``<div style=...>``): only numbers this module
formats go into it; every other text (step titles, the tool name) is escaped
(``text_escape.escape_html`` / ``escape_markdown``). The view subscribes to the session's change
signal and renders from state (pose state, workflow); it calls no other view. Units: mm and
degrees on screen. Its words are the session's language (``Session.translator``); a language
change re-labels the checkbox, the folder and the chart and re-renders the folder. The readout's
layout is the same in every language (axis names, units and the numbers' columns stay).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, TypedDict

from tcp_pendant.calibrate.chart import error_axis_top_mm, error_bars
from tcp_pendant.controller.readout import PoseReadout
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.text_escape import escape_html, escape_markdown
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.views.gui_util import CHART_LEGEND, CheckboxEvent, target_of
from tcp_pendant.views.math_board_view import MathBoardView

if TYPE_CHECKING:
    import viser
    from viser import uplot

    from tcp_pendant.controller.pose_state import PoseState
    from tcp_pendant.wizards import Wizard, WizardResult

__all__ = [
    "CHART_HEIGHT_PX",
    "NORMAL_WIDTH_PX",
    "LABEL_SCALE",
    "PRESENTER_WIDTH_PX",
    "READOUT_FONT_PX",
    "STEPS_FONT_PX",
    "PresenterView",
    "presenter_readout_markdown",
    "presenter_steps_markdown",
]

READOUT_FONT_PX = 28
"""Font size of the presenter readout's numbers (at least 28 px: readable from the back row)."""
STEPS_FONT_PX = 18
"""Font size of the presenter step list."""
CHART_HEIGHT_PX = 150
"""Height of the presenter's error chart, pixels (its title and legend come on top): the pinned
block stays above the fold at 1024x768 with room below it for the panel."""
LABEL_SCALE = 1.8
"""``font_screen_scale`` of the scene's labels in presenter mode (viser draws them about 12 px
high at 1.0)."""
PRESENTER_WIDTH_PX = 320
"""Panel width in presenter mode (viser's "medium"): 31 % of a 1024 px projector."""
NORMAL_WIDTH_PX = 384
"""Panel width otherwise (viser's "large", as ``PendantApp.start`` sets it)."""
class _Theme(TypedDict):
    dark_mode: bool
    show_logo: bool
    show_share_button: bool


_THEME: _Theme = {"dark_mode": False, "show_logo": False, "show_share_button": False}   # as PendantApp.start

_TOGGLE = N_("Presenter mode")
_TOGGLE_HINT = N_("Large readout, step list and error chart for a projector.")
_FOLDER = N_("Presenter")
_CHART_TITLE = N_("Error per touch (mm)")


def _num(value: float, decimals: int = 2) -> str:
    """A number we format ourselves (never user text): right-aligned, 8 characters."""
    if not math.isfinite(value):
        return "     ---"
    return f"{value:8.{decimals}f}"


def presenter_readout_markdown(readout: PoseReadout, distance_mm: float | None, *,
                               font_px: int = READOUT_FONT_PX, tr: Translator = ENGLISH) -> str:
    """The big TCP readout (raw HTML in markdown; numbers, and the distance's and frame's words
    in ``tr``'s language, escaped).

    Args:
        readout: the TCP pose (mm, degrees) in its frame.
        distance_mm: true tool tip to reference tip, mm; None when "Hide distance" is on.
        font_px: font size of the numbers, pixels.
        tr: the language of the words.

    Returns:
        A ``<div>`` with X, Y, Z one a line, monospace, ``font_px`` high; A, B, C on one line
        below at about half that size; the distance; the frame. Compact: the block is pinned
        at the top of the panel and must leave room below it.
    """
    rows = [("X", readout.x_mm, "mm"), ("Y", readout.y_mm, "mm"), ("Z", readout.z_mm, "mm")]
    lines = [f"{name} {_num(float(v))} {unit}" for name, v, unit in rows]
    abc = "  ".join(f"{name} {_num(float(v)).strip()}" for name, v in
                    (("A", readout.a_deg), ("B", readout.b_deg), ("C", readout.c_deg))) + " °"
    _ = tr.gettext
    dist = _("hidden") if distance_mm is None else f"{_num(float(distance_mm)).strip()} mm"
    tip = escape_html(_("tip {distance}").format(distance=dist)).replace(" ", "&nbsp;")
    frame = escape_html(_("TCP in {frame}").format(frame=readout.frame))
    body = "<br>".join(lines).replace(" ", "&nbsp;")
    small = max(int(font_px) // 2 + 1, 12)
    return (f'<div class="presenter-readout" style="font-size:{int(font_px)}px; font-family:monospace; '
            f'line-height:1.1; white-space:nowrap">{body}</div>'
            f'<div class="presenter-abc" style="font-size:{small}px; font-family:monospace; white-space:nowrap">'
            f'{abc.replace(" ", "&nbsp;")}</div>'
            f'<div class="presenter-distance" style="font-size:{int(font_px) - 8}px; font-family:monospace">'
            f'{tip} <span style="font-size:{small}px; font-family:sans-serif">'
            f'{frame}</span></div>')


def presenter_steps_markdown(wizard: Wizard | None, *, font_px: int = STEPS_FONT_PX,
                             tr: Translator = ENGLISH) -> str:
    """The running wizard's steps, wrapped in a few lines (a step never split): ✔ recorded,
    ▶ current (bold), · to do.

    Args:
        wizard: the wizard on show (``CalibrationWorkflow.wizard``), or None.
        font_px: font size, pixels.
        tr: the language of the words: the method's title (an ``N_`` msgid of its class) and
            this function's own; the steps' titles come in the wizard's language as they are.
    """
    _ = tr.gettext
    if wizard is None:
        return _("*No wizard running: start one in the Calibrate tab.*")
    lines = []
    for s in wizard.steps:
        here = s.index == wizard.step_index and not wizard.is_complete
        sym = "▶" if here else ("✔" if s.recorded else "·")
        text = f"{sym} {s.index + 1}. {escape_html(str(s.title))}"
        lines.append(f'<b class="current-step">{text}</b>' if here else text)
    if wizard.is_complete:
        result = escape_html(_("Result"))
        lines.append(f'<b class="current-step">▶ {result}</b>')
    method = getattr(wizard, "title", None)
    title = escape_html(_(str(method)) if method else _("Wizard"))
    items = "".join(f'<span style="white-space:nowrap; margin-right:0.7em">{x}</span> ' for x in lines)
    return (f'<div class="presenter-steps" style="font-size:{int(font_px)}px; line-height:1.3">'
            f'<u style="margin-right:0.7em">{title}</u> ' + items.rstrip() + "</div>")


def _chart_series(tr: Translator = ENGLISH) -> tuple[uplot.Series, ...]:
    """The error chart's series, named in ``tr``'s language."""
    _ = tr.gettext
    no_points: uplot.Series_Points = {"show": False}
    return ({"label": _("touch")},
            {"label": _("error (mm)"), "stroke": "#3b6fd6", "fill": "rgba(59,111,214,0.55)", "width": 2,
             "points": no_points},
            {"label": _("outlier (mm)"), "stroke": "#d62020", "fill": "rgba(214,32,32,0.6)", "width": 2,
             "points": no_points},
            {"label": _("mean (mm)"), "stroke": "#444444", "dash": (6.0, 6.0), "width": 2, "points": no_points})


def _chart_axes(tr: Translator = ENGLISH) -> tuple[uplot.Axis, ...]:
    """The error chart's axes: touch numbers across, mm up (a unit: not translated)."""
    return ({"label": tr.gettext("touch")}, {"label": "mm"})


class PresenterView:
    """The "Presenter mode" checkbox and the presenter folder (see the module docstring).

    Args:
        session: the session (its GUI: one browser, or every browser in ``--shared`` mode).
        on: start in presenter mode (``--presenter``).

    Attributes:
        toggle, folder, readout_md, tool_md, steps_md, chart: the widgets (for tests).
        board: the "Math board" (``views.math_board_view``).
        panel_width_px: the panel width last set, pixels.
    """

    def __init__(self, session: Session, *, on: bool = False) -> None:
        self.session = session
        gui = target_of(session).gui
        tr = session.translator
        _ = tr.gettext
        self.toggle = gui.add_checkbox(_(_TOGGLE), bool(on), order=-950.0, hint=_(_TOGGLE_HINT))
        self.folder = gui.add_folder(_(_FOLDER), order=-949.0, visible=bool(on))
        with self.folder:
            self.readout_md = gui.add_markdown("")
            self.tool_md = gui.add_markdown("")
            self.steps_md = gui.add_markdown("")
            bars = error_bars([1], [0.0])
            self.chart = gui.add_uplot(bars.columns, _chart_series(tr), title=_(_CHART_TITLE),
                                       height=CHART_HEIGHT_PX, visible=False,
                                       scales={"x": {"time": False}, "y": {"range": (0.0, 1.0)}},
                                       axes=_chart_axes(tr), legend=CHART_LEGEND,
                                       padding=(14, 12, 0, 0))   # the top tick's label not cut off
            self.board = MathBoardView(session)         # "The math" over the whole screen
        self._shown: dict[str, str] = {}
        self.panel_width_px = NORMAL_WIDTH_PX
        self._charted: WizardResult | None = None
        self.toggle.on_update(session.loop.on_loop(self._on_toggle))
        session.subscribe(self.on_change)
        if on:
            self._apply_width(True)
            self._apply_label_scale(True)
        self.render()

    @property
    def on(self) -> bool:
        """Presenter mode is on."""
        return bool(self.toggle.value)

    # ------------------------------------------------------------ callbacks
    def _on_toggle(self, _event: CheckboxEvent | None = None) -> None:
        on = self.on
        self.folder.visible = on
        self._apply_width(on)
        self._apply_label_scale(on)
        self.render()

    def _apply_label_scale(self, on: bool) -> None:
        """The scene's labels larger in presenter mode (the wizards' scene spreads them at the
        size they are drawn, on the next camera report or move)."""
        scale = LABEL_SCALE if on else 1.0
        for handle in self.session.views.labels.drawn().values():
            if float(getattr(handle, "font_screen_scale", 1.0)) != scale:
                handle.font_screen_scale = scale

    def _apply_width(self, on: bool) -> None:
        gui = target_of(self.session).gui
        self.panel_width_px = PRESENTER_WIDTH_PX if on else NORMAL_WIDTH_PX
        gui.configure_theme(control_width="medium" if on else "large", **_THEME)
        panel = getattr(gui, "main_panel", None)
        if panel is not None:
            panel.set_width(self.panel_width_px)

    def on_change(self, change: SessionChange) -> None:
        """The change signal: the readout after a move, the steps and the chart after a
        wizard or tool change (only while presenter mode is on); every word after a language
        change."""
        if change.language:
            self._relabel()
        if self.on and (change.pose or change.tool or change.wizard or change.touches or change.language):
            self.render(change.state)

    def _relabel(self) -> None:
        """The checkbox's, the folder's and the chart's words in the session's language."""
        tr = self.session.translator
        _ = tr.gettext
        self.toggle.label, self.toggle.hint = _(_TOGGLE), _(_TOGGLE_HINT)
        self.folder.label = _(_FOLDER)
        self.chart.title = _(_CHART_TITLE)
        self.chart.series = _chart_series(tr)
        self.chart.axes = _chart_axes(tr)

    # ------------------------------------------------------------ render
    def _set(self, handle: viser.GuiMarkdownHandle, key: str, text: str) -> None:
        if self._shown.get(key) != text:
            self._shown[key] = text
            handle.content = text

    def render(self, state: PoseState | None = None) -> None:
        """Show the session's state (nothing while presenter mode is off)."""
        if not self.on:
            return
        s = self.session
        tr = s.translator
        _ = tr.gettext
        state = s.pose_state() if state is None else state
        distance = None if s.hide_distance else float(state.touch.distance_mm)
        self._set(self.readout_md, "readout", presenter_readout_markdown(state.readout("WORLD"), distance, tr=tr))
        tool = s.controller.active_tool
        self._set(self.tool_md, "tool", _("Tool data: **{name}**").format(name=escape_markdown(tool.name))
                  if tool is not None else _("Tool data: **none** (TCP = flange)"))   # one line under the readout
        wf = s.workflow
        wizard = None if wf is None or not wf.is_open else wf.wizard
        self._set(self.steps_md, "steps", presenter_steps_markdown(wizard, tr=tr))
        self._render_chart(None if wizard is None else wizard.result)

    def _render_chart(self, res: WizardResult | None) -> None:
        errors = getattr(res, "per_touch_error_mm", None)
        used = getattr(res, "used_indices", None)
        show = errors is not None and used is not None and len(errors) > 0
        if self.chart.visible != show:
            self.chart.visible = show
        if not show or errors is None or used is None or res is self._charted:
            return
        self._charted = res
        bars = error_bars([i + 1 for i in used], errors, [i + 1 for i in getattr(res, "outliers", ())])
        self.chart.data = bars.columns
        self.chart.scales = {"x": {"time": False}, "y": {"range": (0.0, error_axis_top_mm(errors))}}
