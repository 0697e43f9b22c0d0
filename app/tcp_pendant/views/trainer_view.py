"""The trainer view: the class's live table, the gradebook, a CSV download, settings pushed to
every trainee, and releasing a name.

"Release a name" lists the names a browser holds (``ClassRoom.held_names``); **Release name**
forgets that name's browser key and sends a browser connected under it back to the welcome
window (``ClassRoom.release``), so the trainee can join from another browser with the same
records (a laptop that died), or the name is taken back from a browser that had no right to it.

Built in a browser's own GUI once its "Trainer token" was right (``views.identity``); the
server (``PendantApp``) re-renders every open trainer view when a trainee's row changes. Every
text a trainee typed (names) goes through ``escape_markdown``; callbacks through
``Session.on_loop``.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Protocol

from tcp_pendant.classroom.gradebook import GradeRow, Gradebook
from tcp_pendant.classroom.grading import RecordGrade, grade_record
from tcp_pendant.classroom.recorder import TraineeStatus
from tcp_pendant.pendant.exercise_rules import ExerciseRules
from tcp_pendant.session import Session
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.upload_guard import limit_upload_size
from tcp_pendant.views.trainer_exercise import BriefControl, build_exercise_controls
from tcp_pendant.views.trainer_messages import MessageControl, build_message_controls
from tcp_pendant.wizards.session_record import MAX_RECORD_BYTES, SessionRecordError, check_record_size, load_and_replay
from tcp_pendant.views.gui_util import ButtonEvent, UploadEvent, set_options, target_of

log = logging.getLogger(__name__)
_GRADE_WORKER = ThreadPoolExecutor(max_workers=1, thread_name_prefix="record-grading")
"""Parses, replays and grades uploaded records off viser's event loop, one at a time."""

__all__ = ["AUTO_TOUCH", "EXERCISES", "HIDE_DISTANCE", "ClassControl", "TrainerView", "grades_markdown", "trainees_markdown"]

EXERCISES: dict[str, str | None] = {"Free practice": None, "Mystery tool": "mystery"}
"""Exercise choices of the trainer view: label -> exercise id."""
HIDE_DISTANCE: dict[str, str | None] = {"(keep)": None, "on, locked": "locked", "on": "hidden", "off": "shown"}
"""'Hide distance' choices of the trainer view: label -> the distance aids pushed
(``pendant.exercise_rules``; None: keep). "on, locked": the trainee cannot show them (the
default in an exercise); "on": hidden, the trainee may show them; "off": shown."""
AUTO_TOUCH: dict[str, bool | None] = {"(keep)": None, "off": False, "allowed": True}
"""'Auto-touch' choices of the trainer view (None: keep; an exercise starts with it off)."""
NO_NAME = "(choose a name) "
"""The first choice of "Release a name" (releases nothing; its trailing space keeps it apart from every
stored name, which is stripped)."""
MAX_GRADE_ROWS = 50
"""The gradebook table shows the newest rows only (the CSV has them all)."""


class ClassControl(BriefControl, MessageControl, Protocol):
    """What the trainer view needs of the server."""

    @property
    def tool_keys(self) -> Sequence[str]: ...

    gradebook: Gradebook
    exercise: str | None

    def trainee_statuses(self) -> list[TraineeStatus]: ...

    def grade_rows(self) -> list[GradeRow]: ...

    def grades_csv(self) -> str: ...

    @property
    def rules(self) -> ExerciseRules: ...

    def push_settings(self, exercise: str | None, tool_key: str | None,
                      hide_distance: bool | str | None = None, auto_touch: bool | None = None) -> int: ...

    def held_names(self) -> list[str]: ...

    def release(self, name: str) -> str: ...


def rules_words(rules: ExerciseRules) -> str:
    """The class's rules in one line for the trainer (our own words)."""
    aids = "locked off" if rules.distance_locked else "trainee's choice"
    auto = "allowed" if rules.auto_touch_allowed else "off"
    where = f"Exercise {rules.exercise}" if rules.in_exercise else "Free practice"
    return f"{where}: distance aids {aids}, Auto-touch {auto}."

    def held_names(self) -> list[str]: ...

    def release(self, name: str) -> str: ...


def _cell(text: str) -> str:
    return escape_markdown(text) if text else "-"      # escapes | too: a cell stays a cell


