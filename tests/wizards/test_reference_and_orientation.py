"""XYZ reference, three-point and ABC world wizards driven with synthetic flange poses."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcpcal.tool import Calibration, Tool
from tcp_pendant.wizards import (
    AbcWorldWizard,
    ReferenceWizard,
    ThreePointWizard,
    Wizard,
    WizardError,
    WizardStateError,
)


def library_tool(synth_tool, name="tool", *, calibrated=True) -> Tool:
    cal = Calibration("xyz4-lstsq", "2026-01-01T00:00:00Z", {"ci95_mm": 0.3}) if calibrated else None
    return Tool(name=name, tcp_mm=tuple(synth_tool.tcp_mm), calibration=cal, mass_kg=2.0,
                cog_mm=(1.0, 2.0, 50.0), inertia_kgm2=(0.04, 0.04, 0.01))


def angle_deg(R1, R2) -> float:
    return float(np.degrees(Rotation.from_matrix(R1.T @ R2).magnitude()))


# ----- XYZ reference ----------------------------------------------------------------------
@pytest.mark.parametrize("new_key", ["torch", "gripper", "pointer"])
def test_reference_exact_and_tool_swap_gating(synth, new_key):
    ref_key = "pointer" if new_key != "pointer" else "torch"
    ref, new = synth.tools[ref_key], synth.tools[new_key]
    wiz = ReferenceWizard(library_tool(ref, "ref"), reference_tool_key=ref_key, new_tool_key=new_key)
    assert wiz.step.heading == "Step 1 of 2" and wiz.tool_to_mount == ref_key
    wiz.note_mounted_tool(new_key)
    assert not wiz.can_record and ref_key in wiz.blocked_reason
    with pytest.raises(WizardStateError, match="Mount"):
        wiz.record(np.eye(4))
    wiz.note_mounted_tool(ref_key)
    assert wiz.can_record
    wiz.record(synth.flange_pose_m(ref, synth.tool_orientation(30.0, 40.0, 10.0)))
    wiz.next()
    assert wiz.tool_to_mount == new_key and not wiz.can_record  # still the reference mounted
    assert new_key in wiz.step.instruction or "new tool" in wiz.step.instruction
    wiz.note_mounted_tool(new_key)
    wiz.record(synth.flange_pose_m(new, synth.tool_orientation(20.0, 200.0, -30.0)))
    res = wiz.next()
    assert np.linalg.norm(np.array(res.tcp_mm) - new.tcp_mm) < 1e-6
    assert res.method == "reference" and res.abc_deg is None
    assert any("add up" in w or "sum" in w for w in res.warnings)
    t = wiz.to_tool("new")
    assert t.calibration.method == "reference" and t.abc_deg == (0.0, 0.0, 0.0)


def test_reference_rejects_bad_choices(synth):
    with pytest.raises(WizardError, match="reference tool"):
        ReferenceWizard("pointer")  # type: ignore[arg-type]
    with pytest.raises(WizardError, match="same physical tool"):
        ReferenceWizard(library_tool(synth.tools["pointer"]), reference_tool_key="pointer",
                        new_tool_key="pointer")


# ----- three-point ------------------------------------------------------------------------
def run_three_point(wiz, synth, tool, *, offsets, direction=(15.0, 30.0, 20.0)):
    R_wt = synth.tool_orientation(*direction)
    for k, off in enumerate(offsets):
        assert wiz.can_record
        wiz.record(synth.flange_pose_m(tool, R_wt, offset_tool_mm=off))
        out = wiz.next()
    return out


@pytest.mark.parametrize("variant, third", [(1, (0.0, 60.0, 0.0)), (2, (-20.0, 60.0, 0.0))])
def test_three_point_exact(synth, synth_tool, variant, third):
    wiz = ThreePointWizard(library_tool(synth_tool), variant=variant)
    assert wiz.n_steps == 3 and wiz.steps[2].role == ("plus_y" if variant == 1 else "plus_y_half")
    res = run_three_point(wiz, synth, synth_tool, offsets=[(0, 0, 0), (-60.0, 0, 0), third])
    assert angle_deg(res.rotation, synth_tool.R_flange_tool) < 1e-6
    R_abc = Rotation.from_euler("ZYX", res.abc_deg, degrees=True).as_matrix()
    assert angle_deg(R_abc, synth_tool.R_flange_tool) < 1e-6
    assert res.method == f"three-point-{variant}"
    assert res.displacements_mm[0] == pytest.approx(60.0, abs=1e-6)
    assert res.displacements_mm[1] == pytest.approx(60.0, abs=1e-6)
    assert res.orthogonality_defect_deg < 1e-6
    t = wiz.to_tool("oriented")
    assert t.calibration.method == f"three-point-{variant}"
    assert t.calibration.figures["tcp_ci95_mm"] == pytest.approx(0.3)
    np.testing.assert_allclose(t.tcp_mm, synth_tool.tcp_mm)
    assert angle_deg(t.rotation, synth_tool.R_flange_tool) < 1e-6
    assert (t.mass_kg, t.cog_mm) == (2.0, (1.0, 2.0, 50.0))  # the tool's load is kept
    assert t.inertia_kgm2 == (0.04, 0.04, 0.01)


def test_three_point_warns_on_short_displacement(synth):
    tool = synth.tools["torch"]
    wiz = ThreePointWizard(library_tool(tool, calibrated=False))
    res = run_three_point(wiz, synth, tool, offsets=[(0, 0, 0), (-10.0, 0, 0), (0, 50.0, 0)])
    assert res.displacements_mm[0] == pytest.approx(10.0, abs=1e-6)
    assert any("20" in w and "10" in w for w in res.warnings)
    assert any("no calibration record" in w for w in res.warnings)


def test_three_point_variant_switch(synth):
    tool = synth.tools["gripper"]
    wiz = ThreePointWizard(library_tool(tool), variant=2)
    run_three_point(wiz, synth, tool, offsets=[(0, 0, 0), (-50.0, 0, 0), (-20.0, 40.0, 0)])
    assert wiz.is_complete
    wiz.set_variant(1)  # a half-plane point is not on the +Y axis: step 3 must be redone
    assert wiz.status == "in_progress" and 2 not in wiz.recorded_poses
    assert "+Y axis" in wiz.steps[2].title
    wiz.go_to(2)
    R_wt = synth.tool_orientation(15.0, 30.0, 20.0)
    wiz.record(synth.flange_pose_m(tool, R_wt, offset_tool_mm=(0, 40.0, 0)))
    res = wiz.next()
    assert res.method == "three-point-1" and angle_deg(res.rotation, tool.R_flange_tool) < 1e-6
    with pytest.raises(WizardError):
        wiz.set_variant(3)  # type: ignore[arg-type]


# ----- ABC world --------------------------------------------------------------------------
def test_abc_world_6d_exact(synth, synth_tool):
    wiz = AbcWorldWizard(library_tool(synth_tool))
    assert wiz.n_steps == 1 and wiz.step.role == "parallel"
    T = synth.flange_pose_m(synth_tool, synth.tool_orientation(0.0, 0.0, 0.0), offset_tool_mm=(30, 0, 0))
    # the target triad: prescribed orientation (PA-1), at the believed TCP
    target = wiz.target_T_world_tool_m(T)
    np.testing.assert_allclose(target[:3, :3], [[0, 0, 1], [0, 1, 0], [-1, 0, 0]], atol=1e-15)
    np.testing.assert_allclose(target[:3, 3] * 1000, synth.reference_mm + [0, 0, 30.0], atol=1e-9)
    wiz.record(T)
    res = wiz.next()
    assert angle_deg(res.rotation, synth_tool.R_flange_tool) < 1e-6
    assert res.method == "abc-world-6d"
    assert wiz.to_tool("x").calibration.method == "abc-world-6d"
    assert (wiz.to_tool("x").mass_kg, wiz.to_tool("x").cog_mm) == (2.0, (1.0, 2.0, 50.0))
    assert wiz.to_tool("x").inertia_kgm2 == (0.04, 0.04, 0.01)


def test_abc_world_5d_fixes_tool_x_only(synth):
    tool = synth.tools["torch"]
    wiz = AbcWorldWizard(library_tool(tool), variant="5d")
    assert "does not matter" in wiz.step.instruction
    # tool X down but turned 40 deg about X: only X is calibrated
    R_wt = synth.tool_orientation(0.0, 0.0, 40.0)
    wiz.record(synth.flange_pose_m(tool, R_wt))
    res = wiz.next()
    cos_x = res.rotation[:, 0] @ tool.R_flange_tool[:, 0]
    assert np.degrees(np.arccos(np.clip(cos_x, -1, 1))) < 1e-6
    assert res.method == "abc-world-5d" and any("5D" in w for w in res.warnings)
    # switching to 6D recomputes from the same pose: now the 40 deg spin shows
    wiz.set_variant("6d")
    assert wiz.result.method == "abc-world-6d"
    assert angle_deg(wiz.result.rotation, tool.R_flange_tool) == pytest.approx(40.0, abs=1e-6)


@pytest.mark.parametrize("make", [
    lambda t: ThreePointWizard(t, variant=2),
    lambda t: AbcWorldWizard(t, variant="5d"),
    lambda t: ReferenceWizard(t, reference_tool_key="pointer", new_tool_key="torch"),
])
def test_orientation_and_reference_serialise_round_trip(synth, make):
    tool = synth.tools["torch"]
    wiz = make(library_tool(tool))
    wiz.note_mounted_tool(None)
    wiz.record(synth.flange_pose_m(tool, synth.tool_orientation(10.0, 0.0, 0.0)))
    wiz.cancel()
    again = Wizard.from_dict(json.loads(json.dumps(wiz.to_dict())))
    assert type(again) is type(wiz) and again.status == "cancelled"
    assert again.to_dict()["params"] == wiz.to_dict()["params"]
    again.resume()
    assert again.step_index == 0 and again.step.recorded


def test_wizards_require_a_library_tool():
    with pytest.raises(WizardError, match="calibrated TCP"):
        ThreePointWizard(None)  # type: ignore[arg-type]
    with pytest.raises(WizardError, match="tool library"):
        AbcWorldWizard({"name": "x"})  # type: ignore[arg-type]
    with pytest.raises(WizardError, match="variant"):
        AbcWorldWizard(Tool(name="x", tcp_mm=(0, 0, 100)), variant="4d")  # type: ignore[arg-type]
