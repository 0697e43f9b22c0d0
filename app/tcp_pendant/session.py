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

Commands change that state in one place - :meth:`Session.mount_tool`, :meth:`Session.activate`,
:meth:`Session.deactivate`, :meth:`Session.set_active_data`, :meth:`Session.apply_saved`,
:meth:`Session.record_touch`, :meth:`Session.delete_touch`, :meth:`Session.reload_library`,
:meth:`Session.moved` (after a move of the robot) - and each ends in ONE change signal: every
function given to :meth:`Session.subscribe` is called with a :class:`SessionChange` saying what
changed (pose, tool, touches, wizard, library) and carrying the robot's
:class:`~tcp_pendant.controller.pose_state.PoseState`, computed once for all of them. Views
subscribe and re-render from state; they never call each other. Inside :meth:`Session.batch`
the changes of several commands are merged into one signal (a Calibrate click that mounts a
tool, moves the robot and saves emits once, at its end).

Threading: every GUI callback is registered through :meth:`Session.on_loop`, an ``async``
callback, so viser runs it on its event loop, one at a time and in the order the browser's
messages arrived, and the messages it queues are pushed from the loop's own thread (viser's
message buffer is not safe to push to from other threads). :meth:`Session.guard` is the
synchronous part: it takes ``session.lock`` (a re-entrant lock, still taken because a few
things run elsewhere: workers copy state under it (Check, record replay), tests drive
sessions from their own thread; the session itself is built on the loop, see
``PendantApp.session_steps``), ignores events after the session closed, and turns any exception into a
notification instead of a crash (a browser can send anything). Work from another thread is
handed to the loop (the server's library watcher: ``loop.call_soon_threadsafe``).
"""

from __future__ import annotations

import functools
import logging
import threading
from collections.abc import Callable, Coroutine, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from typing import Any, Protocol, TypeVar

import numpy as np

from tcpcal.library import ToolLibrary
from tcpcal.errors import TcpcalError
from tcpcal.tool import Tool
from tcp_pendant.controller import ControllerError, JogResult, ToolModel, VirtualController
from tcp_pendant.controller.pose_state import PoseState, pose_state, pose_state_key
from tcp_pendant.controller.scenarios import Scenario, ScenarioWorld, bent_tool, realize
from tcp_pendant.pendant import Jogger, touch_label
from tcp_pendant.pendant.exercise_rules import FREE_PRACTICE, ExerciseRules

__all__ = ["GuiTarget", "Session", "SessionChange", "Touch"]

log = logging.getLogger(__name__)
F = TypeVar("F", bound=Callable[..., Any])

_COLORS = {"info": "blue", "success": "green", "warning": "yellow", "error": "red"}


class GuiTarget(Protocol):
    """What views draw into: a ``viser.ClientHandle`` (one browser) or a ``viser.ViserServer``
    (every browser, ``--shared``). Both have ``.scene``, ``.gui`` and ``.atomic()``."""

    scene: Any
    gui: Any

    def atomic(self) -> Any: ...


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
    """

    T_world_flange: np.ndarray
    label: str
    distance_mm: float = float("nan")
    joints_deg: tuple[float, ...] = ()

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
        jog: the outcome of the move, for the status line (None: not a jog, or unchanged).
        state: the robot's pose state after the change (computed once, for every subscriber),
            None when neither ``pose`` nor ``tool`` is set.
    """

    pose: bool = False
    tool: bool = False
    touches: bool = False
    wizard: bool = False
    library: bool = False
    jog: JogResult | None = None
    state: PoseState | None = None

    def merged(self, other: "SessionChange") -> "SessionChange":
        """Both changes as one (flags or-ed; the newer jog outcome; the state is recomputed)."""
        return SessionChange(pose=self.pose or other.pose, tool=self.tool or other.tool,
                             touches=self.touches or other.touches, wizard=self.wizard or other.wizard,
                             library=self.library or other.library,
                             jog=other.jog if other.jog is not None else self.jog)


@dataclass(eq=False)
class Session:
    """State of one pendant (see the module docstring).

    Attributes:
        controller: the session's virtual controller.
        library: the server's shared tool library.
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
            only: views never reach each other through it.
        scene_labels: the scene's labels at the tool and the tip (``"flange"``, ``"tool"``,
            ``"tip"``: viser label handles), which the wizards' scene places apart.
        workflow: the session's ``CalibrationWorkflow`` (the Calibrate tab's wizards), set once
            when the views are built (None without the wizards plug-in); the Jog tab's wizard
            dock renders its state and calls its commands.
        hide_distance: "Hide distance" (training: judge the touch by eye); change it with
            :meth:`set_hide_distance`. While it is on, a jog does not stop at the reference tip.
        rules: what the trainer's exercise allows (``pendant.exercise_rules``); change it with
            :meth:`set_rules`.
    """

    controller: VirtualController
    library: ToolLibrary
    client: Any | None = None
    target: Any | None = None
    touches: list[Touch] = field(default_factory=list)
    lock: threading.RLock = field(default_factory=threading.RLock)
    active_slot: int | None = None
    shared: bool = False
    calibrate_container: Any | None = None
    ready_q_rad: np.ndarray | None = None
    views: dict[str, Any] = field(default_factory=dict)
    scene_labels: dict[str, Any] = field(default_factory=dict)
    workflow: Any | None = None
    hide_distance: bool = False
    rules: ExerciseRules = FREE_PRACTICE

    def __post_init__(self) -> None:
        if self.target is None:
            self.target = self.client
        self.jogger = Jogger(self.controller)
        self.jogger.stop_at_contact = not self.hide_distance
        self.closed = False
        self._subscribers: list[Callable[[SessionChange], None]] = []
        self._close_callbacks: list[Callable[[], None]] = []
        self._pose_state: PoseState | None = None
        self._batch_depth = 0
        self._pending: SessionChange | None = None
        self.library_tools: dict[int, Tool] = {}
        """The library's tools as this session last read them (slot -> tool)."""
        self.library_error: str | None = None
        """Why the library could not be read at the last :meth:`reload_library` (None: it was)."""
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
        self._wizard_stamps: dict[tuple[int, int], str] = {}  # (id(run), step) -> recorded_at seen

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
        if change.wizard:
            self._note_wizard_joints()
        if self._play_moved_reference():
            change = replace(change, pose=True)
        if change.pose or change.tool:
            change = replace(change, pose=True, state=self.pose_state())
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
        distance" on; the views re-render (``pose`` and ``wizard``: the checkbox, Auto-touch)."""
        with self.lock, self.batch():
            self.rules = rules
            if rules.distance_locked:
                self.set_hide_distance(True)
            self.changed(pose=True, wizard=True)

    def refresh(self) -> None:
        """Re-render everything that shows the robot (the same signal as :meth:`moved`)."""
        self.changed(pose=True)

    # ------------------------------------------------------------ tools (state owner)
    def mount_tool(self, tool: ToolModel) -> None:
        """Bolt another physical tool on (the active tool data does not change). While the
        "bent tool" scenario plays, the tool bolted on is the bent version of ``tool``."""
        with self.lock:
            tool = self._physical(tool)
            if tool is self.controller.mounted_tool:
                return
            self.controller.mount_tool(tool)
            self.changed(tool=True)

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
            except TcpcalError as exc:  # e.g. permissions: ToolLibraryError names the file
                tools, self.library_error = {}, str(exc)
            else:
                self.library_error = None
            self.library_tools = dict(tools)
            self.changed(library=True)
            return self.library_tools

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

    def clients(self) -> list[Any]:
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
        total = self._free_records
        wf = self.workflow
        for run in getattr(wf, "runs", ()) or ():
            try:
                total += len(run.wizard.recorded_poses)
            except Exception:  # a plug-in's run without poses
                continue
        return total

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

    def _note_wizard_joints(self) -> None:
        """After a wizard change: the joint values of each step the open run recorded since the
        last signal (``WizardRun.joints_deg``, exported in the session record), taken only when
        the robot is still at the recorded flange pose (else that step has none)."""
        run = getattr(self.workflow, "run", None)
        joints = getattr(run, "joints_deg", None)
        if run is None or joints is None:
            return
        poses = run.wizard.recorded_poses
        for step in [k for k in joints if k not in poses]:
            del joints[step]
        T_now: np.ndarray | None = None
        for step, pose in poses.items():
            key = (id(run), step)
            if self._wizard_stamps.get(key) == pose.recorded_at:
                continue
            self._wizard_stamps[key] = pose.recorded_at
            if T_now is None:
                T_now = self.controller.T_world_flange()
            if np.allclose(T_now, pose.T_world_flange_m, rtol=0.0, atol=1e-12):
                joints[step] = tuple(self.controller.joint_angles_deg().values())
            else:
                joints.pop(step, None)

    # ------------------------------------------------------------ touches
    def record_touch(self) -> Touch:
        """Store the current flange pose as a touch (labelled P1, P2, ...), with the joint
        values (degrees) and the true distance."""
        with self.lock:
            T = self.controller.T_world_flange()
            touch = Touch(T, touch_label(len(self.touches), T), self.controller.touch_geometry().distance_mm,
                          tuple(self.controller.joint_angles_deg().values()))
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
                                     t.joints_deg) for i, t in enumerate(self.touches)]
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
        self.workflow = None
        self.client = None
        self.target = None
