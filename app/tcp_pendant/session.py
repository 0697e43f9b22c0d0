"""One pendant session: a robot (virtual controller), its captured touches and its GUI/scene.

The server makes one :class:`Session` per browser (``on_client_connect``) and drops it on
disconnect; in ``--shared`` mode there is one session whose GUI and scene are the server's
(every browser sees and drives the same robot).

State and its one owner each (docs/architecture.md, "State owners and the change signal"):
the session owns its robot (``controller``: joints, mounted physical tool, active tool data),
its touches, "Hide distance", the exercise's rules and the trainer's messages on screen; the
small owners it builds and holds own the rest, each in its module:

* ``session.motion`` (:class:`~tcp_pendant.session_motion.MotionCommands`): jog, joints,
  Ready, Home, the gizmo;
* ``session.tools`` (:class:`~tcp_pendant.session_tools.SessionTools`): the mounted tool and
  the exercise's lock on it, the active tool data and slot, the session's copy of the library's
  list (the library file itself, shared by every session, owns only the stored tools);
* ``session.wizard_commands`` (:class:`~tcp_pendant.session_wizard.WizardCommands`): the
  calibration wizards of the session's :class:`~tcp_pendant.calibrate.CalibrationWorkflow`
  (``session.workflow``, built by the server with the session);
* ``session.scenario_player`` (:class:`~tcp_pendant.session_scenario.ScenarioPlayer`): the
  systematic error played for training (:meth:`Session.set_scenario`);
* ``session.loop`` (:class:`~tcp_pendant.session_loop.SessionLoop`): GUI callbacks on viser's
  event loop (``on_loop``, ``guard``), jobs off it in the server's job pool (``run_job``);
* ``session.views`` (:class:`~tcp_pendant.session_views.ViewRegistry`): the views by name, for
  tests, and the scene labels views share (``session.views.labels``).

The session is the only command surface of its state: its own commands
(:meth:`Session.record_touch`, :meth:`Session.delete_touch`, :meth:`Session.set_hide_distance`,
:meth:`Session.set_rules`, :meth:`Session.show_message`, :meth:`Session.set_scenario`,
:meth:`Session.set_language`, ...) and
those of the owners above, reached through it. Views never change the controller or the
workflow themselves. Each command ends in ONE change signal of the session: every function
given to :meth:`Session.subscribe` is called with a :class:`SessionChange` saying what to
re-render (pose, tool, touches, wizard, library, notice), what happened (``events``: typed facts
taken when it happened, ``tcp_pendant.events``) and carrying the robot's
:class:`~tcp_pendant.controller.pose_state.PoseState`, computed once for all of them. Views
subscribe and re-render from state; they never call each other. Inside :meth:`Session.batch`
the changes of several commands are merged into one signal (a Calibrate click that mounts a
tool, moves the robot and saves emits once, at its end).

A jog press that waited on a busy event loop (more than :data:`COALESCE_AFTER_S` since it
arrived: the server is behind) is carried out at once, but its change signal waits for the end
of the loop's current round (``loop.call_soon``): the next presses of the same browser already
queued in that round merge into it, so the views re-render (and viser sends) once for them
all; any other signal of the session first takes the waiting one in. On an idle server every
press signals at once. Threads: ``session_loop``'s module docstring.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from typing import Any, ContextManager, Literal, Protocol

import numpy as np

from tcpcal.library import ToolLibrary
from tcp_pendant.calibrate.pendant_rules import FREE_PRACTICE, ExerciseRules
from tcp_pendant.calibrate.workflow import CalibrationWorkflow, ControllerToolState
from tcp_pendant.controller import ControllerError, JogResult, VirtualController
from tcp_pendant.controller.pose_state import PoseState, pose_state, pose_state_key
from tcp_pendant.controller.scenarios import ScenarioWorld
from tcp_pendant.controller.words import Words
from tcp_pendant.events import Crash, SessionEvent
from tcp_pendant.job_pool import JobPool, default_pool
from tcp_pendant.pendant import Jogger, touch_label
from tcp_pendant.refusal_notices import RefusalNotices
from tcp_pendant.session_loop import SessionLoop, running_loop
from tcp_pendant.session_motion import MotionCommands
from tcp_pendant.session_scenario import ScenarioPlayer
from tcp_pendant.session_tools import SessionTools
from tcp_pendant.session_views import ViewRegistry
from tcp_pendant.session_wizard import WizardCommands
from tcp_pendant.translation import SOURCE_LANGUAGE, translator

__all__ = ["MAX_WAITING_MESSAGES", "Browser", "ClassMessage", "GuiTarget", "NotificationColor", "Session",
           "SessionChange", "Touch"]

log = logging.getLogger(__name__)

COALESCE_AFTER_S = 0.010
"""A jog press that waited longer than this (s) on the event loop signals at the end of the
loop's round, merged with the same session's next presses (module docstring)."""

NotificationColor = Literal["blue", "green", "yellow", "red"]
"""The colours of the session's notifications (info, success, warning, error)."""

