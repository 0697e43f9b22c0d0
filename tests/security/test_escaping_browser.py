"""In a browser: what users type is shown as text, never run (chromium + viser).

viser's markdown passes raw HTML through unsanitised, so the harm of an unescaped name is in
the browser: a ``<style>`` restyles the page (computed opacity), an image fetches a URL (a
local HTTP listener counts the requests), a link becomes an ``<a href>``, an ``<iframe
srcdoc>`` runs script (``document.title``). Each test first shows the harm is real with the
raw text (a control), then that the app / the escaping helper prevents it.

Software WebGL is slow here: every wait is on a condition with a generous timeout.
"""

from __future__ import annotations

import http.server
import json
import re
import socket
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import viser
from support.chromium_session import with_render_scale
from support.pendant_page import TIMEOUT_MS, choose, type_text, wait_text
from tcp_pendant.calibrate import AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.text_escape import WORD_JOINER, escape_markdown
from tcp_pendant.wizards.session_record import dumps

from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

from support.calib_helpers import library_tool_with_true_tcp, make_controller

pytestmark = pytest.mark.browser

STYLE = "<style>*{opacity:0}"
LINK = "[click](//evil)"
IFRAME = """<iframe srcdoc="<img src=x onerror=parent.document.title='pwned'>">.json"""


class Listener:
    """A tiny HTTP server on 127.0.0.1 that records every path requested from it."""

    def __init__(self) -> None:
        paths = self.paths = []  # type: list[str]

        class Handler(http.server.BaseHTTPRequestHandler):
            def do_GET(self) -> None:  # noqa: N802 (http.server's name)
                paths.append(self.path)
                self.send_response(204)
                self.end_headers()

            def log_message(self, *args: Any) -> None:
                pass

        self.server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.port = int(self.server.server_address[1])
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def image_name(self, path: str = "") -> str:
        """``![](//127.0.0.1:PORT/path)``: 22 characters for an empty path, a valid tool name."""
        return f"![](//127.0.0.1:{self.port}{'/' + path if path else ''})"

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


@pytest.fixture
def listener() -> Iterator[Listener]:
    lst = Listener()
    yield lst
    lst.close()


def page_state(page: Any) -> dict[str, Any]:
    """What an injected markup would change: title, opacities, links, images, iframes."""
    return page.evaluate("""() => ({
        title: document.title,
        bodyOpacity: getComputedStyle(document.body).opacity,
        buttonOpacities: [...new Set([...document.querySelectorAll('button')].map(b => getComputedStyle(b).opacity))],
        hrefs: [...document.querySelectorAll('a[href]')].map(a => a.getAttribute('href')),
        imgs: [...document.querySelectorAll('img[src]')].map(i => i.getAttribute('src')),
        iframes: document.querySelectorAll('iframe').length,
        userStyles: [...document.querySelectorAll('style')].filter(s => s.textContent.includes('*{opacity:0}')).length,
        text: document.body.innerText,
    })""")


def wait_js(page: Any, predicate_js: str, what: str) -> None:
    try:
        page.wait_for_function(predicate_js, timeout=TIMEOUT_MS)
    except Exception as exc:
        raise AssertionError(f"never saw {what}") from exc


def visible_text(page: Any) -> str:
    return page_state(page)["text"].replace(WORD_JOINER, "")


def assert_harmless(state: dict[str, Any], title: str, listener: Listener) -> None:
    assert state["title"] == title
    # enabled buttons are drawn at opacity 1, disabled ones (Record before a touch, ...) at 0.6 by
    # viser's theme; the injected style would make every one 0
    assert state["bodyOpacity"] == "1" and "1" in state["buttonOpacities"], state
    assert set(state["buttonOpacities"]) <= {"1", "0.6"}, state
    assert state["userStyles"] == 0
    assert not [h for h in state["hrefs"] if "evil" in h or "127.0.0.1" in h], state["hrefs"]
    assert not [s for s in state["imgs"] if "127.0.0.1" in s or s == "x"], state["imgs"]
    assert state["iframes"] == 0
    assert listener.paths == []


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _squash(text: str) -> str:
    """Text as a browser lays it out: runs of blanks and line breaks shown as one space."""
    return re.sub(r"\s+", " ", text)


# ---------------------------------------------------------------------------------------------
@pytest.fixture
def bare_viser(browser: Any) -> Iterator[Callable[[], tuple[viser.ViserServer, Any]]]:
    """A bare viser server in this process and a chromium page on it (no pendant app)."""
    made: list[tuple[viser.ViserServer, Any]] = []

    def make() -> tuple[viser.ViserServer, Any]:
        srv = viser.ViserServer(host="127.0.0.1", port=_free_port(), verbose=False)
        ctx = browser.new_context(viewport={"width": 1000, "height": 800})
        page = ctx.new_page()
        page.set_default_timeout(TIMEOUT_MS)
        made.append((srv, ctx))
        page.goto(with_render_scale(f"http://127.0.0.1:{srv.get_port()}"))
        srv.gui.add_button("Ready")
        page.get_by_role("button", name="Ready").wait_for(state="visible", timeout=TIMEOUT_MS)
        return srv, page

    yield make
    for srv, ctx in made:
        ctx.close()
        srv.stop()


