"""The trainer's dashboard: a browser of its own, full width, no pendant.

A browser that gives the trainer token (the trainer address ``/?trainer=TOKEN``, or the token
typed in the welcome window) becomes the dashboard (:func:`open_dashboard`): its pendant views
are taken down (``Session.drop_views``; the GUI and the robot scene cleared), the control panel
is widened to the whole window (viser's ``main_panel.set_width``; 1024x768 projector), and
:func:`build_dashboard` lays out its folders, each built by one small function (:data:`FOLDERS`):

- **Class**: "Stuck after (min)" and "Idle after (min)" (kept in the gradebook, so they outlast
  a restart: ``classroom.dashboard_settings``) and the live table (``views.dashboard_table``: one
  line per trainee, stuck and idle rows highlighted), then the calibrations in progress;
- **Position errors**: one mark per trainee (x: the trainee's ``#``, y: the last position
  error against the truth, mm; integer ticks only);
- **Trainee**: choose a trainee, then **Reset wizard** (their running wizard cancelled,
  ``ClassRoom.reset_wizard``), **Push to this trainee** (exercise, tool, distance aids,
  Auto-touch: ``ClassRoom.push_to``), **Release name** (``ClassRoom.release``) and **Replay in
  3D** (their last calibration from the gradebook in this browser's own scene,
  ``views.dashboard_replay``; the panel narrows to show it until **Close replay**);
- **Exercise**: the class's settings pushed to every trainee (``views.trainer_view``) and the
  exercise's brief (``views.trainer_exercise``);
- **Message to trainees**: to all or one trainee (``views.trainer_messages``);
- **Gradebook**: the finished calibrations, the CSV download, grading an uploaded record;
- **Tool library (trainer)**: the shared library with the trainer's rights (``views.tool_panel``).

The data: the gradebook (``ClassRoom.board``) plus who is connected (``ClassRoom.connected_names``);
the class room re-renders every dashboard, throttled (``ClassRoom.refresh_trainers``). Every
text a trainee typed is escaped (``escape_html`` in the tables, ``escape_markdown`` in
markdown); every callback runs through ``SessionLoop.on_loop``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Collection, Sequence
from datetime import datetime, timezone
from typing import Protocol

import numpy as np
import viser
from viser.uplot import Scale

from tcp_pendant.controller.tools import builtin_tools
from tcp_pendant.controller.words import error_text
from tcp_pendant.classroom.board import DEFAULT_IDLE_MIN, DEFAULT_STUCK_MIN, DashboardRow, dashboard_rows, open_runs
from tcp_pendant.classroom.dashboard_settings import (
    IDLE_SETTING, MAX_MINUTES, MIN_MINUTES, STUCK_SETTING, keep_minutes, kept_minutes,
)
from tcp_pendant.classroom.class_board import ClassBoard
from tcp_pendant.classroom.grading import grade_record
from tcp_pendant.classroom.replay import CalibrationReplay
from tcp_pendant.job_pool import JobRefused
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.views.dashboard_language import LanguageControl, language_folder
from tcp_pendant.views.dashboard_replay import ReplayScene
from tcp_pendant.views.dashboard_words import DashboardWords
from tcp_pendant.views.dashboard_table import in_progress_html, method_name, trainees_html
from tcp_pendant.views.gui_util import (
    CHART_LEGEND,
    ButtonEvent,
    UploadEvent,
    client_of,
    set_content,
    set_options,
    target_of,
)
from tcp_pendant.views.language_selector import LanguageSelector
from tcp_pendant.views.tool_panel import ToolPanel
from tcp_pendant.views.trainer_exercise import build_exercise_controls
from tcp_pendant.views.trainer_messages import build_message_controls
from tcp_pendant.views.trainer_view import (
    AUTO_TOUCH, EXERCISES, HIDE_DISTANCE, KEEP, ClassControl, grades_markdown, record_grades_markdown,
    rules_words,
)
from tcp_pendant.views.replay_robot import ReplayRobot
from tcp_pendant.views.replay_touches import NO_TOUCH, pose_replay_touch, set_replay_touches
from tcp_pendant.views.upload_guard import limit_upload_size
from tcp_pendant.wizards.session_record import MAX_RECORD_BYTES, SessionRecordError, check_record_size, load_and_replay
from tcp_pendant.wizards.truth import GRADE_WORDS

log = logging.getLogger(__name__)

__all__ = ["FOLDERS", "DashboardControl", "FULL_WIDTH_PX", "NO_TRAINEE", "ONE_EXERCISE", "REPLAY_PANEL_PX",
           "TrainerDashboard", "build_dashboard", "chart_points", "message_folder", "open_dashboard"]

RUN_STATUS_WORDS = {"in_progress": N_("in progress"), "finished": N_("finished"), "cancelled": N_("cancelled")}
"""A calibration's status in the gradebook in words (English msgids)."""

