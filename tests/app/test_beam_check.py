"""In the Tool tab: the TCP service with the beam sensor ("Check with beam",
"Update", ``views.beam_check``). The industrial loop: a tool bent in a crash (the bent-tool
scenario) -> Check with beam finds the bend -> Update writes the measured TCP into the library
(method "beam") and makes it the active data -> the spin test says good. In-process server,
headless websocket client as the browser (``guiclick``)."""

from __future__ import annotations


import numpy as np
import pytest

from support.app_page import AppPage, truth_tool
from support.wsclient import wait_until

from tcp_pendant.controller import builtin_tools
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.beam_replay import ScanPlayer


class Page(AppPage):
    def __init__(self, app) -> None:
        super().__init__(app)
        self.tools = self.session.views["tools"]
        self.beam = self.session.views["beam_check"]
        self.session.views["beam_player"].rate_hz = 400.0                  # the film, fast

    def activate(self, slot: int) -> None:
        opt = next(o for o in self.tools.slots.options if o.startswith(f"{slot}:") or o.startswith(f"{slot} "))
        self.choose(self.tools.slots, opt)
        self.click(self.tools.activate)

    def film_done(self) -> None:
        wait_until(lambda: not self.session.views["beam_player"].playing, timeout=60, what="the scan's film")


# seeded: the beam's repeatability noise (about 0.02 mm per axis) comes from the session's
# randomness, and the checks below allow 0.05 mm
pytestmark = [pytest.mark.app_page(cls=Page, seed=7), pytest.mark.shares_cpu]  # asserts no time, latency or load (tests/conftest.py)


def test_check_with_beam_needs_an_active_tool(page) -> None:
    p = page()
    p.click(p.beam.check)
    assert p.notes and "No tool data is active" in p.notes[-1][1]
    assert p.beam.last_check is None and p.beam.update.disabled


def test_check_with_beam_is_off_in_an_exercise(page) -> None:
    """In a classroom exercise (the workflow hides the truth) the beam would measure the mystery
    tool for the trainee: Check with beam and the Automatic (beam) wizard are refused in words."""
    from tcp_pendant.wizards import WizardError
    p = page({1: truth_tool("pointer", "Pointer")})
    p.activate(1)
    p.session.wizard_commands.set_hide_truth(True)
    p.click(p.beam.check)
    assert p.notes[-1][0] == "Not done" and "off during the trainer's exercise" in p.notes[-1][1]
    assert p.beam.last_check is None and not p.session.views["beam_player"].playing
    with pytest.raises(WizardError, match="Automatic \\(beam\\) wizard is off during the trainer's exercise"):
        p.session.wizard_commands.start("beam")
    assert p.session.wizard_commands.start("xyz4").kind == "xyz4"            # touching is the exercise
    p.session.wizard_commands.set_hide_truth(False)
    p.click(p.beam.check)
    assert p.beam.last_check is not None


def test_the_industrial_loop_crash_check_update_verify(page) -> None:
    p = page({1: truth_tool("pointer", "Pointer")})
    s, c = p.session, p.session.controller
    p.activate(1)
    q_before = c.q_rad
    world = s.set_scenario("bent_tool", 6)                          # the crash: the tool is bent
    bent_tip_mm = c.mounted_tool.T_flange_tool_true[:3, 3] * 1000.0
    stored_mm = np.asarray(s.library.get(1).tcp_mm)
    assert p.beam.update.disabled                                   # nothing measured yet

    p.click(p.beam.check)                                           # Check with beam
    check = p.beam.last_check
    assert check is not None and check.slot == 1 and check.tool_name == "Pointer"
    np.testing.assert_allclose(check.stored_tcp_mm, stored_mm, atol=1e-9)
    np.testing.assert_allclose(check.measured_tcp_mm, bent_tip_mm, atol=0.05)    # the beam sees the bent tip
    assert check.deviation_norm_mm == pytest.approx(world.tool_bend.shift_mm, abs=0.05)
    md = p.beam.result_md.content
    assert "Beam check of Pointer" in md and f"Deviation **{check.deviation_norm_mm:.3f} mm**" in md
    assert not p.beam.update.disabled and not p.beam.replay.disabled
    assert s.views["beam_player"].scan is check.scan                      # the scan plays in the scene
    f = p.beam.framing                                              # and the camera looks at it
    to_sensor = np.asarray(c.beam_sensor.point) - f.position
    forward = (f.look_at - f.position) / np.linalg.norm(f.look_at - f.position)
    assert np.degrees(np.arccos(to_sensor @ forward / np.linalg.norm(to_sensor))) < 10.0
    assert f.distance_m < 1.5                                       # closer than the overview
    p.film_done()
    np.testing.assert_allclose(c.q_rad, q_before, atol=1e-12)       # and the robot is back where it was

    p.click(p.beam.update)                                          # Update
    stored = s.library.get(1)
    np.testing.assert_allclose(stored.tcp_mm, check.measured_tcp_mm, atol=1e-6)
    assert stored.calibration is not None and stored.calibration.method == "beam"
    assert c.active_tool == stored and s.tools.active_slot == 1           # the updated data is active
    assert p.notes[-1][0] == "TCP updated"
    assert "Updated slot 1: Pointer" in p.beam.result_md.content
    assert p.beam.update.disabled                                   # one check, one update

    p.click(p.tools.check_active)                                   # verify: the spin test
    _, spin = p.tools.last_check
    assert spin.implied_tcp_error_mm < 0.1
    assert "TCP good" in p.tools.check_md.content


