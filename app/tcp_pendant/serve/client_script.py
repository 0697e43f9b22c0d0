"""Our own static script in the page: keyboard shortcuts, the remembered name and browser key,
the trainer URL, a constant style sheet for the screen sizes (tip views over the 3D view, touch
targets on coarse pointers, the phone's bottom sheet) and the release click of every held jog key.

viser 1.1 gives the Python side no keyboard events, no browser storage and no page URL. A few
lines of JavaScript in the page can (``static/pendant.js``): keys click the pendant's own GUI
buttons (so the server path is exactly the click path), "Your name" and the browser key the
server issued at the join (``views.identity``) are remembered in the browser's
``localStorage`` and typed into the next welcome window, and ``/?trainer=TOKEN`` fills the
trainer token.

What this module serves, in front of viser's static-file server (``process_request`` of its
``websockets`` server, reached through :func:`tcp_pendant.serve.origin_check.set_http_layer`):

* ``GET /`` and ``GET /index.html`` (and the paths viser maps to them): viser's own response
  with one ``<script src="tcp-pendant/pendant.js"></script>`` inserted right after
  ``<head>``: a classic script, not deferred, so it runs before viser's loader (the next script
  in the head) starts the page's code: the script wraps the page's ``Worker`` constructor before
  viser makes its websocket worker (a deferred script arriving late, over a slow link, ran after
  it and saw nothing of the connection); headers as viser's (the length recomputed; gzip kept when viser used it). The
  ``src`` is relative, so a reverse proxy that serves the pendant under a path prefix
  (``https://school.example/pendant/``) still finds the script.
* ``GET /tcp-pendant/pendant.js``: the script's bytes, read once from the package at import of
  :func:`script_asset` (never a path from the request), ``text/javascript``, gzip when the
  browser accepts it.
* any other path under ``/tcp-pendant/``: 404, touching no file.
* everything else, websocket upgrades included: to viser, unchanged.

Not an XSS hole: the script is a fixed file we author; no request, user text or server state
is ever written into it or into the page around it (the tag is a constant).
"""

from __future__ import annotations

import gzip
import http
import logging
import re
import threading
from dataclasses import dataclass
from importlib import resources
from typing import TYPE_CHECKING
from urllib.parse import unquote

from websockets.datastructures import Headers
from websockets.http11 import Request, Response

if TYPE_CHECKING:
    from websockets.asyncio.server import ServerConnection

    from tcp_pendant.serve.origin_check import ProcessRequest

__all__ = ["SCRIPT_PATH", "SCRIPT_TAG", "ScriptAsset", "inject_script_tag", "is_index_path", "serve",
           "script_asset"]

log = logging.getLogger(__name__)

PREFIX = "tcp-pendant"
"""The first path segment of everything this module answers."""
SCRIPT_PATH = f"/{PREFIX}/pendant.js"
"""Where the page loads the script from."""
SCRIPT_TAG = f'<script src="{SCRIPT_PATH[1:]}"></script>'.encode("ascii")
"""The one tag inserted into viser's index.html."""
JS_CONTENT_TYPE = "text/javascript; charset=utf-8"

_HEAD = re.compile(rb"<head(\s[^>]*)?>", re.IGNORECASE)


@dataclass(frozen=True)
class ScriptAsset:
    """The script's bytes, plain and gzipped (read once).

    Attributes:
        body: the file's bytes (UTF-8 JavaScript).
        gzipped: ``body`` gzip-compressed.
    """

    body: bytes
    gzipped: bytes


_asset_lock = threading.Lock()
_asset: ScriptAsset | None = None
_index_cache: dict[tuple[str, bytes], bytes] = {}


def script_asset() -> ScriptAsset:
    """The packaged ``static/pendant.js`` (read on first use, then kept)."""
    global _asset
    with _asset_lock:
        if _asset is None:
            body = (resources.files("tcp_pendant.serve") / "static" / "pendant.js").read_bytes()
            _asset = ScriptAsset(body, gzip.compress(body, mtime=0))
        return _asset


