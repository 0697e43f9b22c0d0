"""The trainee's touch loop on one screen (in-process server, headless websocket
clients as browsers; clicks arrive as a browser's do, ``guiclick``).

* the wizard dock on the Jog tab shows the running wizard's step and records it (one Record
  concept: "Record point" is hidden meanwhile), Back / Next / Cancel and the meter;
* Record checks the touch: farther than 0.5 mm asks first (how far, which direction), a second
  Record at the same pose within the window records; "Hide distance" records at once;
* the Δ readout is the jog that brings the tips together, in the jog frame's axes;
* an increment stops at contact and says so; the next press goes on;
* continuous jog: the override's speed (mm/s measured on the server), no step larger than
  one 20 Hz tick allows, nothing after the release;
* the status line's stop message does not outlive a move that was not a jog (auto-touch);
* every button group marks its selected option.
"""

from __future__ import annotations

import re
import time

import numpy as np
import pytest

from support.app_page import AppPage, true_tip_at
from support.wsclient import ButtonClient, loop_ran_for, wait_until

from tcp_pendant.pendant.guidance import tip_offset_mm
from tcp_pendant.pendant.jogging import LINEAR_SPEED_MM_S
from tcp_pendant.serve.server import PendantApp
from tcp_pendant.views.pendant_panel import HOLD_HZ, MARK
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.views.wizard_dock import BACK, CANCEL, NEXT, TILT_LINE_STYLE, tilt_line_html


class Page(AppPage):
    """One connected browser: its session and views."""

    def __init__(self, app: PendantApp) -> None:
        super().__init__(app)
        self.dock = self.session.views["dock"]
        self.pendant = self.session.views["pendant"]
        self.calibrate = self.session.views["calibrate"]

    def tip_at(self, offset_mm: tuple[float, float, float]) -> None:
        """Teleport the true tool tip to the reference tip + ``offset_mm`` (WORLD), same
        orientation, and signal the move (as the gizmo would)."""
        true_tip_at(self.session, offset_mm)


pytestmark = pytest.mark.app_page(cls=Page, seed=3)


def test_the_dock_shows_the_wizards_step_on_the_jog_tab_and_records_it(page) -> None:
    p = page()
    s, dock = p.session, p.dock
    touches = s.views["touches"]
    assert s.workflow is p.calibrate.workflow
    assert not dock.folder.visible and touches.record.visible       # no wizard: Record point
    p.click(p.calibrate.start)                                      # XYZ 4-point (the first method)
    assert dock.folder.visible and not touches.record.visible       # one Record: the dock's
    assert "Step 1 of 4" in dock.step_md.content
    assert tuple(dock.nav.options) == (BACK, NEXT, CANCEL)
    assert "Pose diversity" in dock.meter_md.content                # the meter's line; its bar's row
    assert dock.pivot.visible and dock.pivot.disabled and not dock.meter_bar.visible   # holds the estimate
    p.tip_at((0.0, 0.0, 0.2))                                       # 0.2 mm above the tip
    p.click(dock.record)
    wiz = p.calibrate.workflow.wizard
    assert wiz.steps[0].recorded and not s.touches                  # the wizard's step, not the free list
    assert "✔ Step 1 recorded, 0.20 mm from the tip" in dock.note_md.content
    assert "recorded" in dock.step_md.content
    p.choose(dock.nav, NEXT)
    assert "Step 2 of 4" in dock.step_md.content and not dock.note_md.visible   # no stale line
    p.choose(dock.nav, BACK)
    assert "Step 1 of 4" in dock.step_md.content
    p.choose(dock.nav, CANCEL)
    assert not dock.folder.visible and touches.record.visible
    assert any("cancelled" in t for t, _ in p.notes)
    p.click(p.calibrate.resume)                                     # the Calibrate tab resumes it
    assert dock.folder.visible and not dock.note_md.visible         # the old line did not carry over