_COLORS: dict[str, NotificationColor] = {
    "info": "blue", "success": "green", "warning": "yellow", "error": "red"}


class GuiTarget(Protocol):
    """What views draw into: a ``viser.ClientHandle`` (one browser) or a ``viser.ViserServer``
    (every browser, ``--shared``). The session itself only sends its change signal's messages
    as one batch (``atomic()``); the views reach the scene and the GUI through
    ``views.gui_util.target_of``, which types it as viser's (the server gives the session no
    other), so the session's layer imports no viser."""

    def atomic(self) -> ContextManager[None]: ...


class Browser(GuiTarget, Protocol):
    """One browser that shows the session (a ``viser.ClientHandle``; the views type it as one:
    ``views.gui_util.client_of``): what the session itself calls on it."""

    def add_notification(self, title: str, body: str, *, color: NotificationColor,
                         auto_close_seconds: float) -> object: ...


MAX_WAITING_MESSAGES = 10
"""Messages a session (and the gradebook, per trainee) keeps undismissed; a newer one pushes out
the oldest."""


@dataclass(frozen=True)
class ClassMessage:
    """One message of the trainer as a trainee's session keeps it (``classroom.class_messages``:
    how the class sends and keeps them).

    Attributes:
        message_id: the gradebook's id of this trainee's copy, unique in the class (the
            Dismiss button names it).
        text: plain text (``classroom.class_messages.clean_message_text``).
        to: the trainee's name it was sent to, None for the whole class.
        sent_at_utc: when it was sent, ISO 8601 UTC (``2026-12-02T09:30:00Z``).
    """

    message_id: int
    text: str
    to: str | None
    sent_at_utc: str


