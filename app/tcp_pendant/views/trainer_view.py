"""The trainer view (issue 11 item 3): the class's live table, the gradebook, a CSV download and
settings pushed to every trainee.

Built in a browser's own GUI once its "Trainer token" was right (``views.identity``); the
server (``PendantApp``) re-renders every open trainer view when a trainee's row changes. Every
text a trainee typed (names) goes through ``escape_markdown``; callbacks through
``Session.on_loop``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

from tcp_pendant.classroom.gradebook import GradeRow
from tcp_pendant.classroom.recorder import TraineeStatus
from tcp_pendant.session import Session
from tcp_pendant.text_escape import escape_markdown

__all__ = ["EXERCISES", "ClassControl", "TrainerView", "grades_markdown", "trainees_markdown"]

EXERCISES: dict[str, str | None] = {"Free practice": None, "Mystery tool": "mystery"}
"""Exercise choices of the trainer view: label -> exercise id."""
MAX_GRADE_ROWS = 50
"""The gradebook table shows the newest rows only (the CSV has them all)."""


class ClassControl(Protocol):
    """What the trainer view needs of the server."""

    tool_keys: Sequence[str]

    def trainee_statuses(self) -> list[TraineeStatus]: ...

    def grade_rows(self) -> list[GradeRow]: ...

    def grades_csv(self) -> str: ...

    def push_settings(self, exercise: str | None, tool_key: str | None) -> int: ...


def _cell(text: str) -> str:
    return escape_markdown(text) if text else "-"      # escapes | too: a cell stays a cell


def trainees_markdown(rows: Sequence[TraineeStatus]) -> str:
    """The live table of trainees (markdown, every text escaped)."""
    if not rows:
        return "*No trainee has given a name yet.*"
    lines = ["| Trainee | Connected | Method | Step | Touches | Crashes | Last result | Grade |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {_cell(r.name)} | {'yes' if r.connected else 'no'} | {_cell(r.method)} | "
                     f"{_cell(r.step)} | {r.touches} | {r.crashes} | {_cell(r.last_result)} | {_cell(r.grade)} |")
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


class TrainerView:
    """The trainer's panel in one browser (see the module docstring).

    Attributes:
        trainees_md, grades_md, download, exercise, tool, push: the widgets (for tests).
    """

    def __init__(self, session: Session, control: ClassControl) -> None:
        self.session = session
        self.control = control
        gui = session.target.gui
        self.folder = gui.add_folder("Trainer view", order=-900.0)
        with self.folder:
            gui.add_markdown("**Trainees**")
            self.trainees_md = gui.add_markdown("")
            gui.add_markdown("**Gradebook**")
            self.grades_md = gui.add_markdown("")
            self.download = gui.add_button("Download grades (CSV)")
            self.exercise = gui.add_dropdown("Exercise", tuple(EXERCISES), initial_value=tuple(EXERCISES)[0])
            tools = ("(keep)", *control.tool_keys)
            self.tool = gui.add_dropdown("Tool for all", tools, initial_value=tools[0])
            self.push = gui.add_button("Push to all trainees", color="blue")
            self.push_md = gui.add_markdown("")
        self.download.on_click(session.on_loop(self._download))
        self.push.on_click(session.on_loop(self._push))
        self.render()

    def render(self) -> None:
        """Re-read the class and the gradebook."""
        self.trainees_md.content = trainees_markdown(self.control.trainee_statuses())
        self.grades_md.content = grades_markdown(self.control.grade_rows())

    def _download(self, _event: Any = None) -> None:
        client = self.session.client
        if client is not None:
            client.send_file_download("grades.csv", self.control.grades_csv().encode("utf-8"))

    def _push(self, _event: Any = None) -> None:
        exercise = EXERCISES.get(str(self.exercise.value))
        tool = None if self.tool.value == "(keep)" else str(self.tool.value)
        if tool is not None and tool not in self.control.tool_keys:
            raise ValueError(f"Unknown tool {tool!r}; choose one of {', '.join(self.control.tool_keys)}.")
        n = self.control.push_settings(exercise, tool)
        self.push_md.content = f"Pushed to {n} trainee{'s' if n != 1 else ''}."
        self.render()
