"""A class in real browsers (issue 11): two named trainees with mystery tools and the trainer
view (Playwright, three contexts: each its own viser client)."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from pendant_page import TIMEOUT_MS, assert_not_blank, press, type_text, wait_enabled, wait_text  # noqa: E402

pytestmark = pytest.mark.browser

TOKEN = "trainer-secret-42"


def join(page, name: str) -> None:
    welcome = page.get_by_text("Welcome to the TCP Pendant")
    welcome.wait_for(state="visible", timeout=TIMEOUT_MS)
    type_text(page, "Your name", name)
    page.wait_for_timeout(300)             # viser's 50 ms message slot: the name reaches the server first
    press(page, "Join the class")
    welcome.wait_for(state="hidden", timeout=TIMEOUT_MS)
    wait_text(page, f"Trainee: {name}")


def test_two_trainees_and_the_trainer_view(pendant_server, new_page, shot, tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    sp = pendant_server("--class-db", str(db), "--trainer-token", TOKEN, "--exercise", "mystery",
                        "--exercise-seed", "3")
    anna = new_page(sp.url)
    ben = new_page(sp.url)
    trainer = new_page(sp.url)
    assert_not_blank(shot(anna, "classroom_name_prompt"), min_colors=50)
    join(anna, "Anna <b>A</b>")
    join(ben, "Ben")
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
    wait_text(trainer, re.compile(r"^-?\d+\.\d, -?\d+\.\d, -?\d+\.\d$"))
    anna.get_by_role("button", name="Save to tool library").filter(visible=True).first.wait_for(timeout=TIMEOUT_MS)
    # an exercise: the trainee sees no truth (the trainer's gradebook has it)
    assert anna.get_by_text("Against the true TOOL frame").filter(visible=True).count() == 0
    shot(anna, "classroom_trainee_result")
    png = shot(trainer, "classroom_trainer_view")
    assert_not_blank(png, min_colors=50)
    from tcp_pendant.classroom.gradebook import Gradebook

    with Gradebook(db, create=False) as book:
        rows = book.grades()
    assert [r.trainee for r in rows] == ["Anna <b>A</b>"]
    assert rows[0].exercise_id == "mystery" and rows[0].tool_key.startswith("mystery-") and rows[0].auto == 4
