"""The class as the server runs it: names, gradebook recorders, trainer views, the exercise.

:class:`ClassRoom` is the server's classroom state (one per ``PendantApp`` with a gradebook,
per-browser mode). For each new session it shows the "Your name" prompt; a name starts a
gradebook session and a :class:`TraineeRecorder` subscribed to the session's change signal
(and, in the mystery exercise, mounts the trainee's mystery tool); a right trainer token turns
that browser into the trainer's dashboard (its pendant is taken down). Both windows are views,
a layer above the classroom: the server hands the class room their builders
(:class:`~tcp_pendant.classroom.class_views.ClassViews`). Every dashboard
re-renders when a trainee's state changes, at most :data:`RENDER_INTERVAL_S` apart, and every
:data:`TICK_S` for its clocks; its table comes from the gradebook (``Gradebook.board.read``) plus
who is connected now (:meth:`ClassRoom.connected_names`), so it survives a restart.

Per-trainee actions of the trainer (:meth:`ClassRoom.reset_wizard`, :meth:`ClassRoom.push_to`)
run on that one trainee's session through its own commands, handed to viser's loop after the
trainer's callback (never two sessions' locks at once); no other session is touched.

Names are for the one browser that joined under them (``Gradebook.trainees.join``): a browser
gets a browser key when it joins (its page script keeps it, ``views.identity``) and comes back
with it after a reload or a server restart. A name connected in another browser is refused in
words, unless the browser shows that name's key (the same browser: then the newer tab takes
the name and the older one's welcome window opens again, without joining by itself); a
look-alike of a classmate's name is refused naming it (``classroom.names``). The trainer
releases a name (:meth:`ClassRoom.release`): its key is forgotten and a browser connected
under it is shown the welcome window again, so the next browser that joins under it gets the
trainee's records.

The exercise seed (the mystery tools) is the gradebook's, drawn at random for the class the
first time a mystery tool is drawn and kept there (``Gradebook.settings.exercise_seed``); an explicit
``exercise_seed`` (``--exercise-seed``, reproducible demos) is used instead. It is never shown.

In an exercise the trainee sees no truth: the workflow's ``hide_truth`` is set (the result
panel shows no error against the true TOOL frame and no grade, the scene no TRUE triad); the
gradebook keeps them for the trainer. The settings a trainer pushes (exercise, tool, distance
aids, Auto-touch) apply to every named trainee and to those who name themselves later.

Each trainee's pendant follows the class's :class:`~tcp_pendant.calibrate.pendant_rules.ExerciseRules`
(``Session.set_rules``): in an exercise the distance aids are hidden and locked and Auto-touch
is off unless the trainer unlocked or allowed them (``class_rules``); a change of exercise goes
back to those defaults unless the same push sets them.

Each pendant's library rights (``classroom.library_rights``, ``Session.set_library_rights``):
before a name it changes no library slot; a named trainee saves into free slots and their own,
renames and deletes only their own, within ``library_quota`` slots (the owner, the name, is
kept in the library file); the browser that opened the trainer view changes every slot.

The exercise also carries the trainer's **brief** (:meth:`ClassRoom.push_brief`, or
``--exercise-instructions`` / ``--exercise-methods`` / ``--exercise-min-touches`` at start):
instructions (plain text, a banner on every trainee's panel), the methods a trainee may start
and the fewest touches a Finish takes; they are part of the rules (``ExerciseRules``) and stay
until the trainer pushes another brief (a change of exercise keeps them).

The trainer's **messages** (:meth:`ClassRoom.send_message`) go to every connected trainee or
to one, and are kept in the gradebook (``Gradebook.messages.add``: one row per trainee) until
that trainee dismisses them: each is delivered on viser's loop to that trainee's session only
(``Session.show_message``), at once on the trainer's process and by the heartbeat
(:meth:`ClassRoom.beat`) on whichever process holds the trainee now, and again after a reload,
a join on another process or a restart of the server. A Dismiss (the session's ``notice``
signal: a message no longer on its screen) deletes that trainee's row
(``Gradebook.messages.dismiss``). A message to one trainee who left waits for them.

Wrong trainer tokens are counted in the gradebook per source address
(``Gradebook.token_failures.try_token``, ``classroom.trainer_token``), so the lockout holds on every process
of the class and after a restart. Who left (connected, then not: :meth:`trainee_statuses`) is
kept there too (``Gradebook.presence.depart`` / ``departed``), the same on every process.

Several server processes on one gradebook (``tcp-pendant --workers N``): each process has its
own sessions and its own ClassRoom (:attr:`ClassRoom.holder` names it); what the class shares
goes through the gradebook. A joined name is claimed in the gradebook's presence table
(``Gradebook.presence.claim``) and beaten every ``presence_poll_s`` by :meth:`ClassRoom.start`'s
thread with the trainee's live row, so a name connected on one process is refused on another
exactly as on the same one, the same browser's newer tab on another process takes the name
(the older one's welcome window opens again at the next beat), a release by the trainer on
any process sends the browser on its holder back to the welcome window, and
:meth:`trainee_statuses` and :meth:`connected_names` list the whole class (the other
processes' rows as they last beat them, and who left, from the gradebook). Every
push of the trainer's settings is kept in order (``Gradebook.pushes.add``) and applied by the
other processes at their next beat. A reconnect landing on another process gets the
calibrations in progress back from the gradebook (``classroom.restore``), like a restart.

Threads: the session callbacks run on viser's event loop (``Session.on_loop``); connects and
disconnects come from viser's thread pool and hand their trainer-view refresh to the loop
(``hand_to_loop``). The class's own lists are guarded by one lock.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import logging
import os
import secrets
import socket
import threading
import time
from collections.abc import Callable, Sequence
from datetime import datetime, timezone
from typing import Any, cast

from tcp_pendant.classroom.class_board import ClassBoard
from tcp_pendant.classroom.grade_rows import GradeRow
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.gradebook_store import GradebookError
from tcp_pendant.classroom.grades_csv import to_csv
from tcp_pendant.classroom.mystery import draw_mystery_tool
from tcp_pendant.classroom.names import TraineeNameError, validate_trainee_name
from tcp_pendant.classroom.recorder import TraineeRecorder, TraineeStatus
from tcp_pendant.classroom.replay import CalibrationReplay, calibration_replay
from tcp_pendant.classroom.restore import runs_to_restore
from tcp_pendant.classroom.push_words import PUSH_TITLE, push_words
from tcp_pendant.classroom.trainees import TraineeJoin
from tcp_pendant.classroom.trainer_token import FORGET_S, lock_s, locked, log_failure, validate_trainer_token
from tcp_pendant.classroom.class_messages import clean_message_text
from tcp_pendant.classroom.class_views import ClassViews, TrainerView, WelcomeWindow
from tcp_pendant.classroom.exercise_rules import DistanceAids, class_rules, clean_instructions, clean_min_touches
from tcp_pendant.classroom.library_rights import DEFAULT_LIBRARY_QUOTA, MAX_LIBRARY_QUOTA, trainee_rights
from tcp_pendant.calibrate.pendant_rules import UNRESTRICTED, ExerciseRules, LibraryRights
from tcp_pendant.controller import ToolModel
from tcp_pendant.session import ClassMessage, Session, SessionChange
from tcp_pendant.wizards import WIZARD_TYPES, wizard_classes

__all__ = ["EXERCISE_IDS", "RENDER_INTERVAL_S", "TICK_S", "ClassRoom", "clean_methods"]

log = logging.getLogger(__name__)

EXERCISE_IDS = ("mystery",)
"""Exercises a trainer can start (``--exercise``; None: free practice)."""


RENDER_INTERVAL_S = 0.5
"""Dashboards re-render at most this often (seconds): a class of 100 trainees touching at once
costs one gradebook read and one table per trainer browser per interval."""
TICK_S = 5.0
"""Dashboards re-render at least this often while one is open (its clocks: time on the step,
since the last touch, stuck)."""


PUSHED_SETTING = "pushed"
"""The class setting that keeps what the trainer pushed (exercise, "Hide distance", Auto-touch,
tool; the brief: instructions, allowed methods, minimum touches)."""
TOKEN_SETTING = "trainer_token_sha256"
"""The class setting that keeps the trainer token's SHA-256 (hex) in the gradebook, so the
trainer's address keeps working after a restart without the token being stored."""


