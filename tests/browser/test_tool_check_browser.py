"""In a real browser: the Tool tab's "Check" of a saved tool (its deviation table and
the implied TCP error), one controller file downloaded by the browser and parsed back by
tcpcal, and the trainer's "Systematic error" panel in the Calibrate tab."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from support.pendant_page import TIMEOUT_MS, assert_not_blank, choose, press, wait_enabled, wait_text

from tcp_pendant.controller import builtin_tools
from tcpcal.controllers import parse_tool_file
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

pytestmark = pytest.mark.browser


def test_check_a_saved_tool_download_its_abb_file_and_pick_a_scenario(server, new_page, shot) -> None:
    T = builtin_tools()["pointer"].T_flange_tool_true
    tcp = tuple(T[:3, 3] * 1000.0 + [0.0, 1.0, 0.0])               # 1 mm off the true tip
    tool = Tool.from_rotation("Pointer_1mm", tcp, T[:3, :3])
    ToolLibrary(server.library_path).save(1, tool)
    page = new_page(server.url)
    page.get_by_role("tab", name="Tool").click()
    wait_text(page, "Selected: Pointer_1mm", "the saved tool in the list")

    # --- Check: six rotations about the saved TCP, per rotation the true tip's deviation
    page.get_by_role("button", name="Check", exact=True).click()
    wait_text(page, "TCP off by 1.000 mm", "the check's verdict")
    wait_text(page, "Implied TCP error: 1.000 mm", "the implied TCP error")
    for label in ("+A 30°", "-A 30°", "+B 30°", "-B 30°", "+C 30°", "-C 30°"):
        assert page.get_by_role("cell", name=label, exact=True).count() == 1, label
    png = shot(page, "tool_check")
    assert_not_blank(png)

    # --- a whole ABB file, downloaded by this browser, parsed back
    page.get_by_text("Export", exact=True).first.click()
    choose(page, "Controller file", "ABB")
    with page.expect_download(timeout=TIMEOUT_MS) as info:
        page.get_by_role("button", name="Download file", exact=True).click()
    download = info.value
    assert download.suggested_filename == "tool1.mod"
    text = Path(download.path()).read_text(encoding="utf-8")
    (entry,) = parse_tool_file(text, "abb")
    np.testing.assert_allclose(entry.tcp_mm, tcp, atol=1e-3)
    np.testing.assert_allclose(entry.rotation, tool.rotation, atol=1e-5)
    shot(page, "tool_download")

    # --- the trainer's Systematic error panel (Calibrate tab, training mode)
    page.get_by_role("tab", name="Calibrate").click()
    page.get_by_text("Systematic error (training)").first.click()
    choose(page, "Systematic error", "Bent tool", echo=re.compile(r"Playing\s+Bent tool"))
    shot(page, "scenario_panel")
    # a new calibration of the bent tool, then the panel explains how the bend shows
    page.keyboard.press("Escape")                                 # the dropdown's list closed
    wait_enabled(page, "Start")
    press(page, "Start")
    for k in range(1, 5):                   # the Calibrate tab's step (the Jog tab's dock is hidden)
        page.locator(f"text=Step {k} of 4 >> visible=true").first.wait_for(timeout=TIMEOUT_MS)
        press(page, "Auto-touch")
    wait_text(page, "Against the true TOOL frame: good")            # the new TCP is the bent truth
    page.get_by_text("Systematic error (training)").first.scroll_into_view_if_needed()
    wait_text(page, "How this result shows it", "the scenario's explanation after the result")
    wait_text(page, "The tool was bent in a crash")
    shot(page, "scenario_explained")
