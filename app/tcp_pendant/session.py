"""One pendant session: a robot (virtual controller), its captured touches and its GUI/scene.

The server makes one :class:`Session` per browser (``on_client_connect``) and drops it on
disconnect; in ``--shared`` mode there is one session whose GUI and scene are the server's
(every browser sees and drives the same robot). Views (``tcp_pendant.views``) register
*renderers* (push the controller state to the scene and the readouts) and the wizard views
register *motion listeners* (called after every move).

Threading: every GUI callback is registered through :meth:`Session.on_loop`, an ``async``
callback, so viser runs it on its event loop, one at a time and in the order the browser's
messages arrived, and the messages it queues are pushed from the loop's own thread (viser's
message buffer is not safe to push to from other threads). :meth:`Session.guard` is the
synchronous part: it takes ``session.lock`` (a re-entrant lock, still taken because a few
things run elsewhere: the session is built in viser's thread pool, tests drive sessions from
their own thread), ignores events after the session closed, and turns any exception into a
notification instead of a crash (a browser can send anything). Work from another thread is
handed to the loop (the server's library watcher: ``loop.call_soon_threadsafe``).
"""

from __future__ import annotations

import functools
import logging
import threading
from collections.abc import Callable, Coroutine
from dataclasses import dataclass, field
from typing import Any, Protocol, TypeVar

import numpy as np

from tcpcal.library import ToolLibrary
from tcp_pendant.controller import ControllerError, VirtualController
from tcp_pendant.pendant import Jogger, touch_label
from tcp_pendant.controller.pose_state import PoseState, pose_state, pose_state_key

__all__ = ["GuiTarget", "Session", "Touch"]

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
    """

    T_world_flange: np.ndarray
    label: str
    distance_mm: float = float("nan")

    def __post_init__(self) -> None:
        T = np.array(self.T_world_flange, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise ControllerError(f"A touch needs a finite 4x4 flange pose, got shape {T.shape}.")
        T.setflags(write=False)
        object.__setattr__(self, "T_world_flange", T)


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
        active_slot: library slot of the active tool data (None: no tool or typed-in only).
        calibrate_container: the GUI container of the "Calibrate" tab, where wizard views plug
            in (see ``tcp_pendant.views.calibrate``); None before the views are built.
        ready_q_rad: the "Ready pose" button's joint angles (None: the robot's HOME).
        views: named view objects (``"scene"``, ``"pendant"``, ``"tools"``, ...), for tests
            and for the wizard views.
    """

    controller: VirtualController
    library: ToolLibrary
    client: Any | None = None
    target: Any | None = None
    touches: list[Touch] = field(default_factory=list)
    lock: threading.RLock = field(default_factory=threading.RLock)
    active_slot: int | None = None
    calibrate_container: Any | None = None
    ready_q_rad: np.ndarray | None = None
    views: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.target is None:
            self.target = self.client
        self.jogger = Jogger(self.controller)
        self.closed = False
        self._renderers: list[Callable[[], None]] = []
        self._motion_listeners: list[Callable[[], None]] = []
        self._touch_listeners: list[Callable[[], None]] = []
        self._close_callbacks: list[Callable[[], None]] = []
        self._pose_state: PoseState | None = None
        self._in_refresh = False             # refresh() is running its renderers
        self._state_checked = False          # ... and the pose state was checked meanwhile

    # ------------------------------------------------------------ listeners
    def add_renderer(self, fn: Callable[[], None]) -> None:
        """Register a function that pushes controller state to the browser (called by refresh)."""
        self._renderers.append(fn)

    def add_motion_listener(self, fn: Callable[[], None]) -> None:
        """Register ``fn()``, called (under the lock) after every move, after the refresh."""
        self._motion_listeners.append(fn)

    def add_touch_listener(self, fn: Callable[[], None]) -> None:
        """Register ``fn()``, called after a touch was recorded or deleted."""
        self._touch_listeners.append(fn)

    def on_close(self, fn: Callable[[], None]) -> None:
        """Register ``fn()``, called once when the session closes."""
        self._close_callbacks.append(fn)

    # ------------------------------------------------------------ updates
    def pose_state(self) -> PoseState:
        """The robot's current :class:`~tcp_pendant.controller.pose_state.PoseState` (link poses,
        flange, TCP, true TCP, readout, touch geometry, joint angles), computed by one FK pass
        and shared by every renderer and motion listener until the controller changes (keyed
        by joint angles, tool data, mounted tool, reference tip and BASE; within one
        :meth:`refresh` the key is checked once, as renderers do not move the robot)."""
        with self.lock:
            state = self._pose_state
            if self._in_refresh and self._state_checked and state is not None:
                return state
            key = pose_state_key(self.controller)
            if state is None or state.key != key:
                state = self._pose_state = pose_state(self.controller, key)
            self._state_checked = self._in_refresh
            return state

    def refresh(self) -> None:
        """Push scene and readouts after a controller change, as one atomic update."""
        with self.lock:
            if self.closed:
                return
            self._in_refresh, self._state_checked = True, False
            try:
                if self.target is None:
                    for fn in self._renderers:
                        fn()
                    return
                with self.target.atomic():
                    for fn in self._renderers:
                        fn()
            finally:
                self._in_refresh = self._state_checked = False

    def moved(self) -> None:
        """After a move: :meth:`refresh`, then every motion listener (errors are logged)."""
        with self.lock:
            self.refresh()
            for fn in list(self._motion_listeners):
                try:
                    fn()
                except Exception:  # a listener must not break jogging
                    log.exception("motion listener failed")

    def notify(self, title: str, body: str, *, kind: str = "info") -> None:
        """Show a notification in this session's browser(s); ``kind``: info, success, warning, error.

        ``title`` and ``body`` are plain text (viser shows them as text, not markdown): pass user
        text as it is, never through ``text_escape.escape_markdown``."""
        if self.closed:
            return
        color = _COLORS.get(kind, "blue")
        clients = [self.client] if self.client is not None else self._all_clients()
        for c in clients:
            try:
                c.add_notification(title, body, color=color, auto_close_seconds=6.0 if kind != "error" else 12.0)
            except Exception:  # the browser may have gone
                log.debug("notification to a closed client dropped", exc_info=True)

    def _all_clients(self) -> list[Any]:
        get = getattr(self.target, "get_clients", None)
        return list(get().values()) if callable(get) else []

    # ------------------------------------------------------------ touches
    def record_touch(self) -> Touch:
        """Store the current flange pose as a touch (labelled P1, P2, ...)."""
        with self.lock:
            T = self.controller.T_world_flange()
            touch = Touch(T, touch_label(len(self.touches), T), self.controller.touch_geometry().distance_mm)
            self.touches.append(touch)
            self._touches_changed()
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
            self.touches[:] = [Touch(t.T_world_flange, touch_label(i, t.T_world_flange), t.distance_mm)
                               for i, t in enumerate(self.touches)]
            self._touches_changed()

    def _touches_changed(self) -> None:
        for fn in list(self._touch_listeners):
            fn()

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
            self._renderers.clear()
            self._motion_listeners.clear()
            self._touch_listeners.clear()
        for fn in callbacks:
            try:
                fn()
            except Exception:
                log.debug("close callback failed", exc_info=True)
        self.views.clear()
        self._pose_state = None
        self.calibrate_container = None
        self.client = None
        self.target = None
