"""What the trainee reads and sees named: where a step is jogged (Calibrate tab), which way to tilt
for the next touch (the meter), which tool the 3D TOOL label names after a wizard's tool change,
and the 3D legend of a result. In-process pendant and a websocket browser (``page``)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.calibrate.text import scene_legend_markdown
from tcp_pendant.controller import builtin_tools
from tcp_pendant.views.scene import tool_label_text
from tcpcal.tool import Tool
from support.calib_page import Page

pytestmark = pytest.mark.app_page(cls=Page, seed=5)


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
