"""A trainer's words are seen (``tcp-pendant --class``, Debian's chromium at 1024x768): ben has
scrolled down into the XYZ 4-point wizard on the Calibrate tab when the trainer's message comes;
a toast shows it and the message box is pinned at the top of the panel, in view and not covered,
on that tab and on the Jog tab. A "Push to this trainee" tells ben what it changed, in words.
The trainer is a raw viser websocket typing into its view as its browser would."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from support.pendant_page import TIMEOUT_MS, join_class, press, wait_enabled
from support.trainer_socket import TrainerSocket
from support.wsclient import wait_until

pytestmark = pytest.mark.browser

TOKEN = "trainer-message-token-2026"

IN_VIEW_JS = """(text) => {
    const marker = document.querySelector('.trainer-message'), el = marker && marker.closest('.mantine-Paper-root');
    if (!el || !(el.innerText || '').includes(text)) return null;
    const box = el.getBoundingClientRect(), x = box.left + box.width / 2, y = box.top + Math.min(box.height / 2, 30);
    const hit = document.elementFromPoint(x, y);
    return {top: box.top, bottom: box.bottom, height: innerHeight, onTop: !!hit && el.contains(hit)};
}"""
"""The message's folder (the nearest box around its marker): where it is on screen, and whether
it is what shows near its top."""

SCROLLED_JS = """() => { const v = [...document.querySelectorAll('.mantine-ScrollArea-viewport')]
    .find(e => e.scrollHeight > e.clientHeight + 50); if (!v) return -1;
    v.scrollTop = v.scrollHeight; return v.scrollTop; }"""
"""Scroll the panel to its end (the wizard's last rows); how far it scrolled."""


def toast(page: Any, text: str) -> None:
    page.locator(".mantine-Notification-root").filter(has_text=text).first.wait_for(
        state="visible", timeout=TIMEOUT_MS)


def message_in_view(page: Any, text: str) -> None:
    def seen() -> bool:
        m = page.evaluate(IN_VIEW_JS, text)
        return bool(m and m["onTop"] and m["top"] >= 0 and m["top"] < m["height"] - 40)
    wait_until(seen, what=f"the message {text!r} in view, not covered")


def test_a_message_and_a_push_reach_a_trainee_scrolled_into_the_wizard(pendant_server, new_page, shot,
                                                                       tmp_path: Path) -> None:
    token_file = tmp_path / "trainer-token.txt"
    token_file.write_text(TOKEN + "\n", encoding="utf-8")
    sp = pendant_server("--class", "--class-db", str(tmp_path / "class.sqlite3"), "--trainer-token-file",
                        str(token_file))
    ben = new_page(sp.url, width=1024, height=768)
    join_class(ben, "ben")
    ben.get_by_role("tab", name="Calibrate").click()
    wait_enabled(ben, "Start")
    press(ben, "Start")
    ben.get_by_text("Step 1 of 4").filter(visible=True).first.wait_for(timeout=TIMEOUT_MS)
    assert ben.evaluate(SCROLLED_JS) > 200, "the panel did not scroll (nothing to hide the message)"
    trainer = TrainerSocket(sp.port, TOKEN)
    try:
        trainer.open_trainer_view()
        wait_until(lambda: "Send" in trainer.inputs, what="the trainer's message box")
        trainer.send_value("Message", "Ben, tilt the tool more between touches.")
        trainer.send_value("To", "ben")
        trainer.send_value("Send", True)
        toast(ben, "Ben, tilt the tool more between touches.")
        message_in_view(ben, "Ben, tilt the tool more between touches.")
        shot(ben, "message_on_calibrate_1024x768")
        ben.get_by_role("tab", name="Jog").click()
        message_in_view(ben, "Ben, tilt the tool more between touches.")
        # a push to ben alone: the trainee is told what changed
        trainer.send_value("Trainee", "ben")
        trainer.send_value("Hide distance for this trainee", "on, locked")
        trainer.send_value("Auto-touch for this trainee", "off")
        trainer.send_value("Push to this trainee", True)
        toast(ben, "Your trainer changed your pendant")
        toast(ben, "hidden, and locked by the trainer; Auto-touch is off")
        shot(ben, "push_told_1024x768")
    finally:
        trainer.close()
