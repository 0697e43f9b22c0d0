"""Foreign web pages cannot connect: an allow-list of host names and an Origin check.

**Host names.** A web site can make a browser's page talk to any address by pointing its own
name at it (DNS rebinding): the page's requests then carry ``Host: evil.example`` and
``Origin: http://evil.example``, which agree with each other. So every request, plain HTTP
and websocket upgrade alike, is answered only when its one ``Host`` header names a host this
server serves (:func:`served_hosts`: its bind address, the names and addresses it prints at
start, ``localhost`` / ``127.0.0.1`` / ``::1``, and the ``--allow-origin`` hosts); anything
else, a ``Host`` with userinfo (``x@``), or more than one ``Host`` header, gets HTTP 403
(:func:`host_refusal`). The port of ``Host`` is not compared (a reverse proxy may drop it).

**Origin.** A browser lets any web page open a websocket to any address, loopback included,
and says which page asked in the ``Origin`` header. Every websocket upgrade whose ``Origin`` is
present and is neither the origin the page was served from (its host and port equal the
``Host`` header the request came to) nor listed with ``--allow-origin`` (a reverse proxy that
rewrites ``Host``) is refused with 403, and so is an upgrade with more than one ``Origin``.
Requests without ``Origin`` (non-browser clients, the tests' websocket clients) and plain HTTP
requests (the page itself) pass this check.

Where: viser builds its ``websockets`` server inside its background thread and passes no hook
to it, so the thinnest layer that sees the handshake is ``websockets``' own
``ServerConnection.handshake``. :func:`enable` wraps it once per process: the wrapper puts the
checks in front of the ``process_request`` that viser passes (its static-file server), so a
refused request is answered 403 before viser sees it. Policies are per listening port
(:func:`allow`); a port without one serves the loopback names only, with the plain
same-origin rule, so the checks hold from the first connection even before the server's port
is known. A port may also have an HTTP layer (:func:`set_http_layer`:
``client_script.serve``, the page's own script) that answers plain HTTP requests, behind the
checks and in front of viser's static server.

**Not before it is ready.** viser listens as soon as its server object exists, well before the
pendant has put its policies, its page script and its session handlers in place (seconds on a
busy machine): a page loaded then lacked the script (no remembered name and key: a reload
after a restart stayed at the welcome window) and a websocket connected then got no session.
So while a pendant starts (:func:`starting`), every port without a policy yet, and the
pendant's own port once it has one (:func:`allow`), answers every request (after the checks
above) with HTTP 503 "starting" until the pendant marks it ready (:func:`mark_ready`); a
browser's reload, viser's own reconnect and a readiness probe simply retry. A port without a
policy while no pendant starts (a bare viser server in the same process) is not held back.
"""

from __future__ import annotations

import http
import logging
import threading
from collections.abc import Callable, Coroutine, Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any
from urllib.parse import urlsplit

if TYPE_CHECKING:
    from websockets.asyncio.server import ServerConnection
    from websockets.datastructures import Headers
    from websockets.http11 import Request, Response

    ProcessRequest = Callable[[ServerConnection, Request], Response | None]
    """viser's static-file server as websockets calls it: a response, or None to go on with the
    websocket handshake."""
    HttpLayer = Callable[[ServerConnection, Request, ProcessRequest | None], Response | None]
    """An HTTP layer in front of viser's static server (:func:`set_http_layer`)."""

__all__ = ["LOOPBACK_HOSTS", "STARTING", "OriginError", "allow", "enable", "forget", "host_refusal", "mark_ready",
           "normalize_origin", "origin_refusal", "parse_allow_origins", "served_hosts", "set_http_layer", "starting"]

log = logging.getLogger(__name__)

_DEFAULT_PORTS = {"http": 80, "https": 443}
_lock = threading.Lock()
_allowed_by_port: dict[int, frozenset[str]] = {}
_hosts_by_port: dict[int, frozenset[str]] = {}
_original_handshake: Callable[..., Coroutine[object, object, None]] | None = None
_http_layers: dict[int, HttpLayer] = {}
_ready_ports: set[int] = set()
_starting = 0                     # pendants of this process inside starting()
STARTING = "The pendant is starting; reload in a moment."
"""The answer (HTTP 503) of a port that is not ready yet."""


LOOPBACK_HOSTS = frozenset({"localhost", "127.0.0.1", "::1"})
"""Host names every server answers to (only this machine reaches them)."""

_WILDCARD_BINDS = ("0.0.0.0", "::", "")


class OriginError(ValueError):
    """An ``--allow-origin`` value that is not ``http(s)://host[:port]``."""


