"""The page's own script as the server serves it (``tcp_pendant.serve.client_script``): viser's
index.html with one script tag, the one static file at its one path, 404 (and no file read) for
anything else under /tcp-pendant/, the origin check in front of it all unchanged; the printed
trainer URL; the hints and the Keys line that name the keys."""

from __future__ import annotations

import gzip
import http.client
import re
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from importlib import resources
from pathlib import Path
from typing import Any

import msgspec.msgpack
import pytest
import viser
from tcp_pendant.serve import client_script, origin_check
from tcp_pendant.serve.cli import _class_lines
from tcp_pendant.serve.client_script import SCRIPT_PATH, SCRIPT_TAG, inject_script_tag, is_index_path
from tcp_pendant.serve.server import AppConfig, PendantApp
from tcp_pendant.views.pendant_panel import INCREMENT_KEYS, KEYS_LINE, jog_key_hint
from viser import _messages
from websockets.datastructures import Headers
from websockets.exceptions import InvalidStatus
from websockets.http11 import Request
from websockets.sync.client import connect

from support.wsclient import wait_until

VISER_INDEX = (Path(viser.__file__).parent / "client" / "build" / "index.html").read_bytes()
PACKAGED_JS = (resources.files("tcp_pendant.serve") / "static" / "pendant.js").read_bytes()


@pytest.fixture
def app(app_factory: Callable[..., PendantApp], tmp_path: Path) -> PendantApp:
    return app_factory(class_db=tmp_path / "class.sqlite3", trainer_token="token with & and + and #")


def get(port: int, path: str, *, gzip_ok: bool = False, origin: str | None = None) -> tuple[int, dict[str, str], bytes]:
    """GET ``path`` sent exactly as given (no client-side normalization); body decoded."""
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    try:
        headers = {"Accept-Encoding": "gzip" if gzip_ok else "identity"}
        if origin:
            headers["Origin"] = origin
        conn.putrequest("GET", path, skip_accept_encoding=True)
        for k, v in headers.items():
            conn.putheader(k, v)
        conn.endheaders()
        resp = conn.getresponse()
        body = resp.read()
        hdrs = {k.lower(): v for k, v in resp.getheaders()}
        assert int(hdrs.get("content-length", len(body))) == len(body)
        if hdrs.get("content-encoding") == "gzip":
            body = gzip.decompress(body)
        return resp.status, hdrs, body
    finally:
        conn.close()


# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("path", ["/", "/index.html", "/?trainer=abc", "//", "/%2e/index.html"])
@pytest.mark.parametrize("gzip_ok", [False, True])
def test_the_page_is_vipers_with_one_script_tag(app: PendantApp, path: str, gzip_ok: bool) -> None:
    status, headers, body = get(app.port, path, gzip_ok=gzip_ok)
    assert status == 200 and headers["content-type"].startswith("text/html")
    assert headers.get("content-encoding", "identity") == ("gzip" if gzip_ok else "identity")
    assert body.count(SCRIPT_TAG) == 1 and body.count(b"pendant.js") == 1
    assert body.replace(SCRIPT_TAG, b"", 1) == VISER_INDEX          # otherwise viser's page, byte for byte
    head = re.search(rb"<head(\s[^>]*)?>", body)
    assert head is not None and body[head.end():].startswith(SCRIPT_TAG)


@pytest.mark.parametrize("gzip_ok", [False, True])
def test_the_script_is_the_packaged_file_served_as_javascript(app: PendantApp, gzip_ok: bool) -> None:
    status, headers, body = get(app.port, SCRIPT_PATH, gzip_ok=gzip_ok)
    assert status == 200
    assert headers["content-type"] == "text/javascript; charset=utf-8"
    assert headers["x-content-type-options"] == "nosniff"
    assert headers.get("content-encoding", "identity") == ("gzip" if gzip_ok else "identity")
    assert body == PACKAGED_JS                       # a fixed file: nothing of the request or server in it
    assert b"innerHTML" not in body and b"insertAdjacentHTML" not in body and b"eval(" not in body


@pytest.mark.parametrize("path", ["/tcp-pendant/x.js", "/tcp-pendant/", "/tcp-pendant", "/tcp-pendant/pendant.js/x",
                                  "/tcp-pendant/../../etc/passwd", "/tcp-pendant/%2e%2e/%2e%2e/etc/passwd",
                                  "/tcp-pendant/..%2f..%2fetc%2fpasswd", "/tcp-pendant/static/pendant.js",
                                  "/tcp-pendant\\..\\client_script.py", "/tcp-pendant/pendant.JS"])
def test_any_other_path_under_tcp_pendant_is_404(app: PendantApp, path: str) -> None:
    status, _, body = get(app.port, path)
    assert status == 404 and b"root:" not in body and b"import" not in body


