"""Drive viser GUI handles from a test the way a browser's events arrive.

A browser's click or edit reaches the server as a ``GuiEvent`` whose ``client`` is the
browser's ``ClientHandle``; the views ignore events without a client (their own assignments).
These helpers set the value the browser would send and call the handle's callbacks with such
an event: plain callbacks in the calling thread (viser would use its thread pool), ``async``
ones on the server's own event loop, as viser does, waiting until they are done.
"""

from __future__ import annotations

import asyncio
import inspect
from typing import Any

from viser._gui_handles import GuiEvent, UploadedFile


def _fire(handle: Any, client: Any) -> None:
    for cb in list(handle._impl.update_cb):
        out = cb(GuiEvent(client=client, client_id=getattr(client, "client_id", None), target=handle))
        if inspect.isawaitable(out):
            loop = handle._impl.gui_api._event_loop
            asyncio.run_coroutine_threadsafe(out, loop).result(timeout=60)


def click(handle: Any, client: Any) -> None:
    """A click on a button."""
    _fire(handle, client)


def choose(handle: Any, value: Any, client: Any) -> None:
    """The browser sets a dropdown, slider, checkbox or text field to ``value``."""
    handle._impl.value = type(handle._impl.value)(value)
    _fire(handle, client)


def upload(handle: Any, name: str, content: bytes, client: Any) -> None:
    """A file uploaded through an upload button."""
    handle._impl.value = UploadedFile(name, content)
    _fire(handle, client)
