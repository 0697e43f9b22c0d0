"""The touch loop on the Calibrate tab, in a real viser server (in-process) with a
headless websocket client as the browser (``guiclick``): the Auto-touch line never goes stale,
wizard touches keep their distance-at-record for the session record and the result, and an XYZ
4-point wizard can start from the free "Record point" touches."""

from __future__ import annotations

import json

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.session import Touch
from tcp_pendant.wizards import WizardError
from tcp_pendant.wizards.session_record import SessionRecordError, dumps, load_and_replay

from tcpcal.origin import solve_xyz4
from support.calib_page import Page

pytestmark = pytest.mark.app_page(cls=Page, seed=5)


# ---------------------------------------------------------------- stale texts
def test_auto_touch_line_goes_when_a_step_is_recorded_by_hand(page) -> None:
    p = page()
    v = p.view
    p.click(v.start)
    p.click(v.steps.auto_touch)                        # step 1 by auto-touch, the wizard is on step 2
    assert v.workflow.wizard.step_index == 1
    assert v.steps.auto_md.content.startswith("Step 1 recorded")
    p.click(v.steps.record)                            # step 2 recorded by hand
    assert v.workflow.wizard.recorded_poses.keys() == {0, 1}
    assert v.steps.auto_md.content == ""               # no "Step 1 recorded" next to step 2's record


def test_auto_touch_line_follows_every_auto_touch_and_the_step(page) -> None:
    p = page()
    v = p.view
    p.click(v.start)
    for _ in range(3):
        p.click(v.steps.auto_touch)
    assert v.steps.auto_md.content.startswith("Step 3 recorded")
    p.click(v.steps.back)                              # back to step 3: the line was about going on
    assert v.steps.auto_md.content == ""


def test_auto_touch_line_does_not_carry_into_another_wizard(page) -> None:
    p = page()
    v = p.view
    p.click(v.start)
    p.click(v.steps.auto_touch)
    assert v.steps.auto_md.content.startswith("Step 1 recorded")
    p.click(v.steps.cancel)
    p.click(v.start)                                   # another wizard: nothing from the first one
    assert len(v.workflow.runs) == 2
    assert v.steps.auto_md.content == ""


# ---------------------------------------------------------------- helpers (no viser)
DIRECTIONS = ((30.0, 0.0, 0.0), (35.0, 90.0, 20.0), (40.0, 200.0, -30.0), (25.0, 300.0, 45.0),
              (45.0, 45.0, 10.0), (30.0, 150.0, -60.0))


