"""The fixtures every test folder shares (``tests/conftest.py`` registers this module as a
pytest plugin).

A pendant in this process (real viser server on a free port, headless websocket clients):

* ``app_factory(tools=None, active_slot=None, **AppConfig options)``: starts a ``PendantApp``
  (port 0, the tool library ``tmp_path/tools.json`` polled every 0.1 s, holding ``tools``
  {slot: Tool} with ``active_slot`` active; port, library and poll overridden by an option) and
  returns it; every pendant it started is stopped at the end of the test, whatever happened.
* ``page(tools=None, **AppConfig options)``: a pendant (``app_factory``) with one connected
  browser, a ``support.app_page.AppPage`` (``page(on=app)``: one more browser on ``app``); a
  test module names its own subclass and the server's ``--seed`` with the ``app_page`` marker:
  ``pytestmark = pytest.mark.app_page(cls=Page, seed=3)``.

A pendant in a subprocess and Debian's chromium (Playwright), for the browser tests:

* ``pendant_server(*extra_args, port=None)``: starts ``python -m tcp_pendant`` with those options
  (``support.server_process``) and returns its :class:`~support.server_process.ServerProcess`
  (``url``, ``library_path``, ``log()``); terminated at the end of the test.
* ``server``: one such server with default options (KR 6, pointer, an empty tool library).
* ``browser``: chromium launched once per process (``support.chromium_session``).
* ``new_page(url, width=1400, height=900, wait_for="Record point", init_script=None)``: a fresh
  browser context (its own viser client) and page at ``url`` with that viewport (its 3D view at
  ``chromium_session.RENDER_SCALE`` device pixels per CSS pixel), once the button ``wait_for``
  is visible; closed at the end of the test.
* ``shot(page, name)``: a screenshot ``tmp_path/name.png`` (returns its path).

Software WebGL is slow: wait on conditions with generous timeouts, never fixed sleeps.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from tcp_pendant.serve.server import AppConfig, PendantApp

from support import chromium_session, server_process
from support.app_page import AppPage
from support.server_process import ServerProcess
from tcpcal.tool import Tool

UI_TIMEOUT_MS = 60_000


@pytest.fixture
def app_factory(tmp_path: Path) -> Iterator[Callable[..., PendantApp]]:
    """``app_factory(tools=None, active_slot=None, **AppConfig options)``: a started pendant in this process (module
    docstring); all of them stopped at the end of the test."""
    apps: list[PendantApp] = []

    def start(tools: dict[int, Tool] | None = None, *, active_slot: int | None = None, **config: Any) -> PendantApp:
        app = PendantApp(AppConfig(**{"port": 0, "tool_library": tmp_path / "tools.json", "library_poll_s": 0.1,
                                      **config}))
        for slot, tool in (tools or {}).items():
            app.library.save(slot, tool, activate=slot == active_slot)
        try:
            app.start()
        except BaseException:
            with contextlib.suppress(Exception):
                app.stop()
            raise
        apps.append(app)
        return app

    try:
        yield start
    finally:
        errors: list[BaseException] = []
        for app in apps:
            try:
                app.stop()
            except Exception as exc:            # the others are stopped all the same
                errors.append(exc)
        if errors:
            raise errors[0]


@pytest.fixture
def page(request: pytest.FixtureRequest, app_factory: Callable[..., PendantApp]) -> Iterator[Callable[..., AppPage]]:
    """``page(tools=None, **AppConfig options)``: a pendant with one connected browser, of the
    class the test's ``app_page`` marker names (``AppPage`` without one), its server seeded
    with the marker's ``seed`` unless the options give one (module docstring); ``page(on=app)``:
    another browser on the running pendant ``app``."""
    marker = request.node.get_closest_marker("app_page")
    options = marker.kwargs if marker is not None else {}
    page_cls: type[AppPage] = options.get("cls", AppPage)
    seed: int | None = options.get("seed")
    pages: list[AppPage] = []

    def make(tools: dict[int, Tool] | None = None, *, on: PendantApp | None = None, **config: Any) -> AppPage:
        if on is not None:
            assert tools is None and not config, "another browser on a running pendant takes no pendant options"
            app = on
        else:
            if seed is not None:
                config.setdefault("seed", seed)
            app = app_factory(tools, **config)
        p = page_cls(app)
        pages.append(p)
        return p

    try:
        yield make
    finally:
        for p in pages:
            p.ws.close()


@pytest.fixture
def pendant_server(tmp_path: Path) -> Iterator[Callable[..., ServerProcess]]:
    """``pendant_server("--shared", ...)``: a server in a subprocess with extra CLI options
    (``port=N``: on that port, e.g. again on the port of a server that was killed)."""
    started: list[ServerProcess] = []

    def factory(*extra: str, port: int | None = None) -> ServerProcess:
        sp = (server_process.start(tmp_path, *extra) if port is None
              else server_process.start_on(tmp_path, port, *extra))
        started.append(sp)
        return sp

    yield factory
    for sp in started:
        server_process.stop(sp)


@pytest.fixture
def server(pendant_server: Callable[..., ServerProcess]) -> ServerProcess:
    """A pendant server with default options (KR 6, pointer) and an empty tool library."""
    return pendant_server()


@pytest.fixture(scope="session")
def browser() -> Iterator[Any]:
    """Chromium (Debian's) driven by Playwright, shared by the browser tests of one process."""
    try:
        b = chromium_session.acquire()
    except FileNotFoundError as exc:
        pytest.fail(str(exc))
    try:
        yield b
    finally:
        chromium_session.release()


@pytest.fixture
def new_page(browser: Any) -> Iterator[Callable[..., Any]]:
    """``new_page(url)``: a fresh context (its own viser client) at ``url``, once the pendant GUI
    is there (``init_script``: JavaScript run first in its pages; ``locale``: the browser's
    language; module docstring)."""
    contexts: list[Any] = []

    def factory(url: str, *, width: int = 1400, height: int = 900, wait_for: str = "Record point",
                init_script: str | None = None, locale: str | None = None) -> Any:
        # locale: the browser's language ("de-DE": its Accept-Language and navigator.language)
        ctx = browser.new_context(viewport={"width": width, "height": height},
                                  **({} if locale is None else {"locale": locale}))
        contexts.append(ctx)
        if init_script is not None:                # runs in every page of the context before its own scripts
            ctx.add_init_script(init_script)
        page = ctx.new_page()
        page.set_default_timeout(UI_TIMEOUT_MS)
        page.goto(chromium_session.with_render_scale(url))
        if wait_for:
            page.get_by_role("button", name=wait_for).first.wait_for(state="visible", timeout=UI_TIMEOUT_MS)
        return page

    yield factory
    for ctx in contexts:
        try:
            ctx.close()
        except Exception:
            pass


@pytest.fixture
def shot(tmp_path: Path) -> Callable[[Any, str], Path]:
    """``shot(page, "name")`` saves ``tmp_path/name.png`` and returns its path."""

    def take(page: Any, name: str) -> Path:
        path = tmp_path / f"{name}.png"
        page.screenshot(path=str(path))
        return path

    return take
