"""View by view: every markdown a view composes from user text holds no raw
``<`` and no live markdown (tool names from the shared library, names typed in the Save and
numeric-entry fields, a loaded record's file name and tool names, error messages quoting
input). In-process: a real pendant server and headless websocket clients, as tests/app and
tests/calibrate do; the browser tests (test_escaping_browser.py) check the rendered page.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.calibrate.text import (
    menu_markdown,
    replay_markdown,
    save_markdown,
    save_preview_markdown,
    step_markdown,
    steps_list_markdown,
    warnings_markdown,
)
from tcp_pendant.pendant.formatting import tcp_readout_markdown, tool_data_markdown
from tcp_pendant.pendant.tool_entry import ToolEntry, entry_preview_markdown
from tcp_pendant.serve.server import PendantApp
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.wizards import ThreePointWizard
from tcp_pendant.wizards.session_record import dumps, load_and_replay

from tcpcal.library import ToolLibrary
from tcpcal.tool import Calibration, Tool

from support.calib_helpers import library_tool_with_true_tcp, make_controller
from support.guiclick import choose, click, upload
from support.app_page import AppPage
from support.wsclient import wait_until

# valid tool names (<= 24 characters, no double quote) that would do harm as markdown
NAMES = ["<style>*{opacity:0}", "[click](//evil)", "![](//127.0.0.1:9/x)", "![](/etc/passwd)",
         "<img src=x onerror=a()>", "**b** _i_ `c` | d", "www.evil.example"]
_AT = "2026-11-27T12:00:00+00:00"
IFRAME = """<iframe srcdoc="<img src=x onerror=parent.document.title='pwned'>">.json"""


def live(md: str) -> list[str]:
    """The live markup in ``md``: raw HTML, links and images, autolinkable URLs."""
    return re.findall(r"<|\]\(|!\[|www\.|https?:", md)


def shows(md: str, text: str) -> bool:
    """``md`` holds ``text`` as escaped text (and so shows it literally)."""
    return escape_markdown(text) in md


# --------------------------------------------------------------------------- pure text
@pytest.mark.parametrize("name", NAMES)
def test_text_functions_escape_user_fields(name: str) -> None:
    tool = Tool(name=name, tcp_mm=(1.0, 2.0, 3.0),
                calibration=Calibration(method=name, calibrated_at=_AT))
    for md in (tool_data_markdown(tool, 3), tcp_readout_markdown(_readout(), name),
               menu_markdown("three-point", library_tool=f"1: {name}", reference_tool=name, new_tool=name,
                             mounted_tool=name),
               menu_markdown("reference", library_tool=f"1: {name}", reference_tool=name, new_tool="x",
                             mounted_tool=name),
               save_preview_markdown(name, f"2: {name}", (0, 0, 0), (0, 0, 0)), save_markdown(2, name),
               entry_preview_markdown(ToolEntry(name, dict.fromkeys("XYZABC", "0")))):
        assert live(md) == [], md
        assert shows(md, name) or shows(md, name.lower()), md


def _readout() -> Any:
    return make_controller("kr6", "pointer").readout("WORLD")


@pytest.fixture(scope="module")
def hostile_three_point(tmp_path_factory: pytest.TempPathFactory) -> tuple[CalibrationWorkflow, bytes]:
    """A finished three-point run on a library tool named ``<style>...`` (no calibration record,
    so the result's warning quotes the name), and its session record."""
    lib = ToolLibrary(tmp_path_factory.mktemp("lib") / "tools.json")
    lib.save(1, library_tool_with_true_tcp("pointer", NAMES[0]))
    wf = CalibrationWorkflow(make_controller("kr6", "pointer"), lib, robot="kr6", rng=np.random.default_rng(2))
    wf.start("three-point", slot=1)
    assert isinstance(wf.wizard, ThreePointWizard)
    steps = [step_markdown(wf.wizard), steps_list_markdown(wf.wizard)]
    while wf.result is None:
        assert wf.auto_touch(AutoTouchRequest(sigma_mm=0.0)).ok
    assert any(NAMES[0] in w for w in wf.result.warnings)
    for md in (*steps, warnings_markdown(wf.result)):
        assert live(md) == [], md
    assert shows(warnings_markdown(wf.result), f"The TCP of '{NAMES[0]}' has no calibration record")
    assert shows(steps[0], f"With '{NAMES[0]}' active")
    return wf, dumps(wf.export_record()).encode()


def test_wizard_words_quoting_a_tool_name_are_escaped(hostile_three_point) -> None:
    wf, _ = hostile_three_point
    assert "&lt;style&gt;" in warnings_markdown(wf.result)


def test_replay_table_of_a_hostile_record_is_text(hostile_three_point) -> None:
    _, record = hostile_three_point
    loaded = load_and_replay(record)
    md = replay_markdown(loaded.checks)
    assert live(md) == [] and len(md.splitlines()) == 3           # head, rule, one row
    assert all(line.count("|") - line.count("\\|") == 5 for line in md.splitlines())


def test_escaped_markdown_makes_viser_read_no_file(monkeypatch) -> None:
    """viser itself turns ``![x](path)`` in markdown into a data: URL by reading ``path`` on the
    server (any image file, or whatever imageio opens): a tool named ``![](/etc/passwd)`` would
    make the server read that file for every browser. Escaped, viser reads nothing."""
    import imageio.v3 as iio
    import viser

    reads: list[Any] = []
    monkeypatch.setattr(iio, "imread", lambda path, *a, **k: reads.append(path) or (_ for _ in ()).throw(OSError()))
    srv = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        with pytest.warns(UserWarning):
            srv.gui.add_markdown("![](/etc/passwd)")                 # the control: raw, viser reads it
        assert [str(p) for p in reads] == ["/etc/passwd"]
        reads.clear()
        for name in NAMES:
            srv.gui.add_markdown(f"**Active tool:** {escape_markdown(name)}")
        assert reads == []
    finally:
        srv.stop()


# --------------------------------------------------------------------------- the app's views
@pytest.fixture
def app_with_hostile_library(tmp_path: Path, app_factory: Callable[..., PendantApp]) -> Iterator[Callable[[], AppPage]]:
    lib = ToolLibrary(tmp_path / "tools.json")
    for slot, name in enumerate(NAMES, start=1):
        lib.save(slot, Tool(name=name, tcp_mm=(0.0, 0.0, 100.0 + slot),
                            calibration=Calibration(method=name, calibrated_at=_AT)), activate=slot == 1)
    browsers: list[AppPage] = []
    app = app_factory()

    def connect() -> AppPage:
        b = AppPage(app)
        browsers.append(b)
        return b

    try:
        yield connect
    finally:
        for b in browsers:
            b.ws.close()


def _all_markdown(b: AppPage) -> str:
    s = b.session
    handles = [s.views["pendant"].tcp_md, s.views["tools"].active_md, s.views["tools"].slot_md,
               s.views["tools"].entry_preview, s.views["tools"].entry_md, s.views["tools"].entry_name_err]
    v = s.views["calibrate"]
    handles += [v.menu_md, v.record_md, v.steps.head_md, v.steps.steps_md, v.steps.blocked_md,
                v.result.result_md, v.result.warnings_md, v.result.save_preview, v.result.save_md]
    return "\n".join(str(h.content) for h in handles)


def test_every_view_shows_hostile_library_names_as_text(app_with_hostile_library) -> None:
    b = app_with_hostile_library()
    s, tools = b.session, b.session.views["tools"]
    choose(tools.slots, f"1: {NAMES[0]}", b.client)   # a browser's session starts with no active tool
    click(tools.activate, b.client)
    assert shows(s.views["pendant"].tcp_md.content, f"TOOL {NAMES[0]}")
    assert shows(tools.active_md.content, NAMES[0])
    for slot, name in enumerate(NAMES, start=1):
        choose(tools.slots, f"{slot}: {name}", b.client)
        assert shows(tools.slot_md.content, name) and shows(tools.slot_md.content, f"calibrated by {name}")
        assert live(tools.slot_md.content) == [], tools.slot_md.content
    click(tools.activate, b.client)                              # the last one
    assert b.notes[-1] == ("Tool activated", f"{len(NAMES)}: {NAMES[-1]}")   # plain text: not escaped
    assert shows(tools.active_md.content, NAMES[-1])

    # the Calibrate menu lists the library tools
    v = s.views["calibrate"]
    choose(v.method, "Three-point orientation", b.client)
    choose(v.library_tool, f"1: {NAMES[0]}", b.client)
    assert shows(v.menu_md.content, f"1: {NAMES[0]}")
    assert live(_all_markdown(b)) == [], _all_markdown(b)


def test_typed_names_and_errors_quoting_them_are_text(app_with_hostile_library) -> None:
    b = app_with_hostile_library()
    tools = b.session.views["tools"]
    typed = f"{NAMES[0]} {NAMES[1]} and a name far too long for any controller"
    choose(tools.entry_name, typed, b.client)
    assert shows(tools.entry_preview.content, typed)
    click(tools.entry_save, b.client)                            # refused: too long, quoted in the error
    assert tools.entry_name_err.visible and "&lt;style&gt;" in tools.entry_name_err.content
    choose(tools.entry_name, NAMES[1], b.client)                 # already in slot 2
    click(tools.entry_save, b.client)
    assert shows(tools.entry_name_err.content, f"'{NAMES[1]}' is already in slot 2")
    assert live(_all_markdown(b)) == [], _all_markdown(b)


def test_loaded_record_name_and_tool_names_are_text(app_with_hostile_library, hostile_three_point) -> None:
    _, record = hostile_three_point
    b = app_with_hostile_library()
    v = b.session.views["calibrate"]
    upload(v.load, IFRAME, record, b.client)
    wait_until(lambda: "replayed result matches the record" in v.record_md.content, what="the record replayed")
    assert shows(v.record_md.content, f"Loaded {IFRAME}")
    assert shows(v.result.warnings_md.content, f"The TCP of '{NAMES[0]}' has no calibration record")
    assert live(_all_markdown(b)) == [], _all_markdown(b)
    assert "iframe" not in v.record_md.content.replace("&lt;iframe", "")
