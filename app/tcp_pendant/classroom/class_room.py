"""The class as the server runs it: names, gradebook recorders, trainer views, the exercise.

:class:`ClassRoom` is the server's classroom state (one per ``PendantApp`` with a gradebook,
per-browser mode). For each new session it shows the "Your name" prompt
(``views.identity``); a name starts a gradebook session and a :class:`TraineeRecorder`
subscribed to the session's change signal (and, in the mystery exercise, mounts the trainee's
mystery tool); a right trainer token builds a :class:`~tcp_pendant.views.trainer_view.TrainerView`
in that browser. Every trainer view re-renders when a trainee's row changes.

In an exercise the trainee sees no truth: the workflow's ``hide_truth`` is set (the result
panel shows no error against the true TOOL frame and no grade, the scene no TRUE triad); the
gradebook keeps them for the trainer. The settings a trainer pushes (exercise, tool, distance
aids, Auto-touch) apply to every named trainee and to those who name themselves later.

Each trainee's pendant follows the class's :class:`~tcp_pendant.pendant.exercise_rules.ExerciseRules`
(``Session.set_rules``): in an exercise the distance aids are hidden and locked and Auto-touch
is off unless the trainer unlocked or allowed them (``class_rules``); a change of exercise goes
back to those defaults unless the same push sets them.

Threads: the session callbacks run on viser's event loop (``Session.on_loop``); connects and
disconnects come from viser's thread pool and hand their trainer-view refresh to the loop
(``hand_to_loop``). The class's own lists are guarded by one lock.
"""

from __future__ import annotations

import logging
import secrets
import threading
from collections.abc import Callable
from typing import Any, cast

from tcp_pendant.classroom.gradebook import Gradebook, GradeRow
from tcp_pendant.classroom.mystery import draw_mystery_tool
from tcp_pendant.classroom.recorder import TraineeRecorder, TraineeStatus
from tcp_pendant.controller import ToolModel
from tcp_pendant.pendant.exercise_rules import DistanceAids, ExerciseRules, class_rules
from tcp_pendant.session import Session, SessionChange

__all__ = ["EXERCISE_IDS", "ClassRoom"]

log = logging.getLogger(__name__)

EXERCISE_IDS = ("mystery",)
"""Exercises a trainer can start (``--exercise``; None: free practice)."""


