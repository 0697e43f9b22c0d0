"""The wizard's step on show follows a live language switch in the browser's views (issue 47):
the dock shows the step's heading, title and instruction in the new language at once, the pose
and the recorded step stay."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from support.wsclient import DrainingClient, wait_until
from tcp_pendant.text_escape import escape_markdown as _esc
from tcp_pendant.translation import PSEUDO_LANGUAGE

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def test_the_dock_shows_the_step_in_the_new_language_after_a_switch(app_factory: Any) -> None:
    app = app_factory()
    c = DrainingClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 1, what="the session")
        (s,) = app.sessions.values()
        with s.lock:
            s.wizard_commands.start("xyz4")
            s.wizard_commands.record_step()
            s.wizard_commands.next_step()
            dock = s.views["dock"]
            english = s.workflow.wizard.step
            assert english.heading == "Step 2 of 4" and _esc(english.instruction) in dock.step_md.content
        q = s.controller.q_rad.copy()
        s.set_language(PSEUDO_LANGUAGE)
        with s.lock:                          # the change signal ran to its end
            step = s.workflow.wizard.step
            assert step.index == 1 and step.recorded is False and step.instruction != english.instruction
            content = dock.step_md.content
            for text in (step.heading, step.title, step.instruction):
                assert _esc(text) in content, text
            assert english.instruction not in content
        np.testing.assert_array_equal(s.controller.q_rad, q)
        s.set_language("en")
        with s.lock:
            assert _esc(english.instruction) in dock.step_md.content
    finally:
        c.close()
