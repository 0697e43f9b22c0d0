"""A scripted trainee who steers by the two tip views alone, with the distance hidden
(``bench_trainee.py`` runs it and prints its figures).

**What it sees.** The front and side views the pendant draws (``pendant.tip_insets``: the very
image the Jog tab shows, rendered by the same function, and only while the Jog tab shows it:
the tool tip within ``NEAR_MM``, 40 mm). Their zoom it reads off the image (the orange frame of
the views zoomed out ``ZOOM_OUT`` times); in a view without the arrow (``arrow_direction``: the
view shows the tip) it finds the tool's pixels (``TOOL_COLOR``) and takes the tip as the tool
pixel farthest along the tool's pointing direction on the screen (the cone's narrow end, as an
eye sees it), then reads its place off the scale (``PX_PER_MM`` pixels per mm times the zoom,
the reference tip at the grid's origin): front gives X and Z, side gives Y and Z (WORLD), to a
pixel (1/24 mm, 5/24 mm zoomed out). Where no view shows the tip (the views hidden beyond
40 mm, or a view showing only its arrow) it judges the offset in the 3D view, each WORLD axis to
the nearest :data:`EYE_3D_MM` (10 mm): the one model of an eye here, not read off the pendant.
It never reads the distance, the Δ line or the touch indicator; the true distance is measured
only to print it.

**What it presses** (each a press of the pendant: a jog key, a ``[``/``]`` increment step, a
frame change, Record (R), Next, the dock's "Tilt about the wizard's estimate"; :data:`KINDS`):
per touch after the first, that button whenever the dock shows it (from two touches on:
``WizardCommands.estimate_offer``; ``pivot=False``: never, every tilt about the flange), the
pendant's own tilt hint (``calibrate.tilt_advice``, as the dock shows it: the key, its frame, 45°) by 10°
presses (five, 50°, inside the step's 45-60°); then, look by look, the increment that what it
sees allows and the offset asks for (docs/tutorial.md, "Steering in by eye"): no view shows the
tip: 100 mm while an axis is 75 mm or more off, else 10; the zoomed-out views: 1 mm; the close
views: 0.1 mm (never coarser than the offset: 1 mm while an axis is 0.75 mm or more off). At
that increment, up first when the tip is below its margin above the reference tip, X and Y by
``round(offset / increment)`` presses and Z down to the margin (half the increment above the
tip; none at 0.1 mm); an increment that finds nothing to press gives way to the next finer one,
until the close views show the tips within 0.2 mm on every axis. A suggestion counts as
reachable when every press of the tilt ran to its end (no stop at a limit or singularity) and
the tip was then touched with no stop of the robot.
"""

from __future__ import annotations

import math
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from support.calib_helpers import make_session
from support.ros_layouts import kr16_2_urdf

from tcp_pendant.calibrate import CalibrationWorkflow
from tcp_pendant.calibrate.tilt_advice import TiltAdvisor, meter_gain
from tcp_pendant.controller import RobotKinematics, VirtualController, builtin_tools
from tcp_pendant.pendant.jogging import INCREMENTS
from tcp_pendant.pendant.tip_insets import (
    BELOW_MM,
    GAP_PX,
    PX_PER_MM,
    NEAR_MM,
    TOOL_COLOR,
    VIEW_H_MM,
    VIEW_W_MM,
    ZOOM_FRAME_COLOR,
    ZOOM_OUT,
    arrow_direction,
    inset_zoom,
    tip_insets_image,
)
from tcp_pendant.serve.server import default_reference_tip_mm, ready_configuration
from tcp_pendant.session import Session

from tcpcal.library import ToolLibrary

LEVELS = ("100", "10", "1", "0.1")
KINDS = ("pivot", "tilt", "frame", "[ ]", "100", "10", "1", "0.1", "R/N")
"""The kinds of press counted: "Tilt about the wizard's estimate", the tilt's 10° presses, a jog-frame change, an increment step,
the X/Y/Z presses at each increment (mm), Record and Next."""
TILT_PRESSES, TILT_STEP = 5, "10"
"""The tilt by 10° presses: 50° (the steps ask 45 to 60)."""
_W = int(round(VIEW_W_MM * PX_PER_MM))
_VIEWS = {"front": (0, np.array([1.0, 0.0, 0.0])), "side": (_W + GAP_PX, np.array([0.0, 1.0, 0.0]))}
EYE_3D_MM = 10.0
"""Beyond the tip views (hidden farther than ``NEAR_MM``, or a view showing only its arrow) the
trainee judges the tip's offset in the 3D view, each WORLD axis to the nearest 10 mm (the
spike is 45 mm long, the pointer's cone 12 mm): a model of an eye, the one thing here not read
off what the pendant draws."""


@dataclass
class Touch:
    """One touch's figures."""

    presses: int = 0
    distance_mm: float = math.nan
    suggestion: str = ""
    reachable: bool | None = None
    stops: list[str] = field(default_factory=list)
    kinds: dict[str, int] = field(default_factory=dict)
    """Where the presses went (:data:`KINDS`)."""