FULL_WIDTH_PX = 4000
"""The panel's width asked for: wider than any projector, the browser keeps it to its window."""
REPLAY_PANEL_PX = 560
"""The panel's width while a replay is on show (the 3D scene beside it)."""
PANEL_LABEL = N_("TCP Pendant · trainer")
"""The dashboard browser's panel title."""
NO_TRAINEE_WORDS = N_("(choose a trainee)")
NO_TRAINEE = NO_TRAINEE_WORDS + " "
"""The first choice of "Trainee" (acts on nobody; the trailing space keeps it apart from names),
in English; shown in the dashboard's language."""
ONE_EXERCISE: dict[str, str | None | bool] = {KEEP: False, N_("Free practice"): None, N_("Mystery tool"): "mystery"}
"""'Exercise' choices for one trainee (False: keep)."""


class DashboardControl(ClassControl, LanguageControl, Protocol):
    """What the dashboard needs of the class room, beyond the class-wide controls."""

    def board(self) -> ClassBoard: ...

    def replay(self, name: str) -> CalibrationReplay | None: ...

    def reset_wizard(self, name: str, *, tr: Translator = ENGLISH) -> str: ...

    def push_to(self, name: str, exercise: str | None | bool = False, tool_key: str | None = None,
                hide_distance: str | None = None, auto_touch: bool | None = None, *,
                tr: Translator = ENGLISH) -> str: ...


def tool_choices(keys: Sequence[str]) -> dict[str, str]:
    """The tools a push may mount, as the tool dropdowns offer them: English label → key (a
    built-in tool by its model's label, which the dropdown says in the trainer's language;
    another by its key)."""
    models = builtin_tools()
    return {(models[k].label if k in models else k): k for k in keys}


