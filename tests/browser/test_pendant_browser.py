"""End-to-end: the pendant in Debian's chromium (Playwright). Two pages = two browsers:
jogging page 1's robot changes page 1's readout only; recording a point; typing a tool in and
exporting it to KUKA text. Screenshots go to the test's tmp_path."""

from __future__ import annotations

import re
import time

import pytest

from tcpcal.library import ToolLibrary

pytestmark = pytest.mark.browser

TIMEOUT_MS = 60_000


def readout(page) -> str:
    """Text of the TCP readout (the monospace block under "TCP in ...")."""
    block = page.locator("pre").filter(has_text=re.compile(r"X\s+-?\d+\.\d\d mm")).first
    return block.inner_text(timeout=TIMEOUT_MS)


def wait_readout(page, pattern: str) -> str:
    """Wait until the TCP readout matches ``pattern`` (regex); returns the readout."""
    deadline = time.monotonic() + TIMEOUT_MS / 1000
    text = ""
    while time.monotonic() < deadline:
        text = readout(page)
        if re.search(pattern, text):
            return text
        page.wait_for_timeout(100)
    raise AssertionError(f"readout never matched {pattern!r}; last: {text!r}")


def numbers(text: str) -> dict[str, float]:
    """``{"X": .., "Y": .., "Z": .., "A": .., "B": .., "C": ..}`` parsed from a readout."""
    return {k: float(v) for k, v in re.findall(r"([XYZABC])\s+(-?\d+\.\d\d) (?:mm|deg)", text)}


def wait_numbers(page, pred, what: str) -> dict[str, float]:
    """Wait until ``pred(numbers)`` holds for page's readout."""
    deadline = time.monotonic() + TIMEOUT_MS / 1000
    last: dict[str, float] = {}
    while time.monotonic() < deadline:
        last = numbers(readout(page))
        if len(last) == 6 and pred(last):
            return last
        page.wait_for_timeout(100)
    raise AssertionError(f"readout never showed {what}; last: {last}")


def field(page, label: str):
    """The input (or textarea) of a viser GUI row by its exact label."""
    row = page.locator(".mantine-Flex-root").filter(has=page.locator(f"label:text-is('{label}')"))
    return row.locator("input, textarea").first


def type_into(page, label: str, text: str) -> None:
    """Type into a text field like a user (select all, then key by key). Playwright's
    ``fill`` sets several fields faster than viser's client throttles its updates, and an
    update of one field can then be dropped; typing keeps every field's last value."""
    f = field(page, label)
    f.click()
    f.press("Control+a")
    f.press_sequentially(text)


def test_two_pages_jog_record_and_tool_entry(server, new_page, shot) -> None:
    assert server.startup_s < 5.0 + 2.0, f"server needed {server.startup_s:.1f} s (spawn included)"
    p1 = new_page(server.url)
    p2 = new_page(server.url)
    r1 = wait_numbers(p1, lambda n: True, "a readout")
    r2 = wait_numbers(p2, lambda n: True, "a readout")
    assert r1 == r2                                        # both start at the ready pose

    # --- jog page 1 with the buttons: Z- then X- by 10 mm (increment 10, WORLD)
    p1.get_by_role("button", name="10", exact=True).click()
    p1.get_by_role("button", name="Z −", exact=True).click()
    wait_numbers(p1, lambda n: abs(n["Z"] - (r1["Z"] - 10.0)) < 0.011, "Z - 10 mm")
    p1.get_by_role("button", name="X −", exact=True).click()
    j1 = wait_numbers(p1, lambda n: abs(n["X"] - (r1["X"] - 10.0)) < 0.011, "X - 10 mm")
    assert abs(j1["Y"] - r1["Y"]) < 0.011 and abs(j1["Z"] - (r1["Z"] - 10.0)) < 0.011
    # page 2 did not move: after a jog of its own (1 mm up) only that shows
    p2.get_by_role("button", name="1", exact=True).click()
    p2.get_by_role("button", name="Z +", exact=True).click()
    j2 = wait_numbers(p2, lambda n: abs(n["Z"] - (r2["Z"] + 1.0)) < 0.011, "Z + 1 mm")
    assert abs(j2["X"] - r2["X"]) < 0.011 and abs(j2["Y"] - r2["Y"]) < 0.011
    assert numbers(readout(p1)) == j1

    # --- record a point on page 1; it shows in page 1's list only
    p1.get_by_role("button", name="Record point").click()
    p1.get_by_role("button", name="Delete P1").wait_for(timeout=TIMEOUT_MS)
    assert p1.get_by_text(re.compile(r"P1\s+X -?\d+\.\d Y -?\d+\.\d Z -?\d+\.\d mm")).count() >= 1
    assert p2.get_by_role("button", name="Delete P1").count() == 0
    shot(p1, "page1_jogged_recorded")
    shot(p2, "page2_untouched")

    # --- numeric entry with a bad number: error next to the field, nothing saved
    p1.get_by_role("tab", name="Tool").click()
    p1.get_by_text("Enter tool numerically").click()
    type_into(p1, "Name", "Pen")
    for label, value in (("X (mm)", "12.5"), ("Y (mm)", "-3"), ("Z (mm)", "1o0"),
                         ("A (deg)", "0"), ("B (deg)", "90"), ("C (deg)", "0")):
        type_into(p1, label, value)
    p1.get_by_role("button", name="Save to library").click()
    p1.get_by_text("'1o0' is not a number").wait_for(timeout=TIMEOUT_MS)
    assert ToolLibrary(server.library_path).tools() == {}
    shot(p1, "tool_entry_error")
    type_into(p1, "Z (mm)", "100")
    p1.get_by_role("button", name="Save to library").click()
    p1.get_by_text("Saved").wait_for(timeout=TIMEOUT_MS)
    tools = ToolLibrary(server.library_path).tools()
    assert list(tools) == [1] and tools[1].name == "Pen" and tools[1].tcp_mm == (12.5, -3.0, 100.0)

    # --- export to KUKA text
    p1.get_by_text("Export", exact=True).first.click()
    p1.get_by_role("button", name="Export", exact=True).click()
    area = field(p1, "Controller text")
    deadline = time.monotonic() + TIMEOUT_MS / 1000
    while "TOOL_DATA" not in area.input_value() and time.monotonic() < deadline:
        p1.wait_for_timeout(100)
    text = area.input_value()
    assert "TOOL_DATA[1]={X 12.5,Y -3.0,Z 100.0,A 0.0,B 90.0,C 0.0}" in text, text
    assert 'TOOL_NAME[1,]="Pen"' in text
    shot(p1, "tool_export_kuka")

    # --- page 2 sees the tool saved by page 1 (shared library, refreshed on change)
    p2.get_by_role("tab", name="Tool").click()
    p2.get_by_text("Selected: Pen").or_(p2.get_by_text("Pen (slot 1)")).first.wait_for(timeout=TIMEOUT_MS)
    shot(p2, "page2_sees_library")
