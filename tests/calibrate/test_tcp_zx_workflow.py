"""TCP & Z, X (ABB) through the Calibrate workflow on the real virtual controller of both robots:
auto-touch performs every step (touches, reference on tool +Z, on tool +X) and the result is the
tool's hidden true frame (``ToolModel.T_flange_tool_true``, converted with scipy in the test)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from tcp_pendant.calibrate import AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.wizards import CalibrationFailedError, TcpZxWizard, WizardError
from tcp_pendant.wizards.session_record import dumps

from support.calib_helpers import true_frame

EXACT_MM = 1e-6
EXACT_DEG = 1e-6


def run_auto(wf: CalibrationWorkflow, request: AutoTouchRequest | None = None) -> None:
    for _ in range(wf.wizard.n_steps):
        out = wf.auto_touch(request or AutoTouchRequest())
        assert out.ok, out.message
    assert wf.result is not None


def reference_in_true_tool_mm(wf: CalibrationWorkflow) -> np.ndarray:
    """Where the reference tip is now in the mounted tool's true TOOL frame (mm)."""
    T = wf.controller.T_world_tool_true()
    tip = np.asarray(wf.controller.reference_tip_world_m, dtype=float)
    return T[:3, :3].T @ (tip - T[:3, 3]) * 1000.0


@pytest.mark.parametrize("robot,tool", [("kr6", "pointer"), ("kr6", "torch"), ("kr6", "gripper"),
                                        ("gp12", "pointer"), ("gp12", "torch"), ("gp12", "gripper")])
def test_auto_touch_tcp_zx_gives_the_true_frame_and_saves_it(workflow, library, robot, tool) -> None:
    wf = workflow(robot, tool, seed=1)
    wiz = wf.start("tcp-zx", n_points=4)
    assert isinstance(wiz, TcpZxWizard) and [s.role for s in wiz.steps] == ["touch"] * 4 + ["z", "x"]
    for _ in range(4):
        assert wf.auto_touch(AutoTouchRequest()).ok
        np.testing.assert_allclose(reference_in_true_tool_mm(wf), 0.0, atol=1e-6)    # a touch
    assert wf.auto_touch(AutoTouchRequest()).ok
    np.testing.assert_allclose(reference_in_true_tool_mm(wf), [0.0, 0.0, 60.0], atol=1e-6)  # on +Z ahead
    assert wf.auto_touch(AutoTouchRequest()).ok                    # the last one also finishes
    np.testing.assert_allclose(reference_in_true_tool_mm(wf), [60.0, 0.0, 0.0], atol=1e-6)  # on +X
    res = wf.result
    tcp_true, R_true, _ = true_frame(tool)
    np.testing.assert_allclose(res.tcp_mm, tcp_true, atol=EXACT_MM)
    angle = np.degrees(Rotation.from_matrix(R_true.T @ res.rotation).magnitude())
    assert angle < EXACT_DEG
    truth = wf.truth()
    assert truth.position_error_mm < EXACT_MM and truth.orientation_error_deg < EXACT_DEG
    assert truth.grade == "good"
    T_computed = wf.T_flange_tool_computed_m()                    # the COMPUTED triad of the scene
    np.testing.assert_allclose(T_computed[:3, 3] * 1000.0, tcp_true, atol=EXACT_MM)
    np.testing.assert_allclose(T_computed[:3, :3], R_true, atol=1e-8)
    slot, saved = wf.save(f"{tool} ZX")
    stored = library.get(slot)
    np.testing.assert_allclose(stored.tcp_mm, tcp_true, atol=EXACT_MM)
    np.testing.assert_allclose(stored.rotation, R_true, atol=1e-8)
    assert stored.calibration.method == "tcp-zx" and wf.controller.active_tool == saved


def test_operator_error_gives_plausible_errors_and_the_record_replays(workflow) -> None:
    wf = workflow("kr6", "torch", seed=11)
    wf.start("tcp-zx", n_points=6)
    run_auto(wf, AutoTouchRequest(sigma_mm=0.3))
    res, truth = wf.result, wf.truth()
    assert 0.0 < res.rms_error_mm < 1.5 and 0.0 < truth.position_error_mm < 3.0 * res.ci95_mm
    assert 0.0 < truth.orientation_error_deg < 5.0
    text = dumps(wf.export_record())
    assert json.loads(text)["wizards"][0]["state"]["kind"] == "tcp-zx"
    other = workflow(seed=99)
    checks = other.load_record(text)
    assert [c.matches for c in checks] == [True]
    np.testing.assert_allclose(other.result.rotation, res.rotation, atol=1e-9)


def test_start_options_are_checked_and_named(workflow) -> None:
    wf = workflow()
    with pytest.raises(WizardError, match=r"Touches: 3 is out of range 4\.\.20"):
        wf.start("tcp-zx", n_points=3)
    with pytest.raises(WizardError, match="takes no option slot"):
        wf.start("tcp-zx", slot=1)
    with pytest.raises(WizardError, match=r"Unknown calibration method 'zx'.*xyz4.*tcp-zx"):
        wf.start("zx")
    assert wf.runs == []


def test_a_z_pose_at_the_touch_fails_in_words_and_keeps_the_poses(workflow) -> None:
    wf = workflow("kr6", "torch", seed=2)
    wf.start("tcp-zx")
    for _ in range(4):
        wf.auto_touch(AutoTouchRequest())
    wf.record()                      # "z" recorded without backing off: the reference at the TCP
    wf.next()
    with pytest.raises(CalibrationFailedError, match=r"z row 5: .*back the tool off further along its \+Z"):
        wf.auto_touch(AutoTouchRequest())          # the last auto-touch computes: tcpcal says why not
    assert wf.wizard.status == "in_progress" and wf.wizard.on_last_step
    assert len(wf.wizard.recorded_poses) == 6 and wf.result is None
