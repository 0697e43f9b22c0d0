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

The class room holds small owners, one job each: :class:`~tcp_pendant.classroom.roster.Roster`
(who sits here), :class:`~tcp_pendant.classroom.exercise_setup.ExerciseSetup` (what the trainer
set, kept across restarts), :class:`~tcp_pendant.classroom.trainer_login.TrainerLogin` (the
token), :class:`~tcp_pendant.classroom.dashboards.Dashboards` (the open dashboards and their
throttle), :class:`~tcp_pendant.classroom.message_delivery.MessageDelivery` (the messages) and
:class:`~tcp_pendant.classroom.heartbeat.Heartbeat` (the other processes);
``classroom.trainee_settings`` changes one trainee's pendant.

Threads: the session callbacks run on viser's event loop (``Session.on_loop``); connects and
disconnects come from viser's thread pool and hand their trainer-view refresh to the loop
(``hand_to_loop``). The class's own lists are guarded by one lock.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

from tcp_pendant.classroom.class_board import ClassBoard
from tcp_pendant.classroom.class_language import kept_language
from tcp_pendant.classroom.class_views import ClassViews, WelcomeWindow
from tcp_pendant.classroom.dashboards import RENDER_INTERVAL_S, TICK_S, Dashboards
from tcp_pendant.classroom.exercise_rules import DistanceAids
from tcp_pendant.classroom.exercise_setup import EXERCISE_IDS, ExerciseSetup, clean_methods
from tcp_pendant.classroom.grade_rows import GradeRow
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.grades_csv import to_csv
from tcp_pendant.classroom.heartbeat import Heartbeat, LostSeat
from tcp_pendant.classroom.library_rights import DEFAULT_LIBRARY_QUOTA, MAX_LIBRARY_QUOTA, trainee_rights
from tcp_pendant.classroom.message_delivery import MessageDelivery
from tcp_pendant.classroom.names import TraineeNameError, validate_trainee_name
from tcp_pendant.classroom.recorder import TraineeRecorder, TraineeStatus
from tcp_pendant.classroom.replay import CalibrationReplay, calibration_replay
from tcp_pendant.classroom.restore import restored_words, runs_to_restore
from tcp_pendant.classroom.roster import Roster, Seat
from tcp_pendant.classroom.trainee_settings import apply_rules, mount_mystery
from tcp_pendant.classroom.trainees import TraineeJoin
from tcp_pendant.classroom.trainer_login import TrainerLogin
from tcp_pendant.classroom.trainer_pushes import TrainerPushes
from tcp_pendant.calibrate.pendant_rules import UNRESTRICTED, ExerciseRules, LibraryRights
from tcp_pendant.controller import ToolModel
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.translation import ENGLISH, N_, Translator

__all__ = ["EXERCISE_IDS", "RENDER_INTERVAL_S", "TICK_S", "ClassRoom", "clean_methods"]

log = logging.getLogger(__name__)