def test_raw_text_in_viser_markdown_does_harm_the_control(bare_viser, listener) -> None:
    """Why escaping is needed: viser renders these raw payloads as live HTML/markdown."""
    srv, page = bare_viser()
    srv.gui.add_markdown(f"{LINK} and {listener.image_name('control')}")
    srv.gui.add_markdown(f"Loaded {IFRAME}")
    wait_js(page, "() => document.title === 'pwned'", "the iframe's script change the title")
    wait_js(page, "() => !!document.querySelector('a[href=\"//evil\"]')", "a live link")
    wait_js(page, "() => document.querySelectorAll('iframe').length > 0", "an iframe")
    srv.gui.add_markdown(STYLE)
    wait_js(page, "() => getComputedStyle(document.querySelector('button')).opacity === '0'", "buttons at opacity 0")
    deadline_ms = TIMEOUT_MS
    while "/control" not in listener.paths and deadline_ms > 0:
        page.wait_for_timeout(100)
        deadline_ms -= 100
    assert "/control" in listener.paths                      # the image was fetched


PAYLOADS = [STYLE, LINK, IFRAME, "<img src=x onerror=document.title='pwned'>", "<script>document.title='pwned'</script>",
            "**bold** _em_ `code` ~~del~~", "# heading", "- item", "1. item", "> quote", "a | b",
            "www.evil.example http://evil.example/x me@evil.example", "&lt;b&gt; &#60;i&#62;", "back\\slash",
            "two\nlines", "[ref]: //evil", "    indented", "---", "## h2"]


def test_escaped_payloads_render_as_their_literal_text_in_viser(bare_viser, listener, shot) -> None:
    """escape_markdown's output, in paragraphs, bold spans and table cells, through viser's own
    renderer: each shows exactly its text, and nothing is styled, fetched, linked or run."""
    srv, page = bare_viser()
    title = page.title()
    payloads = [*PAYLOADS, listener.image_name("x")]
    for i, p in enumerate(payloads):
        srv.gui.add_markdown(f"M{i}: {escape_markdown(p)} :E{i}")
        srv.gui.add_markdown(f"**B{i}: {escape_markdown(p)}**")
        srv.gui.add_markdown(escape_markdown(p))             # alone: at the start of a line
    srv.gui.add_markdown("| name | slot |\n|---|---|\n" + "\n".join(f"| T{i}: {escape_markdown(p)} | {i} |"
                                                                 for i, p in enumerate(payloads)))
    last = len(payloads) - 1
    wait_js(page, f"() => document.body.innerText.includes(':E{last}')", "the last paragraph")
    wait_js(page, f"() => document.body.innerText.includes('T{last}: ')", "the table")
    text = _squash(visible_text(page))
    for i, p in enumerate(payloads):
        shown = _squash(p).strip()
        assert f"M{i}: {shown} :E{i}" in text, (p, text)
        assert f"B{i}: {shown}" in text, p
        assert f"T{i}: {shown}" in text, p
    cells = page.locator("table td").all_inner_texts()
    assert len(cells) == 2 * len(payloads)                  # no pipe split a row
    # the elements holding the payloads: a paragraph (or cell), a <strong> for the bold ones, nothing else
    inner_tags = page.evaluate("""() => [...document.querySelectorAll('p, td')]
        .filter(e => /^(M|B|T)\\d+: /.test(e.innerText))
        .flatMap(e => [...e.querySelectorAll('*')].map(c => c.tagName.toLowerCase()))""")
    assert set(inner_tags) <= {"strong"}, inner_tags
    assert page.locator("h1, h2, li, blockquote, pre, hr").count() == 0   # no block starts either
    page.wait_for_load_state("networkidle")
    assert_harmless(page_state(page), title, listener)
    shot(page, "escaped_payloads")


# ---------------------------------------------------------------------------------------------
def seed_hostile_library(path: Path, listener: Listener) -> dict[int, str]:
    """The shared library as a trainee could leave it: hostile names, the style one active (the
    file's active slot: the CLI's and --shared mode's start tool)."""
    names = {1: STYLE, 2: LINK, 3: listener.image_name()}
    lib = ToolLibrary(path)
    for slot, name in names.items():
        lib.save(slot, Tool(name=name, tcp_mm=(0.0, 0.0, 100.0 + slot)), activate=slot == 1)
    return names