def session_for(robot: str, library: Path) -> Session:
    """A pendant session without a browser on ``robot`` ("kr6", "gp12", or "kr16": the
    ROS-Industrial KR 16 chain of tests/support/ros_layouts.py), pointer mounted, in the ready
    pose the server starts it in (for the KR 16, a robot without a known home: hovering over the
    reference tip, ``ready_configuration`` given the tip)."""
    if robot != "kr16":
        return make_session(library, robot=robot)
    kin = RobotKinematics.from_urdf(kr16_2_urdf(library.parent / "kr16", meshes=False))
    pointer = builtin_tools()["pointer"]
    tip_m = np.asarray(default_reference_tip_mm(kin, pointer.T_flange_tool_true)) / 1000.0
    c = VirtualController(kin, tool=pointer, reference_tip_world_m=tip_m)
    c.set_q(ready_configuration(kin, tip_m))        # as the server starts it (PendantApp.ready_q_rad)
    lib = ToolLibrary(library)
    rng = np.random.default_rng(0)
    return Session(c, lib, CalibrationWorkflow(c, lib, robot="kr16", rng=rng), rng=rng)


class ViewTrainee:
    """Steers one session by the tip views (module docstring)."""

    def __init__(self, session: Session, *, pivot: bool = True) -> None:
        self.s = session
        self.pivot = pivot
        """Tilt about the wizard's estimate once it offers one (False: always about the flange)."""
        self.advisor = TiltAdvisor()
        self.presses = 0
        self.stops: list[str] = []
        self.kinds: dict[str, int] = {}

    def count(self, kind: str, n: int = 1) -> None:
        """``n`` presses of one kind (:data:`KINDS`)."""
        self.presses += n
        self.kinds[kind] = self.kinds.get(kind, 0) + n

    # ------------------------------------------------------------ the eye
    def _tip_in_view(self, img: np.ndarray, view: str, T: np.ndarray, zoom: int) -> tuple[float, float] | None:
        """(across, up) mm of the tool tip read off one view's pixels at the view's ``zoom``,
        or None: the view does not show it (cut by the window's edge)."""
        x0, right = _VIEWS[view]
        part = img[:, x0:x0 + _W]
        rows, cols = np.nonzero(np.all(part == TOOL_COLOR, axis=2))
        if rows.size == 0:
            return None
        d = np.array([float(T[:3, 0] @ right), -float(T[:3, 0][2])])    # tool X on the screen (col, row)
        score = cols * d[0] + rows * d[1]
        i = int(np.argmax(score)) if np.hypot(*d) > 0.2 else int(np.argmin(np.hypot(
            cols - cols.mean(), rows - rows.mean())))
        c, r = int(cols[i]), int(rows[i])
        if c in (0, _W - 1) or r in (0, part.shape[0] - 1):
            return None                                                 # cut by the window's edge
        return (((c + 0.5) / PX_PER_MM - VIEW_W_MM / 2) * zoom,
                ((VIEW_H_MM - BELOW_MM) - (r + 0.5) / PX_PER_MM) * zoom)

    def look(self) -> tuple[np.ndarray, float]:
        """The tool tip relative to the reference tip as the trainee sees it (WORLD, mm) and the
        coarsest resolution of that reading (mm): the tip views' pixels where a view shows the
        tip (their real zoom, ``inset_zoom``: 1/24 mm a pixel, 5/24 zoomed out), else the 3D
        view (:data:`EYE_3D_MM`)."""
        c = self.s.controller
        T = c.T_world_tool_true()
        ref = c.reference_tip_world_m
        apex = (T[:3, 3] - ref) * 1000.0                     # the geometry the views draw
        eye3d = np.round(apex / EYE_3D_MM) * EYE_3D_MM       # the 3D view, by eye
        shown = bool(np.linalg.norm(apex) <= NEAR_MM)        # the views are hidden beyond 40 mm
        if not shown:
            return eye3d, EYE_3D_MM
        img = tip_insets_image(ref, T)
        zoom = ZOOM_OUT if self._framed(img) else 1
        assert zoom == inset_zoom(apex), "the orange frame is the views' zoom"
        seen = {v: None if arrow_direction(v, apex) is not None else self._tip_in_view(img, v, T, zoom)
                for v in _VIEWS}
        front, side = seen["front"], seen["side"]
        x = front[0] if front else eye3d[0]
        y = side[0] if side else eye3d[1]
        zs = [v[1] for v in (front, side) if v]
        z = float(np.mean(zs)) if zs else eye3d[2]
        res = zoom / PX_PER_MM if front and side else EYE_3D_MM
        return np.array([x, y, z]), res

    @staticmethod
    def _framed(img: np.ndarray) -> bool:
        """The views' orange frame (a zoomed-out view): most of the front view's top row."""
        return bool(np.mean(np.all(img[1, :_W] == ZOOM_FRAME_COLOR, axis=1)) > 0.5)

    # ------------------------------------------------------------ the hands
    def press(self, axis: str, sign: int) -> None:
        res = self.s.motion.jog(axis, sign)
        self.count("tilt" if axis in "ABC" else self.s.jogger.settings.increment)
        if res is not None and not res.ok:
            self.stops.append(f"{res.stopped_by}: {res.message}")

    def increment(self, value: str) -> None:
        now = self.s.jogger.settings.increment
        if now != value:
            self.count("[ ]", abs(INCREMENTS.index(value) - INCREMENTS.index(now)))   # [ / ] steps
            self.s.motion.set_jog_setting("increment", value)

    def frame(self, value: str) -> None:
        if self.s.jogger.settings.frame != value:
            self.count("frame")
            self.s.motion.set_jog_setting("frame", value)

    # ------------------------------------------------------------ the skill
    def pivot_on_estimate(self) -> None:
        """Press the dock's "Tilt about the wizard's estimate" (docs/tutorial.md) when it is
        offered: the rotation keys then turn about the TCP the touches so far give."""
        if self.pivot and self.s.wizard_commands.estimate_offer() is not None:     # the button shows
            self.count("pivot")
            self.s.wizard_commands.pivot_on_estimate()

    def tilt(self) -> str:
        """Follow the pendant's tilt hint; its words ("" none)."""
        self.pivot_on_estimate()
        wf = self.s.workflow
        wiz = wf.wizard
        R_wf = self.s.controller.T_world_flange()[:3, :3]
        meter = meter_gain(wiz, R_wf, [r.wizard for r in wf.runs])
        advice = self.advisor.advise(wiz.other_rotations(), R_wf, self.s.jogger, meter.sigma_mm)
        if advice is None or advice.option is None:
            return "" if advice is None else advice.text
        r = advice.option.reach
        self.frame(r.frame)
        self.increment(TILT_STEP)
        for _ in range(TILT_PRESSES):
            self.press(r.key, r.sign)
        self.frame("WORLD")
        return re.sub(r"\*\*", "", advice.text)

    def bring_tips_together(self, max_presses: int = 200) -> None:
        """Steer the tip onto the reference tip by what the eye sees (module docstring): the
        increment follows the reading's resolution (the 3D view: 100 mm beyond 75 mm, else 10;
        the zoomed-out views: 1 mm; the close views: 0.1 mm), one pass per look, until the
        close views show the tips within 0.2 mm on every axis."""
        start, finer = self.presses, 0
        while self.presses - start <= max_presses:
            apex, res = self.look()
            finest = 1 if res >= EYE_3D_MM else 2 if res > 1.0 / PX_PER_MM else 3   # what the eye can judge
            far = float(np.max(np.abs(apex)))
            by_eye = min(finest, next((k for k, v in enumerate(LEVELS) if far >= 0.75 * float(v)), 3))
            level = LEVELS[min(3, max(by_eye, finer))]
            if level == "0.1" and np.all(np.abs(apex) <= 0.2):
                return
            if self._level(level, float(level)):
                finer = by_eye
            elif level == "0.1":
                return
            else:
                finer = LEVELS.index(level) + 1      # nothing to press at this size: finer

    def _level(self, level: str, step: float) -> bool:
        """One pass at one increment: up first when the tip is below its margin above the
        reference tip, then X and Y to the nearest press, then Z down to the margin (half the
        increment above the tip, the tip's height at 0.1 mm): never down past it."""
        moved = False
        margin = 0.0 if level == "0.1" else 0.5 * step
        for k, axis in enumerate(("Z", "X", "Y", "Z")):
            apex, _ = self.look()
            i = "XYZ".index(axis)
            n = round(-apex[i] / step) if axis != "Z" else round((margin - apex[2]) / step)
            if k == 0 and n <= 0:
                continue                                    # the first Z: only up
            if n:
                self.increment(level)
            for _ in range(abs(n)):
                self.press(axis, 1 if n > 0 else -1)
                moved = True
        return moved


