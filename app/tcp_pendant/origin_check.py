"""Foreign web pages cannot connect: refuse websocket upgrades from another origin.

A browser lets any web page open a websocket to any address, loopback included, and says which
page asked in the ``Origin`` header. viser 1.1 accepts every upgrade, so a page a trainee opens
could drive the pendant. This module refuses, with HTTP 403, every websocket upgrade whose
``Origin`` is present and is neither the origin the page was served from (its host and port equal
the ``Host`` header the request came to) nor listed with ``--allow-origin`` (a reverse proxy
that rewrites ``Host``). Requests without ``Origin`` (non-browser clients, the tests' websocket
clients) and plain HTTP requests (the page itself) are not affected.

Where: viser builds its ``websockets`` server inside its background thread and passes no hook
to it, so the thinnest layer that sees the handshake is ``websockets``' own
``ServerConnection.handshake``. :func:`enable` wraps it once per process: the wrapper puts the
origin check in front of the ``process_request`` that viser passes (its static-file server),
so a refused upgrade is answered 403 before viser sees it. Policies are per listening port
(:func:`allow`); a port without one gets the plain same-origin rule, so the check holds from the
first connection even before the server's port is known. A port may also have an HTTP layer
(:func:`set_http_layer`: ``client_script.serve``, the page's own script) that answers plain
HTTP requests, behind the check and in front of viser's static server.
"""

from __future__ import annotations

import http
import logging
import threading
from collections.abc import Iterable, Sequence
from typing import Any
from urllib.parse import urlsplit

__all__ = ["OriginError", "allow", "enable", "forget", "normalize_origin", "origin_refusal",
           "parse_allow_origins", "set_http_layer"]

log = logging.getLogger(__name__)

_DEFAULT_PORTS = {"http": 80, "https": 443}
_lock = threading.Lock()
_allowed_by_port: dict[int, frozenset[str]] = {}
_original_handshake: Any = None
_http_layers: dict[int, Any] = {}


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


def origin_refusal(headers: Any, allowed: Iterable[str] = ()) -> str | None:
    """Why a websocket upgrade with these request headers is refused, or None to accept it.

    Args:
        headers: the request's headers (``websockets`` ``Headers`` or a mapping).
        allowed: normalized extra origins (:func:`parse_allow_origins`).
    """
    get_all = getattr(headers, "get_all", None)
    origins = list(get_all("Origin")) if callable(get_all) else \
        ([headers["Origin"]] if "Origin" in headers else [])
    if not origins:
        return None                                   # not a browser: nothing to compare
    if len(origins) > 1:
        return "Refused: more than one Origin header."
    origin = origins[0]
    try:
        scheme, host, port = _split(origin)
    except ValueError:
        return f"Refused: the page's origin {origin!r} is not a web page served by this pendant."
    if normalize_origin(origin) in set(allowed):
        return None
    host_header = headers.get("Host") if hasattr(headers, "get") else None
    if host_header:
        try:
            target = urlsplit("//" + str(host_header).strip())
            t_host = (target.hostname or "").lower()
            t_port = target.port if target.port is not None else _DEFAULT_PORTS[scheme]
        except ValueError:
            t_host, t_port = "", -1
        if t_host == host and t_port == port:
            return None
    return (f"Refused: a page from {origin} may not connect to this pendant (served as {host_header}). "
            "Open the pendant's own address, or start it with --allow-origin for a reverse proxy.")


def _is_upgrade(request: Any) -> bool:
    return str(request.headers.get("Upgrade", "")).lower() == "websocket"


def _allowed_for(connection: Any) -> tuple[frozenset[str], Any]:
    """The extra origins and the HTTP layer of the port ``connection`` came to."""
    try:
        port = int(connection.local_address[1])
    except Exception:  # no socket address: same-origin rule only
        return frozenset(), None
    with _lock:
        return _allowed_by_port.get(port, frozenset()), _http_layers.get(port)


def enable() -> None:
    """Put the origin check in front of every websocket handshake of this process (idempotent)."""
    global _original_handshake
    from websockets.asyncio.server import ServerConnection

    with _lock:
        if _original_handshake is not None:
            return
        original = _original_handshake = ServerConnection.handshake

    async def handshake(self: Any, process_request: Any = None, *args: Any, **kwargs: Any) -> None:
        allowed, layer = _allowed_for(self)

        def checked(connection: Any, request: Any) -> Any:
            if _is_upgrade(request):
                refusal = origin_refusal(request.headers, allowed)
                if refusal is not None:
                    log.warning("websocket from %s: %s", request.headers.get("Origin"), refusal)
                    return connection.respond(http.HTTPStatus.FORBIDDEN, refusal + "\n")
            if layer is not None and not _is_upgrade(request):
                return layer(connection, request, process_request)
            return None if process_request is None else process_request(connection, request)

        return await original(self, checked, *args, **kwargs)

    handshake.__doc__ = original.__doc__
    ServerConnection.handshake = handshake  # type: ignore[method-assign]


def set_http_layer(port: int, layer: Any) -> None:
    """On the server listening on ``port``, answer plain HTTP requests (not upgrades) with
    ``layer(connection, request, process_request)`` in front of viser's static server
    (``tcp_pendant.client_script.serve``; None: viser alone). The origin check is unchanged."""
    with _lock:
        if layer is None:
            _http_layers.pop(int(port), None)
        else:
            _http_layers[int(port)] = layer


def allow(port: int, origins: Sequence[str]) -> None:
    """Also accept pages from ``origins`` (normalized) on the server listening on ``port``."""
    with _lock:
        _allowed_by_port[int(port)] = frozenset(origins)


def forget(port: int) -> None:
    """Drop the extra origins and the HTTP layer of ``port`` (the server stopped)."""
    with _lock:
        _allowed_by_port.pop(int(port), None)
        _http_layers.pop(int(port), None)
