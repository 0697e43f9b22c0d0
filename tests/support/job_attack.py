"""The rig of the job-pool attack (``test_job_pool.py``, ``tests/bench/bench_jobs.py``): a
pendant server in this process, the victim's browser over a real websocket (a ButtonClient: it
jogs, and runs the Tool tab's Check through the panel's own callback) and attacker sessions on
the same server and job pool (sessions as the server builds them, without a browser: they run
the Check's job, taken under the session lock as the Tool tab takes it, through the session's
own command ``SessionLoop.run_job``, again the moment its result is back). Every session has the
pointer's true tool data (TCP and axes) active, so every job is the same six rotations (or the
same beam scan) from the same pose."""

from __future__ import annotations

import asyncio
import gc
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from tcp_pendant.calibrate import CalibrationWorkflow
from tcp_pendant.calibrate.beam_service import beam_check_job
from tcp_pendant.serve.cli import set_apart_startup_objects
from tcp_pendant.controller import builtin_tools
from tcp_pendant.job_pool import REST_S, JobPool, JobTiming
from tcp_pendant.serve.server import AppConfig, PendantApp
from tcp_pendant.session import Session
from tcp_pendant.views.tool_check import check_job
from tcpcal.tool import Tool

from support.wsclient import ButtonClient, wait_until

PLUS_X = "X +"


@dataclass(frozen=True)
class Measured:
    """The victim's figures: check latencies (s) alone and under attack, its jogs' latencies
    (s) between its checks under attack and how many of its jog presses were not answered, its pool jobs under attack, the attackers' jobs
    started meanwhile, and per victim job the other sessions' jobs started while it waited."""

    alone: list[float]
    under: list[float]
    jogs: list[float]
    victim_jobs: list[JobTiming]
    attacker_jobs: list[JobTiming]
    ahead: list[list[JobTiming]]
    workers: int
    attackers: int
    unanswered: int
    attack: str = "check"

    @property
    def factor(self) -> float:
        """Median latency under attack over median latency alone."""
        return float(np.median(self.under) / np.median(self.alone))

    @property
    def attacker_run_s(self) -> float:
        """Median run time of the attackers' jobs meanwhile (the same machine, the same moment)."""
        return float(np.median([h.finished_s - h.started_s for h in self.attacker_jobs]))

    @property
    def factor_vs_attackers(self) -> float:
        """Median latency under attack over the median run time of one attacker job meanwhile:
        what waiting for the others cost, in jobs (the pool's rule: at most one per worker, so
        at most ~2 with jobs of the victim's size)."""
        return float(np.median(self.under) / self.attacker_run_s)

    def summary(self) -> str:
        def ms(xs: list[float]) -> str:
            return (f"p50 {np.median(xs) * 1e3:.0f} ms, p95 {np.percentile(xs, 95) * 1e3:.0f} ms, "
                    f"max {max(xs) * 1e3:.0f} ms")
        waits = ", ".join(f"{(v.started_s - v.submitted_s) * 1e3:.0f}/{(v.finished_s - v.started_s) * 1e3:.0f}"
                          for v in self.victim_jobs)
        return (f"victim TCP check alone ({len(self.alone)}): {ms(self.alone)}; under {self.attackers} attackers "
                f"({len(self.under)}, {self.workers} worker(s), {len(self.attacker_jobs)} attacker {self.attack} jobs "
                f"meanwhile, p50 run {self.attacker_run_s * 1e3:.0f} ms): {ms(self.under)}; factor (p50) {self.factor:.2f} "
                f"(over an attacker job's run: {self.factor_vs_attackers:.2f}); victim jogs ({len(self.jogs)}, "
                f"{self.unanswered} unanswered): {ms(self.jogs)}; victim's checks under attack, waited/ran ms: {waits}")