class ClassRoom:
    """Names, recorders and trainer views of one server (see the module docstring).

    Args:
        gradebook: the class gradebook (opened by the server at start).
        tools: the physical tools by key (the built-in ones).
        trainer_token: the token that opens the trainer view.
        exercise: None (free practice) or "mystery".
        exercise_seed: the seed of the mystery tools.
        hand_to_loop: runs a function on viser's event loop.
    """

    def __init__(self, gradebook: Gradebook, tools: dict[str, ToolModel], *, trainer_token: str,
                 exercise: str | None = None, exercise_seed: int = 0,
                 hand_to_loop: Callable[[Callable[[], None]], None] = lambda fn: fn()) -> None:
        if exercise is not None and exercise not in EXERCISE_IDS:
            raise ValueError(f"Unknown exercise {exercise!r}; use one of {', '.join(EXERCISE_IDS)}.")
        if not trainer_token:
            raise ValueError("The trainer token must not be empty.")
        self.gradebook = gradebook
        self.tools = dict(tools)
        self.tool_keys = tuple(self.tools)
        self.trainer_token = trainer_token
        self.exercise = exercise
        self.exercise_seed = int(exercise_seed)
        self._hand_to_loop = hand_to_loop
        self._lock = threading.Lock()
        self._trainees: dict[int, tuple[Session, TraineeRecorder, str]] = {}   # id(session) -> ...
        self._left: list[TraineeStatus] = []        # rows of trainees who left (connected=False)
        self._trainer_views: dict[int, Any] = {}    # id(session) -> TrainerView
        self.distance_aids: DistanceAids | None = None
        """The distance aids as the trainer last pushed them (None: the exercise's default -
        locked in an exercise, each trainee's own choice in free practice)."""
        self.auto_touch: bool | None = None
        """Auto-touch as the trainer last allowed it (None: the default - off in an exercise)."""

    @property
    def rules(self) -> ExerciseRules:
        """The rules every trainee's pendant follows now."""
        return class_rules(self.exercise, self.distance_aids, self.auto_touch)

    def _apply_rules(self, session: Session, *, aids_too: bool = True) -> None:
        """The class's rules on one trainee's pendant (under its lock), and with ``aids_too``
        its distance aids (else a trainee's own "Hide distance" choice is kept where the rules
        allow it)."""
        rules = self.rules
        aids = self.distance_aids or ("locked" if rules.in_exercise else None)
        if not aids_too:
            aids = "locked" if rules.distance_locked else None
        with session.batch():
            if not rules.distance_locked:
                session.set_rules(rules)            # unlock first: "shown" may then switch it off
            if aids is not None:
                session.set_hide_distance(aids != "shown")
            session.set_rules(rules)

    # ------------------------------------------------------------ sessions
    def attach(self, session: Session) -> Any:
        """Show the "Your name" prompt in a new per-browser session (returns the prompt)."""
        from tcp_pendant.views.identity import IdentityPrompt

        prompt = IdentityPrompt(session, lambda name: self.named(session, name),
                                lambda token: self.open_trainer(session, token))
        session.views["identity"] = prompt
        session.on_close(lambda: self.detach(session))
        return prompt

    def named(self, session: Session, name: str) -> TraineeRecorder:
        """The trainee of ``session`` typed ``name`` (validated): a gradebook session, its
        recorder, and the exercise's tool."""
        with session.lock:
            trainee = self.gradebook.add_trainee(name)
            sid = self.gradebook.start_session(trainee, "per-browser")
            calibrate = session.views.get("calibrate")
            workflow = getattr(calibrate, "workflow", None)
            recorder = TraineeRecorder(self.gradebook, sid, name, session.controller, workflow,
                                       exercise_id=self.exercise)

            def on_change(change: SessionChange) -> None:
                before = recorder.status
                recorder.on_change(change)
                if recorder.status != before:
                    self.refresh_trainers()

            session.subscribe(on_change)
            with self._lock:
                self._trainees[id(session)] = (session, recorder, name)
            self._hide_truth(workflow, self.exercise)
            if self.exercise == "mystery":
                self._mount_mystery(session, recorder, name)
            self._apply_rules(session)
        self.refresh_trainers()
        return recorder

    @staticmethod
    def _hide_truth(workflow: Any | None, exercise: str | None) -> None:
        """In an exercise the trainee's result shows no truth (free practice: training mode's)."""
        if workflow is not None:
            workflow.hide_truth = exercise is not None

    def _mount_mystery(self, session: Session, recorder: TraineeRecorder, name: str) -> None:
        base = self.tools.get("pointer") or next(iter(self.tools.values()))
        tool = draw_mystery_tool(self.exercise_seed, name, base)
        workflow = recorder.workflow
        if workflow is not None:
            workflow.tools[tool.key] = tool          # its label in the wizard's tool-change words
        recorder.exercise_id = "mystery"
        session.mount_tool(tool)

    def detach(self, session: Session) -> None:
        """The session closed (its browser left)."""
        with self._lock:
            entry = self._trainees.get(id(session))
            self._trainer_views.pop(id(session), None)
        if entry is not None:
            try:
                entry[1].disconnected()
            except Exception:
                log.exception("ending the gradebook session of %r failed", entry[2])
            with self._lock:                 # one step: the row is never missing from the table
                self._trainees.pop(id(session), None)
                self._left.append(entry[1].status)
        self._hand_to_loop(self.refresh_trainers)

    # ------------------------------------------------------------ trainer
    def open_trainer(self, session: Session, token: str) -> bool:
        """A browser typed ``token``: if it is the trainer token, build the trainer view there."""
        if not secrets.compare_digest(token.encode("utf-8"), self.trainer_token.encode("utf-8")):
            return False
        from tcp_pendant.views.trainer_view import TrainerView

        with self._lock:
            if id(session) in self._trainer_views:
                return True
        view = TrainerView(session, self)
        session.views["trainer"] = view
        with self._lock:
            self._trainer_views[id(session)] = view
        return True

    def refresh_trainers(self) -> None:
        """Re-render every open trainer view (on viser's event loop)."""
        with self._lock:
            views = list(self._trainer_views.values())
        for view in views:
            try:
                view.session.guard(view.render)()
            except Exception:
                log.exception("trainer view refresh failed")

    def trainee_statuses(self) -> list[TraineeStatus]:
        """Rows of the live table: connected trainees in order of arrival, then those who left."""
        with self._lock:
            return [rec.status for _, rec, _ in self._trainees.values()] + list(self._left)

    def grade_rows(self) -> list[GradeRow]:
        return self.gradebook.grades()

    def grades_csv(self) -> str:
        return self.gradebook.to_csv()

    def push_settings(self, exercise: str | None, tool_key: str | None,
                      hide_distance: bool | str | None = None, auto_touch: bool | None = None) -> int:
        """Set the exercise (None: free practice; "mystery": each trainee gets a mystery tool),
        mount ``tool_key`` (None: keep), set the distance aids (``hide_distance``: "locked",
        "hidden" or "shown"; True means "hidden", False "shown"; None: keep) and allow
        Auto-touch or not (None: keep) on every named trainee's pendant; later trainees get
        them when they name themselves. A new exercise starts from its default rules (module
        docstring) except what this push sets. Returns how many trainees."""
        if exercise is not None and exercise not in EXERCISE_IDS:
            raise ValueError(f"Unknown exercise {exercise!r}; use one of {', '.join(EXERCISE_IDS)}.")
        if tool_key is not None and tool_key not in self.tools:
            raise ValueError(f"Unknown tool {tool_key!r}; use one of {', '.join(self.tools)}.")
        named = {True: "hidden", False: "shown"}[hide_distance] if isinstance(hide_distance, bool) else hide_distance
        class_rules(exercise, named, auto_touch)        # type: ignore[arg-type]  # ValueError: unknown aids
        aids = cast("DistanceAids | None", named)
        new_exercise = exercise != self.exercise
        if new_exercise:
            self.distance_aids = self.auto_touch = None
        self.exercise = exercise
        if aids is not None:
            self.distance_aids = aids
        if auto_touch is not None:
            self.auto_touch = bool(auto_touch)
        with self._lock:
            trainees = list(self._trainees.values())
        for session, recorder, name in trainees:
            def apply(session: Session = session, recorder: TraineeRecorder = recorder, name: str = name) -> None:
                with session.batch():
                    recorder.exercise_id = exercise
                    self._hide_truth(recorder.workflow, exercise)
                    if exercise == "mystery":
                        self._mount_mystery(session, recorder, name)
                    elif tool_key is not None:
                        session.mount_tool(self.tools[tool_key])
                    self._apply_rules(session, aids_too=new_exercise or aids is not None)
                    session.changed(wizard=True)      # the result panel shows or hides the truth
            session.guard(apply)()
        return len(trainees)