def test_update_is_refused_when_the_active_tool_changed_since_the_check(page) -> None:
    p = page({1: truth_tool("pointer", "Pointer"), 2: truth_tool("pointer", "Other", (0.0, 0.0, 2.0))})
    p.activate(1)
    p.click(p.beam.check)
    p.film_done()
    assert not p.beam.update.disabled
    p.activate(2)
    assert p.beam.update.disabled                                   # the button says so at once
    before = p.session.library.tools()
    p.click(p.beam.update)                                          # a click that arrives anyway
    assert "active tool changed since the check" in p.notes[-1][1]
    assert p.session.library.tools() == before                      # nothing written


def test_a_hostile_tool_name_is_escaped(page) -> None:
    hostile = "<img src=x>**b**[a](j:x)"
    p = page({1: truth_tool("pointer", hostile)})
    p.activate(1)
    p.click(p.beam.check)
    p.film_done()
    md = p.beam.result_md.content
    assert escape_markdown(hostile) in md and "<img" not in md
    p.click(p.beam.update)
    md = p.beam.result_md.content
    assert "<img" not in md and escape_markdown(hostile) in md


def test_a_tool_the_beam_cannot_see_and_an_unreachable_beam_are_told_in_words(page) -> None:
    from tcp_pendant.controller.beam import BeamSensor

    p = page({1: truth_tool("pointer", "Pointer")})
    p.activate(1)
    gripper = builtin_tools()["gripper"]
    p.choose(p.tools.mounted, gripper.label)                        # no tip to see
    p.click(p.beam.check)
    assert p.notes[-1][0] == "Not done" and "cannot measure this tool" in p.notes[-1][1]
    assert p.beam.last_check is None and not p.beam.check.disabled
    p.choose(p.tools.mounted, builtin_tools()["pointer"].label)
    q = p.session.controller.q_rad
    with p.session.lock:                                            # a beam far out of reach
        p.session.controller.set_beam_sensor(BeamSensor(point=(4.0, 4.0, 0.3), direction=(1.0, 0.0, 0.0)))
    p.click(p.beam.check)                                           # the scan fails in the worker
    assert p.notes[-1][0] == "Beam check not done", p.notes[-1]
    assert p.beam.result_md.content.startswith("⚠") and p.beam.last_check is None
    assert not p.beam.check.disabled and p.beam.update.disabled     # ready for another try
    np.testing.assert_array_equal(p.session.controller.q_rad, q)    # nothing moved


def test_a_second_check_during_the_film_returns_to_where_the_first_started(page) -> None:
    p = page({1: truth_tool("pointer", "Pointer")})
    p.activate(1)
    c = p.session.controller
    q_home = c.q_rad
    player = p.session.views["beam_player"]
    player.rate_hz = 4.0                                            # the first film, slow
    p.click(p.beam.check)
    wait_until(lambda: player.frames_played >= 3, what="the first film under way")
    assert not np.allclose(c.q_rad, q_home)
    player.rate_hz = 400.0
    p.click(p.beam.check)                                           # again, from mid-film
    np.testing.assert_allclose(p.beam.last_check.scan.moves[0].q_start_rad, player.frames[0].q_rad)
    p.film_done()
    np.testing.assert_allclose(c.q_rad, q_home, atol=1e-12)         # home, not the mid-film pose


def test_an_unexpected_failure_is_one_notification_and_the_view_stays_usable(page, monkeypatch) -> None:
    import tcp_pendant.views.beam_check as beam_check

    p = page({1: truth_tool("pointer", "Pointer")})
    p.activate(1)

    def broken(*_a, **_k):
        raise RuntimeError("boom")
    monkeypatch.setattr(beam_check, "beam_check_job", broken)
    p.click(p.beam.check)
    assert p.notes[-1] == ("Beam check failed", "RuntimeError: boom")
    assert not p.beam.check.disabled
    monkeypatch.undo()
    p.click(p.beam.check)                                           # and the next check works
    assert p.beam.last_check is not None


def test_shared_mode_checks_and_updates_the_one_robot(app_factory) -> None:
    from support.guiclick import click
    from support.wsclient import DrainingClient

    app = app_factory({1: truth_tool("pointer", "Pointer", (0.0, 1.0, 0.0))}, active_slot=1, shared=True)   # 1 mm off
    ws = [DrainingClient(app.port), DrainingClient(app.port)]
    try:
        wait_until(lambda: len(app.server.get_clients()) == 2, what="two browsers")
        s = app.shared_session
        s.views["beam_player"].rate_hz = 400.0
        view = s.views["beam_check"]
        a, _b = app.server.get_clients().values()
        s.notify = lambda *args, **kw: None                          # type: ignore[method-assign]
        assert s.tools.active_slot == 1
        click(view.check, a)
        assert view.last_check.deviation_norm_mm == pytest.approx(1.0, abs=0.05)
        wait_until(lambda: not s.views["beam_player"].playing, timeout=60, what="the film")
        click(view.update, a)
        np.testing.assert_allclose(app.library.get(1).tcp_mm, truth_tool("pointer", "x").tcp_mm, atol=0.05)
        assert app.library.active_slot() == 1                        # --shared: the library's active slot
    finally:
        for w in ws:
            w.close()
