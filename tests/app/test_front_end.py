"""A large class in miniature: the nginx front end of docs/nginx-class.conf (Debian's nginx) in
front of two TCP Pendant servers that share one PostgreSQL gradebook (tests/conftest.py).

The documented file is the test's configuration: only its addresses, port and paths are
replaced by the test's own (:func:`render`)."""

from __future__ import annotations

import http.client
import re
import shutil
import socket
import subprocess
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path

import pytest

from support.guiclick import choose, click
from support.wsclient import DrainingClient, free_port, wait_until

from tcp_pendant.classroom.gradebook import Gradebook

CONF = Path(__file__).parents[2] / "docs" / "nginx-class.conf"


def render(folder: Path, listen_port: int, upstream_ports: Sequence[int]) -> Path:
    """docs/nginx-class.conf with the ten documented servers replaced by 127.0.0.1 ports, its
    listen port by ``listen_port`` and its files moved into ``folder``; the file written."""
    text = CONF.read_text()
    servers = "".join(f"\n        server 127.0.0.1:{p} max_fails=3 fail_timeout=10s;" for p in upstream_ports)
    text, n = re.subn(r"(\n\s*server 10\.0\.0\.\d+:8080 [^;\n]*;)+", servers, text)
    assert n == 1, "the upstream block of docs/nginx-class.conf is not where the test expects it"
    text, n = re.subn(r"\n(\s*)listen 80;", rf"\n\1listen 127.0.0.1:{listen_port};", text)
    assert n == 1
    for documented in ("/run/nginx-tcp-pendant.pid", "/var/log/nginx/", "/var/lib/nginx/tcp-pendant/"):
        assert documented in text
    text = text.replace("/run/nginx-tcp-pendant.pid", f"{folder}/nginx.pid")
    text = text.replace("/var/log/nginx/", f"{folder}/").replace("/var/lib/nginx/tcp-pendant/", f"{folder}/")
    assert "10.0.0." not in text
    out = folder / "nginx-class.conf"
    out.write_text(text)
    return out


@pytest.fixture
def nginx_folder() -> Iterator[Path]:
    # Not tmp_path: nginx's workers run as an unprivileged user when it is started as root, and
    # pytest's folders are root's alone.
    folder = Path(tempfile.mkdtemp(prefix="tcp-pendant-nginx-"))
    folder.chmod(0o755)
    (folder / "logs").mkdir()
    try:
        yield folder
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _nginx_test(nginx: Path, conf: Path, folder: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(nginx), "-t", "-c", str(conf), "-p", str(folder)], capture_output=True,
                          text=True, timeout=30)


def test_the_documented_front_end_config_is_one_nginx_accepts(nginx_binary: Path, nginx_folder: Path) -> None:
    conf = render(nginx_folder, free_port(), [free_port(), free_port()])
    done = _nginx_test(nginx_binary, conf, nginx_folder)
    assert done.returncode == 0, done.stderr
    assert "syntax is ok" in done.stderr and "test is successful" in done.stderr
    # and a broken copy is refused: the check can fail
    conf.write_text(conf.read_text().replace("proxy_read_timeout 3600s;", "proxy_read_timeout;"))
    assert _nginx_test(nginx_binary, conf, nginx_folder).returncode != 0


def _listening(port: int) -> bool:
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=0.2):
            return True
    except OSError:
        return False


def _join(session, name: str) -> object:
    prompt = session.views["identity"]
    choose(prompt.name_field, name, session.client)
    click(prompt.start, session.client)
    return prompt