def _split(origin: str) -> tuple[str, str, int]:
    """(scheme, host, port) of ``scheme://host[:port]``; ValueError if it is anything else."""
    parts = urlsplit(origin.strip())
    scheme = parts.scheme.lower()
    if scheme not in _DEFAULT_PORTS or not parts.hostname or parts.path not in ("", "/") \
            or parts.query or parts.fragment or parts.username or parts.password:
        raise ValueError(origin)
    port = parts.port                       # ValueError for a bad port
    return scheme, parts.hostname.lower(), _DEFAULT_PORTS[scheme] if port is None else port


def normalize_origin(origin: str) -> str:
    """``Scheme://Host[:port][/]`` -> ``scheme://host[:port]`` (lower case, default port dropped).

    Raises:
        OriginError: not an http or https origin.
    """
    try:
        scheme, host, port = _split(origin)
    except ValueError:
        raise OriginError(f"{origin!r} is not a web origin; give scheme://host[:port], "
                          "e.g. https://pendant.example.org or http://10.0.0.5:8080.") from None
    shown = f"[{host}]" if ":" in host else host
    return f"{scheme}://{shown}" + ("" if port == _DEFAULT_PORTS[scheme] else f":{port}")


def parse_allow_origins(values: Iterable[str]) -> tuple[str, ...]:
    """The ``--allow-origin`` values (each may hold several, comma-separated), normalized.

    Raises:
        OriginError: a value that is not ``http(s)://host[:port]``.
    """
    out: list[str] = []
    for value in values:
        for item in str(value).split(","):
            if item.strip():
                origin = normalize_origin(item)
                if origin not in out:
                    out.append(origin)
    return tuple(out)


def _header_values(headers: Headers | Mapping[str, str], name: str) -> list[str]:
    get_all = getattr(headers, "get_all", None)
    return [str(v) for v in get_all(name)] if callable(get_all) else ([str(headers[name])] if name in headers else [])


def _host_name(value: str) -> str | None:
    """The host name of a ``Host`` header value (lower case, IPv6 without brackets), or None
    when it is not ``host[:port]``."""
    value = value.strip()
    if not value or any(c in value for c in "@/?#\\ \t"):
        return None
    try:
        parts = urlsplit("//" + value)
        parts.port                                      # noqa: B018  (ValueError for a bad port)
    except ValueError:
        return None
    return (parts.hostname or "").lower() or None


def _shown(value: str) -> str:
    return repr(value if len(value) <= 100 else value[:100] + "...")


def served_hosts(bind_host: str, urls: Iterable[str] = (), allow_origins: Iterable[str] = ()) -> frozenset[str]:
    """The host names a server answers to: :data:`LOOPBACK_HOSTS`, ``bind_host`` (unless it is
    a wildcard such as ``0.0.0.0``), and the hosts of ``urls`` (the network URLs it prints) and
    of ``allow_origins`` (normalized ``--allow-origin`` values)."""
    hosts = set(LOOPBACK_HOSTS)
    bind = bind_host.strip().strip("[]").lower()
    if bind not in _WILDCARD_BINDS:
        hosts.add(bind)
    for url in (*urls, *allow_origins):
        name = urlsplit(url).hostname
        if name:
            hosts.add(name.lower())
    return frozenset(hosts)


def host_refusal(headers: Headers | Mapping[str, str], hosts: Iterable[str] = LOOPBACK_HOSTS) -> str | None:
    """Why a request with these headers is refused for its ``Host``, or None to answer it.

    Args:
        headers: the request's headers (``websockets`` ``Headers`` or a mapping).
        hosts: the host names served (:func:`served_hosts`).
    """
    values = _header_values(headers, "Host")
    if len(values) != 1:
        return "Refused: a request needs exactly one Host header."
    name = _host_name(values[0])
    if name is None or name not in set(hosts):
        return (f"Refused: this pendant is not served as {_shown(values[0])}. Open one of the addresses it "
                "printed at start, or start it with --allow-origin for a reverse proxy.")
    return None


def origin_refusal(headers: Headers | Mapping[str, str], allowed: Iterable[str] = ()) -> str | None:
    """Why a websocket upgrade with these request headers is refused, or None to accept it.

    Args:
        headers: the request's headers (``websockets`` ``Headers`` or a mapping).
        allowed: normalized extra origins (:func:`parse_allow_origins`).
    """
    origins = _header_values(headers, "Origin")
    if not origins:
        return None                                   # not a browser: nothing to compare
    if len(origins) > 1:
        return "Refused: more than one Origin header."
    origin = origins[0]
    try:
        scheme, host, port = _split(origin)
    except ValueError:
        return f"Refused: the page's origin {_shown(origin)} is not a web page served by this pendant."
    if normalize_origin(origin) in set(allowed):
        return None
    host_headers = _header_values(headers, "Host")
    host_header = host_headers[0] if len(host_headers) == 1 else None
    if host_header:
        try:
            target = urlsplit("//" + str(host_header).strip())
            t_host = (target.hostname or "").lower()
            t_port = target.port if target.port is not None else _DEFAULT_PORTS[scheme]
        except ValueError:
            t_host, t_port = "", -1
        if t_host == host and t_port == port:
            return None
    return (f"Refused: a page from {_shown(origin)} may not connect to this pendant (served as "
            f"{_shown(str(host_header))}). Open the pendant's own address, or start it with --allow-origin "
            "for a reverse proxy.")