def test_the_docks_tilt_line_names_a_reachable_tilt_by_its_keyboard_key_in_full(page) -> None:
    """The hint: a tilt of the active jog frame the robot model can make with the tip held (not
    a turn about the tool's own length), its keyboard key, in full (no ellipsis); the reachable
    tilts under it; followed, it does not come back unchanged."""
    from tcp_pendant.controller.reach import tilt_reach

    p = page()
    s, dock = p.session, p.dock
    p.click(p.calibrate.start)                                      # XYZ 4-point
    wiz = p.calibrate.workflow.wizard
    assert dock.tilt_html.visible and dock.tilt_html.content == tilt_line_html(None)   # no touch yet
    assert "nowrap" not in TILT_LINE_STYLE and "ellipsis" not in TILT_LINE_STYLE
    for _ in range(2):
        assert s.wizard_commands.auto_touch(AutoTouchRequest()).ok
    assert wiz.step.index == 2
    html = dock.tilt_html.content
    m = re.search(r"Tilt next: ([ABC]) ([+−]) 45° in WORLD \(key (Shift\+)?([456])\)", html)
    assert m, html
    key, sign = m.group(1), 1 if m.group(2) == "+" else -1
    assert m.group(4) == {"A": "4", "B": "5", "C": "6"}[key] and bool(m.group(3)) == (sign < 0)
    assert tilt_reach(s.controller, "WORLD", key, sign, 45.0).reachable          # on the model
    axis = np.eye(3)[:, {"A": 2, "B": 1, "C": 0}[key]]
    assert abs(axis @ s.controller.T_world_flange()[:3, 2]) < np.cos(np.radians(25.0))   # a tilt
    assert "Reachable 45° tilts, tip held (WORLD):" in html and "…" not in html
    before = m.group(0)
    assert s.controller.jog_cartesian("WORLD", key, sign * 45.0).ok               # followed
    s.moved()
    assert before not in dock.tilt_html.content


def test_record_far_from_the_tip_asks_first_and_hide_distance_records(page) -> None:
    p = page()
    dock, wf = p.dock, p.calibrate.workflow
    p.click(p.calibrate.start)
    p.tip_at((-3.0, 0.0, 0.0))                                      # the reference tip is 3 mm +X of the tool tip
    p.click(dock.record)
    assert not wf.wizard.steps[0].recorded
    note = dock.note_md.content
    assert "3.00 mm" in note and "3.00 mm +X (WORLD)" in note and "Record" in note
    p.click(dock.record)                                            # the second Record, same pose
    assert wf.wizard.steps[0].recorded
    p.choose(dock.nav, NEXT)
    p.tip_at((0.0, -2.0, 0.0))
    p.click(dock.record)                                            # asks ...
    p.tip_at((0.0, -1.0, 0.0))
    p.click(dock.record)                                            # ... and asks again after a move
    assert not wf.wizard.steps[1].recorded and "1.00 mm" in dock.note_md.content
    p.choose(p.pendant.hide_distance, True)                         # the exercise: judged by eye
    assert p.session.hide_distance and "hidden" in p.pendant.touch_md.content
    assert "ΔX" not in p.pendant.touch_md.content and not p.pendant.closeup_md.visible
    p.click(dock.record)
    assert wf.wizard.steps[1].recorded
    assert "mm from the tip" not in dock.note_md.content            # the distance stays hidden


def test_free_practice_by_eye_each_record_says_how_far_the_touch_really_was(page) -> None:
    """Judged by eye, a trainee learns only if told afterwards: in free practice the step says
    how far the touch was and which way; in an exercise it says nothing."""
    from tcp_pendant.classroom.exercise_rules import class_rules

    p = page()
    dock, wf = p.dock, p.calibrate.workflow
    p.click(p.calibrate.start)
    p.choose(p.pendant.hide_distance, True)
    p.tip_at((0.3, -0.2, -0.7))                                     # the tool tip 0.8 mm off, mostly −Z
    p.click(dock.record)
    assert wf.wizard.steps[0].recorded
    assert "0.8 mm off, mostly −Z (WORLD): the tool tip was 0.7 mm −Z of the reference tip" in dock.note_md.content
    p.choose(dock.nav, NEXT)
    p.session.set_rules(class_rules("mystery"))                     # an exercise: the grade tells
    p.tip_at((0.3, -0.2, -0.7))
    p.click(dock.record)
    assert wf.wizard.steps[1].recorded
    assert "mm off" not in dock.note_md.content and "0.8" not in dock.note_md.content