class Classroom:
    """The rig (module docstring).

    Args:
        tmp_path: folder of the tool library.
        pool: the server's job pool (keep_history on: the figures are read from it).
        attackers: attacker sessions.
        attack: the attackers' job: "check" (the TCP check, as the victim's) or "beam" (the TCP
            service's beam check, ~5-10x longer).
    """

    def __init__(self, tmp_path: Path, pool: JobPool, attackers: int = 20, attack: str = "check") -> None:
        if attack not in ("check", "beam"):
            raise ValueError(f"attack must be 'check' or 'beam', got {attack!r}")
        self.attack_kind = attack
        if pool.history is None:
            raise ValueError("the rig reads the pool's history: JobPool(keep_history=True)")
        self.app = app = PendantApp(AppConfig(port=0, tool_library=tmp_path / "tools.json"))
        self.pool = app.jobs = pool
        app.start()
        # as `tcp-pendant` does once it listens: without it, a full collection of the test
        # process's objects (~200k after hundreds of tests) stalls every thread 150-330 ms, past
        # the deadman's bound, and the victim's press is dropped for a reason no server has
        set_apart_startup_objects()
        self.victim_client = ButtonClient(app.port, (PLUS_X,))
        assert self.victim_client.found.wait(30), "the victim never saw the jog keys"
        wait_until(lambda: len(app.sessions) == 1, what="the victim's session")
        (self.victim,) = app.sessions.values()
        self.attackers: list[Session] = []
        for _ in range(attackers):
            c = app.new_controller()
            rng = app.session_rng()
            workflow = CalibrationWorkflow(c, app.library, robot=app.robot_key, rng=rng)
            self.attackers.append(Session(c, app.library, workflow, rng=rng, jobs=app.jobs))
        pointer = builtin_tools()["pointer"]
        T_true = pointer.T_flange_tool_true
        self.tool = Tool.from_rotation("Pointer", tuple(float(v) * 1000.0 for v in T_true[:3, 3]), T_true[:3, :3])
        self.notes: list[tuple[str, str]] = []
        self.victim.notify = lambda title, body, kind="info": self.notes.append((title, body))  # type: ignore[method-assign]
        for s in [self.victim, *self.attackers]:
            with s.lock:
                s.tools.set_active_data(self.tool)
        with self.victim.lock:
            self.victim.jogger.settings = self.victim.jogger.settings.with_(increment="0.1", frame="WORLD")
        self.loop = self.victim.views["calibrate"].load._impl.gui_api._event_loop
        self.stop = threading.Event()
        self.attacks: list[Any] = []

    def check(self) -> float:
        """The victim's Check of its active tool data, as its button's callback runs it:
        seconds from the click to the result shown."""
        panel = self.victim.views["tools"]
        t0 = time.perf_counter()
        asyncio.run_coroutine_threadsafe(panel.run_check(panel._active_for_check), self.loop).result(60)
        assert panel.check_md.content.startswith("**TCP check"), (panel.check_md.content, self.notes)
        return time.perf_counter() - t0

    async def attack(self, s: Session) -> None:
        """One attacker: the Check's job again the moment its result is back, until told to stop."""
        while not self.stop.is_set():
            with s.lock:
                job = (check_job(s.controller, self.tool, "Pointer", 30.0) if self.attack_kind == "check"
                       else beam_check_job(s.controller, None, self.tool, rng_seed=1))
            await s.loop.run_job(job.run, what=f"a {'TCP' if self.attack_kind == 'check' else 'beam'} check")

    def jog_latency_s(self, timeout_s: float = 2.0) -> float | None:
        """Click X+ in the victim's browser and wait until its robot moved: seconds, or None when
        it did not move within ``timeout_s`` (the press was dropped: the server's deadman drops
        a press that waited 250 ms for the event loop)."""
        s = self.victim
        x0 = s.controller.T_world_tcp()[0, 3]
        t0 = time.perf_counter()
        self.victim_client.click(PLUS_X)
        while abs(s.controller.T_world_tcp()[0, 3] - x0) < 5e-5:
            if time.perf_counter() - t0 > timeout_s:
                return None
            time.sleep(0.001)
        return time.perf_counter() - t0

    def measure(self, n_alone: int, n_under: int, rest_s: float = REST_S + 0.1) -> Measured:
        """The victim's ``n_alone`` checks with no attack (after one not counted), then the attack, and once every attacker
        has had its first result (from then on each resubmits busy), ``n_under`` checks, each
        after ``rest_s`` of jogging (a trainee reads the result, jogs, checks again)."""
        history = self.pool.history
        assert history is not None
        self.check()                             # warm: the first check of a session is slower
        alone = [self.check() for _ in range(n_alone)]
        self.attacks = [asyncio.run_coroutine_threadsafe(self.attack(s), self.loop) for s in self.attackers]
        wait_until(lambda: len({id(h.owner) for h in history if h.owner is not self.victim}) == len(self.attackers),
                   timeout=60, what="every attacker's first result")
        under: list[float] = []
        jogs: list[float] = []
        unanswered = 0
        for _ in range(n_under):
            rest_until = time.perf_counter() + rest_s
            while time.perf_counter() < rest_until:
                jog = self.jog_latency_s()
                if jog is None:
                    unanswered += 1
                else:
                    jogs.append(jog)
            under.append(self.check())
        done = list(history)
        victim_jobs = [h for h in done if h.owner is self.victim][-n_under:]
        others = [h for h in done if h.owner is not self.victim]
        ahead = [[h for h in others if v.submitted_s < h.started_s < v.started_s] for v in victim_jobs]
        return Measured(alone, under, jogs, victim_jobs, [h for h in others if h.started_s > victim_jobs[0].submitted_s],
                        ahead, self.pool.workers, len(self.attackers), unanswered, self.attack_kind)

    def close(self) -> None:
        self.stop.set()
        for a in self.attacks:                   # their queued jobs are dropped, not run
            a.cancel()
        self.victim_client.close()
        self.app.stop()
        gc.unfreeze()                            # the later tests' objects are collected as usual
