"""Words a trainee reads (issue 44): predictions from the trainee's own scatter once the touches
over-determine the TCP; the solver's equation labels only in "The math"; "the meter below"
named; the step that asks for a tilt points at the reachable ones."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from support.calib_page import Page
from tcpcal.origin import solve_xyz4
from tcpcal.pose_quality import candidate_gain

from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.calibrate.tilt_advice import MIN_MEASURED_SIGMA_MM, measured_sigma_mm
from tcp_pendant.wizards import ESTIMATOR_LABELS

pytestmark = pytest.mark.app_page(cls=Page, seed=5)


_ORIENTATIONS = ((0.0, 0.0), (40.0, 0.0), (40.0, 90.0), (40.0, 225.0))
"""(tilt, azimuth) deg of the auto-touches: tilted about two axes, then a fourth between."""


def _touches(s, n: int, sigma_mm: float = 0.0) -> None:
    for tilt, az in _ORIENTATIONS[:n]:
        assert s.wizard_commands.auto_touch(AutoTouchRequest(tilt_deg=tilt, azimuth_deg=az, sigma_mm=sigma_mm)).ok


def test_the_prediction_uses_the_trainees_own_scatter(page) -> None:
    """A run's own touches, once tcpcal solves them (four): their noise_sigma; before that, the
    scatter of the trainee's last calibration of the session predicts."""
    p = page()
    v, s = p.view, p.session
    p.click(v.start)
    _touches(s, 4, sigma_mm=0.3)                                              # run 1, finished
    run1 = v.workflow.wizard
    assert run1.is_complete
    poses = run1.recorded_poses
    R = np.array([poses[i].T_world_flange_m[:3, :3] for i in range(4)])
    f = np.array([poses[i].T_world_flange_m[:3, 3] for i in range(4)]) * 1000.0
    first = max(float(solve_xyz4(R, f).noise_sigma), MIN_MEASURED_SIGMA_MM)
    assert measured_sigma_mm(run1) == pytest.approx(first) and first != pytest.approx(0.5, abs=0.01)
    p.click(v.start)                                                          # run 2: three touches
    _touches(s, 3)
    wiz = v.workflow.wizard
    assert wiz is not run1 and measured_sigma_mm(wiz) is None
    assert s.controller.jog_cartesian("WORLD", "C", -45.0).ok                  # toward a fourth orientation
    s.moved()
    want = candidate_gain(wiz.other_rotations(), s.controller.T_world_flange()[:3, :3], sigma=first).predicted_after
    dock = s.views["dock"]
    m = re.search(r"predicted TCP error (\d+\.\d\d) mm if recorded here \(your last calibration scattered "
                  r"(\d+\.\d\d) mm\)", dock.meter_md.content)
    assert m, dock.meter_md.content
    assert float(m.group(1)) == pytest.approx(want, abs=0.006) and float(m.group(2)) == pytest.approx(first, abs=0.006)
    assert f"your last calibration: scatter {first:.2f} mm" in v.steps.meter_md.content


def test_without_a_measured_scatter_the_prediction_says_it_assumes(page) -> None:
    p = page()
    v, s = p.view, p.session
    p.click(v.start)
    _touches(s, 2)
    assert measured_sigma_mm(v.workflow.wizard) is None
    assert "operator error 0.5 mm" in v.steps.meter_md.content


def test_equation_labels_are_in_the_math_only_and_the_meter_is_named(page) -> None:
    p = page()
    v, s = p.view, p.session
    assert all("(4P-" not in label for label in ESTIMATOR_LABELS.values())
    p.click(v.start)
    step2 = v.workflow.wizard.steps[1].instruction
    assert '("Reachable 45° tilts" below names those that work from here)' in step2
    assert "meter below" not in " ".join(st.instruction for st in v.workflow.wizard.steps)
    _touches(s, 4)
    assert v.workflow.result is not None
    p.choose(v.result.compare, True)
    tab = " ".join([v.result.compare_md.content, *map(str, v.result.estimator.options)])
    assert "(4P-" not in tab and "joint least squares (default)" in tab
    assert "(4P-3)" in v.math.md.content                                     # in The math


def test_the_dock_offers_the_wizards_estimate_to_tilt_about(page) -> None:
    """The dock's "Tilt about the wizard's estimate" keeps its row through the XYZ 4-point and is
    enabled after two touches in different orientations; a click makes the estimate the active
    tool data, named as the estimate in the TCP readout, and the button is disabled (the
    estimate is active); the next touch offers a new one."""
    p = page()
    v, s = p.view, p.session
    dock = s.views["dock"]
    p.click(v.start)
    _touches(s, 1)
    assert dock.pivot.visible and dock.pivot.disabled
    _touches_from(s, 1, 2)
    assert dock.pivot.visible and not dock.pivot.disabled and dock.pivot.label == "Tilt about the wizard's estimate"
    p.click(dock.pivot)
    active = s.controller.active_tool
    assert active is not None and active.name == "Estimate, 2 touches"
    assert "Active tool data: TOOL Estimate, 2 touches" in s.views["pendant"].tcp_md.content
    assert dock.pivot.visible and dock.pivot.disabled
    _touches_from(s, 2, 3)
    assert not dock.pivot.disabled                              # three touches: a better estimate


def _touches_from(s, first: int, last: int) -> None:
    for tilt, az in _ORIENTATIONS[first:last]:
        assert s.wizard_commands.auto_touch(AutoTouchRequest(tilt_deg=tilt, azimuth_deg=az)).ok
