"""With operator error sigma = 0.5 mm, the error against truth is consistent with the 95 % radius.

Seeded trials on synthetic poses (independent of the controller): touch noise is Gaussian,
0.5 mm per axis, added to the tool tip position at each touch. Over M trials the fraction of
results whose true error is inside the reported 95 % radius must be near 0.95: with M = 300 the
binomial standard deviation is 1.3 %, so [0.90, 0.99] is a ~4-sigma band.
"""

from __future__ import annotations

import numpy as np
import pytest

from tcpcal.tool import Tool
from tcp_pendant.wizards import ReferenceWizard, Xyz4Wizard
from tcp_pendant.wizards.truth import compare_with_truth

SIGMA_MM = 0.5
TRIALS = 300


@pytest.mark.slow
@pytest.mark.parametrize("n_points", [4, 8])
def test_xyz4_ci95_coverage(synth, n_points):
    rng = np.random.default_rng(1234 + n_points)
    inside = 0
    for trial in range(TRIALS):
        tool = synth.tools[("pointer", "torch", "gripper")[trial % 3]]
        wiz = Xyz4Wizard(n_points=n_points)
        for _ in range(n_points):
            d = (rng.uniform(20, 50), rng.uniform(0, 360), rng.uniform(-90, 90))
            wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(*d),
                                           noise_mm=rng.normal(0.0, SIGMA_MM, 3)))
            res = wiz.next()
        cmp = compare_with_truth(res, tool.T_flange_tool_true_m)
        inside += bool(cmp.inside_ci95)
    print(f"coverage {inside / TRIALS:.3f}")
    assert 0.90 <= inside / TRIALS <= 0.99, inside / TRIALS


@pytest.mark.slow
def test_reference_ci95_coverage_with_assumed_sigma(synth):
    """The reference wizard's radius is predicted from the assumed sigma (no redundancy)."""
    rng = np.random.default_rng(99)
    ref, new = synth.tools["pointer"], synth.tools["torch"]
    lib_ref = Tool(name="ref", tcp_mm=tuple(ref.tcp_mm))
    inside = 0
    for _ in range(TRIALS):
        wiz = ReferenceWizard(lib_ref, assumed_sigma_mm=SIGMA_MM)
        for tool in (ref, new):
            d = (rng.uniform(0, 40), rng.uniform(0, 360), rng.uniform(-90, 90))
            wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(*d),
                                           noise_mm=rng.normal(0.0, SIGMA_MM, 3)))
            res = wiz.next()
        inside += bool(compare_with_truth(res, new.T_flange_tool_true_m).inside_ci95)
    print(f"coverage {inside / TRIALS:.3f}")
    assert 0.90 <= inside / TRIALS <= 0.99, inside / TRIALS
