"""One browser flooding the server with jobs gets its own refusals instead of slowing another
browser's jog (issue 42, item 5).

The attack (``browser_flood.py``): a browser in a process of its own clicks the Tool tab's
Check and "Check active tool" and the Calibrate tab's Auto-touch, in turn, as fast as its
socket takes the clicks; the victim, another browser, jogs X+ press after press and runs its
own TCP check meanwhile. What must hold, counted, not timed:

* every press of the victim is carried out (the deadman drops a press the server reaches more
  than 0.25 s late: none is dropped);
* the attacker is refused in words: past its share of the job pool, "The server is busy with
  this browser's jobs: try again in N s" (``job_pool``), and its refusal notices are coalesced
  (far fewer shown than refused, ``refusal_notices``);
* the victim's check is not refused, and no other session's job started while it waited: it
  waited for at most the one job running when it was submitted.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from tcp_pendant.job_pool import JobPool

from support.browser_flood import FloodRig, Presses
from support.wsclient import wait_until

OVER_SHARE = "The server is busy with this browser's jobs: try again in"
PRESSES = 20


@pytest.fixture
def rig(tmp_path: Path) -> Iterator[FloodRig]:
    r = FloodRig(tmp_path, JobPool(keep_history=True))          # the attacker: as fast as its socket
    yield r
    r.close()


def test_a_job_flooding_browser_is_refused_and_the_victims_presses_are_all_carried_out(rig: FloodRig) -> None:
    presses = Presses()
    with rig.flood() as attacker:
        wait_until(lambda: len([h for h in rig.pool.history or () if h.owner is attacker]) >= 5,
                   timeout=60, what="the attacker's first jobs")       # the flood under way
        rig.presses(PRESSES, presses, gap_s=0.2)
        rig.victim_check()
        rig.presses(PRESSES, presses, gap_s=0.2)
        refused = len(rig.attacker_refusals)
    assert presses.dropped == 0 and len(presses.latencies) == 2 * PRESSES, presses.line()
    # its jobs ran until its share was used up; then it was refused in words
    assert any(r.startswith(OVER_SHARE) for r in rig.attacker_refusals), rig.attacker_notes[:5]
    assert rig.clicks > 1000                                       # the flood really ran
    assert refused > 100 and attacker.refusals.suppressed > 0      # refused, its notices coalesced
    assert attacker.refusals.shown < refused / 10
    assert rig.victim_notes == [], "the victim's check was refused or failed"
    history = rig.pool.history
    assert history is not None
    (victim_job,) = [h for h in history if h.owner is rig.victim]
    assert not victim_job.busy
    attackers = [h for h in history if h.owner is attacker]
    assert attackers, "the attacker's jobs never ran"
    ahead = [h for h in attackers if victim_job.submitted_s < h.started_s < victim_job.started_s]
    assert ahead == [], "another session's job started while the victim's waited"
