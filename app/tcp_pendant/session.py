"""One pendant session: a robot (virtual controller), its captured touches and its GUI/scene.

The server makes one :class:`Session` per browser (``on_client_connect``) and drops it on
disconnect; in ``--shared`` mode there is one session whose GUI and scene are the server's
(every browser sees and drives the same robot).

State and its one owner each (docs/architecture.md, "State owners and the change signal"):

* the session owns its robot (``controller``: joints, mounted physical tool, active tool data),
  its active library slot (``active_slot``), its touches and its copy of the library's list
  (``library_tools``, re-read by :meth:`Session.reload_library`);
* the library (``tcpcal.ToolLibrary``, one file shared by every session and process) owns only
  the stored tools; its ``active_slot`` is the CLI's ``tools activate`` and the ``--shared``
  mode's start tool: a per-browser session starts with no active tool (TCP = flange), never
  reads it and never writes it; the ``--shared`` session starts with it and writes it when a
  tool is activated or saved there.

The session is the only command surface of its state. Its commands: the robot's motion
(:meth:`Session.jog`, :meth:`Session.set_joints`, :meth:`Session.set_joint`,
:meth:`Session.ready`, :meth:`Session.home`, :meth:`Session.move_tcp_to`), the tools
(:meth:`Session.mount_tool`, :meth:`Session.set_exercise_tool`, :meth:`Session.mount_step_tool`,
:meth:`Session.activate`, :meth:`Session.deactivate`,
:meth:`Session.set_active_data`, :meth:`Session.apply_saved`, :meth:`Session.reload_library`),
the free touches (:meth:`Session.record_touch`, :meth:`Session.delete_touch`) and the
calibration wizards of its :class:`~tcp_pendant.calibrate.CalibrationWorkflow`
(:attr:`Session.workflow`, built by the server with the session and owned by it:
:meth:`Session.start_wizard`, :meth:`Session.start_from_touches`, :meth:`Session.record_step`,
:meth:`Session.auto_touch`, :meth:`Session.back`, :meth:`Session.next_step` (Next, or Finish on
the last step), :meth:`Session.cancel_wizard`, :meth:`Session.resume_wizard`,
:meth:`Session.save_result`, ...). Views never change the controller or the workflow
themselves. Each command ends in ONE change signal: every function given to
:meth:`Session.subscribe` is called with a :class:`SessionChange` saying what to re-render
(pose, tool, touches, wizard, library, notice), what happened (``events``: typed facts taken when it
happened, ``tcp_pendant.events``) and carrying the robot's
:class:`~tcp_pendant.controller.pose_state.PoseState`, computed once for all of them. Views
subscribe and re-render from state; they never call each other. Inside :meth:`Session.batch`
the changes of several commands are merged into one signal (a Calibrate click that mounts a
tool, moves the robot and saves emits once, at its end).

A jog press that waited on a busy event loop (more than :data:`COALESCE_AFTER_S` since it
arrived: the server is behind) is carried out at once, but its change signal waits for the end
of the loop's current round (``loop.call_soon``): the next presses of the same browser already
queued in that round merge into it, so the views re-render (and viser sends) once for them
all; any other signal of the session first takes the waiting one in. On an idle server every
press signals at once, as before.

Threading: every GUI callback is registered through :meth:`Session.on_loop`, an ``async``
callback, so viser runs it on its event loop, one at a time and in the order the browser's
messages arrived, and the messages it queues are pushed from the loop's own thread (viser's
message buffer is not safe to push to from other threads). :meth:`Session.guard` is the
synchronous part: it takes ``session.lock`` (a re-entrant lock, still taken because a few
things run elsewhere: workers copy state under it (Check, record replay), tests drive
sessions from their own thread; the session itself is built on the loop, see
``PendantApp.session_steps``), ignores events after the session closed, and turns any exception into a
notification instead of a crash (a browser can send anything). Work from another thread is
handed to the loop (the server's library watcher: ``loop.call_soon_threadsafe``). Work whose
size a browser controls (a check, a scan, a record's replay, Auto-touch's pose probes) is a
job detached from the session, run in the server's job pool by :meth:`Session.run_job`
(``job_pool``: one job per session, a bounded queue), awaited without blocking the loop.
"""

from __future__ import annotations

import asyncio
import functools
import logging
import threading
import time
from collections.abc import Callable, Coroutine, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, ContextManager, Literal, Protocol, TypeVar, cast

import numpy as np

from tcpcal.library import ToolLibrary
from tcpcal.errors import TcpcalError
from tcpcal.tool import Tool
from tcp_pendant.calibrate.autotouch import AutoTouchOutcome
from tcp_pendant.calibrate.pendant_rules import (
    FREE_PRACTICE,
    UNRESTRICTED,
    ExerciseRules,
    LibraryRights,
    RuleRefusal,
    check_tool_change,
)
from tcp_pendant.calibrate.workflow import AutoTouchRequest, CalibrationWorkflow, ControllerToolState
from tcp_pendant.controller import ControllerError, JogResult, ToolModel, VirtualController
from tcp_pendant.controller.pose_state import PoseState, pose_state, pose_state_key
from tcp_pendant.controller.scenarios import Scenario, ScenarioWorld, bent_tool, realize
from tcp_pendant.events import Crash, SessionEvent
from tcp_pendant.job_pool import JobPool, default_pool
from tcp_pendant.pendant import Jogger, touch_label
from tcp_pendant.refusal_notices import RefusalNotices
from tcp_pendant.wizards import Wizard, WizardResult, WizardStateError, wizard_class, wizard_classes