def chart_points(rows: Sequence[DashboardRow]) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) of the position-error chart: the ``#`` and the last position error (mm) of each
    trainee who has one, in table order."""
    marked = [(float(r.number), float(r.position_error_mm)) for r in rows if r.position_error_mm is not None]
    if not marked:
        return np.zeros(0), np.zeros(0)
    x, y = zip(*marked)
    return np.asarray(x, dtype=float), np.asarray(y, dtype=float)


class _Rendered(Protocol):
    """A part of the dashboard built by another module, re-rendered with it."""

    def render(self) -> None: ...


class TrainerDashboard:
    """The dashboard of one trainer browser (module docstring).

    Attributes:
        rows: the live table's rows as last rendered (``classroom.board.DashboardRow``).
        replay_scene: the 3D replay.
        folders: the folders by title ("Class", "Exercise", ...), for the builders of other modules.

    The widgets (for tests): stuck_min, idle_min, table_html, runs_html, chart, trainee, reset,
    replay_button, close_replay, replay_touch, one_exercise, one_tool, one_hide_distance, one_auto_touch,
    push_one, release, action_md, exercise, tool, hide_distance, auto_touch, push, push_md,
    grades_md, download, grade_upload, grade_md.
    """

    # the widgets, set by the folder builders (viser handles)
    language: LanguageSelector
    language_choice: viser.GuiDropdownHandle[str]
    push_language: viser.GuiButtonHandle
    push_language_one: viser.GuiButtonHandle
    language_md: viser.GuiMarkdownHandle
    tool_panel: ToolPanel
    rules_md: viser.GuiMarkdownHandle
    stuck_min: viser.GuiNumberHandle[float]
    idle_min: viser.GuiNumberHandle[float]
    table_html: viser.GuiHtmlHandle
    runs_html: viser.GuiHtmlHandle
    chart: viser.GuiUplotHandle
    trainee: viser.GuiDropdownHandle[str]
    reset: viser.GuiButtonHandle
    replay_button: viser.GuiButtonHandle
    close_replay: viser.GuiButtonHandle
    replay_touch: viser.GuiDropdownHandle[str]
    one_exercise: viser.GuiDropdownHandle[str]
    one_tool: viser.GuiDropdownHandle[str]
    one_hide_distance: viser.GuiDropdownHandle[str]
    one_auto_touch: viser.GuiDropdownHandle[str]
    push_one: viser.GuiButtonHandle
    release: viser.GuiButtonHandle
    action_md: viser.GuiMarkdownHandle
    exercise: viser.GuiDropdownHandle[str]
    tool: viser.GuiDropdownHandle[str]
    hide_distance: viser.GuiDropdownHandle[str]
    auto_touch: viser.GuiDropdownHandle[str]
    push: viser.GuiButtonHandle
    push_md: viser.GuiMarkdownHandle
    grades_md: viser.GuiMarkdownHandle
    download: viser.GuiButtonHandle
    grade_upload: viser.GuiUploadButtonHandle
    grade_md: viser.GuiMarkdownHandle

    def __init__(self, session: Session, control: DashboardControl) -> None:
        self.session = session
        self.control = control
        self.gui = target_of(session).gui
        self.words = DashboardWords(session)
        """The fixed words of the folders, in the dashboard browser's language."""
        self.rows: list[DashboardRow] = []
        self.folders: dict[str, viser.GuiFolderHandle] = {}
        self.class_extras: list[_Rendered] = []
        """The brief's and the message box's controls (``views.trainer_exercise`` /
        ``trainer_messages``), re-rendered with the dashboard."""
        self._grading = False
        self._results_shown: tuple[tuple[int | None, float | None, str | None], ...] | None = None
        client = client_of(session)
        self.replay_scene = ReplayScene(target_of(session).scene, None if client is None else client.camera,
                                        ReplayRobot(target_of(session).scene, session.controller.kinematics))

    def folder(self, title: str, *, expand_by_default: bool = True) -> viser.GuiFolderHandle:
        """A folder of the dashboard titled ``title`` (an English msgid, shown translated), kept in
        :attr:`folders` by its English title."""
        f = self.words(self.gui.add_folder(self.session.translator.gettext(title), expand_by_default=expand_by_default),
                       label=title)
        self.folders[title] = f
        return f

    @property
    def no_trainee(self) -> str:
        """The first choice of "Trainee" in the dashboard's language."""
        return self.session.translator.gettext(NO_TRAINEE_WORDS) + " "

    def on_change(self, change: SessionChange) -> None:
        """The dashboard browser's language changed: every text again in it (the class too)."""
        if not change.language:
            return
        self.words.relabel()
        self._relabel_replay_touches()
        label_chart(self)
        self.gui.set_panel_label(self.session.translator.gettext(PANEL_LABEL))
        self._results_shown = None
        self.render()

    # ------------------------------------------------------------ rendering
    def stuck_after_s(self) -> float:
        try:
            return float(self.stuck_min.value) * 60.0
        except (TypeError, ValueError):
            return DEFAULT_STUCK_MIN * 60.0

    def idle_after_s(self) -> float:
        try:
            return float(self.idle_min.value) * 60.0
        except (TypeError, ValueError):
            return DEFAULT_IDLE_MIN * 60.0

    def _threshold_changed(self, key: str, widget: viser.GuiNumberHandle[float]) -> None:
        """A threshold typed: kept in the gradebook (it outlasts a restart), then the table."""
        keep_minutes(self.control.gradebook.settings, key, float(widget.value))
        self.render()

    def render(self, board: ClassBoard | None = None, connected: Collection[str] | None = None) -> None:
        """Show the class (``board`` and ``connected``: read now when not given)."""
        board = self.control.board() if board is None else board
        connected = set(self.control.connected_names()) if connected is None else connected
        now = datetime.now(timezone.utc)
        self.rows = dashboard_rows(board, connected, now, self.stuck_after_s(), self.idle_after_s())
        tr = self.session.translator
        set_content(self.table_html, trainees_html(self.rows, tr=tr))
        set_content(self.runs_html, in_progress_html(open_runs(board, connected, now), tr=tr))
        self._render_chart()
        no_trainee = self.no_trainee
        keep = None if self.chosen() is not None else no_trainee
        set_options(self.trainee, (no_trainee, *dict.fromkeys(r.name for r in self.rows)), keep)   # option text
        results = tuple((t.result_calibration_id, t.position_error_mm, t.grade) for t in board.trainees)
        if results != self._results_shown:       # the gradebook table (all rows: the costly read) on a new result only
            self._results_shown = results
            set_content(self.grades_md, grades_markdown(self.control.grade_rows(), tr=tr))
        set_content(self.rules_md, escape_markdown(rules_words(self.control.rules, tr=tr)))
        for extra in self.class_extras:
            extra.render()

    def _render_chart(self) -> None:
        x, y = chart_points(self.rows)
        n = max(1, len(self.rows))
        top = float(max(1.0, 1.15 * float(y.max()))) * 1.08 if y.size else 1.08    # the top tick inside
        data = (x, y)
        if not all(np.array_equal(a, b) for a, b in zip(self.chart.data, data)) or len(self.chart.data) != 2:
            self.chart.data = data
        scales: dict[str, Scale] = {"x": {"time": False, "range": (0.5, n + 0.5)},
                                     "y": {"range": (0.0, round(top, 2))}}
        if self.chart.scales != scales:
            self.chart.scales = scales

    # ------------------------------------------------------------ actions
    def chosen(self) -> str | None:
        name = str(self.trainee.value)
        return None if name in (NO_TRAINEE, self.no_trainee) or name not in {r.name for r in self.rows} else name

    def _say(self, text: str) -> None:
        set_content(self.action_md, escape_markdown(text))

    def _need_trainee(self) -> str | None:
        name = self.chosen()
        if name is None:
            self._say(self.session.translator.gettext("Choose a trainee first."))
        return name

    def _reset(self, _event: ButtonEvent | None = None) -> None:
        name = self._need_trainee()
        if name is not None:
            self._say(self.control.reset_wizard(name, tr=self.session.translator))

    def _push_one(self, _event: ButtonEvent | None = None) -> None:
        name = self._need_trainee()
        if name is None:
            return
        english = self.words.english
        ex_label, aids_label, auto_label = (english(self.one_exercise), english(self.one_hide_distance),
                                            english(self.one_auto_touch))
        if ex_label not in ONE_EXERCISE or aids_label not in HIDE_DISTANCE or auto_label not in AUTO_TOUCH:
            raise ValueError("Choose the exercise, Hide distance and Auto-touch from their lists.")
        tool = self._tool_key(english(self.one_tool))
        self._say(self.control.push_to(name, ONE_EXERCISE[ex_label], tool, HIDE_DISTANCE[aids_label],
                                       AUTO_TOUCH[auto_label], tr=self.session.translator))

    def _release(self, _event: ButtonEvent | None = None) -> None:
        name = self._need_trainee()
        if name is not None:
            self._say(self.control.release(name, tr=self.session.translator))
            self.render()

    def _replay(self, _event: ButtonEvent | None = None) -> None:
        name = self._need_trainee()
        if name is None:
            return
        replay = self.control.replay(name)
        tr = self.session.translator
        _ = tr.gettext
        if replay is None:
            self._say(_("{name} has no calibration with a touch yet.").format(name=name))
            return
        self.replay_scene.show(replay, tr=tr)
        self.gui.main_panel.set_width(REPLAY_PANEL_PX)
        self.close_replay.visible = True
        set_replay_touches(self.replay_touch, replay, self.replay_scene.touch_shown, tr=self.session.translator)
        err = "" if replay.position_error_mm is None else _(", error {error} mm").format(
            error=f"{replay.position_error_mm:.2f}")
        grade = "" if replay.grade is None else f", {_(GRADE_WORDS.get(replay.grade, replay.grade))}"
        n = len(replay.touches)
        touches = self.session.translator.ngettext("{n} touch", "{n} touches", n).format(n=n)
        self._say(_("Replay of {name}'s calibration {id} ({method}, {status}): {touches}{error}{grade}. "
                    "The robot as it was at the touch chosen in 'Robot at touch'; triads: the flange at each "
                    "touch; lines: the tool to its tip (blue by hand, orange Auto-touch); frames: result and "
                    "true TOOL frame.").format(name=name, id=replay.calibration_id,
                                               method=method_name(replay.method, tr) if replay.method else "-",
                                               status=_(RUN_STATUS_WORDS.get(replay.status, replay.status)), touches=touches,
                                               error=err, grade=grade))

    def _relabel_replay_touches(self) -> None:
        """The "Robot at touch" options in the session's language (the touch on show kept)."""
        tr, replay = self.session.translator, self.replay_scene.shown
        if replay is not None:
            set_replay_touches(self.replay_touch, replay, self.replay_scene.touch_shown, tr=tr)
        else:
            set_options(self.replay_touch, (tr.gettext(NO_TOUCH),), tr.gettext(NO_TOUCH))

    def _close_replay(self, _event: ButtonEvent | None = None) -> None:
        self.replay_scene.clear()
        self.gui.main_panel.set_width(FULL_WIDTH_PX)
        self.close_replay.visible = self.replay_touch.visible = False

    def _tool_key(self, label: str) -> str | None:
        """The tool a tool dropdown's choice names (its English label: :func:`tool_choices`),
        None for "keep"."""
        if label == KEEP:
            return None
        key = tool_choices(self.control.tool_keys).get(label)
        if key is None:
            raise ValueError(f"Unknown tool {label!r}; choose one of {', '.join(self.control.tool_keys)}.")
        return key

    def _push_all(self, _event: ButtonEvent | None = None) -> None:
        english = self.words.english
        exercise = EXERCISES.get(english(self.exercise))
        tool = self._tool_key(english(self.tool))
        label, auto = english(self.hide_distance), english(self.auto_touch)
        if label not in HIDE_DISTANCE:
            raise ValueError(f"Unknown Hide distance choice {label!r}; choose one of {', '.join(HIDE_DISTANCE)}.")
        if auto not in AUTO_TOUCH:
            raise ValueError(f"Unknown Auto-touch choice {auto!r}; choose one of {', '.join(AUTO_TOUCH)}.")
        n = self.control.push_settings(exercise, tool, HIDE_DISTANCE[label], AUTO_TOUCH[auto])
        tr = self.session.translator
        pushed = tr.ngettext("Pushed to {n} trainee.", "Pushed to {n} trainees.", n).format(n=n)
        self.push_md.content = f"{pushed} {rules_words(self.control.rules, tr=tr)}"
        self.render()

    def _download(self, _event: ButtonEvent | None = None) -> None:
        client = client_of(self.session)
        if client is not None:
            client.send_file_download("grades.csv", self.control.grades_csv().encode("utf-8"))

    def _refused(self, filename: str, size_bytes: int) -> None:
        _ = self.session.translator.gettext
        self.session.notify(_("Record not graded"), _("{file}: {size} bytes is more than {limit} bytes; a session "
                                                      "record is far smaller.").format(
            file=filename or _("The file"), size=size_bytes, limit=MAX_RECORD_BYTES), kind="warning")

    async def _on_grade_upload(self, event: UploadEvent) -> None:
        """The record's bytes are parsed, replayed and graded in the server's job pool (off the loop)."""
        if self.session.closed or getattr(event, "client", None) is None or self._grading:
            return
        upload = event.target.value
        name = str(upload.name or "record")
        self._grading = True
        try:
            check_record_size(len(upload.content))
            data, book = bytes(upload.content), self.control.gradebook
            grades = await self.session.loop.run_job(lambda: grade_record(load_and_replay(data), book),
                                                what="a record's grading")
        except (SessionRecordError, JobRefused) as exc:
            tr = self.session.translator
            self.session.notify(tr.gettext("Record not graded"), f"{name}: {error_text(exc, tr)}", kind="warning")
            return
        except Exception as exc:  # never let an upload kill the server
            log.exception("grading the record %r failed", name)
            self.session.notify(self.session.translator.gettext("Internal error"), f"{type(exc).__name__}: {exc}",
                                kind="error")
            return
        finally:
            self._grading = False
        self.session.loop.guard(lambda: setattr(self.grade_md, "content", record_grades_markdown(
            name, grades, tr=self.session.translator)))()


