"""Every page comes back by itself: a class server (the real ``tcp-pendant --class`` program) is
killed with SIGKILL and started again on the same port and gradebook, five times, while three
trainees' pages and the trainer's page stay open in chromium: chen's in a window without the
focus, ben's behind a slow link (a handshake takes 1.5 s; viser's own client gave each attempt
1 s, then closed it for the next). No page is reloaded: each one reconnects, joins again (the trainees under their names, the trainer with the token of its
address) and finds its calibration at its step with its touches.

The figures printed are the seconds from the new server answering HTTP to each page having
rejoined (the goal is 10 s; a benchmark's figure, not an assertion: the machine is shared).
"""

from __future__ import annotations

import re
import time
from pathlib import Path
from typing import Any

import pytest

from support.pendant_page import TIMEOUT_MS, join_class, press, wait_enabled, wait_text
from support.trainer_socket import TrainerSocket
from support.slow_link import SlowLink
from support.wsclient import free_port, wait_until

pytestmark = pytest.mark.browser

TOKEN = "trainer-reconnect-token-2026"
RESTARTS = 5
REJOIN_TIMEOUT_S = 90.0
"""How long the test waits for a page to rejoin before it fails (far above the 10 s goal: a
page that never rejoins, the fault this test is about, still fails)."""

SLOW_LINK_S = 1.5
"""ben's link: each connection's answer comes this late (a websocket handshake takes 1.5 s)."""

NO_FOCUS_JS = "Document.prototype.hasFocus = function () { return false; };"
"""A page whose window never has the focus (run before the page's own scripts)."""

MARK_JS = """() => { document.querySelectorAll('body *').forEach(e => e.setAttribute('data-old', '1'));
                     window.__notReloaded = true; }"""
"""Marks every element the page shows before the kill, and the page itself (a reload drops it)."""

FRESH_TEXT_JS = """([prefix]) => [...document.querySelectorAll('p, div, span, button')].some(e =>
    !e.hasAttribute('data-old') && e.children.length <= 2 && (e.textContent || '').trim().startsWith(prefix)
    && e.getClientRects().length > 0 && !e.closest('[style*="pointer-events: none"]'))"""
"""An element drawn after the kill (no mark) shows a text starting with ``prefix``, and viser does
not hold it frozen as disconnected (its GUI under a ``pointer-events: none`` wrapper)."""

CONNECTIONS_JS = "document.documentElement.getAttribute('data-tcp-pendant-connections')"
"""How many times the page script saw the page connect (None without the script's count)."""

WELCOME_JS = """() => [...document.querySelectorAll('.mantine-Modal-content')].some(e =>
    e.getClientRects().length > 0 && (e.textContent || '').includes('Welcome to the TCP Pendant'))"""


def _rejoined(page: Any, prefix: str) -> bool:
    return bool(page.evaluate(FRESH_TEXT_JS, [prefix])) and not page.evaluate(WELCOME_JS)


def _touch(page: Any, steps: int) -> None:
    """Start an XYZ 4-point and record ``steps`` touches at once (the distance is hidden)."""
    page.get_by_role("tab", name="Calibrate").click()
    wait_enabled(page, "Start")
    press(page, "Start")
    for k in range(1, steps + 1):
        page.get_by_text(f"Step {k} of 4").filter(visible=True).first.wait_for(timeout=TIMEOUT_MS)
        page.get_by_role("button", name="Record", exact=True).filter(visible=True).first.click()
        wait_enabled(page, "Next")
        page.get_by_role("button", name="Next", exact=True).filter(visible=True).first.click()
    page.get_by_text(f"Step {steps + 1} of 4").filter(visible=True).first.wait_for(timeout=TIMEOUT_MS)


def _at_step(page: Any, touches: int) -> None:
    """The Calibrate tab shows the calibration at step ``touches + 1`` with ``touches`` done."""
    page.get_by_role("tab", name="Calibrate").click()
    page.get_by_text(f"Step {touches + 1} of 4").filter(visible=True).first.wait_for(timeout=TIMEOUT_MS)
    done = r"\s+".join(f"✔ Touch {k}" for k in range(1, touches + 1))
    wait_text(page, re.compile(done + rf"\s+▶ Touch {touches + 1}"))
    page.get_by_role("tab", name="Jog").click()


