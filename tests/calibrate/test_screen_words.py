"""What the trainee reads and sees named: where a step is jogged (Calibrate tab), which way to tilt
for the next touch (the meter), which tool the 3D TOOL label names after a wizard's tool change,
and the 3D legend of a result. In-process pendant and a websocket browser (``page``); the tilt
numbers from tcpcal's own prediction."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.calibrate.diversity import best_tilt, best_tilt_words
from tcp_pendant.calibrate.text import scene_legend_markdown
from tcp_pendant.controller import builtin_tools
from tcp_pendant.views.scene import tool_label_text
from tcpcal.pose_quality import candidate_gain
from tcpcal.tool import Tool
from support.calib_page import Page

pytestmark = pytest.mark.app_page(cls=Page, seed=5)


def _rot(axis: tuple[float, float, float], deg: float) -> np.ndarray:
    return Rotation.from_rotvec(math.radians(deg) * np.asarray(axis, dtype=float)).as_matrix()


R0 = np.diag([1.0, -1.0, -1.0])          # the flange pointing down (WORLD), as at the ready pose


def test_after_start_the_calibrate_tab_says_to_jog_on_the_jog_tab_and_record_in_the_dock(page) -> None:
    p = page()
    v, s = p.view, p.session
    p.click(v.start)                                          # XYZ 4-point
    head = v.steps.head_md.content
    assert "Step 1 of 4" in head and "**Jog on the Jog tab**" in head
    dock = s.views["dock"]
    # the words name what is there: the dock's folder and its Record button, on the Jog tab
    assert f"*{dock.folder.label}* box" in head and dock.record.label == "Record" and "**Record**" in head
    assert "(key R)" in head
    s.wizard_commands.auto_touch(AutoTouchRequest())
    assert "Step 2 of 4" in v.steps.head_md.content and "Jog on the Jog tab" in v.steps.head_md.content
    for _ in range(3):
        s.wizard_commands.auto_touch(AutoTouchRequest())
    assert v.workflow.result is not None
    assert "Jog on the Jog tab" not in v.steps.head_md.content          # the result: nothing to jog


def test_a_beam_scan_step_is_not_sent_to_the_jog_tab(page) -> None:
    p = page()
    v = p.view
    p.choose(v.method, "Automatic (beam)")
    p.click(v.start)
    assert "Beam scan" in v.steps.head_md.content and "Jog on the Jog tab" not in v.steps.head_md.content


def test_best_tilt_after_tilts_about_one_axis_is_about_the_other_with_tcpcals_numbers() -> None:
    # three touches turned about flange X only: the TCP component along X is not observed
    touches = np.array([R0, R0 @ _rot((1, 0, 0), 45.0), R0 @ _rot((1, 0, 0), -45.0)])
    tilt = best_tilt(touches, R0, sigma_mm=0.5)
    assert tilt is not None
    assert tilt.axis in ("Y", "Z") and tilt.key == {"Y": "B", "Z": "A"}[tilt.axis]
    # every other turn of 45 deg about a TOOL (= FLANGE) axis predicts no smaller error
    predicted = {}
    for i, ax in enumerate("XYZ"):
        for sign in (1, -1):
            e = np.zeros(3)
            e[i] = sign
            predicted[(ax, sign)] = candidate_gain(touches, R0 @ _rot(tuple(e), 45.0), sigma=0.5).predicted_after
    assert math.isinf(predicted[("X", 1)]) and math.isinf(predicted[("X", -1)])   # along the unobserved axis
    assert tilt.predicted_mm == pytest.approx(min(predicted.values()))
    assert tilt.predicted_mm == pytest.approx(predicted[(tilt.axis, tilt.sign)])
    assert math.isinf(tilt.predicted_now_mm)                 # recording here adds nothing
    np.testing.assert_allclose(tilt.axis_world, R0[:, "XYZ".index(tilt.axis)], atol=1e-12)
    words = best_tilt_words(tilt)
    assert f"about **TOOL {tilt.axis}**" in words and "by 45°" in words
    assert f"key **{tilt.key} {'+' if tilt.sign > 0 else '−'}**" in words
    assert f"**{tilt.predicted_mm:.2f} mm**" in words
    if tilt.axis == "Y":
        assert "(WORLD -Y now)" in words                     # flange Y points along WORLD -Y here


def test_best_tilt_uses_the_tool_frame_of_the_jog_keys() -> None:
    """With tool data turned 90 deg about flange Z, TOOL X is flange Y: the same missing turn
    is named by the other TOOL axis (and the other key)."""
    touches = np.array([R0, R0 @ _rot((1, 0, 0), 45.0), R0 @ _rot((1, 0, 0), -45.0)])
    plain = best_tilt(touches, R0, sigma_mm=0.5)
    R_ft = _rot((0, 0, 1), 90.0)
    turned = best_tilt(touches, R0, R_flange_tool=R_ft, sigma_mm=0.5)
    assert plain is not None and turned is not None
    np.testing.assert_allclose(np.abs(turned.axis_world), np.abs(plain.axis_world), atol=1e-9)
    assert turned.predicted_mm == pytest.approx(plain.predicted_mm)
    assert (plain.axis, turned.axis) == ("Y", "X") or plain.axis == turned.axis == "Z"


def test_best_tilt_says_nothing_before_two_touches_or_when_here_is_as_good() -> None:
    assert best_tilt(np.array([R0]), R0 @ _rot((0, 1, 0), 45.0)) is None
    spread = np.array([R0, R0 @ _rot((1, 0, 0), 45.0), R0 @ _rot((0, 1, 0), 45.0)])
    here = R0 @ _rot((1, 1, 0) / np.sqrt(2.0), -50.0)         # already a good fourth orientation
    tilt = best_tilt(spread, here)
    now = candidate_gain(spread, here, sigma=0.5).predicted_after
    assert tilt is None or tilt.predicted_mm < 0.95 * now


def test_the_calibrate_tab_meter_names_the_tilt_after_two_touches(page) -> None:
    p = page()
    v, s = p.view, p.session
    p.click(v.start)
    assert "Tilt next" not in v.steps.meter_md.content       # no touch yet
    s.wizard_commands.auto_touch(AutoTouchRequest())
    s.wizard_commands.auto_touch(AutoTouchRequest())
    text = v.steps.meter_md.content
    assert re.search(r"Tilt next: \*\*[ABC] [+−]\*\* 45° in WORLD \(key (Shift\+)?[456]\)", text), text


def test_the_3d_tool_label_follows_a_wizards_tool_change(page) -> None:
    p = page()
    s, c = p.session, p.session.controller
    T = builtin_tools()["pointer"].T_flange_tool_true
    s.library.save(1, Tool.from_rotation("Straight pointer", tuple(T[:3, 3] * 1000.0), T[:3, :3]))
    s.tools.reload_library()
    scene = s.views["scene"]
    s.wizard_commands.start("reference", slot=1, reference_tool_key="pointer", new_tool_key="torch")
    label, axes = scene._active_label, scene._active_axes
    assert label.text == "TOOL Straight pointer"             # the pointer's data on the pointer
    s.wizard_commands.auto_touch(AutoTouchRequest())
    s.wizard_commands.mount_required_tool()                                  # the wizard bolts the torch on
    assert c.mounted_tool.key == "torch" and c.active_tool is not None
    assert label.text == "TOOL Straight pointer · on Bent-neck welding torch"
    np.testing.assert_allclose(axes.position, c.T_flange_tool[:3, 3], atol=1e-12)   # where the data puts the TCP
    # the controller keeps which tool the data was selected on: a view drawn later (a reload, a
    # reconnect after a restart) names the data and the tool bolted on alike
    assert c.active_data_mounted_on is not None and c.active_data_mounted_on.key == "pointer"
    scene._shown_active = None
    scene.update_active_tool()
    assert label.text == "TOOL Straight pointer · on Bent-neck welding torch"
    # new tool data: the label and the triad follow it
    torch_T = builtin_tools()["torch"].T_flange_tool_true
    s.tools.set_active_data(Tool.from_rotation("Bent-neck welding torch", tuple(torch_T[:3, 3] * 1000.0), torch_T[:3, :3]))
    assert label.text == "TOOL Bent-neck welding torch"
    np.testing.assert_allclose(axes.position, torch_T[:3, 3], atol=1e-9)
    assert tool_label_text(None, c.mounted_tool) == "TOOL"


def test_the_result_panel_names_what_3d_draws(page) -> None:
    p = page()
    v, s = p.view, p.session
    p.click(v.start)
    for _ in range(4):
        s.wizard_commands.auto_touch(AutoTouchRequest())
    res = v.workflow.result
    legend = v.result.legend_md.content
    assert v.result.legend_md.visible and "**COMPUTED**" in legend and "**TRUE**" in legend
    assert "**blue wire sphere**" in legend and f"radius {res.sphere_radius_mm:.1f} mm" in legend
    assert scene_legend_markdown(computed=False, true=False, sphere=False) == ""
    assert "TRUE" not in scene_legend_markdown(computed=True, true=False, sphere=False)