def test_the_calibrate_tabs_record_says_how_far_too_in_free_practice_only(page) -> None:
    """The Calibrate tab's own Record gives the dock's words after a touch by eye in free
    practice, and nothing in an exercise."""
    from tcp_pendant.classroom.exercise_rules import class_rules

    p = page()
    steps, wf = p.calibrate.steps, p.calibrate.workflow
    p.click(p.calibrate.start)
    p.choose(p.pendant.hide_distance, True)
    p.tip_at((0.3, -0.2, -0.7))                                     # the tool tip 0.8 mm off, mostly −Z
    p.click(steps.record)
    assert wf.wizard.steps[0].recorded
    assert steps.record_md.content == ("✔ Step 1 recorded: 0.8 mm off, mostly −Z (WORLD): the tool tip was "
                                       "0.7 mm −Z of the reference tip.")
    p.click(steps.next)
    assert steps.record_md.content == ""                            # not carried to the next step
    p.tip_at((1.5, 0.1, 0.2))
    p.click(steps.record)
    assert steps.record_md.content.startswith("✔ Step 2 recorded: 1.5 mm off, mostly +X (WORLD)")
    p.click(steps.next)
    p.session.set_rules(class_rules("mystery"))                     # an exercise: the grade tells
    p.tip_at((0.3, -0.2, -0.7))
    p.click(steps.record)
    assert wf.wizard.steps[2].recorded
    assert steps.record_md.content == ""


@pytest.mark.parametrize("frame", ["WORLD", "TOOL"])
def test_the_delta_readout_is_the_jog_that_brings_the_tips_together(page, frame: str) -> None:
    p = page()
    s = p.session
    p.choose(p.pendant.frame, frame)
    p.tip_at((4.3, -2.6, 7.1))
    text = p.pendant.touch_md.content
    m = re.search(r"ΔX (\S+)  ΔY (\S+)  ΔZ (\S+) mm` to the tip \(" + frame, text)
    assert m, text
    delta = [float(v) for v in m.groups()]
    with s.lock:
        expected = tip_offset_mm(s.pose_state(), s.controller.reference_tip_world_m, frame)
    np.testing.assert_allclose(delta, expected, atol=0.006)
    if frame == "WORLD":
        np.testing.assert_allclose(delta, (-4.3, 2.6, -7.1), atol=0.006)
    with s.lock:                                                    # jog exactly by the readout
        for ax, d in zip("XYZ", delta):
            s.controller.jog_cartesian(frame, ax, d)
        s.moved()
    assert s.pose_state().touch.distance_mm < 0.05                   # the tips meet
    assert "TOUCHING" in p.pendant.touch_md.content
    assert "@" in p.pendant.closeup_md.content                      # one point in the close-up


def test_an_increment_stops_at_contact_and_the_next_press_goes_on(page) -> None:
    p = page()
    s, pendant = p.session, p.pendant
    p.tip_at((0.0, 0.0, 4.0))                                       # 4 mm above the reference tip
    p.choose(pendant.increment, "10")
    p.choose(pendant.cart_rows["Z"], "Z −")                         # 10 mm down: through the tip?
    st = s.pose_state()
    assert st.touch.distance_mm < 0.01 and not st.touch.crashed     # stopped where it touches
    assert "Stopped at the reference tip after 4.00 of 10 mm" in pendant.status_md.content
    assert any(t == "Jog stopped" for t, _ in p.notes)
    p.choose(pendant.cart_rows["Z"], "Z −")                         # the trainee insists: goes on
    assert s.pose_state().touch.crashed and "CRASH" in pendant.touch_md.content
    p.choose(pendant.cart_rows["Z"], "Z +")
    p.choose(pendant.cart_rows["X"], "X +")                         # beside the tip: no stop
    assert pendant.status_md.content == ""


def test_with_the_distance_hidden_a_jog_into_the_tip_stops_as_a_collision_and_is_a_crash(page) -> None:
    """Judged by eye: a press that would drive the tool tip through the reference tip stops where
    the tips meet, as a real collision stops a robot, says so with the key that backs off, and is
    recorded as a crash; the next press the same way goes on through (a second crash)."""
    from tcp_pendant.events import Crash

    p = page()
    s, pendant = p.session, p.pendant
    crashes: list[Crash] = []
    s.subscribe(lambda change: crashes.extend(e for e in change.events if isinstance(e, Crash)))
    p.choose(pendant.hide_distance, True)
    p.tip_at((0.0, 0.0, 4.0))                                       # 4 mm above the reference tip
    p.notes.clear()
    p.choose(pendant.increment, "10")
    p.choose(pendant.cart_rows["Z"], "Z −")                         # 10 mm down: would go 6 mm through
    st = s.pose_state()
    assert st.touch.distance_mm < 0.01 and not st.touch.crashed     # stopped where the tips meet
    assert "COLLISION" in pendant.status_md.content
    assert "Back off with Z + (3, WORLD frame)" in pendant.status_md.content
    assert [c.penetration_mm for c in crashes] == [0.0]             # recorded as a crash
    p.choose(pendant.cart_rows["Z"], "Z −")                         # the trainee insists: goes through
    assert s.pose_state().touch.crashed and "CRASH" in pendant.touch_md.content
    assert len(crashes) == 2


