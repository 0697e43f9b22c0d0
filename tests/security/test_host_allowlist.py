"""DNS rebinding: the server answers HTTP and websocket requests only for the host names it
serves (its bind address, the names and addresses it prints, the loopback names, the
--allow-origin hosts); a page of a rebinding site (Origin and Host both its own name), with any
port, case or userinfo, gets 403, and so do two Origin or two Host headers."""

from __future__ import annotations

import base64
import os
import socket
from collections.abc import Iterator
from pathlib import Path

import pytest
import viser
from tcp_pendant.serve import origin_check
from tcp_pendant.serve.origin_check import LOOPBACK_HOSTS, host_refusal, served_hosts
from tcp_pendant.serve.server import AppConfig, PendantApp
from websockets.datastructures import Headers

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

PROXY = "https://pendant.school.example"


def raw_request(port: int, headers: list[tuple[str, str]], upgrade: bool) -> tuple[int, bytes]:
    """Send one HTTP/1.1 request with exactly ``headers`` (a websocket upgrade when
    ``upgrade``); returns (status code, body start)."""
    lines = ["GET / HTTP/1.1", *(f"{k}: {v}" for k, v in headers)]
    if upgrade:
        lines += ["Upgrade: websocket", "Connection: Upgrade", "Sec-WebSocket-Version: 13",
                  f"Sec-WebSocket-Key: {base64.b64encode(os.urandom(16)).decode()}",
                  f"Sec-WebSocket-Protocol: viser-v{viser.__version__}"]
    with socket.create_connection(("127.0.0.1", port), timeout=20) as s:
        s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
        data = b""
        while b"\r\n\r\n" not in data:
            chunk = s.recv(65536)
            if not chunk:
                break
            data += chunk
        head, _, body = data.partition(b"\r\n\r\n")
        if not body and not upgrade:
            body = s.recv(65536)
    return int(head.split(b" ", 2)[1]), body


@pytest.fixture(scope="module")
def app(tmp_path_factory: pytest.TempPathFactory) -> Iterator[PendantApp]:
    a = PendantApp(AppConfig(port=0, tool_library=tmp_path_factory.mktemp("lib") / "tools.json",
                             allow_origins=(PROXY,)))
    a.start()
    yield a
    a.stop()


def _rebinding_variants(port: int) -> list[tuple[str, str]]:
    return [(f"evil.example:{port}", f"http://evil.example:{port}"),       # the rebinding page itself
            ("evil.example", "http://evil.example"),                       # default port
            (f"EVIL.EXAMPLE:{port}", f"http://EVIL.EXAMPLE:{port}"),       # upper case
            (f"x@evil.example:{port}", f"http://x@evil.example:{port}"),   # userinfo
            (f"x@127.0.0.1:{port}", f"http://127.0.0.1:{port}"),           # userinfo before a served name
            (f"127.0.0.1.evil.example:{port}", f"http://127.0.0.1.evil.example:{port}")]


@pytest.mark.parametrize("upgrade", [True, False], ids=["websocket", "http"])
def test_a_rebinding_site_gets_403_for_websockets_and_pages(app: PendantApp, upgrade: bool) -> None:
    for host, origin in _rebinding_variants(app.port):
        status, body = raw_request(app.port, [("Host", host), ("Origin", origin)], upgrade)
        assert status == 403, (host, status)
        assert body.startswith(b"Refused: this pendant is not served as"), body[:200]
        status, _ = raw_request(app.port, [("Host", host)], upgrade)      # no Origin: still refused
        assert status == 403
    assert app.sessions == {}


def test_two_origin_or_two_host_headers_get_403(app: PendantApp) -> None:
    own = f"127.0.0.1:{app.port}"
    status, body = raw_request(app.port, [("Host", own), ("Origin", f"http://{own}"),
                                          ("Origin", "http://evil.example")], upgrade=True)
    assert (status, body) == (403, b"Refused: more than one Origin header.\n")
    status, body = raw_request(app.port, [("Host", own), ("Host", "evil.example")], upgrade=False)
    assert (status, body) == (403, b"Refused: a request needs exactly one Host header.\n")