@contextmanager
def files_opened() -> Iterator[list[str]]:
    """The files this thread opens inside the block (a process audit hook, idle outside it)."""
    seen: list[str] = []
    me = threading.get_ident()
    state = {"on": True}

    def hook(event: str, args: tuple[Any, ...]) -> None:
        if state["on"] and event == "open" and threading.get_ident() == me:
            seen.append(str(args[0]))

    sys.addaudithook(hook)                 # cannot be removed: switched off at the end
    try:
        yield seen
    finally:
        state["on"] = False


def test_no_request_reads_a_file_and_other_paths_go_to_viser_untouched() -> None:
    client_script.script_asset()          # read once (the server does it at start)
    calls: list[str] = []

    def viser_server(_connection: Any, request: Any) -> str:
        calls.append(request.path)
        return "viser's answer"

    with files_opened() as opened:
        for path in ("/tcp-pendant/../../etc/passwd", "/tcp-pendant/x.js", "/tcp-pendant/pendant.js",
                     "/tcp-pendant/%2e%2e/client_script.py"):
            resp = client_script.serve(None, Request(path, Headers()), viser_server)
            assert resp.status_code == (200 if path.endswith("/pendant.js") else 404)
        assert calls == []
        for path in ("/assets/x.js", "/../etc/passwd", "/favicon.ico"):
            assert client_script.serve(None, Request(path, Headers()), viser_server) == "viser's answer"
    assert opened == []
    assert calls == ["/assets/x.js", "/../etc/passwd", "/favicon.ico"]


def test_the_origin_check_still_refuses_foreign_pages_in_front_of_the_script(app: PendantApp) -> None:
    port = app.port
    for path in ("/", SCRIPT_PATH):
        with pytest.raises(InvalidStatus) as err:
            connect(f"ws://127.0.0.1:{port}{path}", origin="http://evil.example",  # type: ignore[arg-type]
                    subprotocols=[f"viser-v{viser.__version__}"], open_timeout=20)
        assert err.value.response.status_code == 403
    assert app.sessions == {}
    ws = connect(f"ws://127.0.0.1:{port}", origin=f"http://127.0.0.1:{port}",  # type: ignore[arg-type]
                 subprotocols=[f"viser-v{viser.__version__}"], open_timeout=20, max_size=None)
    try:
        camera = _messages.ViewerCameraMessage(wxyz=(1.0, 0.0, 0.0, 0.0), position=(2.0, -2.0, 1.0), fov=1.0,
                                               near=0.01, far=100.0, image_height=720, image_width=1280,
                                               look_at=(0.0, 0.0, 0.5), up_direction=(0.0, 0.0, 1.0))
        ws.send(msgspec.msgpack.encode(camera.as_serializable_dict()))
        wait_until(lambda: len(app.sessions) == 1, what="the own page's session")
    finally:
        ws.close()
    assert origin_check._http_layers[port] is client_script.serve


def test_the_layer_is_the_pendants_port_only(tmp_path: Path) -> None:
    """A bare viser server in the same process serves its page untouched; a stopped pendant's
    port forgets the layer."""
    a = PendantApp(AppConfig(port=0, tool_library=tmp_path / "tools.json"))
    a.start()
    bare = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        assert get(a.port, "/")[2].count(SCRIPT_TAG) == 1
        status, _, body = get(bare.get_port(), "/")
        assert status == 200 and body == VISER_INDEX
        assert get(bare.get_port(), SCRIPT_PATH)[0] == 404
    finally:
        bare.stop()
        port = a.port
        a.stop()
    assert port not in origin_check._http_layers


def test_the_tag_finds_the_script_from_the_page_and_behind_a_path_prefix_proxy() -> None:
    from urllib.parse import urljoin

    src = re.search(rb'src="([^"]+)"', SCRIPT_TAG).group(1).decode()
    for page in ("http://h:8080/", "http://h:8080/index.html", "http://h:8080/?trainer=x"):
        assert urljoin(page, src) == f"http://h:8080{SCRIPT_PATH}"
    assert urljoin("https://school.example/pendant/", src) == f"https://school.example/pendant{SCRIPT_PATH}"


def test_index_paths_and_injection() -> None:
    assert all(is_index_path(p) for p in ("/", "", "/index.html", "//", "/./index.html", "/?a=b", "/%69ndex.html"))
    assert not any(is_index_path(p) for p in ("/x", "/index.htm", "/a/index.html", "/tcp-pendant/pendant.js"))
    page = b"<!doctype html><HTML><Head lang='en'><title>t</title></head><body></body></html>"
    out = inject_script_tag(page)
    assert out == b"<!doctype html><HTML><Head lang='en'>" + SCRIPT_TAG + b"<title>t</title></head><body></body></html>"
    with pytest.raises(ValueError, match="already"):
        inject_script_tag(out)
    with pytest.raises(ValueError, match="no <head>"):
        inject_script_tag(b"<html><body></body></html>")
    # a page without <head> (viser changed): served as viser gave it, not broken
    resp = client_script._index_response(client_script._plain(client_script.http.HTTPStatus.OK, "plain"))
    assert resp.body == b"plain"


