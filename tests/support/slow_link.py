"""A slow network link in front of a server, for a browser test: a TCP relay on a port of its
own whose answer to each new connection reaches the browser ``delay_s`` late (every later byte
of that connection flows at once). A websocket handshake through it takes ``delay_s``; so does
each page or file request. The upstream port may go away and come back (a server restarted on
it): a connection made meanwhile is closed, as a refused one would be.
"""

from __future__ import annotations

import socket
import threading
import time

from support.wsclient import free_port

__all__ = ["SlowLink"]


class SlowLink:
    """``SlowLink(upstream_port, delay_s)``: relays ``127.0.0.1:port`` to the upstream port;
    ``url`` is its address; :meth:`close` stops it."""

    def __init__(self, upstream_port: int, delay_s: float) -> None:
        self.upstream_port, self.delay_s = upstream_port, float(delay_s)
        self.port = free_port()
        self._listener = socket.create_server(("127.0.0.1", self.port))
        self._closed = False
        threading.Thread(target=self._accept, name="slow-link", daemon=True).start()

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    def close(self) -> None:
        self._closed = True
        self._listener.close()

    def _accept(self) -> None:
        while not self._closed:
            try:
                client, _ = self._listener.accept()
            except OSError:
                return
            threading.Thread(target=self._relay, args=(client,), daemon=True).start()

    def _relay(self, client: socket.socket) -> None:
        try:
            upstream = socket.create_connection(("127.0.0.1", self.upstream_port), timeout=5.0)
        except OSError:
            client.close()                       # the server is down: as a refused connection
            return
        upstream.settimeout(None)
        threading.Thread(target=self._pipe, args=(client, upstream, 0.0), daemon=True).start()
        self._pipe(upstream, client, self.delay_s)

    @staticmethod
    def _pipe(src: socket.socket, dst: socket.socket, first_delay_s: float) -> None:
        delay = first_delay_s
        try:
            while True:
                data = src.recv(65536)
                if not data:
                    break
                if delay:
                    time.sleep(delay)            # the link's latency, once per connection
                    delay = 0.0
                dst.sendall(data)
        except OSError:
            pass
        finally:
            for s in (src, dst):
                try:
                    s.shutdown(socket.SHUT_RDWR)
                except OSError:
                    pass
                s.close()