__all__ = ["MAX_WAITING_MESSAGES", "Browser", "ClassMessage", "GuiTarget", "NotificationColor", "Session",
           "SessionChange", "Touch"]

log = logging.getLogger(__name__)
F = TypeVar("F", bound=Callable[..., Any])
R = TypeVar("R")

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
    jog: JogResult | None = None
    state: PoseState | None = None
    events: tuple[SessionEvent, ...] = ()

    def merged(self, other: "SessionChange") -> "SessionChange":
        """Both changes as one (flags or-ed; the newer jog outcome; events in order; the state
        is recomputed)."""
        return SessionChange(pose=self.pose or other.pose, tool=self.tool or other.tool,
                             touches=self.touches or other.touches, wizard=self.wizard or other.wizard,
                             library=self.library or other.library, notice=self.notice or other.notice,
                             jog=other.jog if other.jog is not None else self.jog,
                             events=self.events + other.events)


@dataclass(eq=False)
class Session:
    """State of one pendant (see the module docstring).

    Attributes:
        controller: the session's virtual controller.
        library: the server's shared tool library.
        workflow: the session's calibration wizards (``CalibrationWorkflow``; the server builds
            it with the session, which binds itself as its ``ToolState``); change it only with
            the session's wizard commands.
        client: the browser (None in ``--shared`` mode).
        target: where the views draw (the client, or the server in ``--shared`` mode).
        touches: recorded flange poses, in order.
        lock: guards every state change.
        jogger: the jog keys' logic (settings + continuous timing).
        active_slot: library slot of the active tool data (None: no tool or typed-in only);
            change it with the commands, never directly.
        shared: the ``--shared`` session (activating or saving a tool also sets the library's
            active slot, its start tool).
        calibrate_container: the GUI container of the "Calibrate" tab, where wizard views plug
            in (see ``tcp_pendant.views.calibrate``); None before the views are built.
        ready_q_rad: the "Ready pose" button's joint angles (None: the robot's HOME).
        views: named view objects (``"scene"``, ``"pendant"``, ``"tools"``, ...), for tests
            only: app code never looks a view up through it.
        scene_labels: the scene's labels (viser label handles): at the tool and the tip
            (``"flange"``, ``"tool"``, ``"tip"``), which the wizards' scene places apart, and
            ``"world"``, ``"computed"``, ``"true"``, ``"target"``; presenter mode draws them all
            larger.
        hide_distance: "Hide distance" (training: judge the touch by eye); change it with
            :meth:`set_hide_distance`. While it is on, only a collision stops a jog at the tip.
        rules: what the trainer's exercise allows (``calibrate.pendant_rules``, made by ``classroom.exercise_rules``), with its
            instructions; change it with :meth:`set_rules`.
        rng: the session's random generator (Auto-touch's operator error and directions, the
            beam's repeatability, the scenarios the trainer plays): the server draws it from its
            one seed (``--seed``), so a seeded lesson replays the same way.
        jobs: the server's pool of browser-triggered jobs (``job_pool.JobPool``, one for the
            whole server: :meth:`run_job`); default the process's pool.
    """

    controller: VirtualController
    library: ToolLibrary
    workflow: CalibrationWorkflow
    client: Browser | None = None
    target: GuiTarget | None = None
    touches: list[Touch] = field(default_factory=list)
    lock: threading.RLock = field(default_factory=threading.RLock)
    active_slot: int | None = None
    shared: bool = False
    calibrate_container: Any | None = None
    ready_q_rad: np.ndarray | None = None
    views: dict[str, Any] = field(default_factory=dict)
    scene_labels: dict[str, Any] = field(default_factory=dict)
    hide_distance: bool = False
    rules: ExerciseRules = FREE_PRACTICE
    rng: np.random.Generator = field(default_factory=np.random.default_rng)
    jobs: JobPool = field(default_factory=default_pool, repr=False)

    def __post_init__(self) -> None:
        if self.target is None:
            self.target = self.client
        if self.workflow.controller is not self.controller:
            raise ControllerError("A session's workflow must drive the session's own controller.")
        self.workflow.state = self              # the workflow mounts tools and sets data through us
        self.jogger = Jogger(self.controller)
        self.jogger.stop_at_contact = not self.hide_distance
        self.closed = False
        self._subscribers: list[Callable[[SessionChange], None]] = []
        self._close_callbacks: list[Callable[[], None]] = []
        self._pose_state: PoseState | None = None
        self._batch_depth = 0
        self._pending: SessionChange | None = None
        self._deferred: SessionChange | None = None    # jog presses' signal waiting for the loop's round
        self._deferred_signal: Callable[[], None] | None = None   # guard(_signal_deferred), made once
        self.refusals = RefusalNotices()
        """Which refusals of a click are shown (:meth:`notify_refusal`)."""
        self.library_tools: dict[int, Tool] = {}
        """The library's tools as this session last read them (slot -> tool)."""
        self.library_error: str | None = None
        """Why the library could not be read at the last :meth:`reload_library` (None: it was)."""
        self.library_owners: dict[int, str] = {}
        """Who owns each owned slot, as this session last read it (a class's trainees)."""
        self.library_rights: LibraryRights = UNRESTRICTED
        """How this pendant may change the library (``calibrate.pendant_rules``; the classroom
        sets it with :meth:`set_library_rights`)."""
        self.scenario: Scenario = Scenario()
        """The systematic error played (training; off by default); change it with :meth:`set_scenario`."""
        self.scenario_world: ScenarioWorld | None = None
        """The drawn errors of :attr:`scenario` (None while it is off)."""
        self._scenario_tip0: np.ndarray | None = None   # the reference tip before a scenario moved it
        self._beam_pinned = False  # the moved-reference scenario pinned the default beam sensor
        self._bent: dict[str, ToolModel] = {}           # tool key -> its bent version (bent_tool)
        self._unbent: dict[int, ToolModel] = {}         # id(bent version) -> the tool as it was
        self._free_records = 0                          # "Record point" clicks (free touches)
        self._scenario_base = 0                         # touches recorded before the scenario was set
        self._scenario_touches = 0                      # touches recorded since (never decreases)
        self._crashed = False                           # the touch geometry's crash state at the last signal
        self._truth_hidden_always = False               # --hide-truth: no exercise's end shows it
        self._messages: list[ClassMessage] = []         # the trainer's messages not dismissed yet, oldest first
        self.exercise_tool: ToolModel | None = None
        """The physical tool the exercise keeps mounted (a classroom's mystery tool; None: the
        trainee mounts any tool); change it with :meth:`set_exercise_tool`."""

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

        Commands call it; so does a view after a command of its own model (the Calibrate tab,
        whose workflow drove the robot). Inside :meth:`batch` it is merged and emitted later."""
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
        moved_reference = self._play_moved_reference()
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
            change = SessionChange(pose=True, tool=change.tool, touches=change.touches, wizard=change.wizard,
                                   library=change.library, notice=change.notice, jog=change.jog, state=state,
                                   events=change.events + events if events else change.events)
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
        lock, :meth:`guard`, :meth:`on_loop` and :meth:`notify` serve what is built next; the
        caller clears the browser's GUI and scene."""
        with self.lock:
            self._subscribers.clear()
            self.views.clear()
            self.scene_labels.clear()
            self.calibrate_container = None

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
            loop = _running_loop()
            if (waited_s is None or waited_s <= COALESCE_AFTER_S or loop is None or self.target is None
                    or self._batch_depth):
                self.moved(jog)
                return
            scheduled = self._deferred is not None
            before = None if self._deferred is None else self._deferred.jog
            keep = jog if before is None or before.ok or not jog.ok else before
            self._deferred = SessionChange(pose=True, jog=keep)
            if not scheduled:
                signal = self._deferred_signal          # the guard checks closed when called: one serves all
                if signal is None:
                    signal = self._deferred_signal = self.guard(self._signal_deferred)
                loop.call_soon(signal)

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

    def set_rules(self, rules: ExerciseRules) -> None:
        """The exercise's rules (the classroom sets them): locked distance aids switch "Hide
        distance" on; free practice releases the exercise's tool (:meth:`set_exercise_tool`:
        the lock follows the exercise); the views re-render (``pose`` and ``wizard``: the
        checkbox, Auto-touch, the methods offered; ``notice``: the instructions' banner;
        ``tool``: the Mounted tool lock)."""
        with self.lock, self.batch():
            self.rules = rules
            if rules.distance_locked:
                self.set_hide_distance(True)
            if not rules.in_exercise:
                self.set_exercise_tool(None)
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

    # ------------------------------------------------------------ tools (state owner)
    def mount_tool(self, tool: ToolModel) -> None:
        """Bolt another physical tool on (the active tool data does not change). While the
        "bent tool" scenario plays, the tool bolted on is the bent version of ``tool``.

        Raises:
            RuleRefusal: the exercise keeps its tool mounted (:attr:`exercise_tool`) and
                ``tool`` is another one; nothing changes.
        """
        with self.lock:
            held = self.exercise_tool
            if held is not None:
                check_tool_change(held.key, held.label, tool.key, tool.label)
            self._mount(tool)

    def _mount(self, tool: ToolModel) -> None:
        tool = self._physical(tool)
        if tool is self.controller.mounted_tool:
            return
        self.controller.mount_tool(tool)
        self.changed(tool=True)

    def set_exercise_tool(self, tool: ToolModel | None) -> None:
        """The exercise's tool (the classroom's mystery tool of this trainee): mounted now, and
        from now on "Mounted tool" is locked to it. :meth:`mount_tool` refuses another tool in
        words; a calibration may only measure it (:meth:`start_wizard`); a wizard step's own
        tool change (the XYZ reference method's reference tool, :meth:`mount_step_tool`) may
        mount another for that run's steps, and the exercise's tool is mounted again when the
        run ends or is cancelled. None: released, any tool may be mounted (free practice;
        :meth:`set_rules` of free practice releases it too). One ``tool`` signal."""
        with self.lock, self.batch():
            if tool is None and self.exercise_tool is None:
                return
            self.exercise_tool = tool
            if tool is not None:
                self._mount(tool)
            self.changed(tool=True)

    def mount_step_tool(self, tool: ToolModel) -> None:
        """The tool change a wizard step asks for (its "Mount the tool" button, Auto-touch):
        :meth:`mount_tool`, except that while the exercise holds its tool, the run on show may
        mount the tool of its current step when that run calibrates the exercise's tool (the
        XYZ reference method's reference tool for its first touch).

        Raises:
            RuleRefusal: the exercise holds its tool and this is no such step.
        """
        with self.lock:
            if not self._step_may_mount(tool.key):
                self.mount_tool(tool)
                return
            self._mount(tool)

    def _step_may_mount(self, key: str) -> bool:
        """The run on show is in progress, calibrates the exercise's tool and its current step
        needs the tool ``key`` (the exception to the exercise's lock)."""
        held, run, w = self.exercise_tool, self.workflow.run, self.workflow.wizard
        return (held is not None and run is not None and w is not None and w.status == "in_progress"
                and run.true_tool_key == held.key and w.step.mount_tool_key == key)

    def _remount_exercise_tool(self) -> None:
        """The exercise's tool back on the flange, unless the run on show is in progress,
        calibrates it and one of its steps asks for the tool on the flange now (the XYZ
        reference method between its two touches)."""
        held = self.exercise_tool
        mounted = self.controller.mounted_tool
        if held is None or mounted.key == held.key:
            return
        run, w = self.workflow.run, self.workflow.wizard
        if (run is not None and w is not None and w.status == "in_progress" and run.true_tool_key == held.key
                and any(step.mount_tool_key == mounted.key for step in w.steps)):
            return
        self._mount(held)

    def set_active_data(self, tool: Tool | None, slot: int | None = None) -> None:
        """Make ``tool`` the active tool data (typed in, a wizard's, or the library's ``slot``);
        None: no tool (TCP = flange). The library file is not written."""
        with self.lock:
            self.controller.set_active_tool(tool)
            self.active_slot = slot if tool is not None else None
            self.changed(tool=True)

    def activate(self, slot: int) -> Tool:
        """"Activate": the library tool in ``slot`` (as last read) becomes the active tool data.
        In ``--shared`` mode the library's active slot is set too (the shared start tool).

        Raises:
            ValueError: the slot is empty.
        """
        with self.lock:
            tool = self.library_tools.get(int(slot))
            if tool is None:
                raise ControllerError(f"Slot {slot} of the tool library is empty; pick a stored tool.")
            if self.shared:
                self.library.activate(int(slot))
            self.set_active_data(tool, int(slot))
            return tool

    def deactivate(self) -> None:
        """"No tool": TCP = flange (this session only; the library file is not written)."""
        self.set_active_data(None)

    def apply_saved(self, slot: int, tool: Tool) -> None:
        """After ``tool`` was saved in ``slot`` of the library: it is the active tool data, and
        the session's list of tools is re-read (``--shared``: the library's active slot too)."""
        with self.lock, self.batch():
            if self.shared:
                self.library.activate(int(slot))
            self.reload_library()
            self.set_active_data(tool, int(slot))

    def reload_library(self) -> dict[int, Tool]:
        """Re-read the library's tools into :attr:`library_tools` (an unreadable file gives no
        tools and :attr:`library_error` says why) and signal ``library``."""
        with self.lock:
            try:
                tools = self.library.tools()
                owners = self.library.owners()
            except TcpcalError as exc:  # e.g. permissions: ToolLibraryError names the file
                tools, owners, self.library_error = {}, {}, str(exc)
            else:
                self.library_error = None
            self.library_tools = dict(tools)
            self.library_owners = dict(owners)
            self.changed(library=True)
            return self.library_tools

    def set_library_rights(self, rights: LibraryRights) -> None:
        """How this pendant may change the library from now on (a class: the trainee's slots
        only; ``classroom.library_rights``)."""
        with self.lock:
            self.library_rights = rights
            self.changed(library=True)

    def store_tool(self, slot: int, tool: Tool) -> None:
        """Write ``tool`` into ``slot`` of the library (numeric entry) and re-read the list.

        Raises:
            tcpcal.TcpcalError: the library refused (the name is in another slot, the slot is
                another trainee's, the trainee's quota is full, ...).
        """
        with self.lock:
            rights = self.library_rights
            with rights.in_words():
                self.library.save(int(slot), tool, **rights.save_kwargs())
            self.reload_library()

    def rename_tool(self, slot: int, name: str) -> None:
        """Rename the library tool in ``slot`` (a trainee: one of theirs); the active data
        carries the new name when it is that slot's. One signal."""
        with self.lock, self.batch():
            rights = self.library_rights
            with rights.in_words():
                self.library.rename(int(slot), name, **rights.owner_kwargs())
            self.reload_library()
            renamed = self.library_tools.get(int(slot))
            if self.active_slot == int(slot) and renamed is not None:
                self.set_active_data(renamed, int(slot))

    def delete_tool(self, slot: int) -> None:
        """Delete the library tool in ``slot`` (a trainee: one of theirs) and re-read the list."""
        with self.lock:
            rights = self.library_rights
            with rights.in_words():
                self.library.remove(int(slot), **rights.owner_kwargs())
            self.reload_library()

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

    def clients(self) -> list[Browser]:
        """The browser(s) that show this session: its own, or every browser of the shared GUI."""
        if self.client is not None:
            return [self.client]
        get = getattr(self.target, "get_clients", None)
        return list(get().values()) if callable(get) else []

    # ------------------------------------------------------------ scenarios (training)
    def set_scenario(self, kind: str, seed: int = 0) -> ScenarioWorld:
        """Play a systematic error (``controller.scenarios``; training): "off", "bent_tool",
        "robot_accuracy" or "moved_reference", its errors drawn from ``seed``.

        The physical world changes, the controller's beliefs do not: ``robot_accuracy`` sets the
        controller's ``true_kinematics`` (readouts, recorded poses and jogs stay on the model);
        ``bent_tool`` bolts on the bent version of the mounted tool (and of any tool mounted
        later; the library data stay as they were); ``moved_reference`` knocks the reference tip
        after the scenario's touch ``k`` counted from now (free touches and wizard touches). The
        previous scenario is undone first (the tip back where it was, the unbent tool). Ends in
        one change signal (``tool``).

        Raises:
            ControllerError: unknown kind or a bad seed (names what to choose).
        """
        with self.lock:
            scenario = Scenario(kind, seed=seed)  # type: ignore[arg-type]
            c = self.controller
            # undo the previous one
            if self._scenario_tip0 is not None:
                c.set_reference_tip(self._scenario_tip0)
            if self._beam_pinned:                   # the default beam follows the tip again
                c.set_beam_sensor(None)
                self._beam_pinned = False
            unbent = self._unbent.get(id(c.mounted_tool), c.mounted_tool)
            self._bent.clear()
            self._unbent.clear()
            self._scenario_tip0 = c.reference_tip_world_m
            world = realize(scenario, c.kinematics, unbent)
            self.scenario = scenario
            self.scenario_world = None if scenario.kind == "off" else world
            c.set_true_kinematics(None if world.true_kinematics is c.kinematics else world.true_kinematics)
            if scenario.kind == "bent_tool":
                self._bent[unbent.key] = world.tool_true
                self._unbent[id(world.tool_true)] = unbent
            c.mount_tool(self._physical(unbent))
            self._scenario_base = self._records_total()
            self._scenario_touches = 0
            self._play_moved_reference()
            self.changed(tool=True)
            return world

    def _physical(self, tool: ToolModel) -> ToolModel:
        """The tool as it physically is under the scenario (bent_tool: its bent version)."""
        tool = self._unbent.get(id(tool), tool)
        world = self.scenario_world
        if world is None or world.tool_bend is None:
            return tool
        bent = self._bent.get(tool.key)
        if bent is None:
            bent = self._bent[tool.key] = bent_tool(tool, world.tool_bend)
            self._unbent[id(bent)] = tool
        return bent

    def _records_total(self) -> int:
        """Touches recorded in this session so far: free ones and the wizards' poses."""
        return self._free_records + sum(len(run.wizard.recorded_poses) for run in self.workflow.runs)

    def _play_moved_reference(self) -> bool:
        """Moved reference tip: place the tip for the touches recorded since the scenario was
        set (the count never decreases: a knocked tip stays knocked). True if it moved."""
        world = self.scenario_world
        if world is None or world.reference_move is None or self._scenario_tip0 is None:
            return False
        self._scenario_touches = max(self._scenario_touches, self._records_total() - self._scenario_base)
        tip = world.reference_move.tip_world_m(self._scenario_tip0, self._scenario_touches)
        if np.array_equal(tip, self.controller.reference_tip_world_m):
            return False
        c = self.controller
        if c.beam_sensor_is_default and not self._beam_pinned:
            # the knock moves the spike, not the beam device that stands beside it
            c.set_beam_sensor(c.beam_sensor)
            self._beam_pinned = True
        c.set_reference_tip(tip)
        return True

    # ------------------------------------------------------------ motion (commands)
    def jog(self, axis: str | int, sign: int, *, hold_tick: bool = False,
            waited_s: float | None = None) -> JogResult | None:
        """One jog key: a press (one increment, or nothing in continuous mode) or a tick of a held
        key (``hold_tick``), by the session's :class:`~tcp_pendant.pendant.Jogger`; ends in one
        ``pose`` signal carrying the move's outcome (a press that waited ``waited_s`` on a busy
        loop: :meth:`moved_soon`). None: nothing moved (a skipped tick)."""
        with self.lock:
            res = self.jogger.key(axis, sign, hold_tick=hold_tick)
            if res is not None:
                if hold_tick:
                    self.moved(res)
                else:
                    self.moved_soon(res, waited_s)
            return res

    def set_jog_setting(self, name: str, value: Any) -> None:
        """One jog setting of the Jog tab (``JogSettings`` field ``name``: mode, frame,
        increment, override_pct); the readouts re-render (a ``pose`` signal: the offset to the
        tip is given in the jog frame).

        Raises:
            ControllerError: an unknown setting or value (names the choices).
        """
        with self.lock:
            self.jogger.settings = self.jogger.settings.with_(**{name: value})
            self.changed(pose=True)

    def release_jog(self) -> None:
        """The held key was released (or the hold stopped): no more continuous motion."""
        with self.lock:
            self.jogger.release()

    def set_joints(self, q_rad: np.ndarray, *, status: bool = True) -> JogResult:
        """Put the robot at the joint angles ``q_rad`` (rad; m for a prismatic joint), clipped to
        the limits by the controller; one ``pose`` signal, which carries the move's outcome for
        the status line unless ``status`` is False (a scan's film: the status line stays)."""
        with self.lock:
            self.controller.set_q(np.asarray(q_rad, dtype=float))
            res = JogResult(True, 1.0, None, "")
            self.moved(res if status else None)
            return res

    def set_joint(self, index: int, value_deg: float) -> float:
        """Joint ``index`` (0-based) to ``value_deg``: the joint sliders' unit, the joint
        variable in degrees (``degrees(q_rad)``, as their limits are), clipped to its limits;
        returns the value applied in that unit.

        Raises:
            ControllerError: no such joint, or a value that is not a finite number.
        """
        with self.lock:
            k = self.controller.kinematics
            if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < k.n_joints:
                raise ControllerError(f"There is no joint {index!r}; the robot has {k.n_joints}.")
            value = float(value_deg)
            if not np.isfinite(value):
                raise ControllerError(f"Joint A{index + 1} needs a finite value, got {value_deg!r}.")
            q = self.controller.q_rad
            q[index] = float(np.clip(np.radians(value), k.lower_rad[index], k.upper_rad[index]))
            self.set_joints(q)
            return float(np.degrees(self.controller.q_rad[index]))

    def ready(self) -> JogResult:
        """"Ready pose": the session's start pose (``ready_q_rad``), or HOME when it has none."""
        with self.lock:
            if self.ready_q_rad is None:
                return self.home()
            return self.set_joints(self.ready_q_rad)

    def home(self) -> JogResult:
        """The robot's HOME position (the controller's); one ``pose`` signal."""
        with self.lock:
            self.controller.go_home()
            res = JogResult(True, 1.0, None, "")
            self.moved(res)
            return res

    def move_tcp_to(self, T_world_tcp_m: np.ndarray) -> JogResult:
        """Move the active TCP to ``T_world_tcp_m`` ((4,4), WORLD, m; the gizmo), by the
        controller's Cartesian motion rules; one ``pose`` signal with the outcome."""
        with self.lock:
            res = self.controller.move_tcp_to(np.asarray(T_world_tcp_m, dtype=float))
            self.moved(res)
            return res

    # ------------------------------------------------------------ wizards (commands)
    @contextmanager
    def _wizard_command(self, *, moves: bool = False) -> Iterator[None]:
        """Run a wizard command in one batch that ends in one ``wizard`` signal (``pose`` too
        when the command may have moved the robot), also when it raised; a run that ended or
        was left gives the exercise's tool back to the flange (:meth:`set_exercise_tool`)."""
        with self.lock, self.batch():
            try:
                yield
            finally:
                self._remount_exercise_tool()
                self.changed(wizard=True, pose=moves)

    def _check_method(self, kind: str, options: dict[str, Any] | None = None) -> None:
        """The exercise's methods (``rules.allowed_methods``) and, for a method without Add
        point whose touch count is chosen at start (``options["n_points"]``), its minimum
        number of touches.

        Raises:
            RuleRefusal: the method is not allowed, or too few touches are asked for.
            WizardError: unknown kind, or options the method refuses (``Wizard.parse_options``).
        """
        cls = wizard_class(kind)
        self.rules.check_method(kind, {c.kind: c.title for c in wizard_classes()})
        counted = any(o.name == "n_points" for o in cls.options)
        if counted and not cls.supports_add_point and options is not None and self.rules.min_touches:
            n_points = int(cls.parse_options(options)["n_points"])
            if self.rules.touches_refusal(n_points, can_add_point=False) is not None:
                raise RuleRefusal(f"This exercise asks for at least {self.rules.min_touches} touches: set "
                                  f"Touches to {self.rules.min_touches} or more for the {cls.title} method.")

    def finish_refusal(self) -> str | None:
        """Why Finish of the wizard on show is refused by the exercise (too few touches for a
        method whose touch count the trainee chooses, ``CalibrationWorkflow.touches_short``),
        None when it is not; the step panel shows it, :meth:`next_step` and Auto-touch's last
        touch do not finish then."""
        with self.lock:
            return self.workflow.touches_short()

    def start_wizard(self, kind: str, **options: Any) -> Wizard:
        """Open a wizard of the registered ``kind`` with its start options (the open one is
        cancelled and kept; ``CalibrationWorkflow.start``).

        Raises:
            RuleRefusal: the exercise does not allow the method, or (a method without Add point)
                its ``n_points`` is below the exercise's minimum; nothing is opened.
        """
        with self._wizard_command(moves=True):
            self._check_method(kind, options)
            return self.workflow.start(kind, **options)

    def start_from_touches(self, *, estimator: str = "lstsq") -> Wizard:
        """XYZ 4-point from the free touches recorded with Record point, in order.

        Raises:
            RuleRefusal: the exercise does not allow the XYZ 4-point method.
        """
        with self._wizard_command(moves=True):
            self._check_method("xyz4")
            return self.workflow.start_from_touches(list(self.touches), estimator=estimator)

    def record_step(self) -> None:
        """Record the current flange pose for the open wizard's step."""
        with self._wizard_command():
            self.workflow.record()

    def auto_touch(self, request: AutoTouchRequest) -> AutoTouchOutcome:
        """Training mode: the controller performs the current step (``CalibrationWorkflow.auto_touch``)."""
        with self._wizard_command(moves=True):
            return self.workflow.auto_touch(request)

    async def auto_touch_in_pool(self, request: AutoTouchRequest, *,
                                 shown: Callable[[AutoTouchOutcome], Any] | None = None) -> AutoTouchOutcome:
        """:meth:`auto_touch` with the probes of the poses it reaches (a TCP check's rotations
        from there, ``calibrate.jobs.POSE_CHECKS``) run in the job pool (:meth:`run_job`), off
        viser's event loop: the moves and the record are wizard commands on the loop, each
        ending in its own signal, the probes awaited in between (no probe: one command, one
        signal, as :meth:`auto_touch`). ``shown(outcome)`` runs inside the last command (the
        view's words join its signal). A robot moved meanwhile records nothing
        (``autotouch.MOVED_DURING_PROBE``).

        Refused before anything moves while this session's job runs or its share of the job pool
        is used up (:meth:`admit_job`), and without a signal when the state alone refuses it
        (training off, the wizard finished: ``CalibrationWorkflow.auto_touch_refusal``). Its
        moves are not charged to the share: a wizard has a few steps, and a trainee clicks
        Auto-touch once per step, a whole calibration in a few seconds.

        Raises:
            JobRefused: this session's previous job still runs, its share is used up
                (:meth:`admit_job`), or the queue is full.
            WizardStateError: as :meth:`auto_touch`; the calibration on show changed meanwhile.
        """
        self.admit_job()
        with self.lock:                 # refused by the state alone: nothing moved, nothing to show
            why = self.workflow.auto_touch_refusal()
        if why is not None:
            raise WizardStateError(why)
        steps = self.workflow.auto_touch_steps(request)

        def advance(answer: str | None, first: bool) -> tuple[Callable[[], str | None] | None, Any]:
            with self._wizard_command(moves=True):
                try:
                    return (next(steps) if first else steps.send(answer)), None
                except StopIteration as stop:
                    if shown is not None:
                        shown(stop.value)
                    return None, stop.value

        probe, out = advance(None, True)
        try:
            while probe is not None:
                answer = await self.run_job(probe, what="Auto-touch's check of the pose it reached")
                if self.closed:
                    raise WizardStateError("The session was closed.")
                probe, out = advance(answer, False)
        finally:
            steps.close()
        return cast(AutoTouchOutcome, out)

    def back(self) -> None:
        """One step back (from the result: to the last step); nothing is deleted."""
        with self._wizard_command():
            self.workflow.back()

    def next_step(self) -> WizardResult | None:
        """Next step, or on the last step Finish: the result (a wizard with a controller job runs
        it here, synchronously; the views run it in the job pool instead: :meth:`next_step_in_pool`).

        Raises:
            RuleRefusal: Finish with fewer touches than the exercise asks for
                (:meth:`finish_refusal`); the wizard stays on its last step.
        """
        with self._wizard_command(moves=True):
            return self.workflow.next()

    def cancel_wizard(self) -> bool:
        """Leave the open wizard (kept, resumable). True when it had no result yet (the caller
        may say that nothing recorded is lost)."""
        with self._wizard_command():
            unfinished = self.workflow.result is None
            self.workflow.cancel()
            return unfinished

    def resume_wizard(self, index: int | None = None) -> Wizard:
        """Resume a calibration left half-way (``index`` in the runs; default the newest)."""
        with self._wizard_command(moves=True):
            return self.workflow.resume(index)

    def mount_required_tool(self) -> ToolModel:
        """The tool change the current step asks for."""
        with self._wizard_command(moves=True):
            return self.workflow.mount_required_tool()

    def add_point(self) -> None:
        """One more touch step (the wizards that declare ``supports_add_point``)."""
        with self._wizard_command():
            self.workflow.require_wizard().add_point()

    def set_variant(self, variant: Any) -> None:
        """Switch the open wizard's variant (one of its class's ``variants`` values)."""
        with self._wizard_command():
            self.workflow.require_wizard().set_variant(variant)

    def set_training(self, on: bool) -> None:
        """Training mode on or off (truth after a result, Auto-touch)."""
        with self._wizard_command():
            self.workflow.training = bool(on)

    def save_result(self, name: str, slot: int | None = None) -> tuple[int, Tool]:
        """"Save to tool library": the result on show as tool ``name`` (slot None: the slot with
        that name, else the first free one); it becomes the active tool data."""
        with self._wizard_command(moves=True):
            return self.workflow.save(name, slot)

    def edit_result(self, fn: Callable[[Wizard], Any]) -> Any:
        """A change of the result on show that its wizard offers (the 4-point's estimator,
        outlier drop, restore): ``fn(wizard)`` inside one ``wizard`` signal."""
        with self._wizard_command():
            return fn(self.workflow.require_wizard())

    def set_hide_truth(self, hide: bool, *, always: bool = False) -> None:
        """A classroom exercise (True): no result shows the true TOOL frame or the error
        against it, and the methods that measure the tool by themselves are refused. ``always``
        (the server's ``--hide-truth``, a projector): from now on the truth stays hidden, whatever
        an exercise's end says."""
        with self._wizard_command():
            self._truth_hidden_always = self._truth_hidden_always or always
            self.workflow.hide_truth = bool(hide) or self._truth_hidden_always

    def keep_honest_records(self) -> None:
        """A classroom session: the session record this session exports carries no truth."""
        with self.lock:
            self.workflow.honest_records = True

    def add_physical_tool(self, tool: ToolModel) -> None:
        """Make ``tool`` one of the physical tools the wizards know (a classroom's mystery tool:
        its label in a step's tool-change words)."""
        with self._wizard_command():
            self.workflow.tools[tool.key] = tool

    def take_controller_job(self) -> Any:
        """The controller job the wizard on show waits for before it can finish (None: none);
        taken on the loop, run by the caller in a worker, handed back with
        :meth:`hand_in_controller_job`."""
        with self.lock:
            wiz = self.workflow.wizard
            if wiz is None or not wiz.on_last_step:
                return None
            return self.workflow.controller_job()

    async def next_step_in_pool(self) -> WizardResult | None:
        """Next, or Finish with the controller job the wizard on show waits for (a TCP check's
        rotations, a beam scan) taken on the loop, run in the job pool (:meth:`run_job`, off
        viser's event loop) and handed in on the loop; no job: :meth:`next_step`.

        Raises:
            JobRefused: this session's previous job still runs, or the queue is full.
            WizardStateError: as :meth:`next_step` (the job cannot be taken: the words say why).
        """
        job = self.take_controller_job()
        if job is None:
            return self.next_step()
        outcome = await self.run_job(job.run, what=f"the {job.wizard.title} wizard's controller job")
        if self.closed:
            return None
        return self.hand_in_controller_job(job, outcome)

    def hand_in_controller_job(self, job: Any, outcome: Any) -> WizardResult | None:
        """The outcome of a controller job to its wizard (its result, if it finished)."""
        with self._wizard_command(moves=True):
            return self.workflow.give_controller_job(job, outcome)

    def restore_runs(self, runs: Any) -> list[int]:
        """The calibrations this trainee had in progress before a restart, back on screen
        (``CalibrationWorkflow.restore``); one ``wizard`` signal."""
        with self._wizard_command(moves=True):
            return self.workflow.restore(runs)

    def load_record(self, loaded: Any) -> Any:
        """A session record read and replayed off the loop (``session_record.load_and_replay``)
        added to the runs; returns its replay checks."""
        with self._wizard_command():
            return self.workflow.add_loaded(loaded)

    def admit_job(self) -> None:
        """Refuse at once a job this session may not start now (its previous job still runs, or
        its jobs used their share of the server's time: ``JobPool.admit``), before the event
        loop spends time on taking it.

        Raises:
            JobRefused: ``SessionBusy`` or ``OverShare``; the message says what to do.
        """
        self.jobs.admit(self)

    @contextmanager
    def charged(self) -> Iterator[None]:
        """Count the event loop's time spent inside against this session's share of the job
        pool (``JobPool.charge``): a job's work done on the loop (a TCP check's setup and the
        result it shows)."""
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self.jobs.charge(self, time.perf_counter() - t0)

    async def run_job(self, fn: Callable[[], R], *, what: str) -> R:
        """Run ``fn()``, a job detached from the session (its own copies of what it reads, taken
        on the loop with its limits checked), in the server's job pool, off viser's event loop,
        and return its value (or raise its exception). One job per session at a time, the
        rested sessions' jobs first (``job_pool``).

        Args:
            fn: the job; it must not touch the session, its GUI or its controller.
            what: the job in words with its article ("a TCP check"), for the refusal of
                another job of this session meanwhile.

        Raises:
            JobRefused: this session's previous job still runs (``SessionBusy``) or the
                server's queue is full (``PoolFull``); the message says what to do.
        """
        return await self.jobs.run(self, fn, what=what)

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
                raise ControllerError(f"There is no touch P{index + 1 if isinstance(index, int) else index}; "
                                      f"{len(self.touches)} recorded.")
            del self.touches[index]
            self.touches[:] = [Touch(t.T_world_flange, touch_label(i, t.T_world_flange), t.distance_mm,
                                     t.joints_deg, t.tool_key) for i, t in enumerate(self.touches)]
            self.changed(touches=True)

    # ------------------------------------------------------------ callbacks
    def guard(self, fn: F) -> F:
        """Wrap a GUI callback: lock, skip after close, report errors as notifications."""

        @functools.wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            if self.closed:
                return None
            try:
                with self.lock:
                    if self.closed:
                        return None
                    return fn(*args, **kwargs)
            except ValueError as exc:  # our packages' errors are ValueErrors with clear messages
                self.notify("Not done", str(exc), kind="warning")
            except Exception as exc:  # never let a browser event kill the server
                log.exception("callback %s failed", getattr(fn, "__name__", fn))
                self.notify("Internal error", f"{type(exc).__name__}: {exc}", kind="error")
            return None

        return wrapper  # type: ignore[return-value]

    def on_loop(self, fn: Callable[..., Any]) -> Callable[..., Coroutine[Any, Any, None]]:
        """``fn`` as a GUI callback that viser runs on its event loop, under :meth:`guard`.

        viser awaits an ``async`` callback on its event loop (a plain one goes to its thread
        pool), so callbacks wrapped here run one at a time, in the order the browser sent its
        messages: a callback reads ``event.target.value`` after the previous message was
        handled, and every message it queues is pushed from the loop's thread. It must be
        short (a jog step or an IK solve takes milliseconds); it never awaits. Our own
        assignments to a handle's value fire it too, later on the loop, with
        ``event.client is None``.

        Args:
            fn: the callback, given viser's event (it may also be called with no argument).

        Returns:
            An ``async`` function to register with ``on_click`` / ``on_update`` / ``on_hold``.
        """
        guarded = self.guard(fn)

        @functools.wraps(fn)
        async def callback(*args: Any, **kwargs: Any) -> None:
            guarded(*args, **kwargs)

        return callback

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
        self.views.clear()
        self.scene_labels.clear()
        self._pose_state = None
        self.calibrate_container = None
        self.workflow.state = ControllerToolState(self.controller)   # no cycle back to the closed session
        self.client = None
        self.target = None


def _running_loop() -> asyncio.AbstractEventLoop | None:
    try:
        return asyncio.get_running_loop()
    except RuntimeError:
        return None
