"""The scripted trainees: presses per touch of one XYZ 4-point calibration.

**By the tip views** (the default run; issue 44): ``view_trainee.ViewTrainee`` steers with the
distance hidden by the two tip views alone (the pixels of the views the Jog tab shows, at their
own zoom, with their arrow; beyond them, the 3D view judged to 10 mm; never the distance),
follows the pendant's own tilt hint for touches 2-4 (from touch 3 on tilting about the
wizard's estimate, the dock's button; the same trainee never pressing it is printed too), on
the KR 6, the GP12 and a
ROS-Industrial KR 16 (the chain of ``ros-industrial/kuka_experimental``
``kuka_kr16_support/urdf/kr16_2_macro.xacro``, tests/support/ros_layouts.py). It prints, per
robot and touch, the presses, the true distance (measured, not steered by) and the tilt
suggested and whether the robot made it, then where the presses went (the tilt, frame changes,
increment steps, X/Y/Z presses per increment, Record and Next), then the targets as MET /
NOT MET: at most 30 presses per touch, every touch within 0.5 mm, every suggestion reachable.

**By the Δ line** (``--delta-line``; issue 10's figures): the trainees below, in a real server
through a websocket client.

A trainee who follows only what the Jog tab shows: the wizard dock's step, the Δ readout
("ΔX n ΔY n ΔZ n mm" to the tip, WORLD jog frame), the increment buttons and the compact jog
key rows. No Auto-touch, no scripting of the robot. The pendant server runs in this process
(a real viser server); one headless websocket client is the browser (tests/support/wsclient.py),
and every click reaches the views as a browser's event does (tests/support/guiclick.py), so
each click is served exactly as in a browser (rendering, change signal, messages sent); what
is not measured is a human's reading time and the browser's own rendering.

Per touch k of the 4 standard orientations (the tool tilted with the B and C keys by 10 deg
steps about the TCP, which is the flange: no tool is active yet):

    1: as the ready pose (flange down)   2: B +30    3: B 0, C +30    4: C 0, B -30

the trainee turns the tool (increment 10, B/C keys), then moves the tip onto the reference
tip axis by axis, X and Y first and Z (the approach) last, like a person reading the Δ line:
for each axis, from the largest increment down (100, 10, 1, 0.1 mm), it presses the key
round(|Δ| / increment) times, re-reading the Δ line after every press, until the distance is
within 0.5 mm (an axis within 0.25 mm is left alone); then Record and Next (Finish). A
selection of an increment is a click. The figures printed: clicks and wall time per touch,
next to the issue's figure before this work (464 clicks for the 4 touches, ~116 per touch,
about 17 minutes on this machine driven in chromium).

A second trainee steers by the distance alone (the "Distance to reference tip" figure, no Δ
line), as a person does who only sees how far the tips are apart: it picks the increment below
the distance (100 mm above 150 mm, 10 above 15, 1 above 1.5, else 0.1; never back to a coarser
one); at each
increment it levels first (X, then Y) and then goes down (Z), from above as a careful person
does: along an axis it presses a key, keeps pressing while the distance falls and presses
back once when it rose (or the indicator shows a crash: the tip went through the spike); when
no axis helps at an increment it takes the next finer one. Both trainees are run
in the same process on the same robot, so their figures compare directly.

The default reference tip stands a fraction of a millimetre off the round numbers
(``server.TIP_PLACEMENT_MM``), so no touch ends with the 10 mm increment alone.

Run: ``.venv/bin/python tests/bench/bench_trainee.py`` (the views, a few seconds) or with
``--delta-line`` (about 20-60 s).
"""

from __future__ import annotations

import math
import re
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from tcp_pendant.serve.server import AppConfig, PendantApp
from tcp_pendant.views.pendant_panel import MARK
from tcp_pendant.views.wizard_dock import FINISH, NEXT

if __name__ == "__main__":                  # run as a script: tests/ on sys.path (support.*, bench.*)
    import _tests_on_path  # noqa: F401
