"""A session's motion commands (``Session.motion``): the jog keys, the joint sliders, Ready,
Home and the gizmo. Each moves the session's controller and ends in one ``pose`` change signal
of the session carrying the move's outcome (``JogResult``) for the status line.
"""

from __future__ import annotations

import threading
from typing import Protocol

import numpy as np

from tcp_pendant.controller import ControllerError, JogResult, VirtualController
from tcp_pendant.pendant import Jogger

__all__ = ["MotionCommands", "MotionHost"]


class MotionHost(Protocol):
    """What :class:`MotionCommands` needs of its session."""

    lock: threading.RLock
    controller: VirtualController
    jogger: Jogger
    ready_q_rad: np.ndarray | None

    def moved(self, jog: JogResult | None = None) -> None: ...

    def moved_soon(self, jog: JogResult, waited_s: float | None) -> None: ...

    def changed(self, *, pose: bool = False) -> None: ...


class MotionCommands:
    """The robot's motion commands of one session (module docstring)."""

    def __init__(self, host: MotionHost) -> None:
        self._host = host

    def jog(self, axis: str | int, sign: int, *, hold_tick: bool = False,
            waited_s: float | None = None) -> JogResult | None:
        """One jog key: a press (one increment, or nothing in continuous mode) or a tick of a held
        key (``hold_tick``), by the session's :class:`~tcp_pendant.pendant.Jogger`; ends in one
        ``pose`` signal carrying the move's outcome (a press that waited ``waited_s`` on a busy
        loop: ``Session.moved_soon``). None: nothing moved (a skipped tick)."""
        host = self._host
        with host.lock:
            res = host.jogger.key(axis, sign, hold_tick=hold_tick)
            if res is not None:
                if hold_tick:
                    host.moved(res)
                else:
                    host.moved_soon(res, waited_s)
            return res

    def set_jog_setting(self, name: str, value: object) -> None:
        """One jog setting of the Jog tab (``JogSettings`` field ``name``: mode, frame,
        increment, override_pct); the readouts re-render (a ``pose`` signal: the offset to the
        tip is given in the jog frame).

        Raises:
            ControllerError: an unknown setting or value (names the choices).
        """
        host = self._host
        with host.lock:
            host.jogger.settings = host.jogger.settings.with_(**{name: value})
            host.changed(pose=True)

    def release_jog(self) -> None:
        """The held key was released (or the hold stopped): no more continuous motion."""
        with self._host.lock:
            self._host.jogger.release()

    def set_joints(self, q_rad: np.ndarray, *, status: bool = True) -> JogResult:
        """Put the robot at the joint angles ``q_rad`` (rad; m for a prismatic joint), clipped to
        the limits by the controller; one ``pose`` signal, which carries the move's outcome for
        the status line unless ``status`` is False (a scan's film: the status line stays)."""
        with self._host.lock:
            self._host.controller.set_q(np.asarray(q_rad, dtype=float))
            res = JogResult(True, 1.0, None, "")
            self._host.moved(res if status else None)
            return res

    def set_joint(self, index: int, value_deg: float) -> float:
        """Joint ``index`` (0-based) to ``value_deg``: the joint sliders' unit, the joint
        variable in degrees (``degrees(q_rad)``, as their limits are), clipped to its limits;
        returns the value applied in that unit.

        Raises:
            ControllerError: no such joint, or a value that is not a finite number.
        """
        c = self._host.controller
        with self._host.lock:
            k = c.kinematics
            if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < k.n_joints:
                raise ControllerError(f"There is no joint {index!r}; the robot has {k.n_joints}.")
            value = float(value_deg)
            if not np.isfinite(value):
                raise ControllerError(f"Joint A{index + 1} needs a finite value, got {value_deg!r}.")
            q = c.q_rad
            q[index] = float(np.clip(np.radians(value), k.lower_rad[index], k.upper_rad[index]))
            self.set_joints(q)
            return float(np.degrees(c.q_rad[index]))

    def ready(self) -> JogResult:
        """"Ready pose": the session's start pose (``ready_q_rad``), or HOME when it has none."""
        with self._host.lock:
            if self._host.ready_q_rad is None:
                return self.home()
            return self.set_joints(self._host.ready_q_rad)

    def home(self) -> JogResult:
        """The robot's HOME position (the controller's); one ``pose`` signal."""
        with self._host.lock:
            self._host.controller.go_home()
            res = JogResult(True, 1.0, None, "")
            self._host.moved(res)
            return res

    def move_tcp_to(self, T_world_tcp_m: np.ndarray) -> JogResult:
        """Move the active TCP to ``T_world_tcp_m`` ((4,4), WORLD, m; the gizmo), by the
        controller's Cartesian motion rules; one ``pose`` signal with the outcome."""
        with self._host.lock:
            res = self._host.controller.move_tcp_to(np.asarray(T_world_tcp_m, dtype=float))
            self._host.moved(res)
            return res