def test_two_servers_behind_the_front_end_serve_one_class(app_factory, nginx_binary: Path, nginx_folder: Path,
                                                          postgres_server) -> None:
    """Browsers reach two servers through nginx (websocket upgrade, sticky by the route cookie);
    each joins on its own server, both land in the one PostgreSQL gradebook, and a name held on
    one server is refused on the other."""
    url = postgres_server.fresh_schema()
    front = free_port()
    name = "pendant.school.test"            # the front end's name, as trainees open it
    origin = f"http://{name}:{front}"
    apps = [app_factory(class_db=url, allow_origins=(origin,), trainer_token="one-token-for-every-server")
            for _ in range(2)]
    conf = render(nginx_folder, front, [a.port for a in apps])
    nginx = subprocess.Popen([str(nginx_binary), "-c", str(conf), "-p", str(nginx_folder), "-g", "daemon off;"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    clients: list[DrainingClient] = []
    try:
        wait_until(lambda: _listening(front) or nginx.poll() is not None, timeout=20, what="nginx listening")
        assert nginx.poll() is None, nginx.stderr.read() if nginx.stderr else ""
        # the page through the front end under its name: answered (--allow-origin names it) and
        # a route cookie set; under a name the servers were not given: refused
        for host, status in ((name, 200), ("other.school.test", 403)):
            conn = http.client.HTTPConnection("127.0.0.1", front, timeout=20)
            conn.request("GET", "/", headers={"Host": f"{host}:{front}"})
            page = conn.getresponse()
            body = page.read()
            assert page.status == status, (host, page.status, body[:200])
            conn.close()
            if status == 200:
                assert b"<html" in body.lower()
                assert re.match(r"tcp_pendant_route=[0-9a-f]{32}; Path=/", page.getheader("Set-Cookie") or "")

        # a browser per route cookie until each server has one (consistent hash: a cookie
        # always leads to the same server)
        by_app: dict[int, tuple[str, DrainingClient]] = {}
        for i in range(40):
            if len(by_app) == 2:
                break
            before = [len(a.sessions) for a in apps]
            cookie = f"tcp_pendant_route=browser-{i}"
            c = DrainingClient(front, headers={"Cookie": cookie, "Origin": origin}, host_name=name)
            clients.append(c)
            wait_until(lambda: sum(len(a.sessions) for a in apps) == sum(before) + 1, what="a session")
            k = next(j for j, a in enumerate(apps) if len(a.sessions) > before[j])
            by_app.setdefault(k, (cookie, c))
        assert sorted(by_app) == [0, 1], "40 route cookies all led to one server"

        def session_of(app, client_count: int):
            wait_until(lambda: all("identity" in s.views for s in app.sessions.values()),
                       what="the name prompt")
            return list(app.sessions.values())[client_count - 1]

        names = {0: "Ana", 1: "Bea"}
        for k, app in enumerate(apps):
            prompt = _join(session_of(app, len(app.sessions)), names[k])
            assert prompt.name == names[k]
        with Gradebook(url, create=False) as book:
            assert book.trainees.held_names() == ["Ana", "Bea"]  # one class, two servers

        # the same route cookie leads to the same server again (the websocket of a reload)
        cookie_b, _ = by_app[1]
        before = [len(a.sessions) for a in apps]
        again = DrainingClient(front, headers={"Cookie": cookie_b, "Origin": origin}, host_name=name)
        clients.append(again)
        wait_until(lambda: len(apps[1].sessions) == before[1] + 1, what="the same server again")
        assert len(apps[0].sessions) == before[0]
        # there, another browser typing the name Ana holds on the other server is refused: she
        # is connected there (the gradebook's presence table)
        thief = _join(session_of(apps[1], len(apps[1].sessions)), "Ana")
        assert thief.name is None and "Ana is already connected in another browser" in thief.message.content
        # and a page from another web site cannot open a websocket through the front end
        with pytest.raises(Exception, match="403"):
            DrainingClient(front, headers={"Cookie": cookie_b, "Origin": "http://evil.example"}, host_name=name)
    finally:
        for c in clients:
            c.close()
        nginx.terminate()
        try:
            nginx.wait(timeout=20)
        except subprocess.TimeoutExpired:
            nginx.kill()
            nginx.wait(timeout=20)