# ---------------------------------------------------------------- the folders
def class_folder(dash: TrainerDashboard) -> None:
    """The stuck and idle thresholds (as kept in the gradebook), the live table and the
    calibrations in progress."""
    gui, settings, words = dash.gui, dash.control.gradebook.settings, dash.words
    with dash.folder(N_("Class")):
        dash.stuck_min = words(gui.add_number("", kept_minutes(settings, STUCK_SETTING), min=MIN_MINUTES,
                                              max=MAX_MINUTES, step=0.5),
                               label=N_("Stuck after (min)"),
                               hint=N_("A trainee with no touch and no new step for this long in a "
                                       "calibration is highlighted (the server's downtime not counted)."))
        dash.idle_min = words(gui.add_number("", kept_minutes(settings, IDLE_SETTING), min=MIN_MINUTES,
                                             max=MAX_MINUTES, step=0.5),
                              label=N_("Idle after (min)"),
                              hint=N_("A trainee who joined and has no calibration in progress or finished, "
                                      "with no step and no touch for this long, is marked idle."))
        dash.table_html = gui.add_html("")
        words(gui.add_markdown(""), content=N_("**Calibrations in progress**"))
        dash.runs_html = gui.add_html("")
    dash.stuck_min.on_update(dash.session.loop.on_loop(_on_threshold(dash, STUCK_SETTING)))
    dash.idle_min.on_update(dash.session.loop.on_loop(_on_threshold(dash, IDLE_SETTING)))


