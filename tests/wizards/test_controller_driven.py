"""Every wizard driven by the virtual controller's auto-approach (no browser).

On both robots and with every built-in tool, auto-touch with zero operator error recovers the
hidden true TOOL frame (``ToolModel.T_flange_tool_true``) to 1e-6 mm / 1e-6 deg; with sigma
0.5 mm the error against truth is consistent with the reported 95 % radius.
"""

from __future__ import annotations

import numpy as np
import pytest

from tcpcal.tool import Tool
from tcp_pendant.wizards import AbcWorldWizard, ReferenceWizard, ThreePointWizard, Xyz4Wizard
from tcp_pendant.calibrate.autotouch import auto_touch
from tcp_pendant.wizards.session_record import WizardRun, replay, session_from_controller
from tcp_pendant.wizards.truth import compare_with_truth

import tcp_pendant.controller as controller

ROBOTS = ("kr6", "gp12")
TOOL_KEYS = ("pointer", "torch", "gripper")
TIP_M = {"kr6": (0.55, 0.05, 0.25), "gp12": (0.95, 0.05, 0.35)}


def make_controller(robot: str, tool_key: str):
    kin = controller.RobotKinematics.from_urdf(controller.builtin_robots()[robot])
    return controller.VirtualController(kin, tool=controller.builtin_tools()[tool_key],
                                        reference_tip_world_m=TIP_M[robot])


def true_tool_data(model, name="calibrated") -> Tool:
    """Library data equal to the hidden truth (for the orientation wizards' TCP)."""
    T = model.T_flange_tool_true
    return Tool.from_rotation(name, tuple(T[:3, 3] * 1000.0), T[:3, :3])


def run(wiz, ctrl, rng, *, sigma_mm=0.0, **kw):
    previous = None
    while True:
        out = auto_touch(wiz, ctrl, sigma_mm=sigma_mm, rng=rng, previous_direction_deg=previous, **kw)
        assert out.ok, out.message
        previous = out.direction_deg
        if wiz.on_last_step and wiz.step.recorded:
            return wiz.next()


@pytest.fixture(scope="module")
def controllers():
    cache: dict[tuple[str, str], object] = {}

    def get(robot, tool_key):
        if (robot, tool_key) not in cache:
            cache[(robot, tool_key)] = make_controller(robot, tool_key)
        ctrl = cache[(robot, tool_key)]
        ctrl.mount_tool(controller.builtin_tools()[tool_key])
        return ctrl
    return get


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("tool_key", TOOL_KEYS)
def test_xyz4_exact(controllers, robot, tool_key):
    ctrl = controllers(robot, tool_key)
    wiz = Xyz4Wizard()
    res = run(wiz, ctrl, np.random.default_rng(1))
    cmp = compare_with_truth(res, ctrl.mounted_tool.T_flange_tool_true)
    assert cmp.position_error_mm < 1e-6 and cmp.grade == "good"


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("tool_key", TOOL_KEYS)
@pytest.mark.parametrize("variant", [1, 2])
def test_three_point_exact(controllers, robot, tool_key, variant):
    ctrl = controllers(robot, tool_key)
    wiz = ThreePointWizard(true_tool_data(ctrl.mounted_tool), variant=variant)
    res = run(wiz, ctrl, np.random.default_rng(2))
    cmp = compare_with_truth(res, ctrl.mounted_tool.T_flange_tool_true)
    assert cmp.orientation_error_deg < 1e-6
    assert min(res.displacements_mm) > 20.0


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("tool_key", TOOL_KEYS)
@pytest.mark.parametrize("variant", ["6d", "5d"])
def test_abc_world_exact(controllers, robot, tool_key, variant):
    ctrl = controllers(robot, tool_key)
    wiz = AbcWorldWizard(true_tool_data(ctrl.mounted_tool), variant=variant)
    res = run(wiz, ctrl, np.random.default_rng(3))
    cmp = compare_with_truth(res, ctrl.mounted_tool.T_flange_tool_true)
    if variant == "6d":
        assert cmp.orientation_error_deg < 1e-6
    else:
        assert cmp.x_axis_error_deg < 1e-6 and cmp.graded == ("x_axis",)


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("new_key", ["torch", "gripper"])
def test_reference_exact_with_tool_swap(controllers, robot, new_key):
    ctrl = controllers(robot, "pointer")
    tools = controller.builtin_tools()
    wiz = ReferenceWizard(true_tool_data(tools["pointer"], "pointer"), reference_tool_key="pointer",
                          new_tool_key=new_key)
    res = run(wiz, ctrl, np.random.default_rng(4))
    assert ctrl.mounted_tool.key == new_key  # auto-touch swapped the tool for step 2
    cmp = compare_with_truth(res, tools[new_key].T_flange_tool_true)
    assert cmp.position_error_mm < 1e-6


def test_autotouch_three_point_offsets_put_the_tip_where_asked(controllers):
    ctrl = controllers("kr6", "torch")
    wiz = ThreePointWizard(true_tool_data(ctrl.mounted_tool), variant=2)
    rng = np.random.default_rng(5)
    tip = np.asarray(ctrl.reference_tip_world_m)
    previous = None
    for expected in ((0.0, 0.0, 0.0), (-60.0, 0.0, 0.0), (-20.0, 60.0, 0.0)):
        previous = auto_touch(wiz, ctrl, rng=rng, previous_direction_deg=previous).direction_deg
        T = ctrl.T_world_tool_true()
        in_tool_mm = (T[:3, :3].T @ (tip - T[:3, 3])) * 1000.0
        np.testing.assert_allclose(in_tool_mm, expected, atol=1e-6)


@pytest.mark.slow
def test_xyz4_sigma_coverage_with_controller(controllers):
    """sigma = 0.5 mm auto-touches: 95 % radius covers the true TCP in about 95 % of trials.
    100 seeded trials: binomial sd 2.2 %, band [0.87, 1.0]."""
    ctrl = controllers("kr6", "torch")
    rng = np.random.default_rng(11)
    trials, inside = 100, 0
    for _ in range(trials):
        wiz = Xyz4Wizard(n_points=5)
        res = run(wiz, ctrl, rng, sigma_mm=0.5)
        inside += bool(compare_with_truth(res, ctrl.mounted_tool.T_flange_tool_true).inside_ci95)
    assert 0.87 <= inside / trials <= 1.0, inside / trials


def test_session_record_from_controller_replays(controllers, tmp_path):
    ctrl = controllers("gp12", "gripper")
    rng = np.random.default_rng(6)
    wiz = Xyz4Wizard()
    run(wiz, ctrl, rng, sigma_mm=0.3)
    rec = session_from_controller(ctrl, [WizardRun(wiz, "gripper", ctrl.mounted_tool.T_flange_tool_true)],
                                  robot="gp12")
    assert rec["mounted_tool"]["key"] == "gripper"
    checks = replay(rec)
    assert checks[0].matches and checks[0].truth.position_error_mm == pytest.approx(
        rec["wizards"][0]["truth"]["position_error_mm"])