# ---------------------------------------------------------------------------------------------
def test_the_printed_trainer_url_carries_the_token_percent_encoded(app: PendantApp) -> None:
    url = f"http://127.0.0.1:{app.port}/?trainer=token%20with%20%26%20and%20%2B%20and%20%23"
    assert app.trainer_url == url
    lines = _class_lines(app, print_token=True)                          # tcp-pendant --print-token
    assert f"Trainer view: {url}  trainer token: token with & and + and #\n" in lines
    from urllib.parse import parse_qs, urlsplit

    assert parse_qs(urlsplit(url).query)["trainer"] == ["token with & and + and #"]


def test_no_classroom_no_trainer_url(tmp_path: Path) -> None:
    a = PendantApp(AppConfig(port=0, tool_library=tmp_path / "tools.json"))
    assert a.trainer_url is None and _class_lines(a) == ""


def test_hints_and_the_keys_line_name_the_keys(app: PendantApp) -> None:
    ws = connect(f"ws://127.0.0.1:{app.port}", subprotocols=[f"viser-v{viser.__version__}"], open_timeout=20,
                 max_size=None)
    try:
        camera = _messages.ViewerCameraMessage(wxyz=(1.0, 0.0, 0.0, 0.0), position=(2.0, -2.0, 1.0), fov=1.0,
                                               near=0.01, far=100.0, image_height=720, image_width=1280,
                                               look_at=(0.0, 0.0, 0.5), up_direction=(0.0, 0.0, 1.0))
        ws.send(msgspec.msgpack.encode(camera.as_serializable_dict()))
        wait_until(lambda: len(app.sessions) == 1, what="a session")
        (s,) = app.sessions.values()
        panel = s.views["pendant"]
        assert panel.keys_md.content.startswith(KEYS_LINE + "\n\n<div hidden data-tcp-pendant-labels ")
        for key in ("`1`…`6`", "`Shift`+`1`…`6`", "`[` `]`", "`R` Record"):
            assert key in KEYS_LINE
        assert INCREMENT_KEYS in panel.increment.hint
        for r, ax in enumerate("XYZABC"):
            assert panel.cart_rows[ax].hint.endswith(f"keys {r + 1} (+) and Shift+{r + 1} (−)")
            for sign in (1, -1):
                assert jog_key_hint(r) in panel.cart_buttons[(ax, sign)].hint
        for i, row in enumerate(panel.joint_rows):
            assert row.hint.endswith(jog_key_hint(i))
        assert s.views["dock"].record.hint.endswith("; key R.")
        assert s.views["touches"].record.hint.endswith("; key R.")
    finally:
        ws.close()


def test_a_starting_pendant_answers_503_until_it_is_ready(tmp_path: Path, monkeypatch) -> None:
    """viser listens before the pendant has put its page script and session handlers in place:
    until then the page (which would lack the script: no remembered name and key) and the
    websocket (which would get no session) are answered 503 "starting"; then the page with its
    script. A bare viser server started meanwhile is held back too, and served once it is over."""
    gate, paused = threading.Event(), threading.Event()
    real_ready = origin_check.mark_ready

    def held(port: int) -> None:
        paused.set()
        assert gate.wait(30)
        real_ready(port)

    monkeypatch.setattr(origin_check, "mark_ready", held)
    app = PendantApp(AppConfig(port=0, tool_library=tmp_path / "tools.json"))
    starter = threading.Thread(target=app.start)
    starter.start()
    try:
        assert paused.wait(60)
        status, _, body = get(app.port, "/")
        assert status == 503 and body.decode().strip() == origin_check.STARTING
        with pytest.raises(InvalidStatus) as refused:
            connect(f"ws://127.0.0.1:{app.port}", subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
                    open_timeout=20)
        assert refused.value.response.status_code == 503
        bare = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
        try:
            assert get(bare.get_port(), "/")[0] == 503             # no policy while a pendant starts
            gate.set()
            starter.join(60)
            assert get(bare.get_port(), "/")[0] == 200
        finally:
            bare.stop()
        status, _, body = get(app.port, "/")
        assert status == 200 and body.count(SCRIPT_TAG) == 1
    finally:
        gate.set()
        starter.join(60)
        app.stop()