def test_hostile_tool_names_are_shown_as_text_in_the_pendant(pendant_server, new_page, shot, tmp_path,
                                                             listener) -> None:
    names = seed_hostile_library(tmp_path / "tools.json", listener)
    server = pendant_server()
    page = new_page(server.url)
    title = page.title()
    # a browser's robot starts with no active tool: activate the style one on the Tool tab
    wait_js(page, "() => document.body.innerText.includes('Active tool data: none (FLANGE)')", "no active tool")
    page.get_by_role("tab", name="Tool").click()
    choose(page, "Slot", f"1: {STYLE}")
    page.get_by_role("button", name="Activate", exact=True).click()
    wait_text(page, f"Active tool: {STYLE} (slot 1)")
    # Jog tab: the TCP readout names the active tool
    page.get_by_role("tab", name="Jog").click()
    wait_js(page, "() => document.body.innerText.includes('TOOL <style>*{opacity:0}')", "the active tool's name as text")
    assert_harmless(page_state(page), title, listener)

    page.get_by_role("tab", name="Tool").click()
    for slot in (2, 3):
        choose(page, "Slot", f"{slot}: {names[slot]}")
        wait_text(page, f"Selected: {names[slot]} (slot {slot})")
    page.get_by_role("button", name="Activate", exact=True).click()   # slot 3: the image one
    wait_text(page, f"Active tool: {names[3]} (slot 3)")
    wait_text(page, "Tool activated")                          # the notification: plain text in viser,
    assert f"3: {names[3]}" in visible_text(page)              # so shown as is (not escaped twice)
    page.wait_for_load_state("networkidle")
    assert_harmless(page_state(page), title, listener)
    png = shot(page, "hostile_tool_names")
    assert png.exists()

    # a new browser starts with no active tool, whatever the first one activated; it activates
    # the style one itself
    fresh = new_page(server.url)
    wait_js(fresh, "() => document.body.innerText.includes('Active tool data: none (FLANGE)')", "no active tool")
    fresh.get_by_role("tab", name="Tool").click()
    choose(fresh, "Slot", f"2: {names[2]}")
    choose(fresh, "Slot", f"1: {STYLE}")
    fresh.get_by_role("button", name="Activate", exact=True).click()
    wait_text(fresh, f"Active tool: {STYLE} (slot 1)")
    fresh.get_by_role("tab", name="Jog").click()
    wait_js(fresh, "() => document.body.innerText.includes('TOOL <style>*{opacity:0}')", "the active tool's name")
    fresh.wait_for_load_state("networkidle")
    assert_harmless(page_state(fresh), title, listener)


def _record_with_hostile_tool(tmp_path: Path) -> bytes:
    """A session record whose three-point run belongs to a library tool named ``STYLE`` (no
    calibration record, so its warning quotes the name)."""
    lib = ToolLibrary(tmp_path / "trainee_tools.json")
    lib.save(1, library_tool_with_true_tcp("pointer", STYLE))
    wf = CalibrationWorkflow(make_controller("kr6", "pointer"), lib, robot="kr6", rng=np.random.default_rng(3))
    wf.start("three-point", slot=1)
    while wf.result is None:
        assert wf.auto_touch(AutoTouchRequest(sigma_mm=0.0)).ok
    assert any(STYLE in w for w in wf.result.warnings)       # the name reaches the result's words
    return dumps(wf.export_record()).encode()


def test_uploaded_record_with_hostile_names_runs_nothing(server, new_page, shot, tmp_path, listener) -> None:
    record = _record_with_hostile_tool(tmp_path)
    assert STYLE in json.loads(record)["wizards"][0]["state"]["params"]["tool"]["name"]
    page = new_page(server.url)
    title = page.title()
    page.get_by_role("tab", name="Calibrate").click()
    page.get_by_text("Session record", exact=True).click()
    page.locator("input[type=file]").set_input_files({"name": IFRAME, "mimeType": "application/json",
                                                       "buffer": record})
    wait_text(page, "replayed result matches the record")
    text = visible_text(page)
    assert f"Loaded {IFRAME}" in text                          # the file name, literally
    assert f"The TCP of '{STYLE}' has no calibration record" in text   # the record's tool name
    page.wait_for_load_state("networkidle")
    assert_harmless(page_state(page), title, listener)
    assert page.title() == title and "pwned" not in page.title()
    shot(page, "hostile_record")


def test_typed_names_echo_as_text(server, new_page, listener) -> None:
    """The numeric entry's name field echoes what is typed, before any validation."""
    page = new_page(server.url)
    title = page.title()
    page.get_by_role("tab", name="Tool").click()
    page.get_by_text("Enter tool numerically", exact=True).click()
    typed = f"{LINK} {listener.image_name('typed')} <b>x</b>"
    type_text(page, "Name", typed, echo=re.compile(re.escape(typed.replace("\n", " "))))
    page.wait_for_load_state("networkidle")
    assert_harmless(page_state(page), title, listener)
