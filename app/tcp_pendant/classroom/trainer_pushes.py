"""The trainer's pushes: settings and a brief to every trainee, settings or a reset to one (no viser).

:class:`TrainerPushes` applies each push to this server process's seated trainees, through their
own sessions (``classroom.trainee_settings``), and keeps it in the gradebook in order
(``Gradebook.pushes``) so every other process of the class applies it at its next beat
(:meth:`TrainerPushes.apply_remote`). A push to every trainee also sets the class's
:class:`~tcp_pendant.classroom.exercise_setup.ExerciseSetup`, which later trainees get when they
name themselves and a restart reads back. A push to one trainee connected on another process is
forwarded there.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Callable, Sequence
from typing import Any, cast

from tcp_pendant.classroom.class_language import apply_language, check_language, keep_language, language_name
from tcp_pendant.classroom.exercise_rules import DistanceAids, class_rules
from tcp_pendant.classroom.exercise_setup import ExerciseSetup, check_exercise
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.heartbeat import Heartbeat
from tcp_pendant.classroom.roster import Roster
from tcp_pendant.classroom.trainee_settings import apply_class_push, apply_push_to, reset_wizard
from tcp_pendant.controller import ToolModel
from tcp_pendant.session import Session
from tcp_pendant.translation import ENGLISH, Translator

__all__ = ["TrainerPushes"]

log = logging.getLogger(__name__)


class TrainerPushes:
    """The trainer's pushes on this process (module docstring).

    Args:
        gradebook: the class gradebook (its ``pushes``).
        setup: what the trainer set for the class.
        roster: this process's seats.
        heartbeat: this process's presence (its ``holder``, who is on another process).
        tools: the physical tools a push may mount, by key.
        seed: the class's exercise seed, read when a mystery tool is drawn.
        hand_to_loop: runs a function on viser's event loop.
        is_trainer: True for a session that shows a trainer's dashboard (a language push skips it).
    """

    def __init__(self, gradebook: Gradebook, setup: ExerciseSetup, roster: Roster, heartbeat: Heartbeat, *,
                 tools: dict[str, ToolModel], seed: Callable[[], int],
                 hand_to_loop: Callable[[Callable[[], None]], None],
                 is_trainer: Callable[[Session], bool] = lambda _session: False) -> None:
        self._gradebook, self._setup, self._roster, self._heartbeat = gradebook, setup, roster, heartbeat
        self._tools, self._seed, self._hand_to_loop = tools, seed, hand_to_loop
        self._is_trainer = is_trainer

    def _forward(self, push: dict[str, Any]) -> None:
        self._gradebook.pushes.add({"holder": self._heartbeat.holder, **push})

    def settings(self, exercise: str | None, tool_key: str | None, hide_distance: bool | str | None,
                 auto_touch: bool | None, *, keep: bool) -> int:
        """``ClassRoom.push_settings``; returns how many trainees of this process."""
        setup = self._setup
        aids, new_exercise = setup.push(exercise, tool_key, hide_distance, auto_touch)
        if keep:
            setup.keep(tool_key)
            self._forward({"kind": "settings", "exercise": exercise, "tool_key": tool_key,
                           "hide_distance": aids, "auto_touch": auto_touch})
        seats = self._roster.seats()
        seed = self._seed() if exercise == "mystery" and seats else None
        for seat in seats:
            seat.session.loop.guard(apply_class_push)(seat.session, seat.recorder, seat.name, exercise, tool_key,
                                                 setup.rules, setup.distance_aids,
                                                 aids_too=new_exercise or aids is not None, seed=seed,
                                                 tools=self._tools)
        return len(seats)

    def brief(self, instructions: str, allowed_methods: Sequence[str] | str | None, min_touches: int, *,
              keep: bool) -> int:
        """``ClassRoom.push_brief``; returns how many trainees of this process.

        Raises:
            ValueError: instructions too long, an unknown method, a bad minimum (nothing is set).
        """
        setup = self._setup
        setup.set_brief(instructions, allowed_methods, min_touches)
        if keep:
            setup.keep(None, brief_only=True)
            methods = setup.allowed_methods
            self._forward({"kind": "brief", "instructions": setup.instructions,
                           "allowed_methods": None if methods is None else list(methods),
                           "min_touches": setup.min_touches})
        rules = setup.rules
        seats = self._roster.seats()
        for seat in seats:
            seat.session.loop.guard(seat.session.set_rules)(rules)
        return len(seats)

    def reset(self, name: str, *, forward: bool, tr: Translator = ENGLISH) -> str:
        """``ClassRoom.reset_wizard``; returns what happened, in words for the trainer (in ``tr``'s
        language)."""
        _ = tr.gettext
        seat = self._roster.by_name(name) if isinstance(name, str) else None
        if seat is None and forward and self._heartbeat.on_another_process(name):
            self._forward({"kind": "reset", "name": name})
            return _("Reset {name}'s running wizard (on another server process of the class).").format(name=name)
        if seat is None:
            return _("{name} is not connected: there is no running wizard to reset.").format(name=name)
        session = seat.session
        if not session.workflow.is_open:
            return _("{name} has no wizard running.").format(name=name)
        # after the trainer's callback: one session's lock at a time
        self._hand_to_loop(session.loop.guard(lambda: reset_wizard(session)))
        return _("Reset {name}'s running wizard.").format(name=name)

    def to_one(self, name: str, exercise: str | None | bool, tool_key: str | None, hide_distance: str | None,
               auto_touch: bool | None, *, forward: bool, tr: Translator = ENGLISH) -> str:
        """``ClassRoom.push_to``; returns what happened, in words for the trainer (in ``tr``'s
        language).

        Raises:
            ValueError: an unknown exercise or tool.
        """
        if exercise is not False:
            check_exercise(exercise)
        if tool_key is not None and tool_key not in self._tools:
            raise ValueError(f"Unknown tool {tool_key!r}; use one of {', '.join(self._tools)}.")
        seat = self._roster.by_name(name) if isinstance(name, str) else None
        if seat is None and forward and self._heartbeat.on_another_process(name):
            self._forward({"kind": "push_to", "name": name, "exercise": exercise, "tool_key": tool_key,
                           "hide_distance": hide_distance, "auto_touch": auto_touch})
            return tr.gettext("Pushed to {name} (on another server process of the class).").format(name=name)
        if seat is None:
            return tr.gettext("{name} is not connected: nothing pushed.").format(name=name)
        setup = self._setup
        ex = setup.exercise if exercise is False else cast("str | None", exercise)
        rules = class_rules(ex, cast("DistanceAids | None", hide_distance) or setup.distance_aids,
                            setup.auto_touch if auto_touch is None else bool(auto_touch))
        seed = self._seed() if ex == "mystery" and exercise is not False else None
        self._hand_to_loop(seat.session.loop.guard(lambda: apply_push_to(
            seat.session, seat.recorder, seat.name, ex, tool_key, rules, hide_distance,
            sets_exercise=exercise is not False, seed=seed, tools=self._tools, auto_touch=auto_touch)))
        return tr.gettext("Pushed to {name}.").format(name=seat.name)

    def language(self, language: str, *, keep: bool) -> int:
        """``ClassRoom.push_language``: ``language`` on every trainee's pendant of this process
        (named, or still at the welcome window; never a trainer's dashboard),
        each told in it; with ``keep`` kept as the class's (later browsers start in it) and
        forwarded to the other processes. Returns how many named trainees of this process.

        Raises:
            ValueError: an unknown code (nothing is set).
        """
        check_language(language)
        if keep:
            keep_language(self._gradebook.settings, language)
            self._forward({"kind": "language", "language": language})
        seats = self._roster.seats()
        for session in [seat.session for seat in seats] + self._roster.unnamed():
            if not self._is_trainer(session):
                self._hand_to_loop(session.loop.guard(functools.partial(apply_language, session, language)))
        return len(seats)

    def language_to(self, name: str, language: str, *, forward: bool, tr: Translator = ENGLISH) -> str:
        """``ClassRoom.push_language_to``; returns what happened, in words for the trainer (in
        ``tr``'s language).

        Raises:
            ValueError: an unknown code.
        """
        check_language(language)
        seat = self._roster.by_name(name) if isinstance(name, str) else None
        if seat is None and forward and self._heartbeat.on_another_process(name):
            self._forward({"kind": "language_to", "name": name, "language": language})
            return tr.gettext("{language} pushed to {name} (on another server process of the class).").format(
                language=language_name(language), name=name)
        if seat is None:
            return tr.gettext("{name} is not connected: nothing pushed.").format(name=name)
        session = seat.session
        self._hand_to_loop(session.loop.guard(lambda: apply_language(session, language)))
        return tr.gettext("{language} pushed to {name}.").format(language=language_name(language), name=seat.name)

    def apply_remote(self, push: dict[str, Any]) -> None:
        """A push the trainer made on another server process of the class: settings, a brief,
        a reset or a push to one trainee (``kind``), applied to this process's trainees."""
        kind = push.get("kind", "settings")
        try:
            if kind == "settings":
                self.settings(push.get("exercise"), push.get("tool_key"), push.get("hide_distance"),
                              push.get("auto_touch"), keep=False)
            elif kind == "brief":
                self.brief(push.get("instructions", ""), push.get("allowed_methods"),
                           push.get("min_touches", 0), keep=False)
            elif kind == "reset":
                self.reset(str(push.get("name")), forward=False)
            elif kind == "language":
                self.language(str(push.get("language")), keep=False)
            elif kind == "language_to":
                self.language_to(str(push.get("name")), str(push.get("language")), forward=False)
            elif kind == "push_to":
                self.to_one(str(push.get("name")), push.get("exercise", False), push.get("tool_key"),
                            push.get("hide_distance"), push.get("auto_touch"), forward=False)
        except (ValueError, TypeError) as exc:
            log.warning("a %s pushed on another server process was not applied: %s", kind, exc)
