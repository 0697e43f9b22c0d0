"""The views' jobs in the server's job pool. Auto-touch of a TCP check: the probe of each pose
reached (the check's six rotations from there, ``calibrate.jobs.spin_clearance``) runs in the
pool, not on viser's event loop; a robot moved while a probe ran records nothing, in words.
One job per session whatever its kind: a Check while the session's other job runs is refused
in the pool's words, the Check's line left as it was."""

from __future__ import annotations

import threading
from typing import Any

import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.calibrate.autotouch import MOVED_DURING_PROBE
from tcp_pendant.job_pool import JobPool
from tcp_pendant.session import Session
from tcp_pendant.views.wizard_dock import FINISH

from support.app_page import truth_tool
from support.calib_page import Page

pytestmark = pytest.mark.app_page(cls=Page, seed=5)

PROBE = "Auto-touch's check of the pose it reached"


def _check_wizard(page: Any) -> Any:
    p = page(tools={1: truth_tool("pointer", "Pointer")})
    s = p.session
    s.wizard_commands.start("tcp-check", slot=1)
    return p


def test_the_pose_probes_of_a_tcp_checks_auto_touch_run_in_the_job_pool(page) -> None:
    p = _check_wizard(page)
    s, steps = p.session, p.view.steps
    s.jobs = pool = JobPool(keep_history=True)
    ran_in: list[str] = []
    real_run = pool.run

    async def run(owner: Any, fn: Any, *, what: str) -> Any:
        def traced() -> Any:
            ran_in.append(threading.current_thread().name)
            return fn()
        return await real_run(owner, traced, what=what)

    pool.run = run  # type: ignore[method-assign]
    p.click(steps.auto_touch)
    wiz = s.workflow.wizard
    assert p.notes == [] and wiz is not None and wiz.check_pending          # recorded; Finish checks
    assert pool.history is not None and [h.what for h in pool.history] == [PROBE] * len(ran_in)
    assert ran_in and all(name.startswith("tcp-pendant-job") for name in ran_in)
    assert "recorded" in steps.auto_md.content
    pool.shutdown()


def test_a_robot_moved_while_the_probe_ran_records_nothing(page) -> None:
    p = _check_wizard(page)
    s, steps = p.session, p.view.steps

    class MovingPool(JobPool):
        """The browser jogs while the probe runs (on the loop, between the move and the answer)."""

        async def run(self, owner: Any, fn: Any, *, what: str) -> Any:
            s.motion.jog("x", 1)
            return await super().run(owner, fn, what=what)

    s.jobs = pool = MovingPool()
    with s.lock:
        s.jogger.settings = s.jogger.settings.with_(increment="1", frame="WORLD")
    p.click(steps.auto_touch)
    wiz = s.workflow.wizard
    assert wiz is not None and not wiz.check_pending and wiz.recorded_poses == {}
    assert p.notes == [("Not done", MOVED_DURING_PROBE)]
    pool.shutdown()


def test_a_check_while_the_sessions_other_job_runs_is_refused_in_words(page) -> None:
    p = page(tools={1: truth_tool("pointer", "Pointer")})
    s: Session = p.session
    panel = s.views["tools"]
    s.tools.activate(1)
    gate = threading.Event()
    s.jobs = pool = JobPool()
    running = pool.submit(s, lambda: gate.wait(10), what="a beam check")     # e.g. the TCP service's scan
    try:
        before = panel.check_md.content
        p.click(panel.check_active)
        assert p.notes == [("Check not started", "A beam check is still running here; wait for its result, "
                                                 "then try again.")]
        assert panel.check_md.content == before and panel.last_check is None
    finally:
        gate.set()
    assert running.result(10) is True
    p.notes.clear()
    p.click(panel.check_active)                                              # once it is done: checked
    assert p.notes == [] and panel.last_check is not None
    pool.shutdown()


def test_the_docks_finish_runs_the_check_in_the_job_pool(page) -> None:
    p = _check_wizard(page)
    s: Session = p.session
    s.jobs = pool = JobPool(keep_history=True)
    assert s.wizard_commands.auto_touch(AutoTouchRequest(tilt_deg=25.0, azimuth_deg=30.0)).ok     # probes in place
    p.choose(s.views["dock"].nav, FINISH)
    assert p.notes == [] and s.workflow.result is not None                       # checked, finished
    assert pool.history is not None and [h.what for h in pool.history] == [
        "the TCP check (spin test) wizard's controller job"]
    pool.shutdown()


def test_auto_touch_of_a_check_while_the_sessions_other_job_runs_is_refused_before_it_moves(page) -> None:
    p = _check_wizard(page)
    s: Session = p.session
    gate = threading.Event()
    s.jobs = pool = JobPool()
    running = pool.submit(s, lambda: gate.wait(10), what="a beam check")
    q_before = s.controller.q_rad.copy()
    try:
        p.click(p.view.steps.auto_touch)
        assert p.notes == [("Auto-touch not started", "A beam check is still running here; wait for its "
                                                      "result, then try again.")]
        assert (s.controller.q_rad == q_before).all() and s.workflow.wizard.recorded_poses == {}
    finally:
        gate.set()
    assert running.result(10) is True
    pool.shutdown()
