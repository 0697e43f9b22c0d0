"""The trainer's class-wide pieces, shared by the dashboard (``views.dashboard``): the
choices of the settings pushed to every trainee, the gradebook table, an uploaded record's
grades, and what the dashboard needs of the class room (:class:`ClassControl`).

**Release name** (the dashboard's Trainee folder) forgets the name's browser key and sends a
browser connected under it back to the welcome window (``ClassRoom.release``), so the trainee
can join from another browser with the same records (a laptop that died), or the name is taken
back from a browser that had no right to it.

Every text a trainee typed (names) goes through ``escape_markdown``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from tcp_pendant.classroom.grade_rows import GradeRow
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.grading import RecordGrade
from tcp_pendant.classroom.recorder import TraineeStatus
from tcp_pendant.calibrate.pendant_rules import ExerciseRules
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.views.dashboard_table import grade_word, method_name
from tcp_pendant.views.trainer_exercise import BriefControl
from tcp_pendant.views.trainer_messages import MessageControl

__all__ = ["AUTO_TOUCH", "EXERCISES", "HIDE_DISTANCE", "KEEP", "ClassControl", "grades_markdown",
           "record_grades_markdown", "rules_words"]

KEEP = N_("(keep)")
"""The choice of a pushed setting that keeps each trainee's as it is."""
EXERCISES: dict[str, str | None] = {N_("Free practice"): None, N_("Mystery tool"): "mystery"}
"""Exercise choices of the trainer view: label -> exercise id."""
HIDE_DISTANCE: dict[str, str | None] = {KEEP: None, N_("on, locked"): "locked", N_("on"): "hidden", N_("off"): "shown"}
"""'Hide distance' choices of the trainer view: label -> the distance aids pushed
(``classroom.exercise_rules``; None: keep). "on, locked": the trainee cannot show them (the
default in an exercise); "on": hidden, the trainee may show them; "off": shown."""
AUTO_TOUCH: dict[str, bool | None] = {KEEP: None, N_("off"): False, N_("allowed"): True}
"""'Auto-touch' choices of the trainer view (None: keep; an exercise starts with it off)."""
MAX_GRADE_ROWS = 50
"""The gradebook table shows the newest rows only (the CSV has them all)."""


class ClassControl(BriefControl, MessageControl, Protocol):
    """What the trainer's dashboard needs of the server (the brief's and the message box's
    needs included: ``views.trainer_exercise``, ``views.trainer_messages``)."""

    @property
    def tool_keys(self) -> Sequence[str]: ...

    gradebook: Gradebook

    @property
    def exercise(self) -> str | None: ...

    def trainee_statuses(self) -> list[TraineeStatus]: ...

    def grade_rows(self) -> list[GradeRow]: ...

    def grades_csv(self) -> str: ...

    @property
    def rules(self) -> ExerciseRules: ...

    def push_settings(self, exercise: str | None, tool_key: str | None,
                      hide_distance: bool | str | None = None, auto_touch: bool | None = None) -> int: ...

    def held_names(self) -> list[str]: ...

    def release(self, name: str, *, tr: Translator = ENGLISH) -> str: ...


def rules_words(rules: ExerciseRules, *, tr: Translator = ENGLISH) -> str:
    """The class's rules in one line for the trainer (our own words), in ``tr``'s language."""
    _ = tr.gettext
    aids = _("locked off") if rules.distance_locked else _("trainee's choice")
    auto = _("allowed") if rules.auto_touch_allowed else _("off")
    where = _("Exercise {exercise}").format(exercise=rules.exercise) if rules.in_exercise else _("Free practice")
    return _("{where}: distance aids {aids}, Auto-touch {auto}.").format(where=where, aids=aids, auto=auto)


def _cell(text: str) -> str:
    return escape_markdown(text) if text else "-"      # escapes | too: a cell stays a cell


def grades_markdown(rows: Sequence[GradeRow], *, tr: Translator = ENGLISH) -> str:
    """The gradebook's finished calibrations (newest ``MAX_GRADE_ROWS``), markdown, escaped, in
    ``tr``'s language (the stored method and grade as stored)."""
    _ = tr.gettext
    if not rows:
        return _("*No calibration finished yet.*")
    shown = list(rows)[-MAX_GRADE_ROWS:]
    lines = [_("| # | Trainee | Method | Touches (hand/auto) | Crashes | Pos. err. mm | Grade |"),
             "|---|---|---|---|---|---|---|"]
    for r in shown:
        err = "-" if r.position_error_mm is None else f"{r.position_error_mm:.2f}"
        method = method_name(r.method, tr) if r.method else ""
        lines.append(f"| {r.calibration_id} | {_cell(r.trainee)} | {_cell(method)} | "
                     f"{r.touches} ({r.hand}/{r.auto}) | {r.crashes} | {err} | {_cell(grade_word(r.grade, tr))} |")
    if len(rows) > len(shown):
        older = len(rows) - len(shown)
        lines.append("\n" + tr.ngettext("*{n} older row in the CSV.*", "*{n} older rows in the CSV.*", older).format(n=older))
    return "\n".join(lines)


def record_grades_markdown(name: str, grades: Sequence[RecordGrade], *, tr: Translator = ENGLISH) -> str:
    """The grades of an uploaded record (markdown; the file name escaped), in ``tr``'s language."""
    _ = tr.gettext
    lines = [f"**{escape_markdown(name)}**", "",
             _("| # | Record id | Trainee | Method | Pos. err. mm | Grade | Check |"), "|---|---|---|---|---|---|---|"]
    for g in grades:
        err = "-" if g.position_error_mm is None else f"{g.position_error_mm:.3f}"
        lines.append(f"| {g.index + 1} | {g.record_id if g.record_id is not None else '-'} | {_cell(g.trainee)} | "
                     f"{_cell(method_name(g.method, tr))} | {err} | {_cell(grade_word(g.grade, tr))} | "
                     f"{_cell(g.message)} |")
    if not grades:
        lines.append("| - | - | - | - | - | - | " + _("the record holds no calibration") + " |")
    return "\n".join(lines)