def _is_upgrade(request: Request) -> bool:
    return any(v.lower() == "websocket" for v in _header_values(request.headers, "Upgrade"))


def _allowed_for(connection: ServerConnection) -> tuple[frozenset[str], HttpLayer | None, frozenset[str], bool]:
    """The extra origins, the HTTP layer, the served host names of the port ``connection``
    came to, and whether that port is ready (:func:`mark_ready`)."""
    try:
        port = int(connection.local_address[1])
    except Exception:  # no socket address: same-origin rule, loopback names only
        return frozenset(), None, LOOPBACK_HOSTS, True
    with _lock:
        ready = port in _ready_ports if port in _hosts_by_port else _starting == 0
        return (_allowed_by_port.get(port, frozenset()), _http_layers.get(port),
                _hosts_by_port.get(port, LOOPBACK_HOSTS), ready)


def enable() -> None:
    """Put the host and origin checks in front of every request of this process (idempotent)."""
    global _original_handshake
    from websockets.asyncio.server import ServerConnection

    with _lock:
        if _original_handshake is not None:
            return
        original = _original_handshake = ServerConnection.handshake

    async def handshake(self: ServerConnection, process_request: ProcessRequest | None = None,
                        *args: Any, **kwargs: Any) -> None:         # websockets' other arguments, passed on
        allowed, layer, hosts, ready = _allowed_for(self)

        def checked(connection: ServerConnection, request: Request) -> Response | None:
            try:
                return answer(connection, request)
            except Exception as exc:                # a request nobody foresaw: one line, no traceback
                log.warning("request from %s for %s failed: %s: %s", _peer(connection),
                            _shown(str(getattr(request, "path", "?"))), type(exc).__name__, _shown(str(exc)))
                return connection.respond(http.HTTPStatus.BAD_REQUEST, "Bad request.\n")

        def answer(connection: ServerConnection, request: Request) -> Response | None:
            refusal = host_refusal(request.headers, hosts)
            if refusal is None and _is_upgrade(request):
                refusal = origin_refusal(request.headers, allowed)
            if refusal is not None:
                log.warning("request from %s: %s", _peer(connection), refusal)
                return connection.respond(http.HTTPStatus.FORBIDDEN, refusal + "\n")
            if not ready:
                return connection.respond(http.HTTPStatus.SERVICE_UNAVAILABLE, STARTING + "\n")
            if layer is not None and not _is_upgrade(request):
                return layer(connection, request, process_request)
            return None if process_request is None else process_request(connection, request)

        return await original(self, checked, *args, **kwargs)

    handshake.__doc__ = original.__doc__
    ServerConnection.handshake = handshake  # type: ignore[method-assign,assignment]  # viser's process_request is sync


def _peer(connection: ServerConnection) -> str:
    try:
        return f"{connection.remote_address[0]}:{connection.remote_address[1]}"
    except Exception:
        return "?"


def set_http_layer(port: int, layer: HttpLayer | None) -> None:
    """On the server listening on ``port``, answer plain HTTP requests (not upgrades) with
    ``layer(connection, request, process_request)`` in front of viser's static server
    (``tcp_pendant.serve.client_script.serve``; None: viser alone). The origin check is unchanged."""
    with _lock:
        if layer is None:
            _http_layers.pop(int(port), None)
        else:
            _http_layers[int(port)] = layer


def allow(port: int, origins: Sequence[str], hosts: Iterable[str] = LOOPBACK_HOSTS) -> None:
    """On the server listening on ``port``, answer requests for ``hosts`` (:func:`served_hosts`)
    and also accept pages from ``origins`` (normalized)."""
    with _lock:
        _allowed_by_port[int(port)] = frozenset(origins)
        _hosts_by_port[int(port)] = frozenset(h.lower() for h in hosts)


@contextmanager
def starting() -> Iterator[None]:
    """While a pendant starts: a port without a policy answers 503 (module docstring)."""
    global _starting
    with _lock:
        _starting += 1
    try:
        yield
    finally:
        with _lock:
            _starting -= 1


def mark_ready(port: int) -> None:
    """The server listening on ``port`` is ready: its requests are answered from now on (until
    then: HTTP 503, :data:`STARTING`)."""
    with _lock:
        _ready_ports.add(int(port))


def forget(port: int) -> None:
    """Drop the extra origins, the host names, the HTTP layer and the readiness of ``port``
    (the server stopped)."""
    with _lock:
        _ready_ports.discard(int(port))
        _allowed_by_port.pop(int(port), None)
        _hosts_by_port.pop(int(port), None)
        _http_layers.pop(int(port), None)
