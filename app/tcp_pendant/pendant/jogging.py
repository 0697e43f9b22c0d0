"""Jog settings and the jog keys of the pendant (no viser).

A real pendant jogs either one axis at a time (joint mode, A1..A6) or the TCP in a jog frame
(Cartesian mode, X/Y/Z translations in mm and A/B/C rotations in deg about the Z/Y/X axis of
the frame through the TCP, KUKA habit). Each -/+ key press moves

* by the selected increment (100, 10, 1, 0.1 mm or deg) when the increment is not continuous;
* in continuous mode, by ``speed * override * dt`` for every tick of the held key, where
  ``speed`` is the manual-mode speed at 100 % override: 250 mm/s (KUKA T1 limit), 30 deg/s
  for A/B/C and for joints, and ``dt`` (s) the time since the previous executed tick, clamped
  to ``MAX_TICK_S`` (one 20 Hz tick: no step is larger than the speed allows at 20 Hz, even
  after a stall). A tick that arrives less than half a tick after the previous executed one
  is a backlog (the server fell behind the browser's 20 Hz): it is skipped, so the key stops
  within one tick of its release instead of working off queued ticks.

The deadman of increment presses (:class:`PressGate`): a press is carried out only if the server
reaches it within ``PRESS_BOUND_S`` (250 ms) of its arrival (stamped when viser decodes the
browser's message, ``views.arrival``); an older one is dropped and counted, so that the trainee
can be told. A server that falls behind therefore never works off a backlog of presses: every
press it carries out is at most ``PRESS_BOUND_S`` old, and the robot stands still within that
(plus one step) of the last press reaching the server, at any load.

Stop at contact (a real touch-up): a Cartesian X/Y/Z press or tick whose tool-tip path would
pass through the reference tip (closer than ``guidance.CONTACT_RADIUS_MM`` to it, beyond the
closest point) stops at the closest point and says so (``JogResult.stopped_by == "contact"``);
the next press in the same direction goes on (the tip is touching; that is the warning).
With ``Jogger.stop_at_contact`` False (the session's "Hide distance": the trainee judges the
touch by eye) a small overshoot goes on (the tip pressed into the spike by at most
``touch.CRASH_DEPTH_MM``, as a careful touch does), but a translation that would drive the tool
tip more than that past the reference tip stops where the tips meet, as a real collision stops a
robot (``stopped_by == "collision"``): the message says so and names the key that backs off, and
the session records the collision as a crash. The next press the same way goes on through.

A Cartesian key that stops at a joint limit, a singularity or the edge of the reach says which
way to go instead: after a rotation key, the tilts the model says are reachable from the stop
with the tip held (``pendant.tilts``) and the key that turns back; after a translation key, the
key that goes back; after a joint key, the other key of its row.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from enum import Enum
from typing import Literal

import numpy as np

from tcp_pendant.controller import ControllerError, JogFrame, JogResult, VirtualController
from tcp_pendant.controller.words import Words
from tcp_pendant.pendant.guidance import CONTACT_RADIUS_MM, collision_stop, contact_stop
from tcp_pendant.pendant.tilts import TiltOptions, keyboard_key, key_label, stopped_advice
from tcp_pendant.translation import N_

__all__ = [
    "CARTESIAN_AXES",
    "CONTINUOUS",
    "INCREMENTS",
    "JOG_FRAMES",
    "JOINT_SPEED_DEG_S",
    "LINEAR_SPEED_MM_S",
    "MAX_TICK_S",
    "PRESS_BOUND_S",
    "ROTATION_SPEED_DEG_S",
    "JogMode",
    "JogSettings",
    "Jogger",
    "PressGate",
]

CONTINUOUS = "Cont."
INCREMENTS: tuple[str, ...] = (CONTINUOUS, "100", "10", "1", "0.1")
"""Increment choices as the pendant shows them (mm for X/Y/Z, deg for A/B/C and joints)."""
JOG_FRAMES: tuple[str, ...] = tuple(f.value for f in JogFrame)
CartesianAxis = Literal["X", "Y", "Z", "A", "B", "C"]
CARTESIAN_AXES: tuple[CartesianAxis, ...] = ("X", "Y", "Z", "A", "B", "C")
LINEAR_SPEED_MM_S = 250.0
ROTATION_SPEED_DEG_S = 30.0
JOINT_SPEED_DEG_S = 30.0
MAX_TICK_S = 0.05
"""Largest ``dt`` of one continuous tick (s): one tick at the pendant's 20 Hz."""
PRESS_BOUND_S = 0.25
"""A key press older than this when the server reaches it is dropped (s, since its arrival)."""


