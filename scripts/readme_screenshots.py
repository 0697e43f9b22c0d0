"""Regenerate the documentation's two screenshots and keep the caption's numbers true.

Starts the pendant in this process (default KR 6 and pointer, a throw-away tool library) on a
free port and drives it in Debian's chromium with Playwright like a trainer would:

* ``docs/images/pendant.png``: the page as a trainee first sees it (Jog tab, the robot in its
  ready pose with the pointer above the reference tip);
* ``docs/images/xyz4_result.png``: Calibrate, XYZ 4-point with 6 touches, Auto-touch with a
  0.3 mm operator error, the camera close to the reference tip (fitted sphere, flange points,
  approach lines, COMPUTED and TRUE triads) and the result panel in view.

Every random source is seeded: Auto-touch draws its directions and operator errors from the
session's generator, which a server started with ``--seed SEED`` draws for each session
(``PendantApp.session_rng``). :func:`seeded_figures` computes the same calibration without a browser
(the same controller, workflow and auto-touch calls); the script checks that the browser shows
those figures, then writes them into the caption under the 4-point screenshot in the trainer's
guide, ``docs/trainer.md`` (:func:`update_caption`).
``tests/scripts/test_readme_screenshots.py`` compares the caption with :func:`seeded_figures`.

    .venv/bin/python scripts/readme_screenshots.py [--out-dir docs/images] [--page docs/trainer.md]
"""

from __future__ import annotations

import argparse
import re
import tempfile
import time
import urllib.request
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update"]
TIMEOUT_MS = 120_000
SEED = 20261127
"""Seed of the auto-touch generator (directions and operator errors)."""
N_TOUCHES = 6
SIGMA_MM = 0.3
"""Simulated operator error of Auto-touch, mm per axis."""
CAPTION = re.compile(r"the TCP is (?P<error>\d+\.\d+) mm from the true one,\s+(?P<inside>inside|outside) its "
                     r"95 % radius of (?P<ci95>\d+\.\d+) mm")
"""The numbers of the caption under the 4-point screenshot (docs/trainer.md)."""


@dataclass(frozen=True)
class CaptionFigures:
    """The figures the caption quotes (mm).

    Attributes:
        position_error_mm: distance of the computed TCP from the true one.
        ci95_mm: 95 % radius of the computed TCP.
    """

    position_error_mm: float
    ci95_mm: float

    @property
    def inside(self) -> bool:
        """The true TCP lies inside the 95 % radius."""
        return self.position_error_mm <= self.ci95_mm


def seeded_workflow(app: Any, controller: Any, library: Any) -> Any:
    """The ``CalibrationWorkflow`` of the browser that shoots ``xyz4_result.png`` as a server
    started with ``--seed SEED`` builds it: the second session (``PendantApp.session_rng``: the
    first browser shoots ``pendant.png``)."""
    from tcp_pendant.calibrate import CalibrationWorkflow

    app.session_rng()                                   # session 0: the pendant.png browser
    return CalibrationWorkflow(controller, library, robot=app.robot_key, rng=app.session_rng())


def seeded_figures() -> CaptionFigures:
    """The seeded 4-point calibration of the screenshot, without a browser.

    The same steps as the browser run: a new session's controller (ready pose, default
    reference tip, pointer), XYZ 4-point with ``N_TOUCHES`` touches, ``N_TOUCHES`` Auto-touch
    clicks from random directions with ``SIGMA_MM`` operator error.
    """
    from tcp_pendant.calibrate.workflow import AutoTouchRequest
    from tcp_pendant.serve.server import AppConfig, PendantApp

    with tempfile.TemporaryDirectory() as tmp:
        app = PendantApp(AppConfig(tool_library=Path(tmp) / "tools.json", seed=SEED))
        workflow = seeded_workflow(app, app.new_controller(), app.library)
        workflow.start("xyz4", n_points=N_TOUCHES)
        for _ in range(N_TOUCHES):
            out = workflow.auto_touch(AutoTouchRequest(sigma_mm=SIGMA_MM))
            if not out.ok:
                raise RuntimeError(f"auto-touch failed: {out}")
        return _figures(workflow)


def _figures(workflow: Any) -> CaptionFigures:
    result, truth = workflow.result, workflow.truth()
    if result is None or truth is None or result.ci95_mm is None:
        raise RuntimeError("the seeded calibration gave no result with a 95 % radius")
    return CaptionFigures(position_error_mm=float(truth.position_error_mm), ci95_mm=float(result.ci95_mm))


def caption_figures(page_text: str) -> tuple[float, bool, float]:
    """(position error, inside?, 95 % radius) as the caption states them."""
    m = CAPTION.search(page_text)
    if m is None:
        raise ValueError("the page has no caption 'the TCP is X mm from the true one, inside its 95 % radius "
                         "of Y mm'")
    return float(m["error"]), m["inside"] == "inside", float(m["ci95"])


