"""A screenshot of the pendant per language, to look at (docs/languages.md, step 5 of adding a
language): no boxes instead of letters, no cut labels, the jog keys one row per axis.

For each language a pendant starts with that class default (``AppConfig.language``, what
``tcp-pendant --language X`` sets; a throw-away tool library) and Debian's chromium opens it at
1400x900 (and 1024x768 with ``--small``). The browser's XYZ 4-point is started and its first
touch auto-touched on the server (as the Calibrate tab's Start and Auto-touch do), so the Jog
tab shows the wizard's step in its dock, the jog keys, and the 3D labels (WORLD, FLANGE, TOOL,
reference tip, beam sensor) in the scene. One PNG per language and size:
``<out-dir>/pendant_<language>_<width>x<height>.png``; and ``pendant_<language>_languages.png``
with the language selector opened (every language's name in its own script).

    .venv/bin/python scripts/language_screens.py [--out-dir build/language-screens] [--small] [de ru ...]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = os.environ.get("CHROMIUM", "/usr/bin/chromium")
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update"]
TIMEOUT_MS = 120_000
SIZES = ((1400, 900),)
SMALL = (1024, 768)


def _session(app: Any) -> Any:
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        sessions = app.all_sessions()
        if len(sessions) == 1 and "dock" in sessions[0].views:
            return sessions[0]
        time.sleep(0.1)
    raise SystemExit("no pendant session appeared for the browser")


def shoot(browser: Any, language: str, sizes: tuple[tuple[int, int], ...], out_dir: Path) -> list[Path]:
    """The screenshots of one language (module docstring)."""
    from tcp_pendant.calibrate import AutoTouchRequest
    from tcp_pendant.serve.server import AppConfig, PendantApp

    written = []
    with tempfile.TemporaryDirectory() as tmp:
        app = PendantApp(AppConfig(port=0, tool_library=Path(tmp) / "tools.json", seed=11, language=language))
        url = app.start()
        try:
            page = browser.new_page(viewport={"width": sizes[0][0], "height": sizes[0][1]})
            page.set_default_timeout(TIMEOUT_MS)
            page.goto(url)
            session = _session(app)
            page.locator("[role=tab]").first.wait_for()
            session.wizard_commands.start("xyz4")
            session.wizard_commands.auto_touch(AutoTouchRequest())
            for close in page.locator(".mantine-Notification-closeButton").all():
                close.click()                            # "software WebGL" (no GPU here)
            page.locator("[role=tab]").first.click()     # the Jog tab, its dock showing step 2
            for width, height in sizes:
                page.set_viewport_size({"width": width, "height": height})
                page.wait_for_timeout(3000)              # software WebGL: let the last frames render
                out = out_dir / f"pendant_{language}_{width}x{height}.png"
                page.screenshot(path=str(out))
                written.append(out)
            written.append(shoot_language_list(page, language, out_dir))
            page.close()
        finally:
            app.stop()
    return written


def shoot_language_list(page: Any, language: str, out_dir: Path) -> Path:
    """``pendant_<language>_languages.png``: the View folder's language selector opened, every
    language named in its own script (Cyrillic, Devanagari, Chinese, Japanese) in the panel."""
    row = page.locator(".mantine-Flex-root").filter(has=page.locator("label", has_text="Language")).last
    box = row.locator("input").first
    box.scroll_into_view_if_needed()
    box.click()
    page.get_by_role("option").first.wait_for()
    page.wait_for_timeout(500)
    out = out_dir / f"pendant_{language}_languages.png"
    page.screenshot(path=str(out))
    page.keyboard.press("Escape")
    return out


def main() -> None:
    from tcp_pendant.translation import PSEUDO_LANGUAGE, languages

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("languages", nargs="*", default=[*languages(), PSEUDO_LANGUAGE],
                        help="language codes (default: every language and the pseudo-locale)")
    parser.add_argument("--out-dir", type=Path, default=ROOT / "build" / "language-screens")
    parser.add_argument("--small", action="store_true", help="also at 1024x768")
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    args.out_dir.mkdir(parents=True, exist_ok=True)
    sizes = SIZES + ((SMALL,) if args.small else ())
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        try:
            for language in args.languages:
                for out in shoot(browser, language, sizes, args.out_dir):
                    print(f"wrote {out}")
        finally:
            browser.close()


if __name__ == "__main__":
    main()
