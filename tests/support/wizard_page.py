"""Playwright helpers for the wizard flows of the pendant page: the Jog tab's wizard dock repeats
the step's words and buttons (hidden while the Calibrate tab is shown), so these look at what is
visible only; the Calibrate tab opened (a class's name prompt answered first), every step
Auto-touched, the result saved to the library."""

from __future__ import annotations

import re

from support import pendant_page
from support.pendant_page import TIMEOUT_MS, type_text


def wait_text(page, pattern: str | re.Pattern[str], what: str | None = None) -> None:
    """Wait until some visible element shows ``pattern`` (substring, or a regex)."""
    loc = page.get_by_text(pattern) if isinstance(pattern, re.Pattern) else page.get_by_text(pattern, exact=False)
    try:
        loc.filter(visible=True).first.wait_for(state="visible", timeout=TIMEOUT_MS)
    except Exception as exc:  # a clearer failure than Playwright's
        raise AssertionError(f"never saw {what or pattern!r} on the page") from exc


def press(page, name: str) -> None:
    """Click the visible button named exactly ``name``."""
    page.get_by_role("button", name=name, exact=True).filter(visible=True).first.click()


def wait_enabled(page, name: str) -> None:
    """Wait until a visible button ``name`` is enabled (the Jog tab's dock repeats the wizard's
    buttons, hidden while the Calibrate tab is shown)."""
    pendant_page.wait_enabled(page, name, visible_only=True)


def text_of(page, pattern: str | re.Pattern[str]) -> str:
    """Inner text of the innermost visible element showing ``pattern``."""
    loc = page.locator("div, p, td, span").filter(has_text=pattern).filter(visible=True).last
    return str(loc.inner_text(timeout=TIMEOUT_MS))


def join_class_if_asked(page) -> None:
    """A per-browser server with a class gradebook first asks for the trainee's name (a modal
    over the page): give one, so the tabs can be reached."""
    welcome = page.get_by_text("Welcome to the TCP Pendant")
    try:
        welcome.wait_for(state="visible", timeout=3000)
    except Exception:
        return                                                 # no classroom: no name asked
    type_text(page, "Your name", "Ada Trainee")
    press(page, "Join the class")
    welcome.wait_for(state="hidden", timeout=TIMEOUT_MS)


def open_calibrate(page) -> None:
    join_class_if_asked(page)
    page.get_by_role("tab", name="Calibrate").click()
    wait_enabled(page, "Start")


def auto_touch_to_result(page, n_steps: int) -> None:
    """Auto-touch every step (the last one computes the result)."""
    for k in range(1, n_steps + 1):
        wait_text(page, f"Step {k} of {n_steps}")
        press(page, "Auto-touch")
    wait_text(page, "Against the true TOOL frame: good")


def save_tool(page, name: str, slot_text: str) -> None:
    """Type the name (waiting for the save preview to echo it), save, wait for the confirmation."""
    type_text(page, "Tool name", name, re.compile(rf"Will save {re.escape(name)} · X"))
    press(page, "Save to tool library")
    wait_text(page, re.compile(rf"Saved {re.escape(name)} in slot {slot_text}; it is now the active tool"))