def test_the_served_names_are_answered(app: PendantApp) -> None:
    port = app.port
    for host, origin in ((f"127.0.0.1:{port}", f"http://127.0.0.1:{port}"),
                         (f"LOCALHOST:{port}", f"http://localhost:{port}"),
                         (f"[::1]:{port}", f"http://[::1]:{port}"),
                         ("pendant.school.example", PROXY)):              # the --allow-origin proxy
        assert raw_request(app.port, [("Host", host), ("Origin", origin)], upgrade=True)[0] == 101, host
        assert raw_request(app.port, [("Host", host)], upgrade=False)[0] == 200, host


def test_served_hosts_are_the_bind_address_the_printed_urls_the_loopback_names_and_the_proxies() -> None:
    urls = ["http://classroom-pc:8080", "http://10.0.0.5:8080", "http://[2001:db8::5]:8080"]
    assert served_hosts("0.0.0.0", urls, (PROXY,)) == LOOPBACK_HOSTS | {
        "classroom-pc", "10.0.0.5", "2001:db8::5", "pendant.school.example"}
    assert served_hosts("10.0.0.7") == LOOPBACK_HOSTS | {"10.0.0.7"}
    assert served_hosts("[2001:db8::7]") == LOOPBACK_HOSTS | {"2001:db8::7"}
    assert served_hosts("::") == LOOPBACK_HOSTS


@pytest.mark.parametrize("host, refused", [
    ("127.0.0.1:8080", False), ("localhost", False), ("LocalHost:1", False), ("[::1]:8080", False),
    ("10.0.0.5:8080", False), ("evil.example:8080", True), ("10.0.0.5.evil.example", True),
    ("x@10.0.0.5:8080", True), ("10.0.0.5:99999", True), ("10.0.0.5/x", True), ("", True), ("10.0.0.5 x", True),
])
def test_host_refusal(host: str, refused: bool) -> None:
    why = host_refusal(Headers(Host=host), LOOPBACK_HOSTS | {"10.0.0.5"})
    assert (why is not None) is refused


def test_a_refusal_quotes_a_long_host_cut_short() -> None:
    why = host_refusal(Headers(Host="a" * 5000))
    assert why is not None and len(why) < 300


def test_the_served_names_are_per_server_and_dropped_at_stop(tmp_path: Path) -> None:
    a = PendantApp(AppConfig(port=0, tool_library=tmp_path / "t.json"))
    a.start()
    port = a.port
    try:
        assert origin_check._hosts_by_port[port] == LOOPBACK_HOSTS
        assert raw_request(port, [("Host", "pendant.school.example")], upgrade=False)[0] == 403
    finally:
        a.stop()
    assert port not in origin_check._hosts_by_port


def test_a_request_that_breaks_a_page_handler_is_a_400_without_traceback(app: PendantApp, monkeypatch, caplog) -> None:
    """Whatever raises while a request is answered (here: the page script's layer) gives 400
    and one log line, not websockets' 500 and a traceback."""
    import logging

    def broken(connection, request, process_request):
        raise KeyError("x" * 1000)

    monkeypatch.setitem(origin_check._http_layers, app.port, broken)
    with caplog.at_level(logging.WARNING):
        status, body = raw_request(app.port, [("Host", f"127.0.0.1:{app.port}")], upgrade=False)
    assert (status, body) == (400, b"Bad request.\n")
    assert not [r for r in caplog.records if r.exc_info]
    line = next(r.getMessage() for r in caplog.records if "failed: KeyError" in r.getMessage())
    assert len(line) < 300


def test_on_every_interface_the_printed_names_are_served(app_factory, monkeypatch) -> None:
    """--host 0.0.0.0: the host name and addresses the server prints (addresses.network_urls,
    here fixed) are answered; other names are not."""
    import tcp_pendant.serve.server as server_module

    monkeypatch.setattr(server_module, "network_urls",
                        lambda host, port: [f"http://classroom-pc:{port}", f"http://10.9.8.7:{port}"])
    a = app_factory(host="0.0.0.0")
    port = a.port
    for host in (f"classroom-pc:{port}", f"10.9.8.7:{port}", f"127.0.0.1:{port}", f"localhost:{port}"):
        assert raw_request(port, [("Host", host)], upgrade=False)[0] == 200, host
    for host in (f"evil.example:{port}", f"classroom-pc.evil.example:{port}", f"10.9.8.8:{port}"):
        assert raw_request(port, [("Host", host)], upgrade=False)[0] == 403, host
