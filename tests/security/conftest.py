"""Fixtures of the security tests.

The browser tests here reuse the fixtures of ``tests/browser/conftest.py`` (``pendant_server``,
``server``, ``browser``, ``new_page``, ``shot``): that file is loaded under its own module name
and its fixtures are re-exported, so both folders start servers and chromium the same way.
"""

from __future__ import annotations

import os
import importlib.util
import sys
from pathlib import Path

# a fast path into viser's private API that falls back raises (views.viser_adapter)
os.environ.setdefault("TCP_PENDANT_STRICT_VISER", "1")

_BROWSER_DIR = Path(__file__).parents[1] / "browser"
if str(_BROWSER_DIR) not in sys.path:
    sys.path.insert(0, str(_BROWSER_DIR))          # pendant_page.py, as the browser tests import it

_spec = importlib.util.spec_from_file_location("_browser_fixtures", _BROWSER_DIR / "conftest.py")
assert _spec is not None and _spec.loader is not None
_browser_fixtures = sys.modules.setdefault("_browser_fixtures", importlib.util.module_from_spec(_spec))
if not hasattr(_browser_fixtures, "new_page"):
    _spec.loader.exec_module(_browser_fixtures)

browser = _browser_fixtures.browser
new_page = _browser_fixtures.new_page
pendant_server = _browser_fixtures.pendant_server
server = _browser_fixtures.server
shot = _browser_fixtures.shot
free_port = _browser_fixtures.free_port
CHROMIUM = _browser_fixtures.CHROMIUM
CHROMIUM_ARGS = _browser_fixtures.CHROMIUM_ARGS
