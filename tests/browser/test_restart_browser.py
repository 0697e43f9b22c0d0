"""A class server killed mid-calibration (SIGKILL, no shutdown of any kind) and started again
on the same gradebook and port: the trainee's chromium page, reloaded, joins by itself, finds
its wizard at the same step with its touches and the trainer's "Hide distance: on, locked" still
in force; the trainer view and ``tcp-pendant grades`` list the calibration in progress.

The server is the real program (``python -m tcp_pendant --class --class-db ...
--trainer-token-file ...``); the trainer is a raw viser websocket that types its token and
pushes settings the way its browser would, and reads the texts the server sends it (not the
trainer view's layout)."""

from __future__ import annotations

import csv
import io
import re
import subprocess
import sys
from pathlib import Path

import pytest

from support.pendant_page import BROWSER_KEY_JS, TIMEOUT_MS, join_class, press, wait_enabled, wait_text
from support.trainer_socket import TrainerSocket
from support.wsclient import wait_until

pytestmark = pytest.mark.browser

TOKEN = "trainer-restart-token-2026"


def _grades(db: Path) -> list[dict[str, str]]:
    out = subprocess.run([sys.executable, "-m", "tcp_pendant", "grades", "--class-db", str(db), "--csv"],
                         capture_output=True, text=True, timeout=60, check=True).stdout
    return list(csv.DictReader(io.StringIO(out)))


def _in_progress(db: Path) -> list[tuple[str, int, str]]:
    """(trainee, touches, status) of the gradebook's calibrations, read while the server runs."""
    from tcp_pendant.classroom.gradebook import Gradebook

    with Gradebook(db, create=False) as book:
        return [(r.trainee, r.touches, r.status) for r in book.grades.rows(include_in_progress=True)]


LOCKED_JS = """() => { const b = [...document.querySelectorAll('input[type=checkbox]')]
    .find(e => e.closest('.mantine-Flex-root')?.innerText.includes('Hide distance'));
    return !!(b && b.checked && b.disabled); }"""
"""The "Hide distance" checkbox is ticked and cannot be changed (the trainer's lock)."""


def test_a_killed_server_gives_the_trainees_calibration_back(pendant_server, new_page, shot, tmp_path: Path) -> None:
    db, token_file = tmp_path / "class.sqlite3", tmp_path / "trainer-token.txt"
    token_file.write_text(TOKEN + "\n", encoding="utf-8")
    args = ("--class", "--class-db", str(db), "--trainer-token-file", str(token_file))
    sp = pendant_server(*args)
    anna = new_page(sp.url, width=1100, height=760)      # fewer pixels for software WebGL
    join_class(anna, "Anna")
    anna.wait_for_function(f"/^[A-Za-z0-9_-]{{43}}$/.test({BROWSER_KEY_JS} || '')", timeout=TIMEOUT_MS)
    # the trainer pushes "Hide distance: on, locked"
    trainer = TrainerSocket(sp.port, TOKEN)
    try:
        trainer.open_trainer_view()
        trainer.send_value("Hide distance for all", "on, locked")
        trainer.send_value("Push to all trainees", True)
        wait_until(lambda: trainer.text_with(r"[Pp]ushed") is not None, what="the push acknowledged")
    finally:
        trainer.close()
    anna.wait_for_function(LOCKED_JS, timeout=TIMEOUT_MS)
    # an XYZ 4-point with two touches by hand (Record at once: the distance is hidden)
    anna.get_by_role("tab", name="Calibrate").click()
    wait_enabled(anna, "Start")
    press(anna, "Start")
    for k in (1, 2):                       # Record right away: the distance is hidden, no pose check
        anna.get_by_text(f"Step {k} of 4").filter(visible=True).first.wait_for(timeout=TIMEOUT_MS)
        anna.get_by_role("button", name="Record", exact=True).filter(visible=True).first.click()
        wait_enabled(anna, "Next")
        anna.get_by_role("button", name="Next", exact=True).filter(visible=True).first.click()
    anna.get_by_text("Step 3 of 4").filter(visible=True).first.wait_for(timeout=TIMEOUT_MS)
    assert _in_progress(db) == [("Anna", 2, "in_progress")]    # written before the screen showed it
    # SIGKILL in the middle of the calibration, then the same program on the same files and port
    port = sp.port
    sp.proc.kill()
    assert sp.proc.wait(10) == -9
    again = pendant_server(*args, port=port)
    anna.reload()
    try:
        wait_text(anna, "Trainee: Anna")                    # the page script joined by itself
    except AssertionError:
        shot(anna, "restart_not_joined")
        print("page script:", anna.evaluate("document.documentElement.getAttribute('data-tcp-pendant-script')"),
              "kept:", anna.evaluate(BROWSER_KEY_JS), "\nserver log:", again.log())
        raise
    anna.get_by_text("Welcome to the TCP Pendant").wait_for(state="hidden", timeout=TIMEOUT_MS)
    anna.get_by_role("tab", name="Calibrate").click()
    anna.get_by_text("Step 3 of 4").filter(visible=True).first.wait_for(timeout=TIMEOUT_MS)
    wait_text(anna, re.compile(r"✔ Touch 1\s+✔ Touch 2\s+▶ Touch 3"))  # the step list: two touches done
    wait_text(anna, "2 touches recorded")                         # the math panel
    shot(anna, "restart_restored_calibrate")
    anna.get_by_role("tab", name="Jog").click()
    wait_text(anna, "hidden (judge by eye)")
    assert anna.evaluate(LOCKED_JS), "Hide distance is not on and locked after the restart"
    shot(anna, "restart_restored_jog")
    # the trainer's view lists the calibration in progress; so does `tcp-pendant grades`
    trainer = TrainerSocket(again.port, TOKEN)
    try:
        trainer.open_trainer_view()
        try:
            wait_until(lambda: trainer.text_with(r"(?s)Anna.*XYZ.*3/4") is not None,
                       what="Anna's calibration in progress in the trainer view")
        except AssertionError:
            print("the trainer's texts naming Anna:", trainer.text_with("Anna"))
            raise
    finally:
        trainer.close()
    rows = _grades(db)
    assert [(r["trainee"], r["method"], r["touches"], r["status"]) for r in rows] == [
        ("Anna", "xyz4", "2", "in_progress")]
