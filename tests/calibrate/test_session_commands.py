"""The session is its state's one command surface: every command ends in one change signal, and
the signal carries typed events with the facts of the moment they happened."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.events import Crash, RunCancelled, RunFinished, RunResumed, RunStarted, ToolSaved, TouchRecorded
from tcp_pendant.serve.server import AppConfig, PendantApp
from tcp_pendant.session import SessionChange

from support.calib_helpers import make_session


def recording(session) -> list[SessionChange]:
    changes: list[SessionChange] = []
    session.subscribe(changes.append)
    return changes


def only(changes: list[SessionChange]) -> SessionChange:
    assert len(changes) == 1, f"one signal per command, got {len(changes)}"
    out = changes[0]
    changes.clear()
    return out


def test_each_wizard_command_is_one_signal_with_its_events(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json", seed=3)
    changes = recording(s)
    s.wizard_commands.start("xyz4")
    change = only(changes)
    assert change.wizard and [type(e) for e in change.events] == [RunStarted]
    started = change.events[0]
    assert (started.run_index, started.kind, started.tool_key) == (0, "xyz4", "pointer")
    np.testing.assert_array_equal(started.T_flange_tool_true_m, s.controller.mounted_tool.T_flange_tool_true)

    out = s.wizard_commands.auto_touch(AutoTouchRequest())                 # step 1 by the controller
    change = only(changes)
    (touch,) = change.events
    assert isinstance(touch, TouchRecorded) and touch.auto and not touch.overwrite and touch.step == 0
    assert out.ok and change.pose and change.state is not None
    pose = s.workflow.wizard.recorded_poses[0]
    np.testing.assert_array_equal(touch.T_world_flange_m, pose.T_world_flange_m)
    np.testing.assert_allclose(touch.joints_deg, np.degrees(s.controller.q_rad))
    assert touch.distance_mm == pytest.approx(s.controller.touch_geometry().distance_mm)

    s.wizard_commands.back()
    assert only(changes).events == ()
    s.wizard_commands.record_step()                                        # the same step again, by hand
    (again,) = only(changes).events
    assert isinstance(again, TouchRecorded) and not again.auto and again.overwrite and again.step == 0

    while s.workflow.result is None:
        s.wizard_commands.auto_touch(AutoTouchRequest())
    finished = [e for c in changes for e in c.events if isinstance(e, RunFinished)]
    assert len(finished) == 1 and finished[0].result is s.workflow.result
    changes.clear()

    slot, tool = s.wizard_commands.save_result("Pointer calibrated")
    saved = [e for e in only(changes).events if isinstance(e, ToolSaved)]
    assert saved == [ToolSaved(0, slot, tool.name)]
    s.wizard_commands.cancel()                                      # Close on a saved result
    assert only(changes).events == (RunCancelled(0, finished=True),)


def test_starting_another_cancels_the_open_run_and_resume_brings_it_back(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json", seed=1)
    s.wizard_commands.start("xyz4")
    changes = recording(s)
    s.wizard_commands.start("tcp-zx")
    events = only(changes).events
    assert [type(e) for e in events] == [RunCancelled, RunStarted]
    assert events[0] == RunCancelled(0, finished=False) and events[1].run_index == 1
    s.wizard_commands.resume(0)
    assert only(changes).events == (RunCancelled(1, finished=False), RunResumed(0))


def test_a_crash_is_one_event_of_the_run_open_then(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json", seed=2)
    s.wizard_commands.start("xyz4")
    changes = recording(s)
    c = s.controller
    T_true = c.T_world_tool_true()
    T_true[:3, 3] = c.reference_tip_world_m + 0.004 * T_true[:3, 0]     # 4 mm through the tip
    c.move_true_tool_to(T_true)
    s.moved()
    s.moved()                                                           # still in: no second crash
    crashes = [e for ch in changes for e in ch.events if isinstance(e, Crash)]
    assert len(crashes) == 1 and crashes[0].run_index == 0
    assert crashes[0].penetration_mm == pytest.approx(c.touch_geometry().penetration_mm)


def test_motion_commands_signal_once_and_never_leave_the_limits(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json")
    changes = recording(s)
    k = s.controller.kinematics
    applied = s.motion.set_joint(0, 1e4)                                       # far past the limit: clipped
    change = only(changes)
    assert change.pose and change.jog is not None and change.jog.ok
    assert applied == pytest.approx(np.degrees(k.upper_rad[0]))
    with pytest.raises(ValueError, match="no joint"):
        s.motion.set_joint(k.n_joints, 0.0)
    with pytest.raises(ValueError, match="finite"):
        s.motion.set_joint(1, float("nan"))
    assert changes == []
    s.motion.ready()
    np.testing.assert_allclose(s.controller.q_rad, s.ready_q_rad if s.ready_q_rad is not None else k.home_rad)
    only(changes)
    s.motion.home()
    np.testing.assert_allclose(s.controller.q_rad, k.home_rad)
    only(changes)


def test_the_server_seed_makes_every_session_replay_the_same_way(tmp_path: Path) -> None:
    """One seed (``--seed``) gives session k of every server the same random stream, and each
    session of a server its own."""
    def streams(seed: int | None) -> list[np.ndarray]:
        app = PendantApp(AppConfig(port=0, tool_library=tmp_path / f"tools-{seed}.json", seed=seed))
        try:
            return [app.session_rng().normal(size=4) for _ in range(3)]
        finally:
            app.stop()

    a, b, other = streams(7), streams(7), streams(8)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)
    assert not np.allclose(a[0], a[1]) and not np.allclose(a[0], other[0])
    unseeded = streams(None), streams(None)
    assert not np.allclose(unseeded[0][0], unseeded[1][0])
    with pytest.raises(ValueError, match="seed"):
        PendantApp(AppConfig(port=0, tool_library=tmp_path / "t.json", seed=-1))


def test_a_seeded_session_auto_touches_reproducibly(tmp_path: Path) -> None:
    def touches(seed: int) -> list[np.ndarray]:
        s = make_session(tmp_path / f"tools-{seed}.json", seed=seed)
        s.wizard_commands.start("xyz4")
        for _ in range(4):
            s.wizard_commands.auto_touch(AutoTouchRequest(sigma_mm=0.5))
        return [p.T_world_flange_m for _, p in sorted(s.workflow.wizard.recorded_poses.items())]

    first, again, other = touches(11), touches(11), touches(12)
    for x, y in zip(first, again):
        np.testing.assert_array_equal(x, y)
    assert not np.allclose(first[0], other[0])


def test_hide_truth_always_outlasts_an_exercise(tmp_path: Path) -> None:
    """--hide-truth (a projector): the truth stays off even when an exercise ends."""
    s = make_session(tmp_path / "tools.json", seed=5)
    s.wizard_commands.set_hide_truth(True, always=True)
    s.wizard_commands.set_hide_truth(False)                       # an exercise ends: the projector still hides it
    assert s.workflow.hide_truth is True
    free = make_session(tmp_path / "t2.json", seed=5)
    free.wizard_commands.set_hide_truth(True)
    free.wizard_commands.set_hide_truth(False)
    assert free.workflow.hide_truth is False


def test_the_hide_truth_option_reaches_every_session(app_factory) -> None:
    from tcp_pendant.serve.cli import build_parser

    assert build_parser().parse_args(["--hide-truth"]).hide_truth is True
    assert build_parser().parse_args([]).hide_truth is False
    app = app_factory(hide_truth=True, shared=True)
    s = app.shared_session
    assert s is not None and s.workflow.hide_truth
    s.wizard_commands.start("xyz4")
    while s.workflow.result is None:
        s.wizard_commands.auto_touch(AutoTouchRequest())
    view = s.views["calibrate"]
    assert not view.result.truth_md.visible and not view.scene.true_tool.visible
    assert "Against the true TOOL frame" not in view.result.result_md.content


def test_joints_are_kept_only_for_the_poses_a_run_still_holds(tmp_path: Path) -> None:
    """A step recorded again many times keeps one pose's joints, and the pose the run holds
    still gives the joints it was recorded at."""
    s = make_session(tmp_path / "tools.json", seed=5)
    s.wizard_commands.start("xyz4")
    s.wizard_commands.auto_touch(AutoTouchRequest())
    for _ in range(40):                                    # step 1 again and again, by hand
        if s.workflow.wizard.step_index > 0:
            s.wizard_commands.back()
        s.wizard_commands.record_step()
    held = s.workflow.wizard.recorded_poses
    assert len(held) == 1
    assert len(s.workflow.touches._record_q) == 1
    np.testing.assert_allclose(s.workflow.joints_at_record(held[0]), s.controller.q_rad)
