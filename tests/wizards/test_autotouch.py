"""auto_touch against a test double of the controller (its contract: the docstrings of
calibrate.autotouch, docs/reference/calibrate.md).

The double places the true tool exactly as ``VirtualController.auto_approach`` promises (the
reference tip at ``tip_offset_tool_mm`` in TOOL coordinates, tool X tilted from WORLD -Z), using
the synthetic geometry of conftest.py, so auto-touch's own logic (roles -> offsets, tool swaps,
retries, direction reuse, recording and advancing) is checked independently of the real
controller; test_controller_driven.py runs the same flows on the real one.
"""

from __future__ import annotations


import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcp_pendant.wizards import (
    AbcWorldWizard,
    ReferenceWizard,
    ThreePointWizard,
    WizardStateError,
    Xyz4Wizard,
)
from tcp_pendant.calibrate.autotouch import auto_touch

from support.fake_controller import exact_tool, fake
from tcp_pendant.wizards.truth import compare_with_truth


def test_four_clicks_give_a_4_point_calibration(synth):
    ctrl = fake(synth, "torch")
    wiz = Xyz4Wizard()
    rng = np.random.default_rng(0)
    for k in range(4):
        out = auto_touch(wiz, ctrl, rng=rng)
        assert out.ok and out.step_index == k and out.role == "touch"
        assert 20.0 <= out.tilt_deg <= 50.0
    assert wiz.on_last_step and wiz.step.recorded and wiz.status == "in_progress"  # Finish is a click
    res = wiz.next()
    assert compare_with_truth(res, synth.tools["torch"].T_flange_tool_true_m).position_error_mm < 1e-6
    assert all(c[4] == (0.0, 0.0, 0.0) for c in ctrl.calls)


def test_chosen_direction_and_retries(synth):
    ctrl = fake(synth, fail_first=2)
    wiz = Xyz4Wizard()
    out = auto_touch(wiz, ctrl, rng=np.random.default_rng(1))
    assert out.ok and out.attempts == 3
    ctrl.fail_first = 1
    out = auto_touch(wiz, ctrl, direction_deg=(30.0, 45.0, 10.0))
    assert not out.ok and out.attempts == 1 and "unreachable" in out.message
    assert wiz.step_index == 1 and not wiz.step.recorded  # nothing recorded on failure
    out = auto_touch(wiz, ctrl, direction_deg=(30.0, 45.0, 10.0))
    assert out.ok and ctrl.calls[-1][1:4] == (30.0, 45.0, 10.0)


@pytest.mark.parametrize("variant, third", [(1, (0.0, 60.0, 0.0)), (2, (-20.0, 60.0, 0.0))])
def test_three_point_offsets_and_same_orientation(synth, variant, third):
    ctrl = fake(synth, "gripper")
    wiz = ThreePointWizard(exact_tool(synth, "gripper"), variant=variant)
    rng = np.random.default_rng(2)
    previous = None
    for _ in range(3):
        out = auto_touch(wiz, ctrl, rng=rng, previous_direction_deg=previous)
        assert out.ok
        previous = out.direction_deg                 # the caller (the workflow) keeps it
    offsets = [c[4] for c in ctrl.calls]
    assert offsets == [(0.0, 0.0, 0.0), (-60.0, 0.0, 0.0), third]
    assert len({c[1:4] for c in ctrl.calls}) == 1  # steps 2 and 3 keep step 1's orientation
    res = wiz.next()
    assert compare_with_truth(res, synth.tools["gripper"].T_flange_tool_true_m).orientation_error_deg < 1e-6


def test_auto_touch_keeps_no_hidden_state(synth):
    """The direction of a wizard's previous auto-touch is the caller's to give back (the
    workflow keeps it per run): without it, step 2 draws a new direction."""
    import tcp_pendant.calibrate.autotouch as module

    assert not any(isinstance(v, dict) or type(v).__name__ == "WeakKeyDictionary" for k, v in vars(module).items()
                   if not k.startswith("__"))
    ctrl = fake(synth, "gripper")
    wiz = ThreePointWizard(exact_tool(synth, "gripper"), variant=1)
    rng = np.random.default_rng(2)
    first = auto_touch(wiz, ctrl, rng=rng)
    second = auto_touch(wiz, ctrl, rng=rng)
    assert first.ok and second.ok and first.direction_deg != second.direction_deg


def test_reference_swaps_the_tool(synth):
    ctrl = fake(synth, "gripper")
    wiz = ReferenceWizard(exact_tool(synth, "pointer"), reference_tool_key="pointer", new_tool_key="torch")
    rng = np.random.default_rng(3)
    auto_touch(wiz, ctrl, rng=rng, tools=ctrl.tools)
    assert ctrl.mounted_tool.key == "pointer" and wiz.mounted_tool_key == "pointer"
    auto_touch(wiz, ctrl, rng=rng, tools=ctrl.tools)
    assert ctrl.mounted_tool.key == "torch"
    res = wiz.next()
    assert compare_with_truth(res, synth.tools["torch"].T_flange_tool_true_m).position_error_mm < 1e-6


@pytest.mark.parametrize("variant", ["6d", "5d"])
def test_abc_world_moves_to_prescribed_orientation(synth, variant):
    ctrl = fake(synth, "torch")
    wiz = AbcWorldWizard(exact_tool(synth, "torch"), variant=variant)
    out = auto_touch(wiz, ctrl, rng=np.random.default_rng(4), hover_mm=30.0)
    assert out.ok and out.tilt_deg is None
    T_target = ctrl.calls[-1][1]
    np.testing.assert_allclose(T_target[:3, 3], synth.reference_mm / 1000 + [0, 0, 0.03])
    assert T_target[:3, 0] == pytest.approx([0.0, 0.0, -1.0])  # tool X down in both variants
    res = wiz.next()
    cmp = compare_with_truth(res, synth.tools["torch"].T_flange_tool_true_m)
    assert cmp.x_axis_error_deg < 1e-6
    if variant == "6d":
        assert cmp.orientation_error_deg < 1e-6


def test_abc_world_angular_error_shows_in_the_result(synth):
    ctrl = fake(synth, "pointer")
    errs = []
    for seed in range(30):
        wiz = AbcWorldWizard(exact_tool(synth, "pointer"))
        auto_touch(wiz, ctrl, rng=np.random.default_rng(seed), angle_sigma_deg=1.0)
        errs.append(compare_with_truth(wiz.next(), synth.tools["pointer"].T_flange_tool_true_m).orientation_error_deg)
    # |rotvec| with 1 deg per axis: chi with 3 dof, mean 1.60 deg
    assert 1.2 < np.mean(errs) < 2.0


def test_autotouch_refuses_finished_or_cancelled(synth):
    ctrl = fake(synth)
    wiz = AbcWorldWizard(exact_tool(synth, "pointer"))
    wiz.cancel()
    with pytest.raises(WizardStateError):
        auto_touch(wiz, ctrl)
    with pytest.raises(ValueError):
        auto_touch(Xyz4Wizard(), ctrl, sigma_mm=-1.0)
