"""The tilts a trainee can make from where the robot stands, in the pendant's words (no viser).

:class:`TiltOptions` checks the six rotation keys of a jog frame (A, B, C, each way) by an
angle on the robot model (``controller.reach.tilt_reach``: joint limits, the wrist singularity
margin, the reference tip still reachable after the turn) and keeps the answer while the robot
stays within :data:`REUSE_DEG` of the orientation and :data:`REUSE_MM` of the TCP position it
was asked at (the tool data, the mounted tool, the reference tip and BASE unchanged): the dock's
line, the tilt hint and a stopped jog's advice cost the check (a few ms per key) once, not on
every fine jog press near the tip. The margins of the check (3 deg from every joint limit, the
wrist singularity margin) are wider than what the robot can change within that. A rotation whose axis lies within 25 deg of
the flange axis turns the tool about its own length: it is no tilt (it adds nothing a tilt
adds, and ``calibrate.diversity`` calls the same axis "the flange axis").

The keyboard keys are the page script's (``serve/static/pendant.js``): in Cartesian mode the jog
rows are X, Y, Z, A, B, C, key ``n`` jogs row ``n`` +, ``Shift+n`` jogs it −; so B − is Shift+5.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tcp_pendant.controller import VirtualController
from tcp_pendant.controller.reach import ROTATION_KEYS, TiltReach, frame_axes, tilt_reach
from tcp_pendant.controller.words import Words, in_language
from tcp_pendant.translation import ENGLISH, N_, Translator

__all__ = ["OWN_AXIS_DEG", "REUSE_DEG", "REUSE_MM", "ROW_OF_KEY", "TILT_DEG", "TiltOption", "TiltOptions", "keyboard_key", "key_label",
           "reachable_line", "stopped_advice"]

TILT_DEG = 45.0
"""The tilt the steps ask for (45 to 60 deg: the least of it is checked)."""
OWN_AXIS_DEG = 25.0
"""A rotation axis this close to the flange axis turns the tool about its own length (deg)."""
REUSE_DEG = 2.0
REUSE_MM = 5.0
"""An answer is kept while the flange turned less than ``REUSE_DEG`` and the TCP moved less
than ``REUSE_MM`` since it was checked (module docstring)."""
ROW_OF_KEY = {"X": 1, "Y": 2, "Z": 3, "A": 4, "B": 5, "C": 6}
"""The jog row (and keyboard digit) of each Cartesian key."""
_OWN_AXIS_COS = math.cos(math.radians(OWN_AXIS_DEG))


def keyboard_key(key: str, sign: int) -> str:
    """The keyboard key of a Cartesian jog key: "5" (B +), "Shift+5" (B −)."""
    digit = ROW_OF_KEY[key]
    return f"{digit}" if sign > 0 else f"Shift+{digit}"


def key_label(key: str, sign: int) -> str:
    """The jog key as its button says it: "B +", "B −"."""
    return f"{key} {'+' if sign > 0 else '−'}"


@dataclass(frozen=True)
class TiltOption:
    """One rotation key checked from the current pose.

    Attributes:
        reach: the model's answer (``controller.reach.TiltReach``).
        axis_world: the axis it turns about, WORLD (unit vector, at the pose it was checked at).
        own_axis: the axis is within :data:`OWN_AXIS_DEG` of the flange axis (a turn, no tilt).
    """

    reach: TiltReach
    axis_world: np.ndarray
    own_axis: bool

    @property
    def usable(self) -> bool:
        """A tilt the pendant may suggest: reachable and not a turn about the tool's own axis."""
        return self.reach.reachable and not self.own_axis

    @property
    def words(self) -> str:
        """"B − (Shift+5)"."""
        r = self.reach
        return f"{key_label(r.key, r.sign)} ({keyboard_key(r.key, r.sign)})"


class TiltOptions:
    """The six rotation keys of a jog frame checked on the model, kept per pose (module docstring).

    Args:
        controller: the session's controller (the caller holds the session lock).
    """

    def __init__(self, controller: VirtualController) -> None:
        self.controller = controller
        self._key: tuple[object, ...] | None = None
        self._T: np.ndarray | None = None                  # T_world_tcp the answers were checked at
        self._cache: dict[tuple[str, float], tuple[TiltOption, ...]] = {}
        self.checks = 0
        """How many sets of six keys were checked on the model (for tests and benchmarks)."""

    def _still_valid(self) -> bool:
        c = self.controller
        key = (id(c.kinematics), c.T_flange_tool.tobytes(), id(c.mounted_tool),
               np.asarray(c.reference_tip_world_m).tobytes(), np.asarray(c.T_world_base).tobytes())
        T = c.T_world_tcp()
        if key == self._key and self._T is not None:
            turned = math.degrees(math.acos(max(-1.0, min(1.0, (float(np.trace(self._T[:3, :3].T @ T[:3, :3])) - 1.0) / 2.0))))
            if turned < REUSE_DEG and float(np.linalg.norm(T[:3, 3] - self._T[:3, 3])) * 1000.0 < REUSE_MM:
                return True
        self._key, self._T, self._cache = key, T, {}
        return False

    def options(self, frame: str, angle_deg: float = TILT_DEG) -> tuple[TiltOption, ...]:
        """A, B, C (+ then −) of ``frame``, each checked by ``angle_deg`` from the current pose
        (or one within the reuse distance, module docstring)."""
        c = self.controller
        self._still_valid()
        found = self._cache.get((frame, angle_deg))
        if found is None:
            axes = frame_axes(c, frame)
            flange_z = c.T_world_flange()[:3, 2]
            out = []
            for k in ("A", "B", "C"):
                axis = np.array(axes[:, ROTATION_KEYS[k]], dtype=float)
                own = abs(float(axis @ flange_z)) >= _OWN_AXIS_COS
                for sign in (1, -1):
                    reach = (TiltReach(frame, k, sign, angle_deg, False, Words(N_("a turn about the tool's own length")))
                             if own else tilt_reach(c, frame, k, sign, angle_deg))
                    out.append(TiltOption(reach, axis, own))
            found = self._cache[(frame, angle_deg)] = tuple(out)
            self.checks += 1
        return found