def run_robot(robot: str, *, pivot: bool = True) -> list[Touch]:
    """One XYZ 4-point by the views on ``robot``; the figures per touch (``pivot``: tilts
    about the wizard's estimate once offered, else about the flange)."""
    with tempfile.TemporaryDirectory() as tmp:
        s = session_for(robot, Path(tmp) / "tools.json")
        s.set_hide_distance(True)
        s.wizard_commands.start("xyz4")
        t = ViewTrainee(s, pivot=pivot)
        touches = []
        for k in range(4):
            t.presses, t.stops, t.kinds = 0, [], {}
            touch = Touch()
            if k:
                touch.suggestion = t.tilt()
                tilt_stops = list(t.stops)
            t.bring_tips_together()
            touch.distance_mm = float(s.pose_state().touch.distance_mm)     # measured, never steered by
            if k and touch.suggestion.startswith("Tilt next"):                # the robot never stopped it
                robot_stops = [m for m in tilt_stops + t.stops if not m.startswith("collision")]
                touch.reachable = not robot_stops
            s.wizard_commands.record_step()
            t.count("R/N")                                                  # R
            s.wizard_commands.next_step()
            t.count("R/N")                                                  # Next / Finish
            touch.presses, touch.stops, touch.kinds = t.presses, list(t.stops), dict(t.kinds)
            touches.append(touch)
        return touches