def update_caption(page_text: str, figures: CaptionFigures) -> str:
    """The page's text with the caption's numbers set to ``figures`` (2 decimals)."""
    caption_figures(page_text)                     # raises when the caption is missing

    def fill(m: re.Match[str]) -> str:
        where = "inside" if figures.inside else "outside"
        gap = m.group(0)[m.end("error") - m.start(0):m.start("inside") - m.start(0)]
        return (f"the TCP is {figures.position_error_mm:.2f}{gap}{where} its 95 % radius of "
                f"{figures.ci95_mm:.2f} mm")

    return CAPTION.sub(fill, page_text, count=1)


# ------------------------------------------------------------------ the browser run
def fill(page: Any, label: str, text: str) -> None:
    row = page.locator(".mantine-Flex-root").filter(has=page.locator(f"label:text-is('{label}')"))
    box = row.locator("input").last
    box.click()
    box.press("Control+a")
    box.press_sequentially(text)
    box.press("Enter")


def _only_session(app: Any) -> Any:
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        sessions = app.all_sessions()
        if len(sessions) == 1 and "calibrate" in sessions[0].views:
            return sessions[0]
        time.sleep(0.1)
    raise SystemExit("no pendant session appeared for the browser")


def _close_notifications(page: Any) -> None:
    for close in page.locator(".mantine-Notification-closeButton").all():
        close.click()                                # e.g. "software WebGL" (no GPU here)


def shoot_pendant(page: Any, url: str, out: Path) -> None:
    """``pendant.png``: the page as a trainee first sees it."""
    page.goto(url)
    page.get_by_text("Distance to reference tip").first.wait_for()
    _close_notifications(page)
    page.wait_for_timeout(3000)                      # software WebGL: let the last frame render
    page.screenshot(path=str(out))


def shoot_xyz4(page: Any, url: str, app: Any, out: Path) -> CaptionFigures:
    """``xyz4_result.png``: the seeded 6-touch calibration; returns the session's figures."""
    page.goto(url)
    session = _only_session(app)
    view = session.views["calibrate"]                # the server runs with --seed SEED
    page.get_by_role("button", name="Close-up on reference tip").click()
    page.get_by_role("tab", name="Calibrate").click()
    fill(page, "Touches", str(N_TOUCHES))
    page.wait_for_timeout(300)                       # let the throttled slider update go out
    page.get_by_role("button", name="Start", exact=True).click()
    page.get_by_text(f"Step 1 of {N_TOUCHES}").filter(visible=True).first.wait_for()
    fill(page, "Operator error σ (mm)", f"{SIGMA_MM}")
    for k in range(1, N_TOUCHES + 1):
        page.get_by_text(f"Step {k} of {N_TOUCHES}").filter(visible=True).first.wait_for()
        page.get_by_role("button", name="Auto-touch").click()
        if k < N_TOUCHES:
            page.get_by_text(f"Step {k + 1} of {N_TOUCHES}").filter(visible=True).first.wait_for()
    page.get_by_text("Against the true TOOL frame").wait_for()
    figures = _figures(view.workflow)
    shown = page.get_by_text("Position error of the TCP").first.inner_text()
    if f"{figures.position_error_mm:.3f}" not in shown:
        raise SystemExit(f"the page shows {shown!r}, the session computed {figures}")
    tcp_line = page.get_by_text(re.compile(r"^TCP X ")).first
    tcp_line.evaluate("e => e.scrollIntoView({block: 'start'})")   # the result on top
    _close_notifications(page)
    page.wait_for_timeout(3000)
    page.screenshot(path=str(out))
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=ROOT / "docs" / "images")
    parser.add_argument("--page", type=Path, default=ROOT / "docs" / "trainer.md",
                        help="the page whose caption gets the numbers (default: docs/trainer.md)")
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    from tcp_pendant.serve.server import AppConfig, PendantApp

    expected = seeded_figures()
    args.out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        app = PendantApp(AppConfig(port=0, tool_library=Path(tmp) / "tools.json", seed=SEED))
        url = app.start()
        try:
            with urllib.request.urlopen(url, timeout=30):
                pass
            with sync_playwright() as pw:
                browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
                for name in ("pendant", "xyz4_result"):
                    page = browser.new_page(viewport={"width": 1400, "height": 900})
                    page.set_default_timeout(TIMEOUT_MS)
                    out = args.out_dir / f"{name}.png"
                    if name == "pendant":
                        shoot_pendant(page, url, out)
                    else:
                        figures = shoot_xyz4(page, url, app, out)
                    page.close()
                    print(f"wrote {out}")
                browser.close()
        finally:
            app.stop()
    if figures != expected:
        raise SystemExit(f"the browser run gave {figures}, the seeded run without a browser {expected}")
    text = args.page.read_text(encoding="utf-8")
    args.page.write_text(update_caption(text, figures), encoding="utf-8")
    print(f"caption in {args.page}: TCP {figures.position_error_mm:.2f} mm from the true one, "
          f"95 % radius {figures.ci95_mm:.2f} mm")


if __name__ == "__main__":
    main()