def clean_methods(methods: object) -> tuple[str, ...] | None:
    """The methods an exercise allows, as wizard kinds in menu order (None: every method).

    Args:
        methods: None, or wizard kinds (``"xyz4"``, ``"reference"``, ...) as a sequence or one
            comma-separated string (the CLI's ``--exercise-methods xyz4,reference``).

    Raises:
        ValueError: an unknown kind or no method at all (names the registered kinds).
    """
    if methods is None:
        return None
    if isinstance(methods, str):
        methods = [m for m in (part.strip() for part in methods.split(",")) if m]
    if not isinstance(methods, (list, tuple)) or not all(isinstance(m, str) for m in methods):
        raise ValueError(f"The exercise's methods must be wizard ids, got {type(methods).__name__}.")
    known = [c.kind for c in wizard_classes()]
    unknown = [m for m in methods if m not in WIZARD_TYPES]
    if unknown:
        raise ValueError(f"Unknown calibration method {unknown[0]!r:.60} for the exercise; use some of "
                         f"{', '.join(known)}.")
    if not methods:
        raise ValueError(f"An exercise needs at least one method; choose some of {', '.join(known)}.")
    return tuple(k for k in known if k in methods)


def _token_digest(token: str) -> str:
    # A random token has 128 bits and a given one at least 16 characters: a plain SHA-256 is
    # enough for a file that holds the class's answers anyway.
    return hashlib.sha256(str(token).encode("utf-8")).hexdigest()


