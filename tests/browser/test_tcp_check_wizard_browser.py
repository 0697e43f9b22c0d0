"""In a real browser: the TCP check (spin test) wizard of the Calibrate tab on
a saved tool 1 mm off (auto-touch, Finish, six rows and the implied error; no Save), and the
"Check this TCP" offer on a saved calibration's result."""

from __future__ import annotations

import re

import pytest

from support.pendant_page import assert_not_blank, choose
from support.wizard_page import open_calibrate, press, save_tool, wait_enabled, wait_text

from tcp_pendant.controller import builtin_tools
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

pytestmark = pytest.mark.browser
LABELS = ("+A 30°", "-A 30°", "+B 30°", "-B 30°", "+C 30°", "-C 30°")


def visible_cells(page, label: str) -> int:
    return page.get_by_role("cell", name=label, exact=True).filter(visible=True).count()


def finish_check(page) -> None:
    """Auto-touch the one step, then Finish runs the six rotations (in a worker)."""
    wait_text(page, "Step 1 of 1")
    press(page, "Auto-touch")
    wait_enabled(page, "Finish")
    press(page, "Finish")
    wait_text(page, "Implied TCP error:", "the check's implied TCP error")


def test_tcp_check_wizard_on_a_saved_tool_1mm_off(server, new_page, shot) -> None:
    T = builtin_tools()["pointer"].T_flange_tool_true
    tcp = tuple(T[:3, 3] * 1000.0 + [0.0, 1.0, 0.0])               # 1 mm off the true tip
    ToolLibrary(server.library_path).save(1, Tool.from_rotation("Pointer_1mm", tcp, T[:3, :3]))
    before = ToolLibrary(server.library_path).tools()
    page = new_page(server.url)
    open_calibrate(page)
    choose(page, "Method", "TCP check (spin test)", "Checks the TCP of 1: Pointer_1mm")
    press(page, "Start")
    finish_check(page)
    wait_text(page, "Implied TCP error: 1.00", "1 mm implied")
    wait_text(page, "TCP off by 1.0", "the verdict")
    wait_text(page, re.compile(r"X [+-]0\.000 · Y -1\.00\d · Z [+-]0\.000 mm"), "the correction")
    for label in LABELS:
        assert visible_cells(page, label) == 1, label
    assert page.get_by_role("button", name="Save to tool library", exact=True).filter(visible=True).count() == 0
    assert page.get_by_text("Against the true TOOL frame").filter(visible=True).count() == 0   # not graded
    wait_text(page, "The check is done")
    assert page.get_by_role("button", name="Close", exact=True).filter(visible=True).count() == 1  # done
    wait_text(page, "A check changes no tool data")
    assert_not_blank(shot(page, "tcp_check_wizard_result"))
    assert ToolLibrary(server.library_path).tools() == before                    # nothing saved


def test_check_this_tcp_after_a_saved_calibration(server, new_page, shot) -> None:
    page = new_page(server.url)
    open_calibrate(page)
    press(page, "Start")                                            # XYZ 4-point, the default
    for k in range(1, 5):
        page.locator(f"text=Step {k} of 4 >> visible=true").first.wait_for()
        press(page, "Auto-touch")
    wait_text(page, "Against the true TOOL frame: good")
    save_tool(page, "Pointer checked", "1")
    press(page, "Check this TCP")
    finish_check(page)
    wait_text(page, "TCP check of slot 1: Pointer checked")
    wait_text(page, "TCP good", "an exact calibration checks good")
    for label in LABELS:
        assert visible_cells(page, label) == 1, label
    assert page.get_by_text("A check changes no tool data").filter(visible=True).count() == 0
    assert_not_blank(shot(page, "check_this_tcp"))