def _on_threshold(dash: TrainerDashboard, key: str) -> Callable[[viser.GuiEvent[viser.GuiNumberHandle[float]]], None]:
    """A threshold's callback: the minutes typed are kept in the gradebook under ``key`` (they
    outlast a restart), then the table is drawn again with them."""
    def changed(event: viser.GuiEvent[viser.GuiNumberHandle[float]]) -> None:
        dash._threshold_changed(key, event.target)
    return changed


CHART_TITLE = N_("Last position error per trainee (mm)")
CHART_X = N_("trainee #")
CHART_Y = N_("position error (mm)")


def label_chart(dash: TrainerDashboard) -> None:
    """The chart's title, series and axis labels in the dashboard's language."""
    _ = dash.session.translator.gettext
    chart = dash.chart
    if chart.title != _(CHART_TITLE):
        chart.title = _(CHART_TITLE)
        x, y = chart.series
        chart.series = ({**x, "label": _(CHART_X)}, {**y, "label": _(CHART_Y)})
        ax, ay = chart.axes or ({}, {})
        chart.axes = ({**ax, "label": _(CHART_X)}, ay)


def chart_folder(dash: TrainerDashboard) -> None:
    """The class's position errors, one mark per trainee."""
    gui = dash.gui
    _ = dash.session.translator.gettext
    with dash.folder(N_("Position errors")):
        dash.chart = gui.add_uplot(
            (np.zeros(0), np.zeros(0)),
            ({"label": _(CHART_X)},
             {"label": _(CHART_Y), "stroke": "#3b6fd6", "width": 0,
              "points": {"show": True, "size": 12, "fill": "#3b6fd6", "stroke": "#1b3f96", "width": 2}}),
            title=_(CHART_TITLE), height=200,
            scales={"x": {"time": False, "range": (0.5, 1.5)}, "y": {"range": (0.0, 1.0)}},
            axes=({"label": _(CHART_X), "incrs": (1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0)}, {"label": "mm"}),
            legend=CHART_LEGEND)