def trainees_markdown(rows: Sequence[TraineeStatus]) -> str:
    """The live table of trainees (markdown, every text escaped)."""
    if not rows:
        return "*No trainee has given a name yet.*"
    lines = ["| Trainee | On | Method: step | Touches | Crashes | Last TCP mm | Grade |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        doing = f"{r.method}: {r.step}" if r.method else ""
        lines.append(f"| {_cell(r.name)} | {'yes' if r.connected else 'no'} | {_cell(doing)} | "
                     f"{r.touches} | {r.crashes} | {_cell(r.last_result)} | {_cell(r.grade)} |")
    return "\n".join(lines)


def grades_markdown(rows: Sequence[GradeRow]) -> str:
    """The gradebook's finished calibrations (newest ``MAX_GRADE_ROWS``), markdown, escaped."""
    if not rows:
        return "*No calibration finished yet.*"
    shown = list(rows)[-MAX_GRADE_ROWS:]
    lines = ["| # | Trainee | Method | Touches (hand/auto) | Crashes | Pos. err. mm | Grade |",
             "|---|---|---|---|---|---|---|"]
    for r in shown:
        err = "-" if r.position_error_mm is None else f"{r.position_error_mm:.2f}"
        lines.append(f"| {r.calibration_id} | {_cell(r.trainee)} | {_cell(r.method)} | "
                     f"{r.touches} ({r.hand}/{r.auto}) | {r.crashes} | {err} | {_cell(r.grade or '')} |")
    if len(rows) > len(shown):
        lines.append(f"\n*{len(rows) - len(shown)} older rows in the CSV.*")
    return "\n".join(lines)


def record_grades_markdown(name: str, grades: Sequence[RecordGrade]) -> str:
    """The grades of an uploaded record (markdown; the file name escaped)."""
    lines = [f"**{escape_markdown(name)}**", "",
             "| # | Record id | Trainee | Method | Pos. err. mm | Grade | Check |", "|---|---|---|---|---|---|---|"]
    for g in grades:
        err = "-" if g.position_error_mm is None else f"{g.position_error_mm:.3f}"
        lines.append(f"| {g.index + 1} | {g.record_id if g.record_id is not None else '-'} | {_cell(g.trainee)} | "
                     f"{_cell(g.method)} | {err} | {_cell(g.grade or '')} | {_cell(g.message)} |")
    if not grades:
        lines.append("| - | - | - | - | - | - | the record holds no calibration |")
    return "\n".join(lines)


class TrainerView:
    """The trainer's panel in one browser (see the module docstring).

    Attributes:
        trainees_md, grades_md, download, exercise, tool, hide_distance, auto_touch, push: the
            widgets (for tests).
    """

    def __init__(self, session: Session, control: ClassControl) -> None:
        self.session = session
        self.control = control
        gui = target_of(session).gui
        self.folder = gui.add_folder("Trainer view", order=-900.0)
        with self.folder:
            gui.add_markdown("**Trainees**")
            self.trainees_md = gui.add_markdown("")
            gui.add_markdown("**Gradebook**")
            self.grades_md = gui.add_markdown("")
            self.download = gui.add_button("Download grades (CSV)")
            current = next((label for label, ex in EXERCISES.items() if ex == control.exercise), "Free practice")
            self.exercise = gui.add_dropdown("Exercise", tuple(EXERCISES), initial_value=current)
            tools = ("(keep)", *control.tool_keys)
            self.tool = gui.add_dropdown("Tool for all", tools, initial_value=tools[0])
            self.hide_distance = gui.add_dropdown(
                "Hide distance for all", tuple(HIDE_DISTANCE), initial_value="(keep)",
                hint="on: trainees judge the touch by eye (no distance, no Δ line, no close-up, no stop "
                     "at the tip); locked: they cannot show it (the default in an exercise); off: shown.")
            self.auto_touch = gui.add_dropdown(
                "Auto-touch for all", tuple(AUTO_TOUCH), initial_value="(keep)",
                hint="allowed: trainees may let the robot touch for them (off by default in an exercise).")
            self.push = gui.add_button("Push to all trainees", color="blue")
            self.push_md = gui.add_markdown("")
            self.release_name = gui.add_dropdown(
                "Release a name", (NO_NAME,), initial_value=NO_NAME,
                hint="A name stays with the browser it joined from. Release it so that the trainee can "
                     "join from another browser, or to send a browser that took it back to the welcome window.")
            self.release = gui.add_button("Release name")
            self.release_md = gui.add_markdown("")
            self.grade_upload = gui.add_upload_button(
                "Grade a trainee's record (JSON)", mime_type="application/json",
                hint="A trainee's exported session: each calibration is replayed and graded against "
                     "the truth this gradebook keeps (by its record id).")
            self.grade_md = gui.add_markdown("")
            self.class_extras = (build_exercise_controls(gui, control, session), build_message_controls(gui, control, session))
        self._grading = False
        self.grade_upload.on_upload(self._on_grade_upload)
        limit_upload_size(self.grade_upload, MAX_RECORD_BYTES, self._refused)
        self.download.on_click(session.on_loop(self._download))
        self.push.on_click(session.on_loop(self._push))
        self.release.on_click(session.on_loop(self._release))
        self.render()

    def render(self) -> None:
        """Re-read the class and the gradebook."""
        self.trainees_md.content = trainees_markdown(self.control.trainee_statuses())
        self.grades_md.content = grades_markdown(self.control.grade_rows())
        set_options(self.release_name, (NO_NAME, *self.control.held_names()))   # option text, not markdown
        for extra in self.class_extras:
            extra.render()

    def _release(self, _event: ButtonEvent | None = None) -> None:
        name = str(self.release_name.value)
        if name == NO_NAME or name not in self.control.held_names():
            self.release_md.content = "Choose the name to release first."
            return
        self.release_md.content = escape_markdown(self.control.release(name))
        self.render()

    def _download(self, _event: ButtonEvent | None = None) -> None:
        client = self.session.client
        if client is not None:
            client.send_file_download("grades.csv", self.control.grades_csv().encode("utf-8"))

    def _refused(self, filename: str, size_bytes: int) -> None:
        self.session.notify("Record not graded", f"{filename or 'The file'}: {size_bytes} bytes is more than "
                            f"{MAX_RECORD_BYTES} bytes; a session record is far smaller.", kind="warning")

    async def _on_grade_upload(self, event: UploadEvent) -> None:
        """The record's bytes are parsed, replayed and graded in ``_GRADE_WORKER`` (off the loop)."""
        if self.session.closed or getattr(event, "client", None) is None or self._grading:
            return
        upload = event.target.value
        name = str(upload.name or "record")
        self._grading = True
        try:
            check_record_size(len(upload.content))
            grades = await asyncio.get_running_loop().run_in_executor(
                _GRADE_WORKER, lambda: grade_record(load_and_replay(bytes(upload.content)), self.control.gradebook))
        except SessionRecordError as exc:
            self.session.notify("Record not graded", f"{name}: {exc}", kind="warning")
            return
        except Exception as exc:  # never let an upload kill the server
            log.exception("grading the record %r failed", name)
            self.session.notify("Internal error", f"{type(exc).__name__}: {exc}", kind="error")
            return
        finally:
            self._grading = False
        self.session.guard(lambda: setattr(self.grade_md, "content", record_grades_markdown(name, grades)))()

    def _push(self, _event: ButtonEvent | None = None) -> None:
        exercise = EXERCISES.get(str(self.exercise.value))
        tool = None if self.tool.value == "(keep)" else str(self.tool.value)
        if tool is not None and tool not in self.control.tool_keys:
            raise ValueError(f"Unknown tool {tool!r}; choose one of {', '.join(self.control.tool_keys)}.")
        label = str(self.hide_distance.value)
        if label not in HIDE_DISTANCE:
            raise ValueError(f"Unknown Hide distance choice {label!r}; choose one of {', '.join(HIDE_DISTANCE)}.")
        auto = str(self.auto_touch.value)
        if auto not in AUTO_TOUCH:
            raise ValueError(f"Unknown Auto-touch choice {auto!r}; choose one of {', '.join(AUTO_TOUCH)}.")
        n = self.control.push_settings(exercise, tool, HIDE_DISTANCE[label], AUTO_TOUCH[auto])
        self.push_md.content = f"Pushed to {n} trainee{'s' if n != 1 else ''}. {rules_words(self.control.rules)}"
        self.render()