class JogMode(str, Enum):
    """Joint jog (one axis at a time) or Cartesian jog (TCP in a jog frame)."""

    JOINT = "Joint"
    CARTESIAN = "Cartesian"


@dataclass(frozen=True)
class JogSettings:
    """The pendant's jog selectors.

    Attributes:
        mode: joint or Cartesian.
        frame: jog frame for Cartesian mode ("WORLD", "BASE", "FLANGE", "TOOL").
        increment: one of :data:`INCREMENTS`.
        override_pct: speed override, 1..100 %.
    """

    mode: JogMode = JogMode.CARTESIAN
    frame: str = "WORLD"
    increment: str = "10"
    override_pct: float = 50.0

    def __post_init__(self) -> None:
        try:
            object.__setattr__(self, "mode", JogMode(self.mode))
        except ValueError:
            raise ControllerError(f"Unknown jog mode {self.mode!r}; use Joint or Cartesian.") from None
        frame = str(self.frame).upper()
        if frame not in JOG_FRAMES:
            raise ControllerError(f"Unknown jog frame {self.frame!r}; use one of {', '.join(JOG_FRAMES)}.")
        object.__setattr__(self, "frame", frame)
        if self.increment not in INCREMENTS:
            raise ControllerError(f"Unknown increment {self.increment!r}; use one of {', '.join(INCREMENTS)}.")
        try:
            pct = float(self.override_pct)
        except (TypeError, ValueError):
            raise ControllerError(f"Speed override must be a number, got {self.override_pct!r}.") from None
        if not math.isfinite(pct):
            raise ControllerError(f"Speed override must be finite, got {self.override_pct!r}.")
        object.__setattr__(self, "override_pct", min(100.0, max(1.0, pct)))

    @property
    def continuous(self) -> bool:
        """True when the keys jog continuously while held."""
        return self.increment == CONTINUOUS

    def with_(self, **changes: object) -> JogSettings:
        """A copy with some selectors changed (validated)."""
        return replace(self, **changes)  # type: ignore[arg-type]

    def step_amount(self, *, rotational: bool, joint: bool = False, dt_s: float | None = None) -> float:
        """Size of one key press (mm or deg, positive).

        Incremental mode: the increment. Continuous mode: ``speed * override/100 * dt_s``
        with the speed of the module docstring and ``dt_s`` clamped to [0, MAX_TICK_S].
        """
        if not self.continuous:
            return float(self.increment)
        dt = MAX_TICK_S if dt_s is None else min(MAX_TICK_S, max(0.0, float(dt_s)))
        speed = JOINT_SPEED_DEG_S if joint else (ROTATION_SPEED_DEG_S if rotational else LINEAR_SPEED_MM_S)
        return speed * self.override_pct / 100.0 * dt


class PressGate:
    """The deadman of key presses: lets a press through only while it is fresh.

    Args:
        clock: seconds, monotonic (the clock the arrival stamps are in; injectable for tests).
        bound_s: the largest age of a press that is still carried out (s).

    Attributes:
        dropped: presses dropped since the last :meth:`take_dropped`.
        dropped_total: every press dropped so far.
    """

    def __init__(self, *, clock: Callable[[], float] = time.monotonic, bound_s: float = PRESS_BOUND_S) -> None:
        self._clock = clock
        self.bound_s = bound_s
        self.dropped = 0
        self.dropped_total = 0

    def admit(self, arrived_s: float | None) -> bool:
        """True when a press that arrived at ``arrived_s`` (None: unknown, taken as now) may be
        carried out now; otherwise it is counted as dropped."""
        if arrived_s is None or self._clock() - arrived_s <= self.bound_s:
            return True
        self.dropped += 1
        self.dropped_total += 1
        return False

    def take_dropped(self) -> int:
        """The number of presses dropped since the last call (and reset it)."""
        n, self.dropped = self.dropped, 0
        return n


_WORLD_AXES = np.eye(3)
_WORLD_AXES.setflags(write=False)
_CLEAR_M = CONTACT_RADIUS_MM / 1000.0 * (1.0 + 1e-9) + 1e-12


