"""Helpers to drive the pendant page in Playwright like a user, and to wait for the server.

viser's client sends every GUI message through one 50 ms throttle slot in which a newer
message replaces a pending one: a click right after a selection or a keystroke can drop it.
So each helper that changes a value waits until the server shows it has received it (an
``echo`` text the app renders from the value), before the test goes on.
"""

from __future__ import annotations

import re
import time
from pathlib import Path
from collections.abc import Callable
from typing import Any

import numpy as np

TIMEOUT_MS = 60_000


def wait_until(cond: Callable[[], Any], what: str, timeout: float = 60.0) -> Any:
    """Poll ``cond`` on the test's side (a server's state, not the page) until it gives a
    truthy value, or a non-empty array (a screenshot), and return that value; an empty dict of
    sessions is not yet a session, and numpy's False is False. Fail naming ``what``."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = cond()
        if value.size > 0 if isinstance(value, np.ndarray) else bool(value):   # an image counts as given
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def field(page: Any, label: str) -> Any:
    """The input (or textarea) of a viser GUI row by its exact label."""
    row = page.locator(".mantine-Flex-root").filter(has=page.locator(f"label:text-is('{label}')"))
    return row.locator("input, textarea").first


def wait_text(page: Any, pattern: str | re.Pattern[str], what: str | None = None) -> None:
    """Wait until some element shows ``pattern`` (substring, or a regex)."""
    loc = page.get_by_text(pattern) if isinstance(pattern, re.Pattern) else page.get_by_text(pattern, exact=False)
    try:
        loc.first.wait_for(state="visible", timeout=TIMEOUT_MS)
    except Exception as exc:  # a clearer failure than Playwright's
        raise AssertionError(f"never saw {what or pattern!r} on the page") from exc


def type_text(page: Any, label: str, text: str, echo: str | re.Pattern[str] | None = None) -> None:
    """Type into a text field (select all, then key by key); wait for ``echo`` if given."""
    f = field(page, label)
    f.click()
    f.press("Control+a")
    f.press_sequentially(text)
    if echo is not None:
        wait_text(page, echo, f"the server's echo of {label} = {text!r}")


def choose(page: Any, label: str, option: str, echo: str | re.Pattern[str] | None = None) -> None:
    """Pick ``option`` in the dropdown labelled ``label`` (a Mantine Select); wait for ``echo``."""
    field(page, label).click()
    page.get_by_role("option", name=option, exact=True).click()
    if echo is not None:
        wait_text(page, echo, f"the server's echo of {label} = {option!r}")


def press(page: Any, name: str) -> None:
    """Click the (first visible) button named exactly ``name``."""
    page.get_by_role("button", name=name, exact=True).first.click()


def wait_enabled(page: Any, name: str, *, visible_only: bool = False) -> None:
    """Wait until the button ``name`` is visible and enabled (``visible_only``: the first
    visible button of that name, where a hidden copy of it comes first on the page)."""
    buttons = page.get_by_role("button", name=name, exact=True)
    btn = (buttons.filter(visible=True) if visible_only else buttons).first
    btn.wait_for(state="visible", timeout=TIMEOUT_MS)
    deadline = time.monotonic() + TIMEOUT_MS / 1000
    while btn.is_disabled():
        if time.monotonic() > deadline:
            raise AssertionError(f"button {name!r} stayed disabled")
        page.wait_for_timeout(50)


def text_of(page: Any, pattern: str | re.Pattern[str]) -> str:
    """Inner text of the innermost element showing ``pattern``."""
    loc = page.locator("div, p, td, span").filter(has_text=pattern).last
    return str(loc.inner_text(timeout=TIMEOUT_MS))


def assert_not_blank(png: Path, *, min_colors: int = 400) -> None:
    """A screenshot shows a rendered scene and panel, not an empty page: many distinct colours
    overall, and the 3D view (left part) is not one flat colour."""
    from PIL import Image, ImageStat

    img = Image.open(png).convert("RGB")
    colors = img.getcolors(maxcolors=1 << 20) or []
    assert len(colors) >= min_colors, f"{png.name}: only {len(colors)} colours (blank page?)"
    w, h = img.size
    view = img.crop((0, 0, int(w * 0.6), h))
    spread = max(ImageStat.Stat(view).stddev)
    assert spread > 10.0, f"{png.name}: the 3D view is nearly flat (stddev {spread:.1f})"


BROWSER_KEY_JS = "localStorage.getItem('tcpPendant.browserKey')"
"""JavaScript: the browser key the page script keeps for a trainee who joined a class."""


def join_class(page: Any, name: str) -> None:
    """Answer a class's name prompt with ``name`` and wait until the page names the trainee."""
    welcome = page.get_by_text("Welcome to the TCP Pendant")
    welcome.wait_for(state="visible", timeout=TIMEOUT_MS)
    type_text(page, "Your name", name)
    page.wait_for_timeout(300)             # viser's 50 ms message slot: the name reaches the server first
    press(page, "Join the class")
    welcome.wait_for(state="hidden", timeout=TIMEOUT_MS)
    wait_text(page, f"Trainee: {name}")
