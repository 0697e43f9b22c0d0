"""The trainer dashboard's tables as HTML (``gui.add_html``), made for a 1024x768 projector.

One line per trainee: short headers, no wrapping (``white-space: nowrap``), a long name or
method cut with an ellipsis (the whole text in the cell's tooltip), 15 px text. A stuck row
(``classroom.board``) has a yellow background and a "⚠" before the name; an idle row (joined,
nothing started, quiet) a blue one, "◔" before the name and "idle" in its Step cell; a trainee
not connected is grey. Every text a trainee typed (names) and every stored text (methods, steps)
goes through ``escape_html``: shown literally, never run. Numbers are ours.

Columns of :func:`trainees_html`: ``#`` (the trainee's mark on the chart), Trainee, On (●
connected, ○ not), Method, Step ("2/4", "result", "cancelled"), On step (time on it, m:ss),
Last touch (time since it), Touches, Crashes (of the latest calibration), Err mm (position
error of the last finished calibration against the truth; its TCP in the tooltip), Grade.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from tcp_pendant.classroom.board import DashboardRow, OpenRun, format_duration
from tcp_pendant.text_escape import escape_html
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.wizards.registry import WIZARD_TYPES
from tcp_pendant.wizards.truth import GRADE_WORDS

__all__ = ["FONT_PX", "IDLE_BACKGROUND", "STUCK_BACKGROUND", "grade_word", "in_progress_html", "method_name",
           "short_step", "trainees_html"]

FONT_PX = 15
"""Table text size, pixels (readable from the back of a room on a 1024x768 projector)."""
STUCK_BACKGROUND = "#ffe08a"
"""Background of a stuck trainee's row."""
IDLE_BACKGROUND = "#d6e4ff"
"""Background of an idle trainee's row."""
_CELL = "padding:2px 6px;white-space:nowrap;border-bottom:1px solid #ddd"
_CUT = "display:inline-block;overflow:hidden;text-overflow:ellipsis;vertical-align:bottom;max-width:{em}em"
_STEP = re.compile(r"^Step (\d+) of (\d+)$")
_ON = '<span style="color:#1f9d3a">●</span>'
_OFF = "○"


def short_step(step: str) -> str:
    """"Step 2 of 4" -> "2/4"; anything else as it is."""
    m = _STEP.match(step)
    return f"{m.group(1)}/{m.group(2)}" if m else step


def _cut(text: str, em: int) -> str:
    safe = escape_html(text)
    return f'<span title="{safe}" style="{_CUT.format(em=em)}">{safe}</span>'


def _table(headers: Sequence[tuple[str, str]], body: list[str], cls: str, tr: Translator) -> str:
    _ = tr.gettext
    head = "".join(f'<th title="{escape_html(_(tip))}" style="{_CELL};text-align:left;border-bottom:2px solid #888">'
                   f"{escape_html(h if h == '#' else _(h))}</th>" for h, tip in headers)
    return (f'<div class="{cls}" style="font-size:{FONT_PX}px;line-height:1.35;overflow-x:auto">'
            f'<table style="border-collapse:collapse;width:100%"><thead><tr>{head}</tr></thead>'
            f"<tbody>{''.join(body)}</tbody></table></div>")


TRAINEE_HEADERS: tuple[tuple[str, str], ...] = (
    ("#", N_("the trainee's mark on the chart")), (N_("Trainee"), N_("name")), (N_("On"), N_("connected now")),
    (N_("Method"), N_("the latest calibration")), (N_("Step"), N_("where it is")),
    (N_("On step"), N_("time on the step, or idle for (m:ss)")),
    (N_("Last touch"), N_("time since the last touch (m:ss)")),
    (N_("Touches"), N_("touches recorded in the latest calibration")),
    (N_("Crashes"), N_("crashes in the latest calibration")),
    (N_("Err mm"), N_("position error of the last finished calibration against the true TOOL frame")),
    (N_("Grade"), N_("of the last finished calibration")))
"""The live table's headers and their tooltips (English msgids; ``#`` as it is)."""


