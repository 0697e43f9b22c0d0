"""End-to-end: every calibration wizard in Debian's chromium (Playwright), on the default KR 6.

Each test opens the page, runs its wizard through the GUI with training-mode Auto-touch (zero
operator error), saves the tool, and checks the saved tool's numbers in the library panel and
the library file against the tool's hidden true TOOL frame, computed here from the tool's URDF
(``ToolModel.T_flange_tool_true``) with scipy - not by the app. Screenshots of the result views
go to the test's tmp_path and are checked not to be blank.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

from support.calib_helpers import true_frame
from support.pendant_page import TIMEOUT_MS, assert_not_blank, choose
from support.wizard_page import (
    auto_touch_to_result,
    open_calibrate,
    press,
    save_tool,
    text_of,
    wait_enabled,
    wait_text,
)

pytestmark = pytest.mark.browser

DISPLAY_TOL = 0.006     # the pendant shows two decimals


def truth(key: str) -> tuple[np.ndarray, np.ndarray]:
    """(TCP mm, KUKA A, B, C deg) of a built-in tool's hidden true TOOL frame."""
    tcp, _R, abc = true_frame(key)
    return tcp, abc


def shown_tcp(page) -> np.ndarray:
    """X, Y, Z of the result's "TCP X .. · Y .. · Z .. mm" line."""
    text = text_of(page, re.compile(r"TCP X -?\d+\.\d\d · Y"))
    m = re.search(r"TCP X (-?\d+\.\d\d) · Y (-?\d+\.\d\d) · Z (-?\d+\.\d\d) mm", text)
    assert m, text
    return np.array([float(g) for g in m.groups()])


def shown_abc(page) -> np.ndarray:
    text = text_of(page, re.compile(r"Orientation A -?\d+\.\d\d"))
    m = re.search(r"Orientation A (-?\d+\.\d\d) · B (-?\d+\.\d\d) · C (-?\d+\.\d\d)°", text)
    assert m, text
    return np.array([float(g) for g in m.groups()])


def check_library_panel(page, name: str, slot: int, tcp: np.ndarray, abc: np.ndarray | None) -> None:
    """The Tool tab's active-tool block shows the saved tool with these numbers."""
    page.get_by_role("tab", name="Tool").click()
    wait_text(page, f"Active tool: {name} (slot {slot})")
    block = text_of(page, re.compile(rf"Active tool: {re.escape(name)} \(slot {slot}\)[\s\S]*X -?\d"))
    m = re.search(r"X (-?\d+\.\d\d)\s+Y (-?\d+\.\d\d)\s+Z (-?\d+\.\d\d) mm\s+A (-?\d+\.\d\d)\s+B (-?\d+\.\d\d)"
                  r"\s+C (-?\d+\.\d\d) deg", block)
    assert m, block
    nums = np.array([float(g) for g in m.groups()])
    np.testing.assert_allclose(nums[:3], tcp, atol=DISPLAY_TOL)
    if abc is not None:
        np.testing.assert_allclose(nums[3:], abc, atol=DISPLAY_TOL)


def seed_library(path: Path, tool: Tool) -> None:
    """The library a trainer prepared: slot 1 holds ``tool`` (written before the server starts)."""
    ToolLibrary(path).save(1, tool)


