"""A class in real browsers: two named trainees with mystery tools and the trainer
dashboard (Playwright, three contexts: each its own viser client); the browser key the page script
keeps in localStorage, across a reload and a server restart."""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest

from support.pendant_page import (
    BROWSER_KEY_JS,
    TIMEOUT_MS,
    assert_not_blank,
    join_class,
    press,
    type_text,
    wait_enabled,
    wait_text,
)

pytestmark = pytest.mark.browser

TOKEN = "trainer-secret-4242"


def test_two_trainees_and_the_trainer_view(pendant_server, new_page, shot, tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    sp = pendant_server("--class-db", str(db), "--trainer-token", TOKEN, "--exercise", "mystery",
                        "--exercise-seed", "3")
    anna = new_page(sp.url)
    ben = new_page(sp.url)
    trainer = new_page(sp.url.rstrip("/") + "/?trainer")   # the trainer's page: its welcome window has the token row
    assert_not_blank(shot(anna, "classroom_name_prompt"), min_colors=50)
    join_class(anna, "Anna <b>A</b>")
    join_class(ben, "Ben")
    # the trainer: a wrong token opens nothing, the right one opens the trainer view
    type_text(trainer, "Trainer token", "wrong-token")
    trainer.wait_for_timeout(300)
    press(trainer, "Open trainer view")
    wait_text(trainer, "That trainer token is not right")
    type_text(trainer, "Trainer token", TOKEN)
    trainer.wait_for_timeout(300)
    press(trainer, "Open trainer view")
    trainer.get_by_text("Welcome to the TCP Pendant").wait_for(state="hidden", timeout=TIMEOUT_MS)
    wait_text(trainer, "Download grades (CSV)")
    wait_text(trainer, "Anna <b>A</b>")        # shown literally: escaped, not HTML
    wait_text(trainer, "Ben")
    # Auto-touch is off in an exercise unless the trainer allows it (by its label: viser breaks
    # "Auto-<wbr>touch", which pendant_page.field's exact label text does not match)
    trainer.get_by_label("Auto-touch for all").first.click()
    trainer.get_by_role("option", name="allowed", exact=True).click()
    press(trainer, "Push to all trainees")
    wait_text(trainer, "Auto-touch allowed")
    # Anna calibrates her mystery tool with Auto-touch; the trainer's table follows
    anna.get_by_role("tab", name="Calibrate").click()
    wait_enabled(anna, "Start")
    press(anna, "Start")
    for k in range(1, 5):      # visible text only: the Jog tab's wizard dock repeats it, hidden
        anna.get_by_text(f"Step {k} of 4").filter(visible=True).first.wait_for(timeout=TIMEOUT_MS)
        anna.get_by_role("button", name="Auto-touch", exact=True).filter(visible=True).first.click()
    trainer.locator(".tcp-dashboard-trainees td", has_text=re.compile(r"^(good|fair|poor)$")).first.wait_for(
        timeout=TIMEOUT_MS)                    # Anna's grade in the dashboard's table
    anna.get_by_role("button", name="Save to tool library").filter(visible=True).first.wait_for(timeout=TIMEOUT_MS)
    # an exercise: the trainee sees no truth (the trainer's gradebook has it)
    assert anna.get_by_text("Against the true TOOL frame").filter(visible=True).count() == 0
    shot(anna, "classroom_trainee_result")
    png = shot(trainer, "classroom_trainer_view")
    assert_not_blank(png, min_colors=50)
    from tcp_pendant.classroom.gradebook import Gradebook

    with Gradebook(db, create=False) as book:
        rows = book.grades.rows()
    assert [r.trainee for r in rows] == ["Anna <b>A</b>"]
    assert rows[0].exercise_id == "mystery" and rows[0].tool_key.startswith("mystery-") and rows[0].auto == 4


def _wait(cond, what: str, timeout: float = 30.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = cond()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def test_the_browser_key_is_kept_in_local_storage_across_a_reload_and_a_restart(app_factory, new_page, tmp_path: Path) -> None:
    """Anna's browser gets a key when she joins (the page script keeps it; the server keeps its
    SHA-256 only), another browser cannot be Anna while she is connected, and after a reload
    and after a server restart on the same gradebook her page joins by itself as Anna: the
    script sends the key back. The server runs in this process (the same port after the
    restart: localStorage belongs to the page's origin)."""
    from tcp_pendant.serve.server import PendantApp

    db = tmp_path / "class.sqlite3"

    def start(port: int = 0) -> PendantApp:
        return app_factory(port=port, class_db=db, trainer_token=TOKEN, exercise="mystery")

    app = start()
    anna = new_page(app.url)
    join_class(anna, "Anna")
    anna.wait_for_function(f"/^[A-Za-z0-9_-]{{43}}$/.test({BROWSER_KEY_JS} || '')", timeout=TIMEOUT_MS)
    key = anna.evaluate(BROWSER_KEY_JS)
    assert app.gradebook.trainees.holds_key("Anna", key)
    tool_key = next(s for s in app.sessions.values() if "identity" in s.views
                    and s.views["identity"].name == "Anna").controller.mounted_tool.key
    # another browser: refused in words while Anna is connected; it has no key in its storage
    other = new_page(app.url)
    other.get_by_text("Welcome to the TCP Pendant").wait_for(state="visible", timeout=TIMEOUT_MS)
    assert other.get_by_label("Browser key").count() == 0 or not other.get_by_label("Browser key").first.is_visible()
    type_text(other, "Your name", "Anna")
    other.wait_for_timeout(300)
    press(other, "Join the class")
    wait_text(other, "Anna is already connected in another browser; pick another name or ask the trainer "
                     "to release it")
    assert other.evaluate(BROWSER_KEY_JS) is None
    # a reload: the page joins by itself with the name and the key
    anna.reload()
    wait_text(anna, "Trainee: Anna")
    anna.get_by_text("Welcome to the TCP Pendant").wait_for(state="hidden", timeout=TIMEOUT_MS)
    assert anna.evaluate(BROWSER_KEY_JS) == key
    # a server restart on the same gradebook and port: the same browser is Anna again
    port = app.port
    app.stop()
    app = start(port)
    anna.reload()
    wait_text(anna, "Trainee: Anna")
    anna.get_by_text("Welcome to the TCP Pendant").wait_for(state="hidden", timeout=TIMEOUT_MS)
    named = _wait(lambda: [s for s in app.sessions.values() if "identity" in s.views
                           and s.views["identity"].name == "Anna"], "Anna named after the restart")
    assert named[0].controller.mounted_tool.key == tool_key          # the class's seed survived
    with app.gradebook.store.read() as book:
        assert book.execute("SELECT COUNT(*) FROM trainees").fetchone()[0] == 1
        assert book.execute("SELECT COUNT(*) FROM sessions").fetchone()[0] == 3


def test_the_exercise_banner_is_on_screen_at_1024x768_without_scrolling(pendant_server, new_page, shot,
                                                                         tmp_path: Path) -> None:
    """The instructions given at start (``--exercise-instructions``) are the first thing of the
    trainee's panel: in view on a 1024x768 screen as soon as the trainee joined, shown literally."""
    text = "Calibrate the pointer <b>now</b>: 6 touches from all sides."
    sp = pendant_server("--class-db", str(tmp_path / "class.sqlite3"), "--trainer-token", TOKEN,
                        "--exercise-instructions", text, "--exercise-methods", "xyz4,reference",
                        "--exercise-min-touches", "6")
    anna = new_page(sp.url, width=1024, height=768)
    join_class(anna, "Anna")
    banner = anna.get_by_text(text, exact=True)
    banner.wait_for(state="visible", timeout=TIMEOUT_MS)
    box = banner.bounding_box()
    assert box is not None and box["y"] >= 0 and box["y"] + box["height"] <= 768 and box["x"] + box["width"] <= 1024
    # nothing covers it: the element at its centre is the banner's own text
    hit = anna.evaluate("([x, y]) => document.elementFromPoint(x, y)?.textContent || ''",
                        [box["x"] + box["width"] / 2, box["y"] + box["height"] / 2])
    assert text in hit
    shot(anna, "classroom_exercise_banner_1024x768")