def method_name(method: str, tr: Translator) -> str:
    """A calibration's method as the board has it (a wizard's English title, or its kind when
    the title is unknown: ``xyz4``) in ``tr``'s language: the wizard's translated title."""
    cls = WIZARD_TYPES.get(method)
    return tr.gettext(cls.title if cls is not None else method)


def grade_word(grade: str | None, tr: Translator) -> str:
    """A stored grade ("good", "fair", "poor") in ``tr``'s language; another as it is, "" for
    none."""
    return tr.gettext(GRADE_WORDS[grade]) if grade in GRADE_WORDS else grade or ""


def trainees_html(rows: Sequence[DashboardRow], *, tr: Translator = ENGLISH) -> str:
    """The live table (module docstring) in ``tr``'s language (a method by its translated name);
    every text escaped."""
    _ = tr.gettext
    if not rows:
        empty = escape_html(_("No trainee has given a name yet."))
        return f'<div style="font-size:{FONT_PX}px"><i>{empty}</i></div>'
    body = []
    for r in rows:
        style = (f"background:{STUCK_BACKGROUND};font-weight:600" if r.stuck else
                 f"background:{IDLE_BACKGROUND};font-weight:600" if r.idle else "color:#888" if not r.connected else "")
        err = "-" if r.position_error_mm is None else f"{r.position_error_mm:.2f}"
        if r.tcp_mm is not None:                     # the result itself in the cell's tooltip
            tcp = ", ".join(f"{v:.1f}" for v in r.tcp_mm)
            err = f'<span title="TCP {escape_html(tcp)} mm">{err}</span>'
        name = ("⚠ " if r.stuck else "◔ " if r.idle else "") + r.name
        step = _("idle") if r.idle and not r.step else short_step(r.step)
        cells = (escape_html(str(r.number)), _cut(name, 11), _ON if r.connected else _OFF,
                 _cut(method_name(r.method, tr) if r.method else "-", 10),
                 escape_html(step or "-"), format_duration(r.step_s if r.in_progress else r.quiet_s if r.idle else None),
                 format_duration(r.touch_s), str(r.touches), str(r.crashes), err, escape_html(grade_word(r.grade, tr) or "-"))
        tds = "".join(f'<td style="{_CELL}">{c}</td>' for c in cells)
        kind = "stuck" if r.stuck else "idle" if r.idle else "trainee"
        body.append(f'<tr class="{kind}" style="{style}">{tds}</tr>')
    return _table(TRAINEE_HEADERS, body, "tcp-dashboard-trainees", tr)


RUN_HEADERS: tuple[tuple[str, str], ...] = (
    (N_("Cal."), N_("calibration id in the gradebook")), (N_("Trainee"), N_("name")), (N_("On"), N_("connected now")),
    (N_("Method"), N_("wizard")), (N_("Step"), N_("where it is")), (N_("On step"), N_("time on the step (m:ss)")),
    (N_("Started"), N_("time since it started (m:ss)")), (N_("Touches"), N_("touches that count")))


def in_progress_html(runs: Sequence[OpenRun], *, tr: Translator = ENGLISH) -> str:
    """The calibrations in progress (oldest first) in ``tr``'s language; every text escaped."""
    _ = tr.gettext
    if not runs:
        empty = escape_html(_("No calibration in progress."))
        return f'<div style="font-size:{FONT_PX}px"><i>{empty}</i></div>'
    body = []
    for r in runs:
        cells = (str(r.calibration_id), _cut(r.trainee, 11), _ON if r.connected else _OFF,
                 _cut(method_name(r.method, tr) if r.method else "-", 10),
                 escape_html(short_step(r.step) or "-"), format_duration(r.step_s), format_duration(r.started_s),
                 str(r.touches))
        style = "" if r.connected else "color:#888"
        body.append(f'<tr style="{style}">' + "".join(f'<td style="{_CELL}">{c}</td>' for c in cells) + "</tr>")
    return _table(RUN_HEADERS, body, "tcp-dashboard-runs", tr)