def _clear_of(tip_m: np.ndarray, step_m: np.ndarray, reference_m: np.ndarray) -> bool:
    """True when a translation ``step_m`` of the tool tip at ``tip_m`` cannot come within
    ``CONTACT_RADIUS_MM`` of the reference tip (all WORLD, metres): it starts further from it than
    the step's length plus that radius, so ``guidance.contact_stop`` would say None (every point
    ``tip + t step``, ``0 <= t <= 1``, is at least ``|tip - reference| - |step|`` away). Python
    floats: the test every press of a class makes, far from the tip."""
    return _clear_of_floats(tip_m.tolist(), step_m.tolist(), reference_m.tolist())


def _clear_of_floats(tip_m: list[float], step_m: list[float], reference_m: list[float]) -> bool:
    """:func:`_clear_of` of the three vectors as lists of Python floats."""
    px, py, pz = tip_m
    rx, ry, rz = reference_m
    return math.hypot(rx - px, ry - py, rz - pz) > math.hypot(*step_m) + _CLEAR_M


class Jogger:
    """Turns pendant key presses into controller commands.

    Args:
        controller: the session's controller (the caller holds the session lock).
        clock: seconds, monotonic (injectable for tests).
        tick_s: nominal hold-callback period; the first tick of a hold uses it as ``dt``.

    Attributes:
        gate: the deadman of this pendant's presses (:class:`PressGate`, on ``clock``): the
            views ask it whether a press is still fresh before they jog.
    """

    def __init__(self, controller: VirtualController, *, clock: Callable[[], float] = time.monotonic,
                 tick_s: float = 0.05) -> None:
        self.controller = controller
        self.settings = JogSettings()
        self._clock = clock
        self._tick_s = tick_s
        self._last_tick: dict[str, float] = {}
        self._held_at_contact: str | None = None
        self.gate = PressGate(clock=clock)
        self.stop_at_contact = True
        """Stop a translation at the reference tip (False: "Hide distance": only a collision stops)."""
        self.tilts = TiltOptions(controller)
        """The rotation keys checked on the model from the current pose (``pendant.tilts``)."""

    def key(self, axis: str | int, sign: int, *, hold_tick: bool = False) -> JogResult | None:
        """One press of a -/+ key.

        Args:
            axis: a joint index (0-based, joint jog) or "X".."C" (Cartesian jog in the selected
                frame). The mode selector decides which keys the pendant shows; a key always
                does what it says even if the mode changes while it is held.
            sign: +1 or -1.
            hold_tick: True when called by the held key's periodic callback. In continuous mode
                only hold ticks move (a click is the first tick); in incremental mode only
                clicks move (a held key does not repeat, as on a KUKA pendant).

        Returns:
            The controller's JogResult, or None when this call does not move in this mode.

        Raises:
            ControllerError: bad axis for the mode, bad sign.
        """
        if sign not in (1, -1):
            raise ControllerError(f"Jog sign must be +1 or -1, got {sign!r}.")
        s = self.settings
        continuous = s.continuous
        if hold_tick != continuous:
            return None
        name = ""
        dt = None
        if continuous:
            name = f"{axis}{sign}"
            if self._held_at_contact == name:
                return None
            now = self._clock()
            last = self._last_tick.get(name)
            if last is not None and now - last < 0.5 * self._tick_s:
                return None                          # a queued tick of a server behind: skipped
            dt = self._tick_s if last is None or now - last > 4 * self._tick_s else now - last
            self._last_tick = {name: now}
        if isinstance(axis, int) and not isinstance(axis, bool):
            res = self.controller.jog_joint(axis, sign * s.step_amount(rotational=True, joint=True, dt_s=dt))
            if res.stopped_by == "joint_limit" and axis < 9:          # the way back: the other key of the row
                back = Words(N_("key {n}"), n=axis + 1) if sign < 0 else f"Shift+{axis + 1}"
                res = replace(res, message=Words(N_("{stop}. The other key of that row ({back}) turns it back."),
                                                 stop=res.message, back=back))
            return res
        ax = str(axis).upper()
        if ax not in CARTESIAN_AXES:
            raise ControllerError(f"Jog keys are joint indices or X, Y, Z, A, B, C; got {axis!r}.")
        amount = sign * s.step_amount(rotational=ax in "ABC", dt_s=dt)
        if ax in "XYZ":
            res = self._translate(ax, amount)
            if continuous and res.stopped_by in ("contact", "collision"):
                self._held_at_contact = name         # this hold stays stopped until released
            return self._with_advice(res, ax, sign)
        return self._with_advice(self.controller.jog_cartesian(s.frame, ax, amount), ax, sign)

    def _with_advice(self, res: JogResult, ax: str, sign: int) -> JogResult:
        """A Cartesian key stopped by the robot (a limit, a singularity, the reach) with the way
        to go instead appended to its message (module docstring)."""
        if res.ok or res.stopped_by not in ("joint_limit", "singularity", "unreachable"):
            return res
        if ax in "ABC":
            advice = stopped_advice(self.tilts.options(self.settings.frame), ax, sign)
        else:
            advice = Words(N_("{key} ({keyboard}) goes back."), key=key_label(ax, -sign),
                           keyboard=keyboard_key(ax, -sign))
        return replace(res, message=Words(N_("{stop}. {advice}"), stop=res.message, advice=advice))

    def frame_rotation(self) -> np.ndarray:
        """``R_world_frame`` of the selected jog frame now (the axes the X/Y/Z keys move along)."""
        c = self.controller
        f = self.settings.frame
        if f == "WORLD":
            return np.eye(3)
        if f == "BASE":
            return np.asarray(c.T_world_base)[:3, :3]
        if f == "FLANGE":
            return c.T_world_flange()[:3, :3]
        return c.T_world_tcp()[:3, :3]

    def _translate(self, ax: CartesianAxis, amount_mm: float) -> JogResult:
        """A translation of ``amount_mm`` along axis ``ax`` of the jog frame, stopped at contact,
        or with the distance hidden at a collision (module docstring)."""
        c = self.controller
        i = "XYZ".index(ax)
        frame = self.settings.frame
        reference_m = c.reference_tip_world_m
        if frame == "WORLD":
            # the pre-test on Python floats: the WORLD axis times the step is the step on axis i
            # and (signed) zeros elsewhere (the same length), and the tip to rounding
            # (``tool_tip_true_m``: its few 1e-16 m are far inside _CLEAR_M's margin, so "clear"
            # still means contact_stop of the exact tip says None)
            step = [0.0, 0.0, 0.0]
            step[i] = amount_mm / 1000.0
            clear = _clear_of_floats(c.tool_tip_true_m(), step, reference_m.tolist())
            step_m = _WORLD_AXES[:, i] * (amount_mm / 1000.0)
        else:
            step_m = self.frame_rotation()[:, i] * (amount_mm / 1000.0)
            clear = _clear_of(c.T_world_tool_true()[:3, 3], step_m, reference_m)
        if clear:
            return c.jog_cartesian(frame, ax, amount_mm)
        tip_m = c.T_world_tool_true()[:3, 3]
        if not self.stop_at_contact:
            hit = collision_stop(tip_m, step_m, reference_m)
            if hit is None:
                return c.jog_cartesian(frame, ax, amount_mm)
            return self._collide(ax, amount_mm, hit.fraction)
        stop = contact_stop(tip_m, step_m, reference_m)
        if stop is None:
            return c.jog_cartesian(frame, ax, amount_mm)
        res = c.jog_cartesian(frame, ax, amount_mm * stop.fraction)
        if not res.ok:
            return res
        return JogResult(False, stop.fraction, "contact",
                         Words(N_("Stopped at the reference tip after {moved} of {step} mm (touch-up: the tool "
                                  "tip touches it). Press again to go on."),
                               moved=f"{abs(amount_mm) * stop.fraction:.2f}", step=f"{abs(amount_mm):g}"))

    def _collide(self, ax: CartesianAxis, amount_mm: float, fraction: float) -> JogResult:
        """"Hide distance": the press would run into the reference tip at ``fraction`` of its
        path (``guidance.collision_stop``): it stops there, a collision (module docstring)."""
        c = self.controller
        res = c.jog_cartesian(self.settings.frame, ax, amount_mm * fraction)
        if not res.ok:
            return res
        sign = 1 if amount_mm > 0 else -1
        return JogResult(False, fraction, "collision",
                         Words(N_("COLLISION: the tool ran into the reference tip and the robot stopped "
                                  "(recorded as a crash). Back off with {back} ({keyboard}, {frame} frame); "
                                  "pressing {key} again drives the tool through the tip."),
                               back=key_label(ax, -sign), keyboard=keyboard_key(ax, -sign),
                               frame=f"{self.settings.frame}", key=key_label(ax, sign)))

    def release(self) -> None:
        """Forget the hold timing and a stop at contact (key released)."""
        self._last_tick = {}
        self._held_at_contact = None
