"""One chromium (Debian's, driven by Playwright's sync API) per test process.

Playwright's sync API cannot be started twice in one thread while the first is running ("Sync API
inside the asyncio loop"), so every folder whose conftest has a ``browser`` fixture
(``tests/browser``, ``tests/security``) takes the browser from here: imported by its plain name
from ``sys.path``, this module is one object however many conftest copies import it. The last
fixture to let go closes it.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

CHROMIUM = os.environ.get("CHROMIUM", "/usr/bin/chromium")
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update"]

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
