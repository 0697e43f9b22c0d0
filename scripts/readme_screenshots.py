"""Regenerate the README's screenshot of a finished XYZ 4-point calibration.

Starts the pendant (default KR 6 and pointer, a throw-away tool library) on a free port,
drives it in Debian's chromium with Playwright like a trainer would - Calibrate, 6 touches,
Auto-touch with a 0.3 mm operator error - and saves ``docs/images/xyz4_result.png`` with the
camera close to the reference tip (fitted sphere, flange points, approach lines, COMPUTED and
TRUE triads) and the result panel (figures, per-touch error bars, verdict) in view.

    .venv/bin/python scripts/readme_screenshots.py [--out docs/images/xyz4_result.png]
"""

from __future__ import annotations

import argparse
import re
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update"]
TIMEOUT_MS = 120_000


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def start_server(port: int, library: Path) -> subprocess.Popen[bytes]:
    proc = subprocess.Popen([sys.executable, "-m", "tcp_pendant", "--port", str(port), "--tool-library",
                             str(library)], stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}", timeout=1):
                return proc
        except OSError:
            time.sleep(0.1)
    proc.kill()
    raise SystemExit("the pendant did not start")


def fill(page, label: str, text: str) -> None:
    row = page.locator(".mantine-Flex-root").filter(has=page.locator(f"label:text-is('{label}')"))
    box = row.locator("input").last
    box.click()
    box.press("Control+a")
    box.press_sequentially(text)
    box.press("Enter")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "xyz4_result.png")
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    port = free_port()
    with tempfile.TemporaryDirectory() as tmp:
        proc = start_server(port, Path(tmp) / "tools.json")
        try:
            with sync_playwright() as pw:
                browser = pw.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_ARGS)
                page = browser.new_page(viewport={"width": 1400, "height": 900})
                page.set_default_timeout(TIMEOUT_MS)
                page.goto(f"http://127.0.0.1:{port}")
                page.get_by_role("button", name="Close-up on reference tip").click()
                page.get_by_role("tab", name="Calibrate").click()
                fill(page, "Touches", "6")
                page.wait_for_timeout(300)            # let the throttled slider update go out
                page.get_by_role("button", name="Start", exact=True).click()
                page.get_by_text("Step 1 of 6").wait_for()
                fill(page, "Operator error σ (mm)", "0.3")
                for k in range(1, 7):
                    page.get_by_text(f"Step {k} of 6").first.wait_for()
                    page.get_by_role("button", name="Auto-touch").click()
                    if k < 6:
                        page.get_by_text(f"Step {k + 1} of 6").first.wait_for()
                page.get_by_text("Against the true TOOL frame").wait_for()
                tcp_line = page.get_by_text(re.compile(r"^TCP X ")).first
                tcp_line.evaluate("e => e.scrollIntoView({block: 'start'})")   # the result on top
                for close in page.locator(".mantine-Notification-closeButton").all():
                    close.click()                     # e.g. "software WebGL" (no GPU here)
                page.wait_for_timeout(3000)           # software WebGL: let the last frame render
                args.out.parent.mkdir(parents=True, exist_ok=True)
                page.screenshot(path=str(args.out))
                browser.close()
        finally:
            proc.terminate()
            proc.wait(10)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