def test_every_page_rejoins_after_five_kills(pendant_server, new_page, shot, tmp_path: Path) -> None:
    db, token_file = tmp_path / "class.sqlite3", tmp_path / "trainer-token.txt"
    token_file.write_text(TOKEN + "\n", encoding="utf-8")
    port = free_port()
    link = SlowLink(port, SLOW_LINK_S)          # ben's page is behind a slow link
    args = ("--class", "--class-db", str(db), "--trainer-token-file", str(token_file), "--allow-origin", link.url)
    sp = pendant_server(*args, port=port)
    trainer = TrainerSocket(sp.port, TOKEN)     # "Hide distance: on, locked": Record at once
    try:
        trainer.open_trainer_view()
        trainer.send_value("Hide distance for all", "on, locked")
        trainer.send_value("Push to all trainees", True)
        wait_until(lambda: trainer.text_with(r"[Pp]ushed") is not None, what="the push acknowledged")
    finally:
        trainer.close()
    # small windows: four software-WebGL pages share the machine. Playwright tells every page it
    # has the focus; chen's is told it has not (a window behind another, a projector's page):
    # viser's client asks for no new connection while its window has no focus
    trainees = {name: new_page(link.url if name == "ben" else sp.url, width=820, height=640,
                               init_script=NO_FOCUS_JS if name == "chen" else None)
                for name in ("ana", "ben", "chen")}
    for name, page in trainees.items():
        join_class(page, name)
    touches = {"ana": 2, "ben": 1, "chen": 0}
    for name, n in touches.items():
        if n:
            _touch(trainees[name], n)
    lecturer = new_page(f"{sp.url}/?trainer={TOKEN}", width=1024, height=768, wait_for="Push to all trainees")
    pages = {**{n: (p, f"Trainee: {n}") for n, p in trainees.items()}, "trainer": (lecturer, "Push to all trainees")}

    seconds, rejoined = [], 0
    for restart in range(1, RESTARTS + 1):
        for page, _ in pages.values():
            page.evaluate(MARK_JS)
        before = {name: page.evaluate(CONNECTIONS_JS) for name, (page, _) in pages.items()}
        sp.proc.kill()
        assert sp.proc.wait(10) == -9
        sp = pendant_server(*args, port=port)
        t0 = time.monotonic()
        waiting = dict(pages)
        deadline = t0 + REJOIN_TIMEOUT_S
        connected_at: dict[str, float] = {}      # when the page script saw the socket open (a figure only)
        while waiting and time.monotonic() < deadline:
            for name, (page, prefix) in list(waiting.items()):
                if name not in connected_at and page.evaluate(CONNECTIONS_JS) != before[name]:
                    connected_at[name] = time.monotonic() - t0
                if _rejoined(page, prefix):
                    seconds.append((restart, name, connected_at.get(name, float("nan")), time.monotonic() - t0))
                    del waiting[name]
            time.sleep(0.1)
        for name, (page, _) in waiting.items():
            shot(page, f"not_rejoined_{restart}_{name}")
        assert not waiting, (f"restart {restart}: {sorted(waiting)} did not rejoin in {REJOIN_TIMEOUT_S:.0f} s;"
                             f" server log:\n{sp.log()[-3000:]}")
        for name, (page, _) in pages.items():
            assert page.evaluate("window.__notReloaded === true"), f"{name}'s page was reloaded"
        for name, n in touches.items():
            if n:                                   # chen never started: nothing to find again
                _at_step(trainees[name], n)
            rejoined += 1
    link.close()
    shot(lecturer, "trainer_after_restarts")
    print("\nseconds from the new server's first HTTP answer (restart, page, socket open, rejoined):",
          *(f"{r} {n} {c:.1f} {s:.1f}" for r, n, c, s in seconds), sep="\n  ")
    print(f"trainee pages rejoined without a reload: {rejoined} of {RESTARTS * len(trainees)}")
    assert rejoined == RESTARTS * len(trainees)


def test_a_page_that_cannot_reach_the_server_says_so_and_offers_a_reload(pendant_server, new_page, shot,
                                                                        tmp_path: Path) -> None:
    args = ("--class", "--class-db", str(tmp_path / "class.sqlite3"))
    sp = pendant_server(*args)
    page = new_page(sp.url, width=1024, height=768)
    join_class(page, "dana")
    notice = page.get_by_role("alert").filter(has_text="cannot reach the pendant server")
    for cycle in (1, 2):
        sp.proc.kill()
        assert sp.proc.wait(10) == -9
        notice.wait_for(state="visible", timeout=TIMEOUT_MS)          # after 15 s without a connection
        assert "recorded touches are kept on the server" in notice.inner_text()
        reload = notice.get_by_role("button", name="Reload the page")
        if cycle == 2:          # the button reloads the page (its request is refused: the server is down)
            with page.expect_request(lambda r: r.is_navigation_request() and r.url.startswith(sp.url),
                                     timeout=TIMEOUT_MS):
                reload.click()
            break
        shot(page, "connection_lost_1024x768")
        page.evaluate("window.__notReloaded = true")
        sp = pendant_server(*args, port=sp.port)
        notice.wait_for(state="detached", timeout=TIMEOUT_MS)         # it kept trying: back by itself
        wait_text(page, "Trainee: dana")
        assert page.evaluate("window.__notReloaded === true")