def free_touches(wf, n: int, sigma_mm: float = 0.3) -> list[Touch]:
    """``n`` "Record point" touches of the reference tip from different directions, each with
    its true distance at record (as ``Session.record_touch`` stores them)."""
    c, rng = wf.controller, np.random.default_rng(11)
    out = []
    for i in range(n):
        tilt, azimuth, spin = DIRECTIONS[i % len(DIRECTIONS)]
        res = c.auto_approach(tilt_deg=tilt, azimuth_deg=azimuth + 7.0 * (i // len(DIRECTIONS)), spin_deg=spin,
                              sigma_mm=sigma_mm, rng=rng)
        assert res.ok, res.message
        out.append(Touch(c.T_world_flange(), f"P{i + 1}", c.touch_geometry().distance_mm))
    return out


# ---------------------------------------------------------------- a wizard from the free touches
def test_five_free_touches_start_an_xyz4_wizard_that_equals_solve_xyz4(workflow) -> None:
    wf = workflow()
    touches = free_touches(wf, 5)
    w = wf.start_from_touches(touches, estimator="lstsq")
    assert w.kind == "xyz4" and w.n_points == 5 and w.is_complete is False
    assert sorted(w.recorded_poses) == [0, 1, 2, 3, 4] and w.on_last_step and w.can_next
    res = wf.next()                                    # Finish
    assert res is not None
    R = np.array([t.T_world_flange[:3, :3] for t in touches])
    p_mm = np.array([t.T_world_flange[:3, 3] for t in touches]) * 1000.0
    expected = solve_xyz4(R, p_mm, method="lstsq")
    np.testing.assert_allclose(res.tcp_mm, expected.tcp, atol=1e-9)
    np.testing.assert_allclose(res.per_touch_error_mm, expected.residuals, atol=1e-9)
    assert wf.run.distance_mm == {i: pytest.approx(t.distance_mm) for i, t in enumerate(touches)}


def test_two_free_touches_fill_the_first_steps_of_four(workflow) -> None:
    wf = workflow()
    touches = free_touches(wf, 2)
    w = wf.start_from_touches(touches)
    assert w.n_points == 4 and sorted(w.recorded_poses) == [0, 1] and w.step_index == 2
    np.testing.assert_allclose(w.recorded_poses[1].T_world_flange_m, touches[1].T_world_flange)
    assert not w.can_next                              # step 3 is still to be touched


def test_too_many_or_bad_free_touches_open_nothing(workflow) -> None:
    wf = workflow()
    wf.start("xyz4")
    open_before = wf.wizard
    with pytest.raises(WizardError, match="at most 20: delete some"):
        wf.start_from_touches(free_touches(wf, 21, sigma_mm=0.0))
    bad = np.eye(4)
    bad[:3, :3] *= 2.0                                 # not a rotation
    with pytest.raises(WizardError, match="touch 2"):
        wf.start_from_touches([np.eye(4), bad])
    with pytest.raises(WizardError, match="no recorded points"):
        wf.start_from_touches([])
    assert len(wf.runs) == 1 and wf.wizard is open_before and open_before.status == "in_progress"


# ---------------------------------------------------------------- distance at record
def test_wizard_touches_keep_their_distance_at_record_in_the_session_record(workflow) -> None:
    wf = workflow()
    wf.start("xyz4")
    c = wf.controller
    out = wf.auto_touch(AutoTouchRequest(sigma_mm=0.8))          # step 1, about 1 mm off
    assert out.ok
    d1 = wf.run.distance_mm[0]
    assert 0.0 < d1 == pytest.approx(c.touch_geometry().distance_mm)
    c.jog_cartesian("world", "Z", 5.0)                          # step 2 recorded 5 mm above
    far = c.touch_geometry().distance_mm
    wf.record()
    assert wf.run.distance_mm[1] == pytest.approx(far) and far > 4.0
    record = json.loads(dumps(wf.export_record()))
    assert record["version"] == 2
    assert record["wizards"][0]["distance_mm"] == {"0": pytest.approx(d1), "1": pytest.approx(far)}
    wf2 = workflow()
    wf2.load_record(json.dumps(record).encode())
    assert wf2.runs[0].distance_mm == {0: pytest.approx(d1), 1: pytest.approx(far)}


def test_records_without_distances_still_load_and_bad_distances_are_refused(workflow) -> None:
    wf = workflow()
    wf.start("xyz4")
    wf.auto_touch(AutoTouchRequest())
    record = json.loads(dumps(wf.export_record()))
    old = json.loads(json.dumps(record))
    del old["wizards"][0]["distance_mm"]                        # an older record: no distances
    assert len(load_and_replay(json.dumps(old).encode()).checks) == 1
    for bad in ({"0": -1.0}, {"zero": 0.5}, {"0": "0.5"}, [0.5], {"0": True}):
        broken = json.loads(json.dumps(record))
        broken["wizards"][0]["distance_mm"] = bad
        with pytest.raises(SessionRecordError, match="distance_mm"):
            load_and_replay(json.dumps(broken).encode())


# ---------------------------------------------------------------- the same in the Calibrate tab
def test_the_calibrate_menu_starts_xyz4_from_the_recorded_points(page) -> None:
    p = page()
    v, s = p.view, p.session
    assert v.menu_folder.visible and not v.start_from_points.visible    # no free touch yet
    rng = np.random.default_rng(3)
    for tilt, azimuth, spin in DIRECTIONS[:5]:
        with s.lock:
            assert s.controller.auto_approach(tilt_deg=tilt, azimuth_deg=azimuth, spin_deg=spin,
                                              sigma_mm=0.2, rng=rng).ok
        s.record_touch()                                                 # the Jog tab's "Record point"
    assert v.start_from_points.visible and v.start_from_points.label == "Start from the 5 recorded points"
    p.choose(v.method, "XYZ reference")
    assert not v.start_from_points.visible                              # only for XYZ 4-point
    p.choose(v.method, "XYZ 4-point")
    p.click(v.start_from_points)
    w = v.workflow.wizard
    assert p.notes == [] and v.steps.folder.visible and not v.menu_folder.visible
    assert w.kind == "xyz4" and w.n_points == 5 and sorted(w.recorded_poses) == [0, 1, 2, 3, 4]
    assert v.steps.next.label == "Finish" and not v.steps.next.disabled
    p.click(v.steps.next)
    res = v.workflow.result
    assert res is not None and v.result.folder.visible
    R = np.array([t.T_world_flange[:3, :3] for t in s.touches])
    p_mm = np.array([t.T_world_flange[:3, 3] for t in s.touches]) * 1000.0
    np.testing.assert_allclose(res.tcp_mm, solve_xyz4(R, p_mm).tcp, atol=1e-9)
    assert len(s.touches) == 5                                         # the free list is kept


def test_the_result_shows_the_distance_of_touches_recorded_hidden(page) -> None:
    p = page()
    v, s = p.view, p.session
    s.set_hide_distance(True)                                           # the exercise: judge by eye
    p.click(v.start)
    v.steps.auto_sigma.value = 0.5
    for _ in range(4):
        p.click(v.steps.auto_touch)
    res, run = v.workflow.result, v.workflow.run
    assert res is not None and run.distance_hidden == {0, 1, 2, 3}
    assert v.result.hidden_md.visible
    md = v.result.hidden_md.content
    assert "distance at record" in md
    for i in range(4):
        assert f"| P{i + 1} | {run.distance_mm[i]:.2f} mm | {res.per_touch_error_mm[i]:.2f} mm |" in md


def test_no_distance_table_when_the_distance_was_shown(page) -> None:
    p = page()
    v = p.view
    p.click(v.start)
    for _ in range(4):
        p.click(v.steps.auto_touch)
    assert v.workflow.result is not None and len(v.workflow.run.distance_mm) == 4
    assert not v.result.hidden_md.visible
