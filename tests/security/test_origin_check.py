"""Foreign web pages cannot connect. A websocket upgrade whose Origin is present
and is not the page's own address (nor an --allow-origin one) is refused with HTTP 403."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import msgspec.msgpack
import pytest
import viser
from tcp_pendant.serve import origin_check
from tcp_pendant.serve.cli import build_parser, main
from tcp_pendant.serve.origin_check import OriginError, normalize_origin, origin_refusal, parse_allow_origins
from tcp_pendant.serve.server import AppConfig, PendantApp
from viser import _messages
from websockets.datastructures import Headers
from websockets.exceptions import InvalidStatus
from websockets.sync.client import ClientConnection, connect

from support.wsclient import wait_until

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

PROXY = "https://pendant.school.example"
CAMERA = _messages.ViewerCameraMessage(wxyz=(1.0, 0.0, 0.0, 0.0), position=(2.0, -2.0, 1.0), fov=1.0, near=0.01,
                                       far=100.0, image_height=720, image_width=1280, look_at=(0.0, 0.0, 0.5),
                                       up_direction=(0.0, 0.0, 1.0))


@pytest.mark.parametrize("given, expected", [
    ("http://127.0.0.1:8080", "http://127.0.0.1:8080"),
    ("HTTPS://Pendant.School.Example:443/", "https://pendant.school.example"),
    ("http://host:80", "http://host"),
    ("http://[::1]:8080", "http://[::1]:8080"),
])
def test_origins_are_normalized(given: str, expected: str) -> None:
    assert normalize_origin(given) == expected


@pytest.mark.parametrize("bad", ["evil.example", "ftp://x", "http://", "http://h/path", "http://h:99999",
                                 "null", "http://user@h"])
def test_a_bad_allow_origin_names_the_value_and_the_form(bad: str) -> None:
    with pytest.raises(OriginError, match=r"is not a web origin; give scheme://host\[:port\]"):
        parse_allow_origins([bad])


def test_allow_origin_is_repeatable_and_comma_separated() -> None:
    args = build_parser().parse_args(["--allow-origin", f"{PROXY}, http://10.0.0.5:8080",
                                      "--allow-origin", "http://10.0.0.5:8080/"])
    assert parse_allow_origins(args.allow_origin) == (PROXY, "http://10.0.0.5:8080")
    assert build_parser().parse_args([]).allow_origin == []


def test_the_command_refuses_a_bad_allow_origin_with_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--port", "0", "--allow-origin", "evil.example"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tcp-pendant: error: 'evil.example' is not a web origin")


def _h(**headers: str) -> Headers:
    return Headers(**{k.replace("_", "-"): v for k, v in headers.items()})


@pytest.mark.parametrize("headers, refused", [
    (_h(Host="127.0.0.1:8080"), False),                                          # no Origin: not a browser
    (_h(Host="127.0.0.1:8080", Origin="http://127.0.0.1:8080"), False),         # the pendant's own page
    (_h(Host="LOCALHOST:8080", Origin="http://localhost:8080"), False),
    (_h(Host="pendant.school.example", Origin="https://pendant.school.example"), False),   # default ports
    (_h(Host="[::1]:8080", Origin="http://[::1]:8080"), False),
    (_h(Host="127.0.0.1:8080", Origin="http://evil.example"), True),
    (_h(Host="127.0.0.1:8080", Origin="http://127.0.0.1:8081"), True),          # another port, another origin
    (_h(Host="127.0.0.1:8080", Origin="https://127.0.0.1:8080"), False),        # TLS proxy on the same address
    (_h(Host="127.0.0.1", Origin="http://127.0.0.1:8080"), True),
    (_h(Host="127.0.0.1:8080", Origin="null"), True),                           # sandboxed frame, file://
    (_h(Origin="http://127.0.0.1:8080"), True),                                 # no Host to compare with
])
def test_origin_refusal_compares_the_origin_with_the_host_it_came_to(headers: Headers, refused: bool) -> None:
    why = origin_refusal(headers)
    assert (why is not None) is refused
    if refused:
        assert why.startswith("Refused:")


def test_two_origin_headers_are_refused_and_allowed_origins_pass() -> None:
    h = Headers([("Host", "127.0.0.1:8080"), ("Origin", "http://127.0.0.1:8080"), ("Origin", "http://evil.example")])
    assert origin_refusal(h) == "Refused: more than one Origin header."
    proxied = _h(Host="127.0.0.1:8080", Origin=PROXY)
    assert origin_refusal(proxied) is not None
    assert origin_refusal(proxied, (PROXY,)) is None


@pytest.fixture
def app(app_factory: Callable[..., PendantApp]) -> PendantApp:
    return app_factory(allow_origins=(PROXY,))


def _handshake(port: int, origin: str | None) -> ClientConnection:
    """A raw websocket handshake as viser's client makes it (with or without an Origin)."""
    return connect(f"ws://127.0.0.1:{port}", origin=origin, subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[arg-type]
                   open_timeout=20, max_size=None)


def test_a_foreign_page_gets_403_and_no_session_while_own_page_proxy_and_plain_clients_connect(app: PendantApp) -> None:
    port = app.port
    for origin in ("http://evil.example", f"http://localhost:{port}", "null"):
        with pytest.raises(InvalidStatus) as err:
            _handshake(port, origin)
        assert err.value.response.status_code == 403
        assert err.value.response.body.startswith(b"Refused: ")
    assert app.sessions == {}
    for origin in (f"http://127.0.0.1:{port}", None, PROXY):
        ws = _handshake(port, origin)               # accepted: viser serves it a session
        try:
            ws.send(msgspec.msgpack.encode(CAMERA.as_serializable_dict()))   # "connected" for viser
            wait_until(lambda: len(app.sessions) == 1, what=f"the session of a page from {origin}")
        finally:
            ws.close()
        wait_until(lambda: app.sessions == {}, what="the session closed")


def test_the_page_itself_is_still_served_to_anyone(app: PendantApp) -> None:
    import urllib.request

    req = urllib.request.Request(f"http://127.0.0.1:{app.port}/", headers={"Origin": "http://evil.example"})
    with urllib.request.urlopen(req, timeout=20) as resp:
        assert resp.status == 200 and b"<html" in resp.read().lower()


def test_the_allowed_origins_are_per_server_and_dropped_at_stop(tmp_path: Path) -> None:
    plain = PendantApp(AppConfig(port=0, tool_library=tmp_path / "t.json"))
    plain.start()
    try:
        with pytest.raises(InvalidStatus) as err:       # another server's --allow-origin is not this one's
            _handshake(plain.port, PROXY)
        assert err.value.response.status_code == 403
        assert origin_check._allowed_by_port[plain.port] == frozenset()
    finally:
        plain.stop()
    assert plain.port not in origin_check._allowed_by_port