_RELEASED = N_("The trainer released the name {name}: this browser left the class. Join under your own name.")
_OTHER_TAB = N_("{name} joined from another tab or window of this browser, so this one left the class. Close "
                "it, or join here again (the other one then leaves).")


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
        self.tools = dict(tools)
        self.tool_keys = tuple(self.tools)
        self.setup = ExerciseSetup(gradebook.settings, self.tool_keys, exercise, instructions=instructions,
                                   allowed_methods=allowed_methods, min_touches=min_touches)
        """What the trainer set for the class (exercise, aids, Auto-touch, tool, brief)."""
        self.login = TrainerLogin(gradebook, trainer_token)
        self.trainer_token = self.login.token
        """The trainer token (None: the class's, kept hashed in the gradebook, not known here)."""
        self.gradebook = gradebook
        if exercise_seed is not None and (isinstance(exercise_seed, bool) or not isinstance(exercise_seed, int)):
            raise ValueError(f"The exercise seed must be a whole number, got {exercise_seed!r:.40}.")
        self._exercise_seed = exercise_seed      # None: the gradebook's, read when first needed
        self._hand_to_loop = hand_to_loop
        self._views = views
        self._join_lock = threading.Lock()       # one join or release at a time
        self.clock = clock
        self.roster = Roster()
        self.dashboards = Dashboards(lambda: (self.board(), set(self.connected_names())), call_later)
        self.messages = MessageDelivery(gradebook, self.roster, hand_to_loop)
        self.heartbeat = Heartbeat(gradebook, self.roster, presence_poll_s, hand_to_loop=hand_to_loop,
                                   on_lost=self._lost, on_push=lambda push: self.pushes.apply_remote(push),
                                   deliver=self.messages.deliver_kept, refresh=self.refresh_trainers)
        self.holder = self.heartbeat.holder
        """This server process's id in the gradebook's presence table (host, pid, a nonce)."""
        self.pushes = TrainerPushes(gradebook, self.setup, self.roster, self.heartbeat, tools=self.tools,
                                    seed=self._seed, hand_to_loop=hand_to_loop, is_trainer=self.dashboards.shows)

    # ------------------------------------------------------------ what the trainer set
    @property
    def exercise(self) -> str | None:
        """The class's exercise (None: free practice; "mystery")."""
        return self.setup.exercise

    @property
    def distance_aids(self) -> DistanceAids | None:
        """The distance aids as the trainer last pushed them (``ExerciseSetup.distance_aids``)."""
        return self.setup.distance_aids

    @property
    def auto_touch(self) -> bool | None:
        """Auto-touch as the trainer last allowed it (None: the exercise's default)."""
        return self.setup.auto_touch

    @property
    def instructions(self) -> str:
        """The exercise's instructions (plain text; "" none)."""
        return self.setup.instructions

    @property
    def allowed_methods(self) -> tuple[str, ...] | None:
        """The wizard kinds trainees may start (None: every method)."""
        return self.setup.allowed_methods

    @property
    def min_touches(self) -> int:
        """The fewest touches a Finish takes (0: none)."""
        return self.setup.min_touches

    @property
    def rules(self) -> ExerciseRules:
        """The rules every trainee's pendant follows now."""
        return self.setup.rules

    # ------------------------------------------------------------ sessions
    def attach(self, session: Session) -> WelcomeWindow:
        """Show the "Your name" prompt in a new per-browser session (returns the prompt)."""
        prompt = self._class_views().welcome(session, lambda name, key: self._joined(self.named(session, name, key)),
                                             lambda token: self.open_trainer(session, token))
        session.views["identity"] = prompt
        self.roster.welcome(session, prompt)
        session.tools.set_library_rights(self._library_rights(session, None))   # no change before a name
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
        return UNRESTRICTED if self.dashboards.shows(session) else trainee_rights(name, self.library_quota)

    def _seed(self) -> int:
        if self._exercise_seed is None:
            self._exercise_seed = self.gradebook.settings.exercise_seed()
        return self._exercise_seed

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
            if self.roster.released(session) == clean:
                raise TraineeNameError(N_("The trainer released the name {name} from this browser; join "
                                          "under your own name."), name=clean)
            holder = self.roster.by_name(clean, other_than=session)
            elsewhere = self.heartbeat.held_elsewhere(clean)
            if (holder is not None or elsewhere) and not self.gradebook.trainees.holds_key(clean, key):
                raise TraineeNameError(N_("{name} is already connected in another browser; pick another "
                                          "name or ask the trainer to release it."), name=clean)
            join = self.gradebook.trainees.join(clean, key)
            if holder is not None:         # the same browser (its key): the newer tab takes the name
                self._leave(holder, _OTHER_TAB, forget=False)
            self._start(session, join)
        self.refresh_trainers()
        return join

    def _start(self, session: Session, join: TraineeJoin) -> TraineeRecorder:
        with session.lock:
            sid = self.gradebook.records.start_session(join.trainee_id, "per-browser")
            session.wizard_commands.keep_honest_records()             # the trainee's export carries no answer key
            recorder = TraineeRecorder(self.gradebook, sid, join.name, session.workflow,
                                       exercise_id=self.exercise)
            # claimed before the name is in the table the heartbeat reads: a beat never sees a
            # name of ours that the presence table does not give to us yet
            self.heartbeat.claim(join.name, recorder.status)
            follow = self.roster.sit(Seat(session, recorder, join.name))
            self.messages.welcome(session, join.name)     # what the trainee had not dismissed yet
            if follow:
                session.subscribe(lambda change: self._on_change(session, change))
            session.wizard_commands.set_hide_truth(self.exercise is not None)
            session.tools.set_library_rights(self._library_rights(session, join.name))
            if self.exercise == "mystery":
                mount_mystery(session, recorder, join.name, self._seed(), self.tools)
            apply_rules(session, self.rules, self.distance_aids)
            self._restore(session, recorder, join.name)
        return recorder

    def _on_change(self, session: Session, change: SessionChange) -> None:
        seat = self.roster.seat(session)
        if seat is None:                  # not (or no longer) a named trainee: nothing to store
            return
        if change.notice:
            self.messages.note_dismissed(session, seat.name)
        before = seat.recorder.status
        seat.recorder.on_change(change)
        if seat.recorder.status != before:
            self.refresh_trainers()

    def _end(self, seat: Seat) -> bool:
        """The gradebook session of ``seat`` ends and its row moves to those who left; then it
        leaves the roster (True: it was still seated)."""
        try:
            seat.recorder.disconnected()
        except Exception:
            log.exception("ending the gradebook session of %r failed", seat.name)
        self.heartbeat.depart(seat)       # before it leaves the table: the row is never missing
        if not self.roster.unseat(seat):
            return False
        self.heartbeat.drop(seat.name)
        return True

    def _leave(self, seat: Seat, message: str, *, forget: bool) -> None:
        """The session of ``seat`` is no longer its trainee: its gradebook session ends, its row
        moves to those who left, and its welcome window opens again with ``message`` (an English
        msgid with ``{name}``: shown in the trainee's language, with the seat's name)."""
        session = seat.session
        message = session.translator.gettext(message).format(name=seat.name)
        if not self.roster.holds(seat):
            return
        prompt = self.roster.prompt(session)
        if not self._end(seat):
            return
        session.tools.library_rights = self._library_rights(session, None)  # at once: it changes nothing more
        self._hand_to_loop(session.loop.guard(lambda: session.tools.set_library_rights(session.tools.library_rights)))
        if prompt is not None:         # on the loop, after this callback: no two sessions' locks at once
            self._hand_to_loop(session.loop.guard(lambda: prompt.reopen(message, forget=forget)))

    def release(self, name: str, *, tr: Translator = ENGLISH) -> str:
        """The trainer releases ``name``: the gradebook forgets its browser key and a browser
        connected under it leaves the class (its welcome window opens again and its page script
        forgets the name). Returns what happened, in words for the trainer (plain text, in
        ``tr``'s language)."""
        if not isinstance(name, str):
            raise ValueError("Choose the name to release.")
        with self._join_lock:
            held = self.gradebook.trainees.release(name)
            elsewhere = self.gradebook.presence.drop(name) and name not in self.roster.names()
            holders = self.roster.all_named(name)
            for seat in holders:
                self.roster.note_released(seat.session, name)
                self._leave(seat, _RELEASED, forget=True)
        self.refresh_trainers()
        if not held and not holders and not elsewhere:
            return tr.gettext("{name} was not held by any browser.").format(name=name)
        if holders or elsewhere:
            return tr.gettext("Released {name} and its browser left the class: the next browser that joins as "
                              "{name} gets the trainee's records.").format(name=name)
        return tr.gettext("Released {name}: the next browser that joins as {name} gets the trainee's "
                          "records.").format(name=name)

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
        indices = session.wizard_commands.restore_runs([r.run for r in restored])
        for index, r in zip(indices, restored):
            recorder.adopt(index, r.calibration_id, r.touch_ids)
        tr = session.translator
        session.notify(tr.gettext("Calibration restored"), restored_words(restored, tr=tr), kind="info")

    def detach(self, session: Session) -> None:
        """The session closed (its browser left)."""
        self.dashboards.drop(session)
        self.messages.forget(session)
        seat = self.roster.forget(session)
        if seat is not None and not self._end(seat):
            self.heartbeat.drop(seat.name)    # its name goes unless this process holds it again
        self._hand_to_loop(self.refresh_trainers)

    # ------------------------------------------------------------ presence (server processes)
    def start(self) -> None:
        """Start the heartbeat thread (the server calls it; module docstring)."""
        self.heartbeat.start()

    def close(self) -> None:
        """Stop the heartbeat and free every name this process holds (the server stops)."""
        self.heartbeat.close()

    def beat(self) -> None:
        """One heartbeat (the thread of :meth:`start` every ``presence_poll_s``; tests call it):
        renew this process's names with their rows; a name this process lost (taken by the same
        browser on another process, released by the trainer there) sends its session back to
        the welcome window; take in the other processes' rows and the trainer's pushes made
        there; hand this process's trainees the messages the gradebook keeps for them that
        they were not handed yet (sent on another process, or before they came here)."""
        self.heartbeat.beat()

    def _lost(self, lost: list[LostSeat]) -> None:
        for seat, released in lost:
            if released:
                self.roster.note_released(seat.session, seat.name)
                self._leave(seat, _RELEASED, forget=True)
            else:
                self._leave(seat, _OTHER_TAB, forget=False)
        self.refresh_trainers()

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
        client_id = getattr(session.client, "client_id", None)
        who = "a shared page" if client_id is None else f"browser {client_id}"
        if not self.login.check(token, self.source_address(session), self.clock(), who):
            return False
        if self.dashboards.shows(session):
            return True
        view = self._class_views().dashboard(session, self)
        session.views["trainer"] = view
        self.dashboards.add(session, view)
        session.tools.set_library_rights(UNRESTRICTED)        # the trainer renames and deletes every slot
        return True

    def refresh_trainers(self) -> None:
        """Re-render every open dashboard (on viser's event loop): at once when the last render
        is :data:`RENDER_INTERVAL_S` old, else once when it is (later changes join that one)."""
        self.dashboards.refresh()

    # ------------------------------------------------------------ the dashboard's data
    def board(self) -> ClassBoard:
        """The class as the gradebook knows it (``Gradebook.board.read``)."""
        return self.gradebook.board.read()

    def replay(self, name: str) -> CalibrationReplay | None:
        """The latest calibration of ``name`` that has a touch, from the gradebook (None: none)."""
        cid = self.gradebook.records.last_calibration(name)
        return None if cid is None else calibration_replay(self.gradebook, cid)

    def reset_wizard(self, name: str, *, forward: bool = True, tr: Translator = ENGLISH) -> str:
        """Cancel the running wizard of the trainee ``name`` (``Session.cancel_wizard`` on their
        session only; kept, resumable; the gradebook records the cancel) and tell them. Returns
        what happened, in words for the trainer (plain text). A trainee connected on another
        server process of the class gets it there at its next beat (``forward``; False: a
        request from there, applied here only)."""
        return self.pushes.reset(name, forward=forward, tr=tr)

    def push_to(self, name: str, exercise: str | None | bool = False, tool_key: str | None = None,
                hide_distance: str | None = None, auto_touch: bool | None = None, *, forward: bool = True,
                tr: Translator = ENGLISH) -> str:
        """Push settings to the one trainee ``name``: ``exercise`` (False: keep; None: free
        practice; "mystery": their mystery tool), ``tool_key`` (None: keep; ignored with the
        mystery exercise), distance aids ``hide_distance`` ("locked" / "hidden" / "shown", None:
        keep) and Auto-touch (None: keep). Only that trainee's session is changed; until their
        next reconnect or the next push to all. Returns what happened (plain text). A trainee
        connected on another server process gets it there (``forward``, as :meth:`reset_wizard`)."""
        return self.pushes.to_one(name, exercise, tool_key, hide_distance, auto_touch, forward=forward, tr=tr)

    def trainee_statuses(self) -> list[TraineeStatus]:
        """Rows of the live table: this process's connected trainees in order of arrival, those
        connected on the other server processes of the class (by name, as they last beat),
        then those who were connected and left, on any process of the class, the latest first,
        with their last row (``Gradebook.presence.departed``; a trainee connected again is not among
        them)."""
        return self.heartbeat.trainee_statuses()

    def grade_rows(self) -> list[GradeRow]:
        return self.gradebook.grades.rows()

    def grades_csv(self) -> str:
        return to_csv(self.gradebook.grades.rows(), self.gradebook.grades.attendance())

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
        return self.pushes.settings(exercise, tool_key, hide_distance, auto_touch, keep=keep)

    @property
    def class_language(self) -> str | None:
        """The language the trainer pushed to the class (None: none; ``classroom.class_language``)."""
        return kept_language(self.gradebook.settings)

    def push_language(self, language: str, *, keep: bool = True) -> int:
        """Set ``language`` (a code of ``translation.languages``) on every trainee's pendant, each
        told in it; browsers that connect later start in it (kept in the gradebook, ``keep`` as
        for :meth:`push_settings`). A trainee may switch back. Returns how many named trainees of
        this process.

        Raises:
            ValueError: an unknown code.
        """
        return self.pushes.language(language, keep=keep)

    def push_language_to(self, name: str, language: str, *, forward: bool = True, tr: Translator = ENGLISH) -> str:
        """Set ``language`` on the one trainee ``name``'s pendant (until their browser reconnects),
        told in it; returns what happened, in words for the trainer (``forward`` as for
        :meth:`reset_wizard`; ``tr``: the trainer's language).

        Raises:
            ValueError: an unknown code.
        """
        return self.pushes.language_to(name, language, forward=forward, tr=tr)

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
        return self.pushes.brief(instructions, allowed_methods, min_touches, keep=keep)

    # ------------------------------------------------------------ messages
    def connected_names(self) -> list[str]:
        """Names of the trainees connected now on every server process of the class (the
        trainer's "To" choices): this process's in order of arrival, then the other processes'
        by name (the presence table); the one place the dashboard learns who is connected."""
        return self.heartbeat.connected_names()

    def send_message(self, text: str, to: str | None = None, *, tr: Translator = ENGLISH) -> str:
        """Send ``text`` (plain text) to every connected trainee of the class (``to`` None) or
        to the trainee named ``to`` (connected, or one who left: it waits until they join
        again). It is kept in the gradebook for each of them until they dismiss it
        (``Gradebook.messages.add``), shown at once to those on this process and by the other
        processes' heartbeat to theirs (module docstring). Returns what happened, in words for
        the trainer (plain text).

        Raises:
            ValueError: an empty or too long text; ``to`` is no trainee of this class.
        """
        return self.messages.send(text, to, self.connected_names(), tr=tr)