# ---------------------------------------------------------------------------------------------
def test_xyz4_wizard_auto_touch_save_export_and_replay(pendant_server, new_page, shot, tmp_path) -> None:
    server = pendant_server()
    page = new_page(server.url)
    open_calibrate(page)
    wait_text(page, "Calibrates the TCP of the straight pointer now mounted")
    press(page, "Start")
    wait_text(page, "Pose diversity")                          # the live meter is there
    auto_touch_to_result(page, 4)
    tcp_true, _ = truth("pointer")
    np.testing.assert_allclose(shown_tcp(page), tcp_true, atol=DISPLAY_TOL)
    wait_text(page, "P1 0.00, P2 0.00, P3 0.00, P4 0.00")    # per-touch errors, zero operator error
    assert page.locator(".uplot").count() >= 1                 # the per-touch error chart
    assert_not_blank(shot(page, "xyz4_result"))

    # --- session record: export, then load it back and replay
    page.get_by_text("Session record", exact=True).click()
    with page.expect_download(timeout=TIMEOUT_MS) as dl:
        press(page, "Export session (JSON)")
    record = json.loads(Path(dl.value.path()).read_text())
    (run,) = record["wizards"]
    np.testing.assert_allclose(run["result"]["tcp_mm"], tcp_true, atol=1e-6)
    assert run["truth"]["grade"] == "good" and run["truth"]["position_error_mm"] < 1e-6
    exported = tmp_path / "session.json"
    exported.write_text(json.dumps(record))
    page.locator("input[type=file]").set_input_files(str(exported))
    wait_text(page, "replayed result matches the record")

    # --- save: the tool is in the library, active, with the true numbers
    save_tool(page, "Pointer 4P", "1")
    assert_not_blank(shot(page, "xyz4_saved"))
    check_library_panel(page, "Pointer 4P", 1, tcp_true, np.zeros(3))
    saved = ToolLibrary(server.library_path)
    assert saved.active_slot() is None       # active in this browser only (the page says so above)
    np.testing.assert_allclose(saved.get(1).tcp_mm, tcp_true, atol=1e-6)
    shot(page, "xyz4_library_panel")


def test_reference_wizard_swaps_the_tool_and_saves(pendant_server, new_page, shot, tmp_path) -> None:
    ptr_tcp, _ = truth("pointer")
    seed_library(tmp_path / "tools.json", Tool(name="Pointer", tcp_mm=tuple(ptr_tcp)))
    server = pendant_server()
    page = new_page(server.url)
    open_calibrate(page)
    choose(page, "Method", "XYZ reference", "Touch 1 with the data 1: Pointer on the straight pointer")
    choose(page, "New tool", "Bent-neck welding torch", "touch 2 with the bent-neck welding torch")
    press(page, "Start")
    wait_text(page, "Step 1 of 2")
    press(page, "Auto-touch")
    wait_text(page, "Step 2 of 2")
    # step 2 needs the torch: Record is disabled until the tool change
    wait_text(page, "Mount the bent-neck welding torch first: the straight pointer is mounted now.")
    assert page.get_by_role("button", name="Record", exact=True).filter(visible=True).first.is_disabled()
    press(page, "Mount the bent-neck welding torch")
    wait_enabled(page, "Record")
    shot(page, "reference_tool_swapped")
    press(page, "Auto-touch")
    wait_text(page, "Against the true TOOL frame: good")
    wait_text(page, "the TCP error is the sum of both touches' errors")   # the method's warning
    tcp_true, _ = truth("torch")
    np.testing.assert_allclose(shown_tcp(page), tcp_true, atol=DISPLAY_TOL)
    assert_not_blank(shot(page, "reference_result"))
    save_tool(page, "Torch", "2")
    check_library_panel(page, "Torch", 2, tcp_true, np.zeros(3))
    saved = ToolLibrary(server.library_path)
    np.testing.assert_allclose(saved.get(2).tcp_mm, tcp_true, atol=1e-6)
    assert saved.get(1).name == "Pointer"                      # nothing else touched


def start_torch_orientation(pendant_server, new_page, tmp_path: Path, method: str, n_steps: int):
    """The torch mounted, its TCP calibrated in slot 1 (orientation not yet), ``method`` started.
    Returns (server, page)."""
    tcp_true, _ = truth("torch")
    seed_library(tmp_path / "tools.json", Tool(name="Torch", tcp_mm=tuple(tcp_true)))
    server = pendant_server("--tool", "torch")
    page = new_page(server.url)
    open_calibrate(page)
    choose(page, "Method", method, "Calibrates the orientation of 1: Torch")
    press(page, "Start")
    wait_text(page, f"Step 1 of {n_steps}")
    return server, page