class ClassRoom:
    """Names, recorders and trainer views of one server (see the module docstring).

    Args:
        gradebook: the class gradebook (opened by the server at start).
        tools: the physical tools by key (the built-in ones).
        trainer_token: the token that opens the trainer view (16 to 200 printable characters).
        exercise: None (free practice) or "mystery".
        exercise_seed: the seed of the mystery tools; None: the class's own secret seed, kept in
            the gradebook.
        instructions: the exercise's instructions given at start (None: those kept in the
            gradebook, else none); each part of the brief given wins over the kept one.
        allowed_methods: the methods the exercise allows, given at start (None: as kept).
        min_touches: the fewest touches a Finish takes, given at start (None: as kept).
        hand_to_loop: runs a function on viser's event loop.
        clock: Unix time, seconds (the token's lockout windows, kept in the gradebook for every
            process of the class; tests set it).
        call_later: ``call_later(delay_s, fn)`` runs ``fn`` on viser's event loop after a
            delay (the dashboards' throttle and clock tick); None: dashboards render at once,
            every time (tests).
        library_quota: tool-library slots one trainee may hold (1..16; ``--library-quota``).
        presence_poll_s: the heartbeat period of :meth:`start` (seconds; module docstring).
        views: the welcome window, the dashboard and the browser's address, as the server
            builds them (``classroom.class_views``); None: a class room without browsers (its
            data and rules only: :meth:`attach` and :meth:`open_trainer` refuse).

    Raises:
        TrainerTokenError: a token that breaks the rules.
        ValueError: a library quota out of range.
    """

    def __init__(self, gradebook: Gradebook, tools: dict[str, ToolModel], *, trainer_token: str | None,
                 exercise: str | None = None, exercise_seed: int | None = None,
                 instructions: str | None = None, allowed_methods: Sequence[str] | str | None = None,
                 min_touches: int | None = None, views: ClassViews | None = None,
                 hand_to_loop: Callable[[Callable[[], None]], None] = lambda fn: fn(),
                 clock: Callable[[], float] = time.time,
                 call_later: Callable[[float, Callable[[], None]], None] | None = None,
                 library_quota: int = DEFAULT_LIBRARY_QUOTA, presence_poll_s: float = 1.0) -> None:
        if (isinstance(library_quota, bool) or not isinstance(library_quota, int)
                or not 1 <= library_quota <= MAX_LIBRARY_QUOTA):
            raise ValueError(f"The library quota must be a whole number of slots 1..{MAX_LIBRARY_QUOTA}, "
                             f"got {library_quota!r:.40}.")
        self.library_quota = library_quota
        if exercise is not None and exercise not in EXERCISE_IDS:
            raise ValueError(f"Unknown exercise {exercise!r}; use one of {', '.join(EXERCISE_IDS)}.")
        given_instructions = None if instructions is None else clean_instructions(instructions)
        given_methods = clean_methods(allowed_methods)
        given_min = None if min_touches is None else clean_min_touches(min_touches)
        stored = gradebook.settings.get(TOKEN_SETTING)
        if trainer_token is None and isinstance(stored, str):
            self.trainer_token: str | None = None      # the class's token, kept (hashed) in the gradebook
            self._token_sha256 = stored
        else:
            token = secrets.token_urlsafe(16) if trainer_token is None else trainer_token
            validate_trainer_token(token, "The trainer token")
            self.trainer_token = token
            self._token_sha256 = _token_digest(token)
            gradebook.settings.set(TOKEN_SETTING, self._token_sha256)
        self.gradebook = gradebook
        self.tools = dict(tools)
        self.tool_keys = tuple(self.tools)
        self.exercise = exercise
        if exercise_seed is not None and (isinstance(exercise_seed, bool) or not isinstance(exercise_seed, int)):
            raise ValueError(f"The exercise seed must be a whole number, got {exercise_seed!r:.40}.")
        self._exercise_seed = exercise_seed      # None: the gradebook's, read when first needed
        self._hand_to_loop = hand_to_loop
        self._views = views
        self._lock = threading.Lock()
        self._join_lock = threading.Lock()       # one join or release at a time
        self._trainees: dict[int, tuple[Session, TraineeRecorder, str]] = {}   # id(session) -> ...
        self._subscribed: set[int] = set()          # id(session) of sessions whose changes we follow
        self._prompts: dict[int, WelcomeWindow] = {}   # id(session) -> its welcome window
        self._released: dict[int, str] = {}          # id(session) -> the name the trainer released there
        self._trainer_views: dict[int, TrainerView] = {}   # id(session) -> its dashboard
        self._call_later = call_later
        self._render_due = False                    # a throttled dashboard render is scheduled
        self._tick_due = False                      # the dashboards' clock tick is scheduled
        self._last_render = -float("inf")           # time.monotonic() of the last render
        self.clock = clock
        self.distance_aids: DistanceAids | None = None
        """The distance aids as the trainer last pushed them (None: the exercise's default -
        locked in an exercise, each trainee's own choice in free practice)."""
        self.auto_touch: bool | None = None
        """Auto-touch as the trainer last allowed it (None: the default - off in an exercise)."""
        self.pushed_tool: str | None = None
        """The tool the trainer last pushed (kept across restarts)."""
        self.instructions = ""
        """The exercise's instructions (plain text; "" none)."""
        self.allowed_methods: tuple[str, ...] | None = None
        """The wizard kinds trainees may start (None: every method)."""
        self.min_touches = 0
        """The fewest touches a Finish takes, for methods whose touch count is chosen (0: none)."""
        self._on_screen: dict[int, set[int]] = {}   # id(session) -> message ids on its screen, last seen
        self._handed: dict[int, set[int]] = {}      # id(session) -> message ids handed to it (the loop shows them)
        self.holder = f"{socket.gethostname()}:{os.getpid()}:{secrets.token_hex(4)}"
        """This server process's id in the gradebook's presence table (host, pid, a nonce)."""
        self.presence_poll_s = float(presence_poll_s)
        self._remote: dict[str, TraineeStatus] = {}   # name -> row, connected on another process
        self._push_seen = gradebook.pushes.last_id()  # the pushes before are in the kept settings
        self._beater: threading.Thread | None = None
        self._stopping = threading.Event()
        self._apply_kept(exercise_given=exercise is not None)   # what the trainer pushed before a restart
        if given_instructions is not None:
            self.instructions = given_instructions
        if given_methods is not None:
            self.allowed_methods = given_methods
        if given_min is not None:
            self.min_touches = given_min
        if (given_instructions, given_methods, given_min) != (None, None, None):
            self._keep_pushed(None, brief_only=True)

    @property
    def rules(self) -> ExerciseRules:
        """The rules every trainee's pendant follows now."""
        return class_rules(self.exercise, self.distance_aids, self.auto_touch, instructions=self.instructions,
                           allowed_methods=self.allowed_methods, min_touches=self.min_touches)

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
    def attach(self, session: Session) -> WelcomeWindow:
        """Show the "Your name" prompt in a new per-browser session (returns the prompt)."""
        prompt = self._class_views().welcome(session, lambda name, key: self._joined(self.named(session, name, key)),
                                             lambda token: self.open_trainer(session, token))
        session.views["identity"] = prompt
        with self._lock:
            self._prompts[id(session)] = prompt
        session.set_library_rights(self._library_rights(session, None))   # no change before a name
        session.on_close(lambda: self.detach(session))
        return prompt

    def _class_views(self) -> ClassViews:
        if self._views is None:
            raise RuntimeError("this class room was made without views (ClassRoom(views=...)): it shows no browser")
        return self._views

    def source_address(self, session: Session) -> str:
        """The address the browser of ``session`` connects from (its websocket's peer IP, the
        trainer token's lockout counts per address); "unknown" when there is none to read (a
        shared page, a closed connection): all such tries share one count
        (``ClassViews.client_address``)."""
        return self._class_views().client_address(session.client) or "unknown"

    @staticmethod
    def _joined(join: TraineeJoin) -> tuple[str, str | None]:
        return join.name, join.new_key

    def _library_rights(self, session: Session, name: str | None) -> LibraryRights:
        """The trainer changes every slot; a trainee (``name``; None: not joined) only their own."""
        with self._lock:
            trainer = id(session) in self._trainer_views
        return UNRESTRICTED if trainer else trainee_rights(name, self.library_quota)

    def _seed(self) -> int:
        if self._exercise_seed is None:
            self._exercise_seed = self.gradebook.settings.exercise_seed()
        return self._exercise_seed

    def _holder(self, name: str, other_than: Session) -> tuple[Session, TraineeRecorder, str] | None:
        with self._lock:
            return next((e for e in self._trainees.values() if e[2] == name and e[0] is not other_than), None)

    def named(self, session: Session, name: Any, key: Any = None) -> TraineeJoin:
        """The browser of ``session`` joins as ``name`` showing the browser key ``key`` (or
        none): the gradebook's check (``Gradebook.trainees.join``), then a gradebook session, its
        recorder, and the exercise's tool.

        Raises:
            TraineeNameError: the name is refused (invalid, a look-alike of a classmate's,
                connected in another browser, held by another browser); the words say why.
        """
        clean = validate_trainee_name(name)
        with self._join_lock:
            if self._released.get(id(session)) == clean:
                raise TraineeNameError(f"The trainer released the name {clean} from this browser; join "
                                       "under your own name.")
            holder = self._holder(clean, session)
            elsewhere = self.gradebook.presence.holder(clean) not in (None, self.holder)
            if (holder is not None or elsewhere) and not self.gradebook.trainees.holds_key(clean, key):
                raise TraineeNameError(f"{clean} is already connected in another browser; pick another "
                                       "name or ask the trainer to release it.")
            join = self.gradebook.trainees.join(clean, key)
            if holder is not None:         # the same browser (its key): the newer tab takes the name
                self._leave(holder, f"{clean} joined from another tab or window of this browser, so this "
                            "one left the class. Close it, or join here again (the other one then leaves).",
                            forget=False)
            self._start(session, join)
        self.refresh_trainers()
        return join

    def _start(self, session: Session, join: TraineeJoin) -> TraineeRecorder:
        with session.lock:
            sid = self.gradebook.records.start_session(join.trainee_id, "per-browser")
            session.keep_honest_records()             # the trainee's export carries no answer key
            recorder = TraineeRecorder(self.gradebook, sid, join.name, session.workflow,
                                       exercise_id=self.exercise)
            # claimed before the name is in the table the heartbeat reads: a beat never sees a
            # name of ours that the presence table does not give to us yet
            self.gradebook.presence.claim(join.name, self.holder, dataclasses.asdict(recorder.status))
            with self._lock:
                self._trainees[id(session)] = (session, recorder, join.name)
                follow = id(session) not in self._subscribed
                self._subscribed.add(id(session))
            for message in self._kept_messages(join.name):     # what the trainee had not dismissed yet
                session.show_message(message)
            with self._lock:
                self._on_screen[id(session)] = {m.message_id for m in session.messages}
                self._handed[id(session)] = set(self._on_screen[id(session)])
            if follow:
                session.subscribe(lambda change: self._on_change(session, change))
            session.set_hide_truth(self.exercise is not None)
            session.set_library_rights(self._library_rights(session, join.name))
            if self.exercise == "mystery":
                self._mount_mystery(session, recorder, join.name)
            self._apply_rules(session)
            self._restore(session, recorder, join.name)
        return recorder

    def _on_change(self, session: Session, change: SessionChange) -> None:
        with self._lock:
            entry = self._trainees.get(id(session))
        if entry is None:                  # not (or no longer) a named trainee: nothing to store
            return
        if change.notice:
            self._note_dismissed(session, entry[2])
        recorder = entry[1]
        before = recorder.status
        recorder.on_change(change)
        if recorder.status != before:
            self.refresh_trainers()

    def _leave(self, entry: tuple[Session, TraineeRecorder, str], message: str, *, forget: bool) -> None:
        """The session of ``entry`` is no longer its trainee: its gradebook session ends, its row
        moves to those who left, and its welcome window opens again with ``message``."""
        session, recorder, name = entry
        with self._lock:
            if self._trainees.get(id(session)) is not entry:
                return
            prompt = self._prompts.get(id(session))
        try:
            recorder.disconnected()
        except Exception:
            log.exception("ending the gradebook session of %r failed", name)
        self._depart(entry)               # before it leaves the table: the row is never missing
        with self._lock:
            if self._trainees.get(id(session)) is not entry:
                return
            self._trainees.pop(id(session), None)
        self._drop_presence(name)
        session.library_rights = self._library_rights(session, None)  # at once: it changes nothing more
        self._hand_to_loop(session.guard(lambda: session.set_library_rights(session.library_rights)))
        if prompt is not None:         # on the loop, after this callback: no two sessions' locks at once
            self._hand_to_loop(session.guard(lambda: prompt.reopen(message, forget=forget)))

    def release(self, name: str) -> str:
        """The trainer releases ``name``: the gradebook forgets its browser key and a browser
        connected under it leaves the class (its welcome window opens again and its page script
        forgets the name). Returns what happened, in words for the trainer (plain text)."""
        if not isinstance(name, str):
            raise ValueError("Choose the name to release.")
        with self._join_lock:
            held = self.gradebook.trainees.release(name)
            elsewhere = self.gradebook.presence.drop(name) and name not in self._local_names()
            with self._lock:
                holders = [e for e in self._trainees.values() if e[2] == name]
            for entry in holders:
                self._released[id(entry[0])] = name
                self._leave(entry, f"The trainer released the name {name}: this browser left the class. "
                            "Join under your own name.", forget=True)
        self.refresh_trainers()
        if not held and not holders and not elsewhere:
            return f"{name} was not held by any browser."
        where = " and its browser left the class" if holders or elsewhere else ""
        return f"Released {name}{where}: the next browser that joins as {name} gets the trainee's records."

    def held_names(self) -> list[str]:
        """Names a browser holds (the trainer view's "Release a name" choices)."""
        return self.gradebook.trainees.held_names()

    def _restore(self, session: Session, recorder: TraineeRecorder, name: str) -> None:
        """The calibrations ``name`` had in progress (a reload, a restart of the server with this
        gradebook): back on the trainee's screen at their step, written on into the same
        calibrations (``classroom.restore``)."""
        restored = runs_to_restore(self.gradebook, name)
        if not restored:
            return
        indices = session.restore_runs([r.run for r in restored])
        for index, r in zip(indices, restored):
            recorder.adopt(index, r.calibration_id, r.touch_ids)
        n = len(restored)
        session.notify("Calibration restored", f"{n} calibration{'s' if n != 1 else ''} you had in progress "
                       "came back, each at its step with its touches.", kind="info")

    def _mount_mystery(self, session: Session, recorder: TraineeRecorder, name: str) -> None:
        base = self.tools.get("pointer") or next(iter(self.tools.values()))
        tool = draw_mystery_tool(self._seed(), name, base)
        recorder.exercise_id = "mystery"
        session.add_physical_tool(tool)              # its label in the wizard's tool-change words
        session.set_exercise_tool(tool)              # mounted, and "Mounted tool" locked to it

    def detach(self, session: Session) -> None:
        """The session closed (its browser left)."""
        with self._lock:
            entry = self._trainees.get(id(session))
            self._trainer_views.pop(id(session), None)
            self._on_screen.pop(id(session), None)
            self._handed.pop(id(session), None)
            self._prompts.pop(id(session), None)
            self._released.pop(id(session), None)
            self._subscribed.discard(id(session))
        if entry is not None:
            try:
                entry[1].disconnected()
            except Exception:
                log.exception("ending the gradebook session of %r failed", entry[2])
            self._depart(entry)           # before it leaves the table: the row is never missing
            with self._lock:
                if self._trainees.get(id(session)) is entry:
                    self._trainees.pop(id(session), None)
            self._drop_presence(entry[2])
        self._hand_to_loop(self.refresh_trainers)

    # ------------------------------------------------------------ presence (server processes)
    def _local_names(self) -> set[str]:
        with self._lock:
            return {e[2] for e in self._trainees.values()}

    def _depart(self, entry: tuple[Session, TraineeRecorder, str]) -> None:
        """The trainee of ``entry`` leaves this process: kept in the gradebook with their last
        row (the trainer's table on every process lists them as not connected), unless another
        session of this process holds the name now."""
        session, recorder, name = entry
        if self._holder(name, session) is not None:
            return
        try:
            left = dataclasses.replace(recorder.status, connected=False)
            self.gradebook.presence.depart(name, dataclasses.asdict(left))
        except GradebookError:
            log.exception("the departure of %r could not be kept", name)

    def _drop_presence(self, name: str) -> None:
        """The name's row goes, unless another session of this process holds the name now."""
        if name in self._local_names():
            return
        try:
            self.gradebook.presence.drop(name, self.holder)
        except GradebookError:
            log.exception("the presence of %r could not be dropped", name)

    def start(self) -> None:
        """Start the heartbeat thread (the server calls it; module docstring)."""
        if self._beater is not None:
            return
        self._beater = threading.Thread(target=self._beat_loop, name="class-presence", daemon=True)
        self._beater.start()

    def close(self) -> None:
        """Stop the heartbeat and free every name this process holds (the server stops)."""
        self._stopping.set()
        if self._beater is not None:
            self._beater.join(timeout=5.0)
            self._beater = None
        try:
            self.gradebook.presence.drop_holder(self.holder)
        except GradebookError:
            log.debug("presence not dropped: gradebook closed", exc_info=True)

    def _beat_loop(self) -> None:
        while not self._stopping.wait(self.presence_poll_s):
            try:
                self.beat()
            except GradebookError:
                log.exception("class heartbeat failed")
            except Exception:  # the heartbeat must go on whatever one beat met
                log.exception("class heartbeat failed")

    def beat(self) -> None:
        """One heartbeat (the thread of :meth:`start` every ``presence_poll_s``; tests call it):
        renew this process's names with their rows; a name this process lost (taken by the same
        browser on another process, released by the trainer there) sends its session back to
        the welcome window; take in the other processes' rows and the trainer's pushes made
        there; hand this process's trainees the messages the gradebook keeps for them that
        they were not handed yet (sent on another process, or before they came here)."""
        with self._lock:
            entries = {e[2]: e for e in self._trainees.values()}
        statuses = {name: dataclasses.asdict(e[1].status) for name, e in entries.items()}
        held = self.gradebook.presence.beat(self.holder, statuses)
        lost = [(entries[n], self.gradebook.presence.holder(n) is None) for n in sorted(set(statuses) - held)]
        if lost:
            self._hand_to_loop(lambda: self._lost(lost))
        fields = {f.name for f in dataclasses.fields(TraineeStatus)}
        remote = {}
        for name, holder, st in self.gradebook.presence.present():
            if holder != self.holder and isinstance(st, dict):
                try:
                    remote[name] = TraineeStatus(**{k: v for k, v in st.items() if k in fields})
                except TypeError:
                    continue
        with self._lock:
            changed = remote != self._remote
            self._remote = remote
        for push_id, push in self.gradebook.pushes.after(self._push_seen):
            self._push_seen = push_id
            if push.get("holder") != self.holder:
                self._hand_to_loop(functools.partial(self._apply_remote_push, push))
        self._deliver_kept({name: e for name, e in entries.items() if name in held})
        if changed:
            self._hand_to_loop(self.refresh_trainers)

    def _lost(self, lost: list[tuple[tuple[Session, TraineeRecorder, str], bool]]) -> None:
        for entry, released in lost:
            name = entry[2]
            if released:
                self._released[id(entry[0])] = name
                self._leave(entry, f"The trainer released the name {name}: this browser left the class. "
                            "Join under your own name.", forget=True)
            else:
                self._leave(entry, f"{name} joined from another tab or window of this browser, so this "
                            "one left the class. Close it, or join here again (the other one then leaves).",
                            forget=False)
        self.refresh_trainers()

    def _apply_remote_push(self, push: dict[str, Any]) -> None:
        """A push the trainer made on another server process of the class: settings, a brief,
        a reset or a push to one trainee (``kind``), applied to this process's trainees."""
        kind = push.get("kind", "settings")
        try:
            if kind == "settings":
                self.push_settings(push.get("exercise"), push.get("tool_key"), push.get("hide_distance"),
                                   push.get("auto_touch"), keep=False)
            elif kind == "brief":
                self.push_brief(push.get("instructions", ""), push.get("allowed_methods"),
                                push.get("min_touches", 0), keep=False)
            elif kind == "reset":
                self.reset_wizard(str(push.get("name")), forward=False)
            elif kind == "push_to":
                self.push_to(str(push.get("name")), push.get("exercise", False), push.get("tool_key"),
                             push.get("hide_distance"), push.get("auto_touch"), forward=False)
        except (ValueError, TypeError) as exc:
            log.warning("a %s pushed on another server process was not applied: %s", kind, exc)

    # ------------------------------------------------------------ trainer
    def open_trainer(self, session: Session, token: str) -> bool:
        """A browser typed ``token``: if it is the trainer token, build the trainer view there.
        Wrong tokens are counted per source address in the gradebook, for every server process
        of the class (``Gradebook.token_failures.try_token``, ``classroom.trainer_token``); the right one
        forgives its address's.

        Raises:
            TrainerTokenLocked: this browser's address typed too many wrong tokens; the token was
                not tried.
            ValueError: the gradebook cannot count the try (the token is not tried either).
        """
        now = self.clock()
        source = self.source_address(session)
        try:
            wait, failures, counted = self.gradebook.token_failures.try_token(source, now=now, forget_s=FORGET_S,
                                                                              lock_s=lock_s)
        except GradebookError as exc:
            log.error("a trainer token was not tried: %s", exc)
            raise ValueError("The class gradebook cannot be read now, so no trainer token is tried; "
                             "try again in a moment.") from None
        if not counted:
            raise locked(wait)
        if not secrets.compare_digest(_token_digest(token), self._token_sha256):
            client_id = getattr(session.client, "client_id", None)
            log_failure("a shared page" if client_id is None else f"browser {client_id}", failures, token)
            return False
        try:
            self.gradebook.token_failures.forgive(source)
        except GradebookError:
            log.exception("the wrong trainer tokens of %s could not be forgiven", source)
        with self._lock:
            if id(session) in self._trainer_views:
                return True
        view = self._class_views().dashboard(session, self)
        session.views["trainer"] = view
        with self._lock:
            self._trainer_views[id(session)] = view
        self._schedule_tick()
        session.set_library_rights(UNRESTRICTED)        # the trainer renames and deletes every slot
        return True

    def refresh_trainers(self) -> None:
        """Re-render every open dashboard (on viser's event loop): at once when the last render
        is :data:`RENDER_INTERVAL_S` old, else once when it is (later changes join that one)."""
        with self._lock:
            if self._render_due or not self._trainer_views:
                return
            wait = self._last_render + RENDER_INTERVAL_S - time.monotonic()
            if wait > 0 and self._call_later is not None:
                self._render_due = True
                later = self._call_later
            else:
                later = None
        if later is not None:
            try:
                later(wait, self._render_trainers)
            except RuntimeError:                 # the loop is closed: the server is stopping
                with self._lock:
                    self._render_due = False
            return
        self._render_trainers()

    def _render_trainers(self) -> None:
        with self._lock:
            self._render_due = False
            self._last_render = time.monotonic()
            views = list(self._trainer_views.values())
        if not views:
            return
        try:
            board, connected = self.board(), set(self.connected_names())
        except GradebookError:
            log.exception("the gradebook could not be read for the dashboards")
            return
        for view in views:
            try:
                view.session.guard(view.render)(board, connected)
            except Exception:
                log.exception("trainer dashboard refresh failed")
        self._schedule_tick()

    def _schedule_tick(self) -> None:
        with self._lock:
            if self._tick_due or not self._trainer_views or self._call_later is None:
                return
            self._tick_due = True
            later = self._call_later
        try:
            later(TICK_S, self._tick)
        except RuntimeError:
            with self._lock:
                self._tick_due = False

    def _tick(self) -> None:
        with self._lock:
            self._tick_due = False
        self.refresh_trainers()

    # ------------------------------------------------------------ the dashboard's data
    def board(self) -> ClassBoard:
        """The class as the gradebook knows it (``Gradebook.board.read``)."""
        return self.gradebook.board.read()

    def replay(self, name: str) -> CalibrationReplay | None:
        """The latest calibration of ``name`` that has a touch, from the gradebook (None: none)."""
        cid = self.gradebook.records.last_calibration(name)
        return None if cid is None else calibration_replay(self.gradebook, cid)

    def _entry_of(self, name: str) -> tuple[Session, TraineeRecorder, str] | None:
        with self._lock:
            return next((e for e in self._trainees.values() if e[2] == name), None)

    def _on_another_process(self, name: object) -> bool:
        with self._lock:
            return isinstance(name, str) and name in self._remote

    def reset_wizard(self, name: str, *, forward: bool = True) -> str:
        """Cancel the running wizard of the trainee ``name`` (``Session.cancel_wizard`` on their
        session only; kept, resumable; the gradebook records the cancel) and tell them. Returns
        what happened, in words for the trainer (plain text). A trainee connected on another
        server process of the class gets it there at its next beat (``forward``; False: a
        request from there, applied here only)."""
        entry = self._entry_of(name) if isinstance(name, str) else None
        if entry is None and forward and self._on_another_process(name):
            self.gradebook.pushes.add({"holder": self.holder, "kind": "reset", "name": name})
            return f"Reset {name}'s running wizard (on another server process of the class)."
        if entry is None:
            return f"{name} is not connected: there is no running wizard to reset."
        session = entry[0]
        if not session.workflow.is_open:
            return f"{name} has no wizard running."

        def cancel() -> None:
            if session.workflow.is_open:
                session.cancel_wizard()
                session.notify("The trainer reset your calibration",
                               "Your trainer closed the wizard; start it again (your touches are kept: "
                               "Resume brings them back).", kind="warning")
        self._hand_to_loop(session.guard(cancel))   # after the trainer's callback: one session's lock at a time
        return f"Reset {name}'s running wizard."

    def push_to(self, name: str, exercise: str | None | bool = False, tool_key: str | None = None,
                hide_distance: str | None = None, auto_touch: bool | None = None, *, forward: bool = True) -> str:
        """Push settings to the one trainee ``name``: ``exercise`` (False: keep; None: free
        practice; "mystery": their mystery tool), ``tool_key`` (None: keep; ignored with the
        mystery exercise), distance aids ``hide_distance`` ("locked" / "hidden" / "shown", None:
        keep) and Auto-touch (None: keep). Only that trainee's session is changed; until their
        next reconnect or the next push to all. Returns what happened (plain text). A trainee
        connected on another server process gets it there (``forward``, as :meth:`reset_wizard`)."""
        if exercise is not False and exercise is not None and exercise not in EXERCISE_IDS:
            raise ValueError(f"Unknown exercise {exercise!r}; use one of {', '.join(EXERCISE_IDS)}.")
        if tool_key is not None and tool_key not in self.tools:
            raise ValueError(f"Unknown tool {tool_key!r}; use one of {', '.join(self.tools)}.")
        entry = self._entry_of(name) if isinstance(name, str) else None
        if entry is None and forward and self._on_another_process(name):
            self.gradebook.pushes.add({"holder": self.holder, "kind": "push_to", "name": name, "exercise": exercise,
                                       "tool_key": tool_key, "hide_distance": hide_distance, "auto_touch": auto_touch})
            return f"Pushed to {name} (on another server process of the class)."
        if entry is None:
            return f"{name} is not connected: nothing pushed."
        session, recorder, who = entry
        ex = self.exercise if exercise is False else exercise
        rules = class_rules(ex, cast("DistanceAids | None", hide_distance) or self.distance_aids,
                            self.auto_touch if auto_touch is None else bool(auto_touch))

        def apply() -> None:
            with session.batch():
                if exercise is not False:
                    recorder.exercise_id = ex
                    session.set_hide_truth(ex is not None)
                    if ex == "mystery":
                        self._mount_mystery(session, recorder, who)
                    else:
                        session.set_exercise_tool(None)     # free practice: the trainee swaps tools again
                if tool_key is not None and ex != "mystery":
                    session.mount_tool(self.tools[tool_key])
                if not rules.distance_locked:
                    session.set_rules(rules)
                if hide_distance is not None:
                    session.set_hide_distance(hide_distance != "shown")
                elif exercise is not False and rules.in_exercise:
                    session.set_hide_distance(True)
                session.set_rules(rules)
                session.changed(wizard=True)
            session.notify(PUSH_TITLE, push_words(exercise, None if tool_key is None else self.tools[tool_key].label,
                                                  hide_distance, auto_touch), kind="warning")
        self._hand_to_loop(session.guard(apply))
        return f"Pushed to {who}."

    def trainee_statuses(self) -> list[TraineeStatus]:
        """Rows of the live table: this process's connected trainees in order of arrival, those
        connected on the other server processes of the class (by name, as they last beat),
        then those who were connected and left, on any process of the class, the latest first,
        with their last row (``Gradebook.presence.departed``; a trainee connected again is not among
        them). The departures are read after the connected trainees: a departure is kept before
        its trainee leaves the table, so one leaving meanwhile is in one list or the other."""
        fields = {f.name for f in dataclasses.fields(TraineeStatus)}
        with self._lock:
            local = [rec.status for _, rec, _ in self._trainees.values()]
            names = {row.name for row in local}
            remote = [row for name, row in sorted(self._remote.items()) if name not in names]
        names |= {row.name for row in remote}
        try:
            departed = self.gradebook.presence.departed()
        except GradebookError:
            log.exception("who left the class could not be read")
            departed = []
        left = []
        for name, st in departed:
            if name in names:
                continue
            try:
                left.append(TraineeStatus(**{k: v for k, v in st.items() if k in fields}))
            except TypeError:
                continue
        return local + remote + left

    def grade_rows(self) -> list[GradeRow]:
        return self.gradebook.grades.rows()

    def grades_csv(self) -> str:
        return to_csv(self.gradebook.grades.rows())

    def _keep_pushed(self, tool_key: str | None, *, brief_only: bool = False) -> None:
        """Keep what the trainer pushed in the gradebook (``PUSHED_SETTING``), so a restart with
        this gradebook applies it again (:meth:`_apply_kept`); ``brief_only``: the brief's keys
        only (the brief given at start: the exercise given with it is not kept by that)."""
        kept = self.gradebook.settings.get(PUSHED_SETTING)
        kept = dict(kept) if isinstance(kept, dict) else {}
        if not brief_only:
            kept.update({"exercise": self.exercise, "distance_aids": self.distance_aids,
                         "auto_touch": self.auto_touch})
        kept.update({"instructions": self.instructions, "min_touches": self.min_touches,
                     "allowed_methods": None if self.allowed_methods is None else list(self.allowed_methods)})
        if tool_key is not None:
            kept["tool_key"] = tool_key
        self.gradebook.settings.set(PUSHED_SETTING, kept)

    def _apply_kept(self, exercise_given: bool) -> None:
        """At start: the settings the trainer pushed before a restart (an ``--exercise`` given
        at start wins over a kept one; a value this version does not know is ignored)."""
        kept = self.gradebook.settings.get(PUSHED_SETTING)
        if not isinstance(kept, dict):
            return
        if not exercise_given and kept.get("exercise") in (None, *EXERCISE_IDS):
            self.exercise = kept.get("exercise")
        aids, auto = kept.get("distance_aids"), kept.get("auto_touch")
        try:
            class_rules(self.exercise, aids, auto if isinstance(auto, bool) else None)
        except ValueError:
            aids = None
        self.distance_aids = cast("DistanceAids | None", aids)
        self.auto_touch = auto if isinstance(auto, bool) else None
        tool = kept.get("tool_key")
        self.pushed_tool = tool if isinstance(tool, str) and tool in self.tools else None
        try:                              # the brief (absent in an older gradebook: none)
            self.instructions = clean_instructions(kept.get("instructions", ""))
        except ValueError:
            self.instructions = ""
        try:
            self.allowed_methods = clean_methods(kept.get("allowed_methods"))
        except ValueError:                # a method this version does not know: every method
            self.allowed_methods = None
        try:
            self.min_touches = clean_min_touches(kept.get("min_touches", 0))
        except ValueError:
            self.min_touches = 0

    def push_settings(self, exercise: str | None, tool_key: str | None,
                      hide_distance: bool | str | None = None, auto_touch: bool | None = None, *,
                      keep: bool = True) -> int:
        """Set the exercise (None: free practice; "mystery": each trainee gets a mystery tool),
        mount ``tool_key`` (None: keep), set the distance aids (``hide_distance``: "locked",
        "hidden" or "shown"; True means "hidden", False "shown"; None: keep) and allow
        Auto-touch or not (None: keep) on every named trainee's pendant; later trainees get
        them when they name themselves. A new exercise starts from its default rules (module
        docstring) except what this push sets. Returns how many trainees of this process.
        ``keep``: keep the push in the gradebook for a restart and for the other server
        processes of the class (False: a push one of them made, applied here)."""
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
        if keep:
            self._keep_pushed(tool_key)
            self.gradebook.pushes.add({"holder": self.holder, "kind": "settings", "exercise": exercise,
                                       "tool_key": tool_key, "hide_distance": named, "auto_touch": auto_touch})
        with self._lock:
            trainees = list(self._trainees.values())
        for session, recorder, name in trainees:
            def apply(session: Session = session, recorder: TraineeRecorder = recorder, name: str = name) -> None:
                with session.batch():
                    recorder.exercise_id = exercise
                    session.set_hide_truth(exercise is not None)
                    if exercise == "mystery":
                        self._mount_mystery(session, recorder, name)
                    else:
                        session.set_exercise_tool(None)     # free practice: the trainee swaps tools again
                        if tool_key is not None:
                            session.mount_tool(self.tools[tool_key])
                    self._apply_rules(session, aids_too=new_exercise or aids is not None)
                    session.changed(wizard=True)      # the result panel shows or hides the truth
            session.guard(apply)()
        return len(trainees)

    def push_brief(self, instructions: str, allowed_methods: Sequence[str] | str | None,
                   min_touches: int, *, keep: bool = True) -> int:
        """Set the exercise's brief: ``instructions`` (plain text, at most
        ``MAX_INSTRUCTIONS_CHARS``; "" none), the methods trainees may start (wizard kinds; None:
        every method) and the fewest touches a Finish takes (0: none), on every named trainee's
        pendant (their rules, ``Session.set_rules``) and for those who name themselves later;
        kept in the gradebook (``keep``, as for :meth:`push_settings`). Returns how many
        trainees of this process.

        Raises:
            ValueError: instructions too long, an unknown method, a bad minimum (nothing is set).
        """
        text = clean_instructions(instructions)
        methods = clean_methods(allowed_methods)
        minimum = clean_min_touches(min_touches)
        self.instructions, self.allowed_methods, self.min_touches = text, methods, minimum
        if keep:
            self._keep_pushed(None, brief_only=True)
            self.gradebook.pushes.add({"holder": self.holder, "kind": "brief", "instructions": text,
                                       "allowed_methods": None if methods is None else list(methods),
                                       "min_touches": minimum})
        rules = self.rules
        with self._lock:
            trainees = list(self._trainees.values())
        for session, _recorder, _name in trainees:
            session.guard(session.set_rules)(rules)
        return len(trainees)

    # ------------------------------------------------------------ messages
    def connected_names(self) -> list[str]:
        """Names of the trainees connected now on every server process of the class (the
        trainer's "To" choices): this process's in order of arrival, then the other processes'
        by name (the presence table); the one place the dashboard learns who is connected."""
        with self._lock:
            local = [name for _, _, name in self._trainees.values()]
        try:
            remote = sorted({name for name, holder, _ in self.gradebook.presence.present() if holder != self.holder})
        except GradebookError:
            log.exception("the class's presence table is unreadable")
            remote = []
        return local + [name for name in remote if name not in local]

    def send_message(self, text: str, to: str | None = None) -> str:
        """Send ``text`` (plain text) to every connected trainee of the class (``to`` None) or
        to the trainee named ``to`` (connected, or one who left: it waits until they join
        again). It is kept in the gradebook for each of them until they dismiss it
        (``Gradebook.messages.add``), shown at once to those on this process and by the other
        processes' heartbeat to theirs (module docstring). Returns what happened, in words for
        the trainer (plain text).

        Raises:
            ValueError: an empty or too long text; ``to`` is no trainee of this class.
        """
        clean = clean_message_text(text)
        if to is not None and not isinstance(to, str):
            raise ValueError("Choose whom to send the message to.")
        connected = self.connected_names()
        if to is not None and to not in connected and to not in self.gradebook.trainees.names():
            raise ValueError(f"{to:.60} is not in the class; choose a trainee in the list, or all trainees.")
        names = connected if to is None else [to]
        sent = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        if names:
            try:
                self.gradebook.messages.add(clean, names, to_all=to is None, sent_at=sent)
            except GradebookError as exc:
                log.error("a message was not kept: %s", exc)
                raise ValueError("The class gradebook cannot be written now, so the message was not sent; "
                                 "try again in a moment.") from None
        with self._lock:
            entries = {e[2]: e for e in self._trainees.values() if e[2] in names}
        self._deliver_kept(entries)
        if to is None:
            n = len(names)
            return f"Sent to {n} trainee{'s' if n != 1 else ''}." if n else "No trainee is connected: nobody got it."
        return f"Sent to {to}." if to in connected else f"{to} is not connected: the message waits until they join again."

    def _kept_messages(self, name: str) -> list[ClassMessage]:
        """The messages the gradebook keeps for ``name`` (not dismissed), oldest first."""
        try:
            kept = self.gradebook.messages.waiting([name]).get(name, [])
        except GradebookError:
            log.exception("the messages of %r could not be read", name)
            return []
        return [ClassMessage(mid, text, None if to_all else name, sent) for mid, to_all, sent, text in kept]

    def _deliver_kept(self, entries: dict[str, tuple[Session, TraineeRecorder, str]]) -> None:
        """Hand each of this process's trainees of ``entries`` (by name) the messages the
        gradebook keeps for them that their session was not handed yet (shown on viser's loop,
        on that session only)."""
        if not entries:
            return
        try:
            kept = self.gradebook.messages.waiting(list(entries))
        except GradebookError:
            log.exception("the class's messages could not be read")
            return
        for name, rows in kept.items():
            session = entries[name][0]
            with self._lock:
                if self._trainees.get(id(session)) is not entries[name]:
                    continue
                handed = self._handed.setdefault(id(session), set())
                new = [ClassMessage(mid, text, None if to_all else name, sent)
                       for mid, to_all, sent, text in rows if mid not in handed]
                handed &= {row[0] for row in rows}
                handed.update(m.message_id for m in new)
            if new:
                self._hand_to_loop(session.guard(functools.partial(self._show, session, new)))

    @staticmethod
    def _show(session: Session, messages: list[ClassMessage]) -> None:
        for message in messages:
            session.show_message(message)

    def _note_dismissed(self, session: Session, name: str) -> None:
        """After a ``notice`` signal of ``name``'s session: the messages that were on its screen
        and are not any more were dismissed there (or pushed out by newer ones): the gradebook
        forgets them for ``name``."""
        now = {m.message_id for m in session.messages}
        with self._lock:
            before = self._on_screen.get(id(session), set())
            self._on_screen[id(session)] = now
        gone = sorted(before - now)
        if gone:
            try:
                self.gradebook.messages.dismiss(name, gone)
            except GradebookError:
                log.exception("the dismissal of %r's messages could not be kept", name)
