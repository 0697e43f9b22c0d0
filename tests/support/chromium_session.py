"""One chromium (Debian's, driven by Playwright's sync API) per test process.

Playwright's sync API cannot be started twice in one thread while the first is running ("Sync API
inside the asyncio loop"), so the ``browser`` fixture (``support.fixtures``) and any other user
take the browser from here; the last to let go closes it.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any
from urllib.parse import parse_qsl, urlsplit, urlunsplit

CHROMIUM = os.environ.get("CHROMIUM", "/usr/bin/chromium")
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update"]

RENDER_SCALE = os.environ.get("UI_RENDER_SCALE", "0.5")
"""The 3D view's resolution in the tests' pages, device pixels per CSS pixel (viser's ``fixedDpr``
address parameter, read by its client at load; the page's layout and the screenshots' size are
unchanged). WebGL is software-rendered here (SwiftShader), at a cost per pixel: an idle pendant
page at 1400 x 900 took 1.4-1.5 of the machine's two cores at the browser's own scale (viser
adapts it down to 0.75 on a slow machine) and 0.9 at 0.5, and ten jog clicks, each waited on until
its readout changed, took 5.8-7.1 s against 4.7 s, the server and the test sharing the same cores.
At 0.5 the 3D labels still read in a screenshot (at 0.3 they do not). ``UI_RENDER_SCALE=`` (empty)
leaves the browser's own."""

_state: dict[str, Any] = {"users": 0, "pw": None, "browser": None}


def acquire() -> Any:
    """The shared chromium (launched on first use). Pair every call with :func:`release`.

    Raises:
        FileNotFoundError: no chromium at ``$CHROMIUM`` (default ``/usr/bin/chromium``).
    """
    if _state["browser"] is None:
        if not shutil.which(CHROMIUM) and not Path(CHROMIUM).exists():
            raise FileNotFoundError(f"chromium not found at {CHROMIUM}; install it (apt-get install chromium) "
                                    "or set $CHROMIUM (scripts/run-tests.sh installs it).")
        from playwright.sync_api import sync_playwright  # noqa: PLC0415 - only browser tests need it

        pw = sync_playwright().start()
        try:
            _state["browser"] = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        except Exception:
            pw.stop()
            raise
        _state["pw"] = pw
    _state["users"] += 1
    return _state["browser"]


def with_render_scale(url: str) -> str:
    """``url`` with :data:`RENDER_SCALE` as viser's ``fixedDpr`` parameter, appended to the query
    as it is written (a page that drops a parameter of its own, e.g. ``trainer``, keeps this one);
    unchanged when the scale is empty or the address gives one."""
    parts = urlsplit(url)
    if not RENDER_SCALE or any(name == "fixedDpr" for name, _ in parse_qsl(parts.query)):
        return url
    query = f"{parts.query}&" if parts.query else ""
    return urlunsplit(parts._replace(path=parts.path or "/", query=f"{query}fixedDpr={RENDER_SCALE}"))


def release() -> None:
    """Let go of the browser; the last user closes chromium and stops Playwright."""
    _state["users"] -= 1
    if _state["users"] > 0 or _state["browser"] is None:
        return
    browser, pw = _state["browser"], _state["pw"]
    _state["browser"] = _state["pw"] = None
    try:
        browser.close()
    finally:
        pw.stop()
