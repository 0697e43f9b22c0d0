"""The beam sensor in a real browser (Debian's chromium, Playwright), on the default KR 6 with the pointer:

* the "Automatic (beam)" wizard from the Calibrate menu after a manual XYZ 4-point of the same
  tool: the scan runs, the events list shows, the result sets the beam's real-robot time next to
  the manual time with the errors of both against the true tool (the beam's TCP error below
  0.1 mm), and Save stores a TCP within 0.1 mm of the truth computed here from the tool's URDF;
* the industrial loop on the Tool tab: the "Bent tool" scenario (a crash) -> "Check with beam"
  shows the deviation of the bend (computed here from the scenario's seed) -> "Update" writes the
  measured TCP into the library (method "beam") -> the spin test of the active tool says good.

Screenshots (1400 x 900) go to the test's tmp_path and are checked not to be blank.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from support.calib_helpers import true_frame
from support.pendant_page import assert_not_blank, choose, type_text
from support.wizard_page import auto_touch_to_result, open_calibrate, press, text_of, wait_enabled, wait_text

from tcp_pendant.controller import builtin_tools
from tcp_pendant.controller.scenarios import Scenario, bent_tool_frame, draw_tool_bend
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

pytestmark = pytest.mark.browser


def row_text(page, first_cell: str, *, also: str = "") -> str:
    """Inner text of the visible table row whose text starts with ``first_cell`` (and holds
    ``also``: the result's "method" row names the method too)."""
    row = page.get_by_role("row").filter(has_text=first_cell).filter(has_text=also).filter(visible=True).first
    return str(row.inner_text(timeout=60_000))


def test_automatic_beam_wizard_next_to_the_manual_calibration(server, new_page, shot) -> None:
    page = new_page(server.url)
    open_calibrate(page)
    press(page, "Start")                                      # XYZ 4-point by Auto-touch
    auto_touch_to_result(page, 4)
    press(page, "Close (not saved)")

    choose(page, "Method", "Automatic (beam)", "BullsEye")
    wait_enabled(page, "Start")
    press(page, "Start")
    wait_text(page, "Beam scan")
    press(page, "Finish")                                     # the controller runs the scan
    wait_text(page, "on a real robot", "the beam result")

    tcp_true, _, _ = true_frame("pointer")
    # the events list: 4 orientations, each one tip event and two sideways crossings
    wait_text(page, "Events (12)")
    assert page.get_by_role("cell", name="tip on the beam", exact=True).filter(visible=True).count() == 4
    assert page.get_by_role("cell", name="shaft crossed sideways", exact=True).filter(visible=True).count() == 8
    # the real-robot time, and automatic vs by hand with the errors of both against the truth
    assert re.search(r"scan on a real robot\s+\d+\.\d s \(path", row_text(page, "scan on a real robot"))
    beam_row = row_text(page, "Automatic (beam)", also="on a real robot")
    m = re.search(r"(\d+\.\d+) s on a real robot\s+(\d+\.\d+) mm", beam_row)
    assert m, beam_row
    assert 5.0 < float(m.group(1)) < 60.0                     # seconds, as a BullsEye takes
    assert float(m.group(2)) < 0.1, beam_row                  # the beam's TCP error vs truth
    hand_row = row_text(page, "XYZ 4-point (by Auto-touch)")     # the four touches were Auto-touch's
    assert "(Auto-touch's clicks)" in hand_row and re.search(r"\d+\.\d+ mm", hand_row), hand_row
    wait_text(page, "Against the true TOOL frame: good")
    press(page, "Replay scan")                                # the film again (the robot goes through it)
    page.wait_for_timeout(1500)
    assert_not_blank(shot(page, "beam_wizard_replay"))

    # Save: the measured TCP in the library, within 0.1 mm of the truth
    type_text(page, "Tool name", "Pointer beam", re.compile(r"Will save Pointer beam · X"))
    press(page, "Save to tool library")
    wait_text(page, re.compile(r"Saved Pointer beam in slot 1; it is now the active tool"))
    saved = ToolLibrary(server.library_path).get(1)
    assert saved is not None and saved.name == "Pointer beam"
    np.testing.assert_allclose(saved.tcp_mm, tcp_true, atol=0.1)
    stored = json.loads(server.library_path.read_text())
    assert "beam" in json.dumps(stored)                       # the calibration method is on file
    assert_not_blank(shot(page, "beam_wizard_saved"))


def test_crash_check_with_beam_update_and_verify_by_spin_test(server, new_page, shot) -> None:
    pointer = builtin_tools()["pointer"]
    T = pointer.T_flange_tool_true
    ToolLibrary(server.library_path).save(1, Tool.from_rotation("Pointer", tuple(T[:3, 3] * 1000.0), T[:3, :3]))
    bend = draw_tool_bend(Scenario("bent_tool", seed=0))      # what the panel's seed 0 plays
    bent_tip_mm = bent_tool_frame(T, bend)[:3, 3] * 1000.0

    page = new_page(server.url)
    page.get_by_role("tab", name="Tool").click()
    wait_text(page, "Selected: Pointer")
    press(page, "Activate")
    wait_text(page, "Active tool: Pointer (slot 1)")

    # the crash: the trainer plays "Bent tool" (Calibrate tab, Systematic error)
    page.get_by_role("tab", name="Calibrate").click()
    page.get_by_text("Systematic error (training)").first.click()
    choose(page, "Systematic error", "Bent tool", echo=re.compile(r"Playing\s+Bent tool"))
    page.keyboard.press("Escape")

    # Check with beam: the deviation is the bend
    page.get_by_role("tab", name="Tool").click()
    press(page, "Check with beam")
    wait_text(page, "Beam check of Pointer", "the beam check's result")
    m = re.search(r"Deviation (\d+\.\d+) mm", text_of(page, re.compile(r"Deviation \d+\.\d+ mm")))
    assert m and float(m.group(1)) == pytest.approx(bend.shift_mm, abs=0.05), (m and m.group(0), bend.shift_mm)
    wait_enabled(page, "Update")
    page.get_by_text("TCP service (beam sensor)").first.evaluate("e => e.scrollIntoView({block: 'start'})")
    page.wait_for_timeout(500)
    assert_not_blank(shot(page, "beam_check"))

    # Update: the library has the measured TCP (method beam), active in this browser
    press(page, "Update")
    wait_text(page, "Updated slot 1: Pointer", "the update's confirmation")
    updated = ToolLibrary(server.library_path).get(1)
    np.testing.assert_allclose(updated.tcp_mm, bent_tip_mm, atol=0.05)
    assert updated.calibration is not None and updated.calibration.method == "beam"

    # verify by the spin test of the active tool (the bent tool turns about its new TCP)
    press(page, "Check active tool")
    wait_text(page, "TCP good", "the spin test's verdict on the updated TCP")
    assert_not_blank(shot(page, "beam_check_verified"))