def _segments(raw_path: str) -> list[str]:
    """The path's segments as viser's static server sees them (query dropped, percent-decoded,
    backslashes as slashes, empty and ``.`` segments dropped)."""
    path = unquote(raw_path.partition("?")[0]).replace("\\", "/")
    return [s for s in path.split("/") if s and s != "."]


def is_index_path(raw_path: str) -> bool:
    """True for the paths viser answers with its index.html (``/``, ``/index.html``, ``//`` ...)."""
    return _segments(raw_path) in ([], ["index.html"])


def inject_script_tag(html: bytes) -> bytes:
    """``html`` with :data:`SCRIPT_TAG` right after its ``<head>`` tag.

    Raises:
        ValueError: no ``<head>`` tag, or the tag is there already.
    """
    if SCRIPT_TAG in html:
        raise ValueError("the page already holds the pendant script")
    m = _HEAD.search(html)
    if m is None:
        raise ValueError("the page has no <head> tag")
    return html[:m.end()] + SCRIPT_TAG + html[m.end():]


def _plain(status: http.HTTPStatus, text: str) -> Response:
    body = text.encode("utf-8")
    return Response(status.value, status.phrase, Headers({"Content-Type": "text/plain; charset=utf-8",
                                                          "Content-Length": str(len(body))}), body)


def _script_response(request: Request) -> Response:
    asset = script_asset()
    use_gzip = "gzip" in str(request.headers.get("Accept-Encoding", ""))
    body = asset.gzipped if use_gzip else asset.body
    headers = Headers({"Content-Type": JS_CONTENT_TYPE, "Content-Length": str(len(body)),
                       "Content-Encoding": "gzip" if use_gzip else "identity", "Vary": "Accept-Encoding",
                       "Cache-Control": "no-cache", "X-Content-Type-Options": "nosniff"})
    return Response(http.HTTPStatus.OK.value, "OK", headers, body)


def _index_response(response: Response | None) -> Response | None:
    """viser's index.html response with the script tag (viser's response itself if it is not a
    200 HTML page or holds no ``<head>``)."""
    if response is None or getattr(response, "status_code", None) != 200:
        return response
    headers = response.headers
    if not str(headers.get("Content-Type", "")).startswith("text/html"):
        return response
    encoding = str(headers.get("Content-Encoding", "identity")).lower()
    if encoding not in ("gzip", "identity"):
        return response
    body = bytes(response.body)
    key = (encoding, body)
    new_body = _index_cache.get(key)
    if new_body is None:
        html = gzip.decompress(body) if encoding == "gzip" else body
        try:
            page = inject_script_tag(html)
        except ValueError as exc:
            log.warning("viser's page left as it is (%s): no keyboard shortcuts", exc)
            return response
        new_body = gzip.compress(page, mtime=0) if encoding == "gzip" else page
        if len(_index_cache) > 8:                 # viser's page does not change; bound it anyway
            _index_cache.clear()
        _index_cache[key] = new_body
    new_headers = Headers()
    for name, value in headers.raw_items():
        if name.lower() != "content-length":
            new_headers[name] = value
    new_headers["Content-Length"] = str(len(new_body))
    return Response(response.status_code, response.reason_phrase, new_headers, new_body)


def serve(connection: ServerConnection, request: Request, process_request: ProcessRequest | None) -> Response | None:
    """The HTTP layer (``origin_check.set_http_layer``): answer a plain GET (module docstring).

    Args:
        connection: the ``websockets`` server connection.
        request: its ``Request`` (``path``, ``headers``).
        process_request: viser's static-file server, ``process_request(connection, request)``,
            or None.

    Returns:
        A ``Response``, or None to go on with the websocket handshake (viser's answer).
    """
    def viser() -> Response | None:
        return None if process_request is None else process_request(connection, request)

    try:
        segments = _segments(str(request.path))
    except Exception:  # a path unquote cannot read: viser decides
        return viser()
    if segments and segments[0] == PREFIX:
        if segments == [PREFIX, "pendant.js"]:
            return _script_response(request)
        return _plain(http.HTTPStatus.NOT_FOUND, "Not found.\n")
    if segments in ([], ["index.html"]):
        response = viser()
        try:
            return _index_response(response)
        except Exception:  # never worse than viser's own page
            log.exception("adding the pendant script to the page failed")
            return response
    return viser()