def trainee_folder(dash: TrainerDashboard) -> None:
    """Choose a trainee; reset, push to, release, replay."""
    gui, on_loop, words = dash.gui, dash.session.loop.on_loop, dash.words
    with dash.folder(N_("Trainee")):
        dash.trainee = words(gui.add_dropdown("", (dash.no_trainee,), initial_value=dash.no_trainee),
                             label=N_("Trainee"))
        dash.reset = words(gui.add_button("", color="red"), label=N_("Reset wizard"),
                           hint=N_("Close this trainee's running wizard (kept: they can resume it)."))
        dash.replay_button = words(gui.add_button(""), label=N_("Replay in 3D"),
                                   hint=N_("Draw this trainee's last calibration from the gradebook."))
        dash.close_replay = words(gui.add_button("", visible=False), label=N_("Close replay"))
        no_touch = dash.session.translator.gettext(NO_TOUCH)
        dash.replay_touch = words(gui.add_dropdown("", (no_touch,), initial_value=no_touch, visible=False),
                                  label=N_("Robot at touch"),
                                  hint=N_("The robot of the replay, posed as it was at that touch."))
        dash.one_exercise = words.dropdown(gui, N_("Exercise for this trainee"), tuple(ONE_EXERCISE))
        dash.one_tool = words.dropdown(gui, N_("Tool for this trainee"), (KEEP, *tool_choices(dash.control.tool_keys)))
        dash.one_hide_distance = words.dropdown(gui, N_("Hide distance for this trainee"), tuple(HIDE_DISTANCE))
        dash.one_auto_touch = words.dropdown(gui, N_("Auto-touch for this trainee"), tuple(AUTO_TOUCH))
        dash.push_one = words(gui.add_button("", color="blue"), label=N_("Push to this trainee"))
        dash.release = words(gui.add_button(""), label=N_("Release name"),
                             hint=N_("A name stays with the browser it joined from. Release it so that the "
                                     "trainee can join from another browser, or to send a browser that took "
                                     "it back to the welcome window."))
        dash.action_md = gui.add_markdown("")
    dash.reset.on_click(on_loop(dash._reset))
    dash.replay_button.on_click(on_loop(dash._replay))
    dash.close_replay.on_click(on_loop(dash._close_replay))
    dash.replay_touch.on_update(on_loop(lambda _e: pose_replay_touch(dash.replay_scene, dash.replay_touch)))
    dash.push_one.on_click(on_loop(dash._push_one))
    dash.release.on_click(on_loop(dash._release))