@dataclass(frozen=True)
class Touch:
    """One recorded flange pose.

    Attributes:
        T_world_flange: (4,4) flange pose in WORLD, metres (read-only copy).
        label: text of the touch list, e.g. ``"P1  X 525.0 Y 0.0 Z 400.0 mm"``.
        distance_mm: true tool tip to reference tip when recorded (for the trainer; not shown
            when the distance is hidden).
        joints_deg: the joint values when recorded, degrees (mm for a prismatic joint), in
            joint order (as RoboDK and ABB store touches); () when not known.
        tool_key: the physical tool mounted when recorded (None: not known); an XYZ 4-point
            started from the touches measures that tool.
    """

    T_world_flange: np.ndarray
    label: str
    distance_mm: float = float("nan")
    joints_deg: tuple[float, ...] = ()
    tool_key: str | None = None

    def __post_init__(self) -> None:
        T = np.array(self.T_world_flange, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise ControllerError(f"A touch needs a finite 4x4 flange pose, got shape {T.shape}.")
        T.setflags(write=False)
        object.__setattr__(self, "T_world_flange", T)
        joints = tuple(float(v) for v in self.joints_deg)
        if not all(np.isfinite(joints)):
            raise ControllerError(f"A touch's joint values must be finite, got {joints}.")
        object.__setattr__(self, "joints_deg", joints)


@dataclass(frozen=True, eq=False)
class SessionChange:
    """What one command changed (the session's change signal; see the module docstring).

    Attributes:
        pose: the robot moved, or something its pose state depends on changed (joints, mounted
            tool, active tool data): the scene and the readouts re-render.
        tool: the mounted tool, the active tool data or the active slot changed.
        touches: a touch was recorded or deleted.
        wizard: the Calibrate workflow's state changed (a click in the Calibrate tab).
        library: the session's copy of the library's list was re-read.
        notice: the exercise's instructions or the trainer's messages waiting here changed
            (the banner and the message box re-render).
        language: the session's language changed (:meth:`Session.set_language`): every view
            re-renders its texts with ``session.translator``.
        jog: the outcome of the move, for the status line (None: not a jog, or unchanged).
        state: the robot's pose state after the change (computed once, for every subscriber),
            None when neither ``pose`` nor ``tool`` is set.
        events: what happened, in order (``tcp_pendant.events``: a run started, a touch
            recorded with its facts at record time, a run finished or cancelled, a crash, a
            tool saved); empty for a change that only re-renders.
    """

    pose: bool = False
    tool: bool = False
    touches: bool = False
    wizard: bool = False
    library: bool = False
    notice: bool = False
    language: bool = False
    jog: JogResult | None = None
    state: PoseState | None = None
    events: tuple[SessionEvent, ...] = ()

    def merged(self, other: "SessionChange") -> "SessionChange":
        """Both changes as one (flags or-ed; the newer jog outcome; events in order; the state
        is recomputed)."""
        return SessionChange(pose=self.pose or other.pose, tool=self.tool or other.tool,
                             touches=self.touches or other.touches, wizard=self.wizard or other.wizard,
                             library=self.library or other.library, notice=self.notice or other.notice,
                             language=self.language or other.language,
                             jog=other.jog if other.jog is not None else self.jog,
                             events=self.events + other.events)


@dataclass(eq=False)
class Session:
    """State of one pendant and its one change signal (see the module docstring).

    Attributes:
        controller: the session's virtual controller.
        library: the server's shared tool library.
        workflow: the session's calibration wizards (``CalibrationWorkflow``; the server builds
            it with the session, whose :attr:`tools` become its ``ToolState``); change it only
            with :attr:`wizard_commands`.
        client: the browser (None in ``--shared`` mode).
        target: where the views draw (the client, or the server in ``--shared`` mode).
        touches: recorded flange poses, in order.
        lock: guards every state change.
        shared: the ``--shared`` session (activating or saving a tool also sets the library's
            active slot, its start tool).
        ready_q_rad: the "Ready pose" button's joint angles (None: the robot's HOME).
        hide_distance: "Hide distance" (training: judge the touch by eye); change it with
            :meth:`set_hide_distance`. While it is on, only a collision stops a jog at the tip.
        rules: what the trainer's exercise allows (``calibrate.pendant_rules``, made by
            ``classroom.exercise_rules``), with its instructions; change it with :meth:`set_rules`.
        rng: the session's random generator (Auto-touch's operator error and directions, the
            beam's repeatability, the scenarios the trainer plays): the server draws it from its
            one seed (``--seed``), so a seeded lesson replays the same way.
        jobs: the server's pool of browser-triggered jobs (``job_pool.JobPool``, one for the
            whole server: ``SessionLoop.run_job``); default the process's pool.
        language: the language of this browser's texts (a code of ``translation.languages``,
            or the pseudo-locale); change it with :meth:`set_language`; its messages are
            :attr:`translator`'s.

    Its owners, built with it: :attr:`jogger` (the jog keys' settings), :attr:`motion`
    (``MotionCommands``), :attr:`tools` (``SessionTools``), :attr:`wizard_commands`
    (``WizardCommands``), :attr:`scenario_player`
    (``ScenarioPlayer``), :attr:`loop` (``SessionLoop``), :attr:`views` (``ViewRegistry``) and
    :attr:`refusals` (``RefusalNotices``).
    """

    controller: VirtualController
    library: ToolLibrary
    workflow: CalibrationWorkflow
    client: Browser | None = None
    target: GuiTarget | None = None
    touches: list[Touch] = field(default_factory=list)
    lock: threading.RLock = field(default_factory=threading.RLock)
    shared: bool = False
    ready_q_rad: np.ndarray | None = None
    hide_distance: bool = False
    rules: ExerciseRules = FREE_PRACTICE
    rng: np.random.Generator = field(default_factory=np.random.default_rng)
    jobs: JobPool = field(default_factory=default_pool, repr=False)
    language: str = SOURCE_LANGUAGE

    def __post_init__(self) -> None:
        self.translator = translator(self.language)     # raises on an unknown code
        self.workflow.set_translator(self.translator)   # the wizards' steps, warnings and refusals
        if self.target is None:
            self.target = self.client
        if self.workflow.controller is not self.controller:
            raise ControllerError("A session's workflow must drive the session's own controller.")
        self.closed = False
        self.jogger = Jogger(self.controller)
        self.jogger.stop_at_contact = not self.hide_distance
        self.loop = SessionLoop(self)
        self.views = ViewRegistry()
        self.refusals = RefusalNotices(more_words=self._refusals_left_out)
        self.scenario_player = ScenarioPlayer(self.controller, self._records_total)
        self.tools = SessionTools(self)
        self.workflow.state = self.tools        # the workflow mounts tools and sets data through them
        self.wizard_commands = WizardCommands(self)
        self.motion = MotionCommands(self)
        self._subscribers: list[Callable[[SessionChange], None]] = []
        self._close_callbacks: list[Callable[[], None]] = []
        self._pose_state: PoseState | None = None
        self._batch_depth = 0
        self._pending: SessionChange | None = None
        self._deferred: SessionChange | None = None    # jog presses' signal waiting for the loop's round
        self._free_records = 0                          # "Record point" clicks (free touches)
        self._crashed = False                           # the touch geometry's crash state at the last signal
        self._messages: list[ClassMessage] = []         # the trainer's messages not dismissed yet, oldest first

    # ------------------------------------------------------------ the change signal
    def subscribe(self, fn: Callable[[SessionChange], None]) -> None:
        """Call ``fn(change)`` after every change of this session's state (under its lock, in one
        atomic GUI update with the other subscribers, in the order they subscribed)."""
        self._subscribers.append(fn)

    def add_motion_listener(self, fn: Callable[[], None]) -> None:
        """Call ``fn()`` after every change that moved the robot or its TCP (a subscription to
        :class:`SessionChange` ``pose``)."""
        def on_change(change: SessionChange) -> None:
            if change.pose:
                fn()
        on_change.__qualname__ = getattr(fn, "__qualname__", "motion listener")
        self.subscribe(on_change)

    @contextmanager
    def batch(self) -> Iterator[None]:
        """Merge the changes of the commands run inside into one signal, emitted at the end
        (also when a command raised: what it changed before is shown)."""
        with self.lock:
            self._batch_depth += 1
            try:
                yield
            finally:
                self._batch_depth -= 1
                if self._batch_depth == 0 and self._pending is not None:
                    pending, self._pending = self._pending, None
                    self._emit(pending)

    def changed(self, change: SessionChange | None = None, **what: Any) -> None:
        """Emit the change signal: ``changed(pose=True, jog=res)`` or a :class:`SessionChange`.

        Commands call it (the session's own and its owners'); so does a view after a command of
        its own model. Inside :meth:`batch` it is merged and emitted later."""
        change = SessionChange(**what) if change is None else change
        with self.lock:
            if self._batch_depth:
                self._pending = change if self._pending is None else self._pending.merged(change)
                return
            self._emit(change)

    def _emit(self, change: SessionChange) -> None:
        if self.closed:
            return
        if self._deferred is not None:            # presses waiting to signal: shown first, in this one
            change, self._deferred = self._deferred.merged(change), None
        if change.tool:                           # the open wizard checks its steps' tool changes
            self.workflow.note_mounted_tool()
        events = self.workflow.take_events()      # whoever drove the workflow, nothing is lost
        moved_reference = self.scenario_player.move_reference()
        if change.pose or change.tool or moved_reference:
            state = self.pose_state()
            crashed = bool(state.touch.crashed)
            if crashed and not self._crashed:
                run = self.workflow.run_index if self.workflow.is_open else None
                events += (Crash(float(state.touch.penetration_mm), run),)
            elif change.jog is not None and change.jog.stopped_by == "collision":   # stopped at the tip
                events += (Crash(0.0, self.workflow.run_index if self.workflow.is_open else None),)
            self._crashed = crashed
            # the change as the subscribers get it, built once: pose, its state, every event
            change = replace(change, pose=True, state=state, events=change.events + events)
        elif events:
            change = replace(change, events=change.events + events)
        subscribers = list(self._subscribers)
        if self.target is None:
            for fn in subscribers:
                fn(change)
            return
        with self.target.atomic():
            for fn in subscribers:
                try:
                    fn(change)
                except Exception:  # one view must not keep the others from showing the change
                    log.exception("session subscriber %s failed", getattr(fn, "__qualname__", fn))

    def drop_views(self) -> None:
        """Take the views down (the browser became the trainer's dashboard): they no longer
        follow the change signal and :attr:`views` forgets them. The session stays open: its
        lock, :attr:`loop` and :meth:`notify` serve what is built next; the caller clears the
        browser's GUI and scene."""
        with self.lock:
            self._subscribers.clear()
            self.views.drop()

    def on_close(self, fn: Callable[[], None]) -> None:
        """Register ``fn()``, called once when the session closes."""
        self._close_callbacks.append(fn)

    # ------------------------------------------------------------ updates
    def pose_state(self) -> PoseState:
        """The robot's current :class:`~tcp_pendant.controller.pose_state.PoseState` (link poses,
        flange, TCP, true TCP, readout, touch geometry, joint angles), computed by one FK pass
        when the controller changed (keyed by joint angles, tool data, mounted tool, reference
        tip and BASE). The change signal carries it (``SessionChange.state``): subscribers read
        that, not the controller."""
        with self.lock:
            state = self._pose_state
            key = pose_state_key(self.controller)
            if state is None or state.key != key:
                state = self._pose_state = pose_state(self.controller, key)
            return state

    def moved(self, jog: JogResult | None = None) -> None:
        """After a move of the robot (a jog, the gizmo, Home, an auto-touch): the change signal
        with ``pose`` (and the move's outcome ``jog`` for the status line)."""
        self.changed(pose=True, jog=jog)

    def moved_soon(self, jog: JogResult, waited_s: float | None) -> None:
        """:meth:`moved` after a jog press that waited ``waited_s`` on the event loop (None:
        unknown): at once on an idle loop, else at the end of the loop's round, merged with the
        session's next presses (module docstring). A stopped jog's outcome is kept over a later
        one that went through, so its message is shown."""
        with self.lock:
            if (waited_s is None or waited_s <= COALESCE_AFTER_S or running_loop() is None or self.target is None
                    or self._batch_depth):
                self.moved(jog)
                return
            before = None if self._deferred is None else self._deferred.jog
            keep = jog if before is None or before.ok or not jog.ok else before
            if self._deferred is None:
                self.loop.at_round_end(self._signal_deferred)
            self._deferred = SessionChange(pose=True, jog=keep)

    def _signal_deferred(self) -> None:
        if self._deferred is not None:
            change, self._deferred = self._deferred, None
            self._emit(change)

    def set_hide_distance(self, hide: bool) -> None:
        """"Hide distance" on or off: the readouts re-render (a ``pose`` change); while it is
        on, a jog goes through the reference tip instead of stopping there.

        Raises:
            RuleRefusal: the exercise's rules lock the distance aids and ``hide`` is False.
        """
        with self.lock:
            self.rules.check_hide_distance(bool(hide))
            if bool(hide) == self.hide_distance:
                return
            self.hide_distance = bool(hide)
            self.jogger.stop_at_contact = not self.hide_distance
            self.changed(pose=True)

    def set_language(self, language: str) -> None:
        """This session's language (a code of ``translation.languages`` or the pseudo-locale):
        the views re-render their texts (a ``language`` change); the pose, the touches and the
        wizard stay as they are, the wizards' texts (the step on show, a result's warnings) now
        composed in the new language (``CalibrationWorkflow.set_translator``). Another session's
        language never changes.

        Raises:
            ValueError: an unknown code (naming the known ones).
        """
        with self.lock:
            new = translator(language)
            if new.language == self.language:
                return
            self.language, self.translator = new.language, new
            self.workflow.set_translator(new)
            self.changed(language=True, wizard=True)

    def set_rules(self, rules: ExerciseRules) -> None:
        """The exercise's rules (the classroom sets them): locked distance aids switch "Hide
        distance" on; free practice releases the exercise's tool (``SessionTools.set_exercise_tool``:
        the lock follows the exercise); the views re-render (``pose`` and ``wizard``: the
        checkbox, Auto-touch, the methods offered; ``notice``: the instructions' banner;
        ``tool``: the Mounted tool lock)."""
        with self.lock, self.batch():
            self.rules = rules
            if rules.distance_locked:
                self.set_hide_distance(True)
            if not rules.in_exercise:
                self.tools.set_exercise_tool(None)
            self.changed(pose=True, wizard=True, notice=True)

    # ------------------------------------------------------------ the trainer's messages
    @property
    def messages(self) -> tuple[ClassMessage, ...]:
        """The trainer's messages given to this session and not dismissed, oldest first."""
        with self.lock:
            return tuple(self._messages)

    def show_message(self, message: ClassMessage) -> None:
        """Keep ``message`` until it is dismissed (the classroom delivers it; a message already
        here is not shown twice; beyond ``MAX_WAITING_MESSAGES`` the oldest goes); one
        ``notice`` signal."""
        if not isinstance(message, ClassMessage):
            raise ControllerError(f"A message must be a ClassMessage, got {type(message).__name__}.")
        with self.lock:
            if any(m.message_id == message.message_id for m in self._messages):
                return
            self._messages.append(message)
            del self._messages[:-MAX_WAITING_MESSAGES]
            self.changed(notice=True)

    def dismiss_message(self, message_id: int) -> bool:
        """The trainee dismissed the message ``message_id`` (one of :attr:`messages`); a stale
        or unknown id changes nothing. True when one was dismissed; one ``notice`` signal."""
        with self.lock:
            kept = [m for m in self._messages if m.message_id != message_id]
            if len(kept) == len(self._messages):
                return False
            self._messages = kept
            self.changed(notice=True)
            return True

    def refresh(self) -> None:
        """Re-render everything that shows the robot (the same signal as :meth:`moved`)."""
        self.changed(pose=True)

    # ------------------------------------------------------------ the browsers
    def notify(self, title: str, body: str, *, kind: str = "info") -> None:
        """Show a notification in this session's browser(s); ``kind``: info, success, warning, error.

        ``title`` and ``body`` are plain text (viser shows them as text, not markdown): pass user
        text as it is, never through ``text_escape.escape_markdown``."""
        if self.closed:
            return
        color = _COLORS.get(kind, "blue")
        for c in self.clients():
            try:
                c.add_notification(title, body, color=color, auto_close_seconds=6.0 if kind != "error" else 12.0)
            except Exception:  # the browser may have gone
                log.debug("notification to a closed client dropped", exc_info=True)

    def notify_refusal(self, title: str, body: str) -> None:
        """A click refused at once, as a warning; coalesced per session (``refusal_notices``:
        at most one every 2 s, the ones left out counted in the next)."""
        shown = self.refusals.body(body)
        if shown is not None:
            self.notify(title, shown, kind="warning")

    def _refusals_left_out(self, n: int) -> str:
        """The count of refusals a notice left out, in this session's language."""
        return self.translator.ngettext("({n} more click was refused meanwhile.)",
                                        "({n} more clicks were refused meanwhile.)", n).format(n=n)

    def clients(self) -> list[Browser]:
        """The browser(s) that show this session: its own, or every browser of the shared GUI."""
        if self.client is not None:
            return [self.client]
        get = getattr(self.target, "get_clients", None)
        return list(get().values()) if callable(get) else []

    # ------------------------------------------------------------ scenarios (training)
    def set_scenario(self, kind: str, seed: int = 0) -> ScenarioWorld:
        """Play a systematic error (``session_scenario``; training): "off", "bent_tool",
        "robot_accuracy" or "moved_reference", its errors drawn from ``seed``; one ``tool`` signal.

        Raises:
            ControllerError: unknown kind or a bad seed (names what to choose).
        """
        with self.lock:
            world = self.scenario_player.play(kind, seed)
            self.changed(tool=True)
            return world

    def _records_total(self) -> int:
        """Touches recorded in this session so far: free ones and the wizards' poses."""
        return self._free_records + sum(len(run.wizard.recorded_poses) for run in self.workflow.runs)

    # ------------------------------------------------------------ touches
    def record_touch(self) -> Touch:
        """Store the current flange pose as a touch (labelled P1, P2, ...), with the joint
        values (degrees) and the true distance."""
        with self.lock:
            T = self.controller.T_world_flange()
            touch = Touch(T, touch_label(len(self.touches), T), self.controller.touch_geometry().distance_mm,
                          tuple(self.controller.joint_angles_deg().values()), self.controller.mounted_tool.key)
            self.touches.append(touch)
            self._free_records += 1
            self.changed(touches=True)
            return touch

    def delete_touch(self, index: int) -> None:
        """Delete one touch (0-based); the others are relabelled P1..Pn in order.

        Raises:
            ControllerError: no such touch.
        """
        with self.lock:
            if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < len(self.touches):
                name = f"P{index + 1 if isinstance(index, int) else index}"
                count = len(self.touches)
                raise ControllerError(Words.by(lambda tr: tr.ngettext(
                    "There is no touch {name}; {n} recorded.", "There is no touch {name}; {n} recorded.",
                    count).format(name=name, n=count)))
            del self.touches[index]
            self.touches[:] = [Touch(t.T_world_flange, touch_label(i, t.T_world_flange), t.distance_mm,
                                     t.joints_deg, t.tool_key) for i, t in enumerate(self.touches)]
            self.changed(touches=True)

    def close(self) -> None:
        """Drop the session: no more callbacks act on it; listeners are released."""
        with self.lock:
            if self.closed:
                return
            self.closed = True
            callbacks, self._close_callbacks = self._close_callbacks, []
            self._subscribers.clear()
        for fn in callbacks:
            try:
                fn()
            except Exception:
                log.debug("close callback failed", exc_info=True)
        self.views.drop()
        self._pose_state = None
        self.workflow.state = ControllerToolState(self.controller)   # no cycle back to the closed session
        self.client = None
        self.target = None