def test_with_the_distance_hidden_a_firm_touch_goes_on_and_a_backing_off_key_in_tool_warns(page) -> None:
    """0.1 mm past the tip is a firm touch (no stop, no word: the stop would give the tip away);
    in TOOL, where the tool's own +Z leads into the tip, "backing off" with Z + is stopped."""
    p = page()
    s, pendant = p.session, p.pendant
    p.choose(pendant.hide_distance, True)
    p.tip_at((0.0, 0.0, 0.35))
    p.choose(pendant.increment, "1")
    p.choose(pendant.cart_rows["Z"], "Z −")                         # 0.65 mm past: beyond the 0.5 mm
    assert "COLLISION" in pendant.status_md.content
    p.tip_at((0.0, 0.0, 0.3))
    p.choose(pendant.increment, "0.1")
    for _ in range(4):
        p.choose(pendant.cart_rows["Z"], "Z −")                     # ends 0.1 mm past: a firm touch
    assert "COLLISION" not in pendant.status_md.content and not s.pose_state().touch.crashed
    p.choose(pendant.frame, "TOOL")
    p.tip_at((0.0, 0.0, 5.0))                                       # 5 mm above the tip, flange down
    p.choose(pendant.increment, "10")
    p.choose(pendant.cart_rows["Z"], "Z +")                         # TOOL +Z points down, into the tip
    assert "COLLISION" in pendant.status_md.content and not s.pose_state().touch.crashed
    assert "Back off with Z − (Shift+3, TOOL frame)" in pendant.status_md.content


def test_a_stop_message_does_not_outlive_an_auto_touch(page) -> None:
    p = page()
    s, pendant = p.session, p.pendant
    p.tip_at((0.0, 0.0, 4.0))
    p.choose(pendant.increment, "10")
    p.choose(pendant.cart_rows["Z"], "Z −")
    assert "Stopped" in pendant.status_md.content
    p.click(p.calibrate.start)
    p.click(p.calibrate.steps.auto_touch)                           # moves, not a jog
    assert pendant.status_md.content == ""


def test_every_button_group_marks_its_selected_option(page) -> None:
    p = page()
    pendant = p.pendant
    assert MARK + "10" in pendant.increment.options and MARK + "Cartesian" in pendant.mode.options
    assert MARK + "WORLD" in pendant.readout_frame.options
    p.choose(pendant.increment, "1")                                # a browser sends the label ...
    assert MARK + "1" in pendant.increment.options and "10" in pendant.increment.options
    p.choose(pendant.increment, MARK + "1")                         # ... also the marked one
    assert p.session.jogger.settings.increment == "1"
    p.choose(pendant.readout_frame, "BASE")
    assert MARK + "BASE" in pendant.readout_frame.options and "TCP in BASE" in pendant.tcp_md.content
    p.choose(pendant.mode, "Joint")
    assert MARK + "Joint" in pendant.mode.options
    assert all(r.visible for r in pendant.joint_rows) and not any(r.visible for r in pendant.cart_rows.values())
    p.choose(pendant.increment, "Cont.")                            # hold keys in continuous mode
    assert not any(r.visible for r in pendant.joint_rows) and pendant.joint_buttons[(0, 1)].visible


def test_continuous_jog_moves_at_the_override_speed_and_stops_at_release(app_factory) -> None:
    app = app_factory()
    client = ButtonClient(app.port, ("X +",))
    assert client.found.wait(30)
    wait_until(lambda: len(app.sessions) == 1, what="session built")
    (s,) = app.sessions.values()
    try:
        with s.lock:
            s.jogger.settings = s.jogger.settings.with_(increment="Cont.", override_pct=50, frame="WORLD")
        xs: list[tuple[float, float]] = []
        s.add_motion_listener(lambda: xs.append((time.monotonic(), float(s.controller.T_world_tcp()[0, 3]))))
        x0 = float(s.controller.T_world_tcp()[0, 3])
        period = 1.0 / HOLD_HZ
        t_start = time.monotonic()
        n = 30                                                      # 1.5 s held, like a browser
        for i in range(n):
            client.hold_tick("X +", HOLD_HZ)
            time.sleep(max(0.0, t_start + (i + 1) * period - time.monotonic()))
        client.click("X +")                                         # the release
        wait_until(lambda: len(xs) >= n - 3, what="the hold ticks")
        client.sync(s.client)                                       # the release handled
        loop_ran_for(app.server.get_event_loop(), 3 / HOLD_HZ)      # three ticks' time on the server
        x_end = float(s.controller.T_world_tcp()[0, 3])
        held_s = n * period
        speed = (x_end - x0) * 1000.0 / held_s
        expected = LINEAR_SPEED_MM_S * 0.5                          # 125 mm/s at 50 %
        print(f"continuous jog: {speed:.1f} mm/s over {held_s:.2f} s (set {expected:.0f} mm/s), {len(xs)} ticks moved")
        assert speed == pytest.approx(expected, rel=0.2)
        steps = np.diff([x0] + [x for _, x in xs]) * 1000.0
        assert steps.max() <= expected / HOLD_HZ * 1.001            # no jump beyond one 20 Hz tick
        assert xs[-1][1] == x_end                                   # the release click did not move
    finally:
        client.close()


