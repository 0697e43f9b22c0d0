"""A minimal headless viser client for tests and the benchmark: a websocket that speaks viser's
subprotocol and drains whatever the server sends (no rendering)."""

from __future__ import annotations

import threading

import msgspec.msgpack
import viser
from viser import _messages
from websockets.sync.client import connect


class DrainingClient:
    """Connects to a viser server and reads (and discards) every message in a thread.

    Attributes:
        n_messages, n_bytes: what the server sent so far.
    """

    def __init__(self, port: int, host: str = "127.0.0.1") -> None:
        self.ws = connect(f"ws://{host}:{port}", subprotocols=[f"viser-v{viser.__version__}"],
                          max_size=None, open_timeout=20)
        self.n_messages = 0
        self.n_bytes = 0
        self._thread = threading.Thread(target=self._drain, daemon=True)
        self._thread.start()
        # viser counts a client as connected at its first camera message
        cam = _messages.ViewerCameraMessage(wxyz=(1.0, 0.0, 0.0, 0.0), position=(2.0, -2.0, 1.0), fov=1.0,
                                            near=0.01, far=100.0, image_height=720, image_width=1280,
                                            look_at=(0.0, 0.0, 0.5), up_direction=(0.0, 0.0, 1.0))
        self.ws.send(msgspec.msgpack.encode(cam.as_serializable_dict()))

    def _drain(self) -> None:
        try:
            for msg in self.ws:
                self.n_messages += 1
                self.n_bytes += len(msg)
        except Exception:
            pass

    def close(self) -> None:
        """Close the websocket (the server then fires on_client_disconnect)."""
        try:
            self.ws.close()
        finally:
            self._thread.join(timeout=10)