def reachable_line(options: tuple[TiltOption, ...], *, frame: str, joint_mode: bool,
                   tr: Translator = ENGLISH) -> str:
    """The dock's line of the tilts reachable from here (markdown, our words only), both ways of
    a key in one, the blocked ones grouped by their reason (:func:`_short`), e.g. "Reachable 45°
    tilts, tip held (WORLD): **B −** (Shift+5), **C ±** (6, Shift+6). Not: A (own axis); B +
    (A5 limit)." (in ``tr``'s language; key and axis names as they are)."""
    _ = tr.gettext
    if not options:
        return ""
    angle = options[0].reach.angle_deg
    ok = []
    for key in ("A", "B", "C"):
        signs = [o.reach.sign for o in options if o.usable and o.reach.key == key]
        if len(signs) == 2:
            ok.append(f"**{key} ±** ({keyboard_key(key, 1)}, {keyboard_key(key, -1)})")
        elif signs:
            ok.append(f"**{key_label(key, signs[0])}** ({keyboard_key(key, signs[0])})")
    own = sorted({o.reach.key for o in options if o.own_axis})
    blocked: dict[str, list[str]] = {}
    for o in options:
        if not o.own_axis and not o.reach.reachable:
            blocked.setdefault(_short(o.reach.why, tr), []).append(key_label(o.reach.key, o.reach.sign))
    if ok:
        head = _("Reachable {angle}° tilts, tip held ({frame}): {keys}.").format(
            angle=f"{angle:.0f}", frame=frame, keys=", ".join(ok))
    else:
        head = _("Reachable {angle}° tilts, tip held ({frame}): none in this frame: change the Jog frame or "
                 "press Ready pose.").format(angle=f"{angle:.0f}", frame=frame)
    nots = ([_("{keys} (own axis)").format(keys=" ".join(own))] if own else []) + [
        f"{', '.join(keys)} ({why})" for why, keys in blocked.items()]
    text = head + (" " + _("Not: {tilts}.").format(tilts="; ".join(nots)) if nots else "")
    if joint_mode:
        text += " " + _("(Set Mode to Cartesian: the keys are joints now.)")
    return text


_SINGULARITY_KINDS = {"wrist": N_("wrist singularity"), "elbow": N_("elbow singularity"),
                      "shoulder": N_("shoulder singularity")}


def _short(why: str, tr: Translator = ENGLISH) -> str:
    """A blocked tilt's reason in two or three words: "wrist singularity", "A5 limit", "tip out
    of reach" (the whole reason is in a stopped jog's message), read from its English text."""
    _ = tr.gettext
    if "out of reach" in why:
        return _("tip out of reach")
    if "singularity" in why:
        for kind, words in _SINGULARITY_KINDS.items():
            if kind in why:
                return _(words)
        return _("singularity")
    if "limit" in why:
        return _("{joint} limit").format(joint=why.split()[0])
    return in_language(why, tr)


def stopped_advice(options: tuple[TiltOption, ...], stopped_key: str, stopped_sign: int) -> Words:
    """What to press instead after rotation key ``stopped_key`` stopped at a limit or a
    singularity: the reachable tilts (checked from the stop), and the opposite key, which turns
    back the way it came."""
    others = [o.words for o in options if o.usable
              and (o.reach.key, o.reach.sign) != (stopped_key, stopped_sign)]
    back = Words(N_("{key} ({keyboard}) turns back"), key=key_label(stopped_key, -stopped_sign),
                 keyboard=keyboard_key(stopped_key, -stopped_sign))
    if others:
        return Words(N_("Instead tilt with {tilts} (reachable from here with the tip held); {back}."),
                     tilts=", ".join(others), back=back)
    return Words(N_("No tilt of 45° is reachable from here in this frame (try another Jog frame); {back}."),
                 back=back)
