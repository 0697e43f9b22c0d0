"""The class's settings on one trainee's pendant, through that session's own commands (no viser).

Each function changes one session only (the caller runs it under that session's guard, on
viser's loop): the class's rules and distance aids (:func:`apply_rules`), the trainee's mystery
tool (:func:`mount_mystery`), a push to every trainee (:func:`apply_class_push`) or to this one
(:func:`apply_push_to`), and the trainer's reset of the running wizard (:func:`reset_wizard`).
"""

from __future__ import annotations

from tcp_pendant.classroom.exercise_rules import DistanceAids
from tcp_pendant.classroom.mystery import draw_mystery_tool
from tcp_pendant.classroom.push_words import PUSH_TITLE, push_words
from tcp_pendant.classroom.recorder import TraineeRecorder
from tcp_pendant.calibrate.pendant_rules import ExerciseRules
from tcp_pendant.controller import ToolModel
from tcp_pendant.session import Session

__all__ = ["apply_class_push", "apply_push_to", "apply_rules", "mount_mystery", "reset_wizard"]


def apply_rules(session: Session, rules: ExerciseRules, distance_aids: DistanceAids | None, *,
                aids_too: bool = True) -> None:
    """The class's ``rules`` on the pendant, and with ``aids_too`` the distance aids the trainer
    pushed (``distance_aids``; None: the exercise's default) - else a trainee's own "Hide
    distance" choice is kept where the rules allow it."""
    aids = distance_aids or ("locked" if rules.in_exercise else None)
    if not aids_too:
        aids = "locked" if rules.distance_locked else None
    with session.batch():
        if not rules.distance_locked:
            session.set_rules(rules)            # unlock first: "shown" may then switch it off
        if aids is not None:
            session.set_hide_distance(aids != "shown")
        session.set_rules(rules)


def mount_mystery(session: Session, recorder: TraineeRecorder, name: str, seed: int,
                  tools: dict[str, ToolModel]) -> None:
    """Mount ``name``'s mystery tool (drawn from the class's ``seed``, made from the pointer or
    the first of ``tools``) and lock "Mounted tool" to it."""
    base = tools.get("pointer") or next(iter(tools.values()))
    tool = draw_mystery_tool(seed, name, base)
    recorder.exercise_id = "mystery"
    session.wizard_commands.add_physical_tool(tool)              # its label in the wizard's tool-change words
    session.tools.set_exercise_tool(tool)              # mounted, and "Mounted tool" locked to it


def apply_class_push(session: Session, recorder: TraineeRecorder, name: str, exercise: str | None,
                     tool_key: str | None, rules: ExerciseRules, distance_aids: DistanceAids | None, *,
                     aids_too: bool, seed: int | None, tools: dict[str, ToolModel]) -> None:
    """A push to every trainee (``ClassRoom.push_settings``) on ``name``'s pendant: the
    exercise (the mystery one: their mystery tool from the class's ``seed``), the tool to mount
    (``tool_key`` of ``tools``; None: keep; free practice only), the rules and, with
    ``aids_too``, the aids."""
    with session.batch():
        if not _set_exercise(session, recorder, name, exercise, seed, tools) and tool_key is not None:
            session.tools.mount_tool(tools[tool_key])
        apply_rules(session, rules, distance_aids, aids_too=aids_too)
        session.changed(wizard=True)      # the result panel shows or hides the truth


def _set_exercise(session: Session, recorder: TraineeRecorder, name: str, exercise: str | None,
                  seed: int | None, tools: dict[str, ToolModel]) -> bool:
    """Put ``name``'s pendant in ``exercise`` (None: free practice): recorded as the exercise, the
    truth hidden in one, the mystery tool from ``seed`` mounted and locked, or the lock lifted.
    True: the mystery tool was mounted (no other tool may be)."""
    recorder.exercise_id = exercise
    session.wizard_commands.set_hide_truth(exercise is not None)
    if exercise == "mystery" and seed is not None:
        mount_mystery(session, recorder, name, seed, tools)
        return True
    session.tools.set_exercise_tool(None)         # free practice: the trainee swaps tools again
    return False


def apply_push_to(session: Session, recorder: TraineeRecorder, name: str, exercise: str | None,
                  tool_key: str | None, rules: ExerciseRules, hide_distance: str | None, *,
                  sets_exercise: bool, seed: int | None, tools: dict[str, ToolModel],
                  auto_touch: bool | None = None) -> None:
    """A push to the one trainee ``name`` (``ClassRoom.push_to``): the ``exercise`` in force
    (set on the pendant when the push ``sets_exercise``; the mystery one: their mystery tool
    from the class's ``seed``), ``tool_key`` (None: keep; not with the mystery exercise), the
    ``rules`` and the distance aids ``hide_distance`` (None: keep; a new exercise hides them).
    The trainee is told in words what changed (``push_words``; ``auto_touch`` as pushed, None:
    not changed)."""
    with session.batch():
        if sets_exercise:
            _set_exercise(session, recorder, name, exercise, seed, tools)
        if tool_key is not None and exercise != "mystery":
            session.tools.mount_tool(tools[tool_key])
        if not rules.distance_locked:
            session.set_rules(rules)
        if hide_distance is not None:
            session.set_hide_distance(hide_distance != "shown")
        elif sets_exercise and rules.in_exercise:
            session.set_hide_distance(True)
        session.set_rules(rules)
        session.changed(wizard=True)
    tr = session.translator
    label = None if tool_key is None else tools[tool_key].label
    tool_name = tr.gettext(label) if label else label       # a built-in tool's label may be a msgid
    session.notify(tr.gettext(PUSH_TITLE), push_words(exercise if sets_exercise else False, tool_name,
                                                      hide_distance, auto_touch, tr=tr), kind="warning")


def reset_wizard(session: Session) -> None:
    """The trainer's reset: cancel the running wizard (kept, resumable) and tell the trainee."""
    if session.workflow.is_open:
        session.wizard_commands.cancel()
        _ = session.translator.gettext
        session.notify(_("The trainer reset your calibration"),
                       _("Your trainer closed the wizard; start it again (your touches are kept: "
                         "Resume brings them back)."), kind="warning")
