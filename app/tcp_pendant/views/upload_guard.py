"""Refuse an oversized upload at viser's file-transfer layer, before it is buffered.

viser 1.1 receives an upload as a ``FileTransferStartUpload`` message (file name, announced
``size_bytes``, ``part_count``) and then ``FileTransferPart`` messages, which its ``GuiApi``
buffers in ``_current_file_upload_states`` until every part has come; only then does the upload
button's ``on_upload`` callback run. It sets no size limit, so a browser could make the server
hold any amount of data before our callback can look at it.

:func:`limit_upload_size` registers two more handlers for those messages on the same websocket
interface as viser's own ``GuiApi`` (``register_handler`` appends, so they run right after
viser's): when the announced size is above the limit the transfer's state is dropped at once
(viser then ignores the following parts), and a transfer whose parts add up to more than the
limit (a client lying about its size) is dropped as soon as it does. Either way the session
is told once. viser's internals are reached through ``views.viser_adapter.upload_hook``; if a
viser version lacks them the guard is skipped (logged) and the size check in the upload callback
still runs before any parsing. Every upload, guarded here or not, is also bounded per browser
and per server, and times out (``views.viser_adapter.UploadLimits``).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TYPE_CHECKING

import viser

from tcp_pendant.views.viser_adapter import upload_hook

if TYPE_CHECKING:
    from viser.infra import ClientId

    from tcp_pendant.views.viser_adapter import UploadPart, UploadStart

__all__ = ["limit_upload_size"]

log = logging.getLogger(__name__)


def limit_upload_size(handle: viser.GuiUploadButtonHandle, max_bytes: int,
                      on_refused: Callable[[str, int], None]) -> bool:
    """Drop uploads to the upload button ``handle`` bigger than ``max_bytes`` as they start.

    Args:
        handle: a ``viser.GuiUploadButtonHandle``.
        max_bytes: largest accepted file, bytes.
        on_refused: called (on viser's event loop) with the file name and its announced (or
            received so far) size in bytes, once per refused transfer.

    Returns:
        True when the guard is installed; False when this viser lacks the hook (then only the
        callback's own check applies).
    """
    hook = upload_hook(handle)
    if hook is None:
        log.warning("viser has no file-transfer hook: uploads are size-checked only after they arrived")
        return False
    uuid, states = hook.uuid, hook.states

    def on_start(_client_id: ClientId, message: UploadStart) -> None:
        if message.source_component_uuid != uuid:
            return
        size = int(getattr(message, "size_bytes", 0) or 0)
        if size > max_bytes and states.pop(message.transfer_uuid, None) is not None:
            on_refused(str(message.filename), size)

    def on_part(_client_id: ClientId, message: UploadPart) -> None:
        if message.source_component_uuid != uuid:
            return
        state = states.get(message.transfer_uuid)
        if state is not None and int(state.get("transferred_bytes", 0)) > max_bytes:
            states.pop(message.transfer_uuid, None)
            on_refused(str(state.get("filename", "")), int(state["transferred_bytes"]))

    hook.register(on_start, on_part)
    return True