def exercise_folder(dash: TrainerDashboard) -> None:
    """The class's settings, pushed to every trainee."""
    gui, control, words = dash.gui, dash.control, dash.words
    with dash.folder(N_("Exercise")):
        current = next((label for label, ex in EXERCISES.items() if ex == control.exercise), "Free practice")
        dash.exercise = words.dropdown(gui, N_("Exercise"), tuple(EXERCISES), value=current)
        dash.tool = words.dropdown(gui, N_("Tool for all"), (KEEP, *tool_choices(control.tool_keys)))
        dash.hide_distance = words.dropdown(
            gui, N_("Hide distance for all"), tuple(HIDE_DISTANCE),
            hint=N_("on: trainees judge the touch by eye (no distance, no Δ line, no close-up, no stop "
                    "at the tip); locked: they cannot show it (the default in an exercise); off: shown."))
        dash.auto_touch = words.dropdown(
            gui, N_("Auto-touch for all"), tuple(AUTO_TOUCH),
            hint=N_("allowed: trainees may let the robot touch for them (off by default in an exercise)."))
        dash.push = words(gui.add_button("", color="blue"), label=N_("Push to all trainees"))
        dash.push_md = gui.add_markdown("")
        dash.class_extras.append(build_exercise_controls(gui, control, dash.session))   # "Exercise brief"
    dash.push.on_click(dash.session.loop.on_loop(dash._push_all))