@pytest.mark.parametrize("variant", [1, 2])
def test_three_point_wizard_calibrates_the_orientation(pendant_server, new_page, shot, tmp_path, variant) -> None:
    tcp_true, abc_true = truth("torch")
    server, page = start_torch_orientation(pendant_server, new_page, tmp_path, "Three-point orientation", 3)
    if variant == 2:
        choose(page, "Variant", "Variant 2: tip in the +Y half-plane", "Tip in the tool's +Y half-plane")
    auto_touch_to_result(page, 3)
    np.testing.assert_allclose(shown_abc(page), abc_true, atol=DISPLAY_TOL)
    wait_text(page, "orthogonality defect")
    wait_text(page, re.compile(r"displacement lengths Δ\s*\d+\.\d mm, \d+\.\d mm"))
    assert_not_blank(shot(page, f"three_point_{variant}_result"))
    save_tool(page, "Torch", "1")                              # the same tool, now oriented
    check_library_panel(page, "Torch", 1, tcp_true, abc_true)
    saved = ToolLibrary(server.library_path).get(1)
    np.testing.assert_allclose(saved.abc_deg, abc_true, atol=1e-6)
    np.testing.assert_allclose(saved.tcp_mm, tcp_true, atol=1e-9)


def test_abc_world_wizard_calibrates_the_orientation(pendant_server, new_page, shot, tmp_path) -> None:
    tcp_true, abc_true = truth("torch")
    server, page = start_torch_orientation(pendant_server, new_page, tmp_path, "ABC world (parallel axes)", 1)
    assert_not_blank(shot(page, "abc_world_target"))           # the WORLD-aligned target triad
    press(page, "Auto-touch")
    wait_text(page, "Against the true TOOL frame: good")
    np.testing.assert_allclose(shown_abc(page), abc_true, atol=DISPLAY_TOL)
    assert_not_blank(shot(page, "abc_world_result"))
    save_tool(page, "Torch", "1")
    check_library_panel(page, "Torch", 1, tcp_true, abc_true)
    np.testing.assert_allclose(ToolLibrary(server.library_path).get(1).abc_deg, abc_true, atol=1e-6)


def test_tcp_zx_wizard_calibrates_tcp_and_frame_in_one_go(pendant_server, new_page, shot, tmp_path) -> None:
    """ABB TCP & Z, X with the torch: four touches, the reference on tool +Z, then on +X."""
    tcp_true, abc_true = truth("torch")
    server = pendant_server("--tool", "torch")
    page = new_page(server.url)
    open_calibrate(page)
    choose(page, "Method", "TCP & Z, X (ABB)",
           "Calibrates the TCP and the orientation of the bent-neck welding torch now mounted")
    wait_text(page, "then the reference tip on the tool's +Z axis ahead of the TCP")     # the blurb
    press(page, "Start")
    wait_text(page, "Pose diversity")                          # the meter on the touches
    for k in range(1, 5):
        wait_text(page, f"Step {k} of 6")
        press(page, "Auto-touch")
    wait_text(page, "Step 5 of 6: Reference on the tool's +Z axis")
    wait_text(page, "back off straight along the tool's Z axis")
    shot(page, "tcp_zx_step_z")
    press(page, "Auto-touch")
    wait_text(page, "Step 6 of 6: Reference on the tool's +X axis")
    press(page, "Auto-touch")                                  # the last one computes
    wait_text(page, "Against the true TOOL frame: good")
    np.testing.assert_allclose(shown_tcp(page), tcp_true, atol=DISPLAY_TOL)
    np.testing.assert_allclose(shown_abc(page), abc_true, atol=DISPLAY_TOL)
    wait_text(page, "P1 0.00, P2 0.00, P3 0.00, P4 0.00")    # per-touch errors, zero operator error
    wait_text(page, "orthogonality defect")
    wait_text(page, re.compile(r"displacement lengths Δ\s*60\.0 mm, 60\.0 mm"))   # z and x distances
    assert_not_blank(shot(page, "tcp_zx_result"))
    save_tool(page, "Torch ZX", "1")
    check_library_panel(page, "Torch ZX", 1, tcp_true, abc_true)
    shot(page, "tcp_zx_library_panel")
    saved = ToolLibrary(server.library_path).get(1)
    np.testing.assert_allclose(saved.tcp_mm, tcp_true, atol=1e-6)
    np.testing.assert_allclose(saved.abc_deg, abc_true, atol=1e-6)
    assert saved.calibration.method == "tcp-zx"