from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until

BEFORE_CLICKS_PER_TOUCH = 116.0
"""The pendant's figure before the one-screen touch loop (464 clicks for one 4-point calibration)."""
GOAL_CLICKS_PER_TOUCH = 30.0
ORIENTATIONS_DEG: tuple[tuple[int, int], ...] = ((0, 0), (30, 0), (0, 30), (-30, 0))
"""(B, C) of each touch relative to the ready pose, degrees."""
INCREMENTS = ("100", "10", "1", "0.1")
_DELTA = re.compile(r"ΔX (\S+)  ΔY (\S+)  ΔZ (\S+) mm")


class Trainee:
    """Clicks the page like a person reading it; counts the clicks."""

    def __init__(self, app: PendantApp) -> None:
        self.ws = DrainingClient(app.port)
        wait_until(lambda: len(app.sessions) == 1, what="session built")
        (self.session,) = app.sessions.values()
        self.client = self.session.client
        self.session.notify = lambda *a, **k: None      # type: ignore[method-assign]
        self.pendant = self.session.views["pendant"]
        self.dock = self.session.views["dock"]
        self.clicks = 0

    # what the page shows
    def delta(self) -> np.ndarray:
        m = _DELTA.search(self.pendant.touch_md.content)
        assert m, f"no Δ readout on the page: {self.pendant.touch_md.content!r}"
        return np.array([float(v) for v in m.groups()])

    def distance(self) -> float:
        """The distance the touch indicator shows (mm); infinite while it shows a crash (the
        tool went through the tip: any key that got there was wrong)."""
        text = self.pendant.touch_md.content
        if "CRASH" in text:
            return math.inf
        m = re.search(r"(?:Distance to reference tip: \*\*|TOUCHING\*\* the reference tip \()(\d+\.\d\d) mm", text)
        assert m, f"no distance on the page: {text!r}"
        return float(m.group(1))

    def selected_increment(self) -> str:
        return next(o[len(MARK):] for o in self.pendant.increment.options if o.startswith(MARK))

    # clicks
    def press_option(self, group, value: str) -> None:
        choose(group, value, self.client)
        self.clicks += 1

    def press(self, handle) -> None:
        click(handle, self.client)
        self.clicks += 1

    def increment(self, value: str) -> None:
        if self.selected_increment() != value:
            self.press_option(self.pendant.increment, value)

    def key(self, axis: str, sign: int) -> None:
        self.press_option(self.pendant.cart_rows[axis], f"{axis} {'+' if sign > 0 else '−'}")

    # the skill
    def turn(self, axis: str, degrees: int) -> None:
        if degrees:
            self.increment("10")
        for _ in range(abs(degrees) // 10):
            self.key(axis, 1 if degrees > 0 else -1)

    def bring_tips_together(self, max_clicks: int = 400) -> None:
        start = self.clicks
        while self.distance() > 0.5:
            if self.clicks - start > max_clicks:
                raise RuntimeError(f"no touch after {max_clicks} clicks; Δ {self.delta()}")
            for i, axis in enumerate("XYZ"):       # X, Y first; Z (the approach) last
                for inc in INCREMENTS:
                    step = float(inc)
                    n = round(abs(self.delta()[i]) / step)
                    if n == 0 or abs(self.delta()[i]) <= 0.25:
                        continue
                    self.increment(inc)
                    for _ in range(int(n)):
                        d = self.delta()[i]
                        if abs(d) <= 0.25 or abs(d) < step / 2:
                            break
                        self.key(axis, 1 if d > 0 else -1)
                if self.distance() <= 0.5:
                    break


class DistanceTrainee(Trainee):
    """Steers by the distance figure alone: never reads the Δ line (module docstring)."""

    @staticmethod
    def increment_for(distance_mm: float) -> str:
        return "100" if distance_mm > 150 else "10" if distance_mm > 15 else "1" if distance_mm > 1.5 else "0.1"

    def bring_tips_together(self, max_clicks: int = 1500) -> None:
        start = self.clicks
        inc = self.increment_for(self.distance())
        while self.distance() > 0.5:
            if self.clicks - start > max_clicks:
                raise RuntimeError(f"no touch after {max_clicks} clicks; distance {self.distance()}")
            by_distance = self.increment_for(self.distance())   # finer when close, never coarser
            inc = max(inc, by_distance, key=INCREMENTS.index)
            progress = False
            for axes in ("XY", "Z"):                      # level first, then down: from above
                while self.distance() > 0.5 and self.descend(inc, axes):
                    progress = True
            if not progress:                              # nothing helps at this size: finer
                if inc == INCREMENTS[-1]:
                    raise RuntimeError(f"stuck at {self.distance()} mm with the finest increment")
                inc = INCREMENTS[INCREMENTS.index(inc) + 1]

    def descend(self, inc: str, axes: str) -> bool:
        """Try ``axes`` in turn at increment ``inc``: along the first key that brings the tips
        closer, press until the distance rises, then press back once. True if it helped."""
        self.increment(inc)
        for axis in axes:
            for sign in (1, -1):
                before = self.distance()
                self.key(axis, sign)
                if self.distance() >= before - 1e-9:
                    self.key(axis, -sign)                 # worse (or no better): back
                    continue
                while self.distance() > 0.5:
                    before = self.distance()
                    self.key(axis, sign)
                    if self.distance() >= before - 1e-9:
                        self.key(axis, -sign)             # one too far: back
                        break
                return True
        return False


def run(trainee_cls: type[Trainee] = Trainee) -> dict[str, list[float]]:
    with tempfile.TemporaryDirectory() as tmp:
        app = PendantApp(AppConfig(port=0, tool_library=Path(tmp) / "tools.json", library_poll_s=1.0))
        app.start()
        try:
            t = trainee_cls(app)
            calibrate = t.session.views["calibrate"]
            click(calibrate.start, t.client)             # Calibrate tab: XYZ 4-point, Start (not counted)
            clicks, seconds, dist = [], [], []
            b = c = 0
            for k, (b_deg, c_deg) in enumerate(ORIENTATIONS_DEG):
                t.clicks = 0
                t0 = time.perf_counter()
                t.turn("B", b_deg - b)
                t.turn("C", c_deg - c)
                b, c = b_deg, c_deg
                t.bring_tips_together()
                dist.append(t.distance())
                t.press(t.dock.record)
                t.press_option(t.dock.nav, FINISH if k == len(ORIENTATIONS_DEG) - 1 else NEXT)
                seconds.append(time.perf_counter() - t0)
                clicks.append(float(t.clicks))
            wf = calibrate.workflow
            assert wf.result is not None, "the calibration did not finish"
            truth = wf.truth()
            err = None if truth is None else truth.position_error_mm
            t.ws.ws.close()
            return {"clicks": clicks, "seconds": seconds, "distance_mm": dist,
                    "tcp_error_mm": [] if err is None else [float(err)]}
        finally:
            app.stop()


def report(title: str, out: dict[str, list[float]]) -> float:
    print(title)
    print(f"{'touch':>5} {'(B, C) deg':>11} {'clicks':>7} {'wall s':>7} {'distance mm':>12}")
    for k, ((b, c), n, s, d) in enumerate(zip(ORIENTATIONS_DEG, out["clicks"], out["seconds"],
                                              out["distance_mm"])):
        print(f"{k + 1:>5} {f'({b}, {c})':>11} {n:>7.0f} {s:>7.2f} {d:>12.2f}")
    mean = float(np.mean(out["clicks"]))
    print(f"clicks per touch: {mean:.1f}, wall time per touch {np.mean(out['seconds']):.2f} s in-process")
    if out["tcp_error_mm"]:
        print(f"TCP error of the result vs the hidden truth: {out['tcp_error_mm'][0]:.3f} mm")
    return mean


ROBOTS = ("kr6", "gp12", "kr16")
GOAL_PRESSES_PER_TOUCH = 30
GOAL_DISTANCE_MM = 0.5


def views_table() -> bool:
    """Run the view trainee on every robot, print its table and the targets; True: all met."""
    from bench.view_trainee import KINDS, run_robot

    print("Scripted trainee by the two tip views, distance hidden, XYZ 4-point, pointer, "
          "following the pendant's tilt hints\n")
    print(f"{'robot':<6} {'touch':>5} {'presses':>7} {'true mm':>8} {'reachable':>9}  suggestion")
    presses, distances, suggested, reachable = [], [], 0, 0
    runs = {robot: run_robot(robot) for robot in ROBOTS}
    for robot, touches in runs.items():
        for k, t in enumerate(touches):
            presses.append(t.presses)
            distances.append(t.distance_mm)
            mark = "-" if t.reachable is None else ("yes" if t.reachable else "NO")
            if t.reachable is not None:
                suggested += 1
                reachable += int(t.reachable)
            words = t.suggestion.split(" → ")[0] if t.suggestion else "(first touch: any orientation)"
            print(f"{robot:<6} {k + 1:>5} {t.presses:>7} {t.distance_mm:>8.3f} {mark:>9}  {words}")
    print("\nWhere the presses go (X/Y/Z presses by increment, mm):")
    print(f"{'robot':<6} {'touch':>5} " + " ".join(f"{kind:>5}" for kind in KINDS))
    for robot, touches in runs.items():
        for k, t in enumerate(touches):
            print(f"{robot:<6} {k + 1:>5} " + " ".join(f"{t.kinds.get(kind, 0):>5}" for kind in KINDS))
    flange = [[t.presses for t in run_robot(robot, pivot=False)] for robot in ROBOTS]
    print("\nThe same trainee never pressing \"Tilt about the wizard's estimate\" (every tilt about the "
          "flange), presses per touch:")
    for robot, row in zip(ROBOTS, flange):
        print(f"{robot:<6} " + " ".join(f"{n:>5}" for n in row))
    ok_presses = max(presses) <= GOAL_PRESSES_PER_TOUCH
    ok_distance = max(distances) <= GOAL_DISTANCE_MM
    ok_reach = suggested > 0 and reachable == suggested
    print(f"\npresses per touch: mean {np.mean(presses):.1f}, max {max(presses)}")
    print(f"TARGET at most {GOAL_PRESSES_PER_TOUCH} presses per touch: {'MET' if ok_presses else 'NOT MET'}")
    print(f"TARGET every touch within {GOAL_DISTANCE_MM} mm (max {max(distances):.3f} mm): "
          f"{'MET' if ok_distance else 'NOT MET'}")
    print(f"TARGET every suggested tilt reachable on {', '.join(ROBOTS)} ({reachable} of {suggested}): "
          f"{'MET' if ok_reach else 'NOT MET'}")
    return ok_presses and ok_distance and ok_reach


def delta_line_tables() -> None:
    print("Scripted trainees, XYZ 4-point, 4 standard orientations, KR 6 + pointer (issue 10)\n")
    delta = report("Trainee reading the Δ line:", run(Trainee))
    print()
    dist = report("Trainee steering by the distance alone (no Δ line):", run(DistanceTrainee))
    print(f"\nclicks per touch: Δ line {delta:.1f}, distance alone {dist:.1f} "
          f"({dist / delta:.1f}x; Δ line before issue 10: ~{BEFORE_CLICKS_PER_TOUCH:.0f}; "
          f"goal with the Δ line <= {GOAL_CLICKS_PER_TOUCH:.0f})")


def main(argv: list[str] | None = None) -> None:
    args = sys.argv[1:] if argv is None else argv
    if "--delta-line" in args:
        delta_line_tables()
    else:
        views_table()


if __name__ == "__main__":
    main()