def test_the_scripted_trainee_touches_in_at_most_30_clicks() -> None:
    """tests/bench/bench_trainee.py's trainee (only what the page shows) finishes the 4-point
    calibration within 0.5 mm per touch, in at most 30 clicks per touch (the goal)."""
    from bench.bench_trainee import run

    out = run()
    assert len(out["clicks"]) == 4 and max(out["distance_mm"]) <= 0.5
    assert max(out["clicks"]) <= 30, out["clicks"]
    assert out["tcp_error_mm"] and out["tcp_error_mm"][0] < 1.0       # a usable result


def test_continuous_jog_keeps_its_speed_at_10_renewals_a_second_and_stops_when_they_lapse(app_factory) -> None:
    """A held key is a lease (``pendant.hold``): renewed 10 times a second (the least the page
    must send) the server's own 20 Hz ticks keep the set speed, in steps no larger than one
    tick's; renewed only every 0.5 s (a browser too busy to renew) it stops 250 ms after a
    renewal, says so, and a renewal after the lapse moves nothing until the key is released."""
    from tcp_pendant.views.pendant_panel import LAPSE_TEXT

    app = app_factory()
    client = ButtonClient(app.port, ("X +",))
    assert client.found.wait(30)
    wait_until(lambda: len(app.sessions) == 1, what="session built")
    (s,) = app.sessions.values()
    try:
        with s.lock:
            s.jogger.settings = s.jogger.settings.with_(increment="Cont.", override_pct=50, frame="WORLD")
        xs: list[float] = []
        s.add_motion_listener(lambda: xs.append(float(s.controller.T_world_tcp()[0, 3])))
        x0 = float(s.controller.T_world_tcp()[0, 3])
        t0 = time.monotonic()
        for k in range(15):                                          # 10 renewals a second, 1.5 s
            client.hold_tick("X +", HOLD_HZ)
            time.sleep(max(0.0, t0 + (k + 1) * 0.1 - time.monotonic()))
        client.click("X +")
        held_s = time.monotonic() - t0
        client.sync(s.client)                                       # the release handled
        panel = s.views["pendant"]
        assert not panel._hold.active                               # it stopped the server's ticks
        x_end = float(s.controller.T_world_tcp()[0, 3])
        speed = (x_end - x0) * 1000.0 / held_s
        print(f"10 Hz renewals: {speed:.1f} mm/s over {held_s:.2f} s, {len(xs)} ticks")
        assert speed == pytest.approx(125.0, rel=0.2)
        assert np.diff([x0] + xs).max() * 1000.0 <= 125.0 / HOLD_HZ * 1.001
        loop_ran_for(app.server.get_event_loop(), 3 / HOLD_HZ)      # three ticks' time on the server
        assert float(s.controller.T_world_tcp()[0, 3]) == x_end      # stopped at the release
        # renewals 0.5 s apart: the lease runs out after the first, the later ones move nothing
        client.hold_tick("X +", HOLD_HZ)
        client.sync(s.client)
        wait_until(lambda: panel._hold.lapsed is not None, what="the lease run out")
        x_lapsed = float(s.controller.T_world_tcp()[0, 3])
        assert (x_lapsed - x_end) * 1000.0 <= 125.0 * (0.25 + 1 / HOLD_HZ) + 1e-6
        assert panel._last_text.get("status") == f"⚠ {LAPSE_TEXT}"
        time.sleep(0.5)                                              # the busy browser's pace
        client.hold_tick("X +", HOLD_HZ)
        client.sync(s.client)                                       # the late renewal handled
        loop_ran_for(app.server.get_event_loop(), 3 / HOLD_HZ)
        assert float(s.controller.T_world_tcp()[0, 3]) == x_lapsed
        client.click("X +")                                          # let go ...
        client.sync(s.client)
        assert panel._hold.lapsed is None
    finally:
        client.close()