def message_folder(dash: TrainerDashboard) -> None:
    """The messages to all or one trainee (``views.trainer_messages``: its own folder)."""
    dash.class_extras.append(build_message_controls(dash.gui, dash.control, dash.session))


def gradebook_folder(dash: TrainerDashboard) -> None:
    """The finished calibrations, the CSV, grading an uploaded record."""
    gui, words = dash.gui, dash.words
    with dash.folder(N_("Gradebook")):
        dash.grades_md = gui.add_markdown("")
        dash.download = words(gui.add_button(""), label=N_("Download grades (CSV)"))
        dash.grade_upload = words(gui.add_upload_button("", mime_type="application/json"),
                                  label=N_("Grade a trainee's record (JSON)"),
                                  hint=N_("A trainee's exported session: each calibration is replayed and graded "
                                          "against the truth this gradebook keeps (by its record id)."))
        dash.grade_md = gui.add_markdown("")
    dash.download.on_click(dash.session.loop.on_loop(dash._download))
    dash.grade_upload.on_upload(dash._on_grade_upload)
    limit_upload_size(dash.grade_upload, MAX_RECORD_BYTES, dash._refused)


def tool_library_folder(dash: TrainerDashboard) -> None:
    """The shared tool library as the pendant's Tool tab shows it (``views.tool_panel``), with the
    trainer's rights: rename and delete any trainee's slot (``session.views["tools"]``)."""
    with dash.folder(N_("Tool library (trainer)"), expand_by_default=False):
        dash.tool_panel = ToolPanel(dash.session)
    dash.session.views["tools"] = dash.tool_panel


FOLDERS: list[Callable[[TrainerDashboard], None]] = [class_folder, chart_folder, trainee_folder, exercise_folder,
                                                     language_folder, message_folder, gradebook_folder,
                                                     tool_library_folder]
"""The dashboard's folders, top to bottom, each built by one function."""


def build_dashboard(session: Session, control: DashboardControl) -> TrainerDashboard:
    """Lay the dashboard out in ``session``'s GUI (:data:`FOLDERS`) and show the class; the
    dashboard browser's own Language selector under its title (it changes this browser only)."""
    dash = TrainerDashboard(session, control)
    gui = dash.gui
    with session.lock, target_of(session).atomic():
        dash.words(gui.add_markdown(""), content=N_("### Trainer dashboard"))
        dash.language = LanguageSelector(session)
        dash.rules_md = gui.add_markdown("")
        for build in FOLDERS:
            build(dash)
        dash.render()
        session.subscribe(dash.on_change)
    return dash


def open_dashboard(session: Session, control: DashboardControl) -> TrainerDashboard:
    """Turn ``session``'s browser into the trainer's dashboard: its pendant taken down (views,
    GUI, robot scene), the panel over the whole window, then :func:`build_dashboard`."""
    target = target_of(session)
    with session.lock, target.atomic():
        session.drop_views()
        target.gui.reset()
        target.scene.reset()
        target.gui.set_panel_label(session.translator.gettext(PANEL_LABEL))
        target.gui.main_panel.set_width(FULL_WIDTH_PX)
    return build_dashboard(session, control)
