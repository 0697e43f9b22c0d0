"""Every use of viser's private API, in one place (viser ``>=1.1,<1.2``, see pyproject.toml).

viser's public API is enough to build the pendant, but not to make it fast or safe on a class
network. What this module reaches into, and why:

* **Fast paths** (the readouts and the robot pose change on every jog step):
  :func:`queue_markdown` stores a markdown's ``_markdown`` prop and queues viser's
  ``GuiUpdateMessage`` itself (``handle._impl``, ``gui_api._websock_interface``), skipping the
  public setter's per-call typing machinery; :func:`queue_pose` (and :class:`PoseQueue`, one
  per scene node, which the scene keeps) writes a scene node's ``wxyz`` / ``position`` and
  queues ``SetOrientationMessage`` / ``SetPositionMessage`` stamped with the scene's
  ``_owner_id`` as ``api._queue_scene_message`` does, on ``api._websock_interface``, their
  ``_cached_redundancy_key`` set from viser's own ``redundancy_key`` of the node's first
  message. Each returns False when viser's internals differ (:func:`pose_queue`: None), and the
  caller then uses the public setter. Which path ran is counted (:func:`path_counts`); the first
  fallback of each path logs a warning, and with ``TCP_PENDANT_STRICT_VISER=1`` in the
  environment (the tests' flag) a fallback raises :class:`ViserInternalsChanged` instead.
* **The browser's languages** (:func:`accept_language`): the ``Accept-Language`` header of
  a client's websocket handshake, from the connection viser's websocket server keeps per
  client (``_live_connections``): the session's start language.
* **Uploads** (:func:`upload_hook`): the file-transfer messages and ``GuiApi``'s
  ``_current_file_upload_states``, for the per-button size limit of ``views.upload_guard``.
* **Incoming messages** (:func:`install`): viser decodes each websocket message and hands it to
  its handlers in a task of its own, with no check of the values' types; a bad message raised in
  that task ("Task exception was never retrieved", quoting the value) or, when it could not
  even be decoded, closed the sender's socket. :func:`install` wraps viser's message consumer
  (``infra._infra._message_consumer``: a frame that does not decode is dropped, and each
  connection is read at most at the pace of ``message_rate.MessagePacer``, in reads of at most
  :data:`READ_BYTES`, asyncio's transport's ``max_size``; each message is stamped with its
  earliest arrival for the deadman, ``views.arrival``, from the event loop's polls, timed by
  wrapping asyncio's ``loop._selector``, and from what of the connection was still unread when
  it was asked for: websockets' ``recv_messages.frames`` and ``protocol.reader.buffer`` and the
  kernel's ``FIONREAD``) and
  ``WebsockMessageHandler._handle_incoming_message`` (each message is checked, then its
  handlers run under one ``try``): :func:`message_refusal` checks every field against the
  message class's annotations (types, finite numbers), refuses the share-URL requests (a
  trainee must not publish the class server on viser's share tunnel), and for a
  ``GuiUpdateMessage`` :func:`gui_value_refusal` checks the value against its handle (only
  ``value`` may change; type, finite, the handle's min / max, its options, a text length
  limit; nothing for a disabled input, not even a button hold; a refused value is sent back as
  the server holds it).
  Uploads are bounded per client and per server
  (:class:`UploadLimits`). A refused or failing message is logged in one line, user values cut
  at :data:`LOG_VALUE_CHARS` characters, at most :data:`LOG_BUDGET` lines at a time (the rest
  counted: :func:`message_counts`); the socket stays open.
* **One port, several processes** (:func:`listen_reuse_port`): viser 1.1 binds its port in
  ``infra._infra`` with ``websockets.asyncio.server.serve(ws_handler, host, port, ...)`` and
  takes no socket or option of ours; the wrapper adds ``reuse_port=True`` (``SO_REUSEPORT``,
  which ``serve`` hands to ``loop.create_server``), so the server processes of
  ``tcp-pendant --workers N`` listen on the same port and the kernel spreads the connections
  over them.
* **A tab's title** (:func:`set_tab_label`): viser 1.1's ``GuiTabHandle`` has no label setter
  (only ``icon``); the title is its ``_label``, sent in its group's tab tuples, which
  ``_rebuild_tab_props()`` recomputes from the tabs (as the ``icon`` setter does). The tab
  titles follow a switch of the session's language that way.

Moving viser up a minor version: run ``tests/security`` and ``tests/app/test_viser_adapter.py``
(their conftest sets ``TCP_PENDANT_STRICT_VISER=1``: a fallback fails the test), then re-read in
viser's source each name used here: ``_GuiHandleState`` (``uuid``, ``value``, ``props``,
``removed``, ``gui_api``), ``GuiApi._gui_input_handle_from_uuid`` /
``_current_file_upload_states`` / ``_websock_interface``, ``SceneApi._queue_scene_message`` (what
it stamps: ``_owner_id``) / ``_websock_interface``, ``Message.redundancy_key`` (its
``_cached_redundancy_key``),
``GuiTabHandle._label`` / ``_parent._rebuild_tab_props``,
the scene handle's ``_impl`` (``name``, ``wxyz``, ``position``, ``api``),
``WebsockMessageHandler._handle_incoming_message`` / ``_incoming_handlers``,
``infra._infra._message_consumer`` (its signature and its ``deserialize`` call), websockets'
``ServerConnection.recv_messages.frames`` / ``protocol.reader.buffer`` / ``transport``, the message
classes named below, and the props classes' ``min`` / ``max`` / ``options`` / ``disabled``.
"""

from __future__ import annotations

import array
import asyncio
import collections
import dataclasses
import fcntl
import logging
import math
import os
import re
import termios
import threading
import time
import types
import typing
import weakref
from collections import Counter
from collections.abc import Callable, Generator
from typing import TYPE_CHECKING, Any, TypeGuard, cast

import msgspec
import viser

from tcp_pendant.message_rate import MessagePacer
from tcp_pendant.views import arrival

if TYPE_CHECKING:                        # viser's and websockets' private types, named here only
    import selectors
    import socket
    from contextlib import AbstractContextManager

    from viser._gui_api import _FileUploadState
    from viser._gui_handles import _GuiInputHandle
    from viser._messages import (
        FileTransferPart,
        FileTransferStartUpload,
        GuiButtonHoldMessage,
        GuiMarkdownProps,
        GuiUpdateMessage,
        SetOrientationMessage,
        SetPositionMessage,
    )
    from viser.infra import ClientId, WebsockMessageHandler
    from viser.infra._messages import Message

    from tcp_pendant.session import Browser
    from websockets.asyncio.server import Server, ServerConnection, serve

    UploadStart = FileTransferStartUpload
    """A browser's announcement of an upload (:class:`UploadHook`'s ``on_start`` gets it)."""
    UploadPart = FileTransferPart
    """One part of an upload (:class:`UploadHook`'s ``on_part`` gets it)."""

__all__ = ["LOG_VALUE_CHARS", "MAX_ABS_NUMBER", "MAX_TEXT_CHARS", "UploadHook", "UploadLimits",
           "ViserInternalsChanged", "gui_value_refusal", "install", "listen_reuse_port", "message_refusal", "path_counts",
           "queue_markdown", "PoseQueue", "pose_queue",
           "message_counts", "queue_pose", "reset_path_counts", "set_tab_label", "short", "upload_hook", "upload_limits",
           "uploads_in_flight"]

log = logging.getLogger(__name__)

LOG_VALUE_CHARS = 200
"""User values are cut to this many characters in log lines."""

MAX_TEXT_CHARS = 10_000
"""Longest text a browser may send for a text field (the longest the app writes itself, a
controller file's text, is a few kB)."""

MAX_ABS_NUMBER = 1e12
"""Largest magnitude a browser may send for a number, also for an input without min / max (no
pendant quantity comes near it; ``-1e308`` would overflow the app's arithmetic)."""

STRICT_ENV = "TCP_PENDANT_STRICT_VISER"
"""Environment variable: ``1`` makes a fast path's fallback raise (tests)."""

REFUSED_MESSAGES = ("ShareUrlRequest", "ShareUrlDisconnect")
"""Client messages never handled: they would open (or close) viser's public share tunnel."""


class ViserInternalsChanged(RuntimeError):
    """A fast path had to fall back while ``TCP_PENDANT_STRICT_VISER=1``."""


def short(value: object, limit: int = LOG_VALUE_CHARS) -> str:
    """``repr(value)`` cut to ``limit`` characters (with the full length) for log lines."""
    try:
        text = repr(value)
    except Exception:                           # a value whose repr fails is still logged
        text = f"<{type(value).__name__}>"
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} chars)"


# ------------------------------------------------------------------ fast paths
_counts: Counter[tuple[str, str]] = Counter()
_warned: set[str] = set()


def path_counts() -> dict[tuple[str, str], int]:
    """How often each fast path ran: ``{(path, "fast" | "fallback"): n}``."""
    return dict(_counts)


def reset_path_counts() -> None:
    """Forget the counts (tests)."""
    _counts.clear()


def _fast(path: str) -> bool:
    _counts[(path, "fast")] += 1
    return True


def _fallback(path: str, exc: BaseException) -> bool:
    _counts[(path, "fallback")] += 1
    if os.environ.get(STRICT_ENV) == "1":
        raise ViserInternalsChanged(f"viser fast path {path!r} fell back: {type(exc).__name__}: {exc}") from exc
    if path not in _warned:
        _warned.add(path)
        log.warning("viser's internals differ (%s: %s): %s takes its fallback from now on (viser's public "
                    "setters, slower; for \"unread\", jog presses timed by the loop's polls only); see "
                    "tcp_pendant.views.viser_adapter", type(exc).__name__, exc, path)
    return False


def queue_markdown(handle: viser.GuiMarkdownHandle, text: str) -> bool:
    """Set a markdown handle's content to ``text`` without viser's public setter.

    Stores ``_content`` and the ``_markdown`` prop and queues the one ``GuiUpdateMessage`` the
    setter would (nothing when the text is unchanged). Only for text without images (viser's
    setter inlines those). Returns False when the caller must use ``handle.content = text``
    (a removed handle, or viser's internals differ).
    """
    try:
        update = _GUI_UPDATE[0] if _GUI_UPDATE else _gui_update_message()
        impl = handle._impl
        if impl.removed:
            return False
        object.__setattr__(handle, "_content", text)
        props = cast("GuiMarkdownProps", impl.props)
        if props._markdown != text:
            props._markdown = text
            impl.gui_api._websock_interface.queue_message(update(impl.uuid, {"_markdown": text}))
    except (AttributeError, ImportError) as exc:
        return _fallback("markdown", exc)
    return _fast("markdown")


_GUI_UPDATE: list[type[GuiUpdateMessage]] = []
"""viser's ``GuiUpdateMessage`` once imported (an import statement per readout costs a lookup)."""


def _gui_update_message() -> type[GuiUpdateMessage]:
    from viser._messages import GuiUpdateMessage

    _GUI_UPDATE.append(GuiUpdateMessage)
    return GuiUpdateMessage


try:
    from viser import _messages as _viser_messages
except ImportError:                     # queue_pose falls back to the public setters (AttributeError)
    _viser_messages = None  # type: ignore[assignment]


class PoseQueue:
    """Queues one scene node's ``SetOrientationMessage`` / ``SetPositionMessage`` without viser's
    public setters, its internals looked up once (:func:`pose_queue` builds it): writes the
    node's ``wxyz`` / ``position`` in place, stamps each message with the scene's owner as
    ``SceneApi._queue_scene_message`` does and queues it on the scene's ``_websock_interface``.
    The node's redundancy key (per message class) is viser's own ``Message.redundancy_key`` of
    its first message, then set on the next ones (viser caches it in ``_cached_redundancy_key``
    the first time it asks; it depends on the node and the message class, never on the pose):
    not rebuilt per message."""

    __slots__ = ("_impl", "_keys", "_name", "_orientation", "_owner", "_position", "_ws")

    def __init__(self, handle: viser.SceneNodeHandle) -> None:
        messages = _viser_messages             # None (AttributeError below): viser differs
        impl = handle._impl
        api = impl.api
        self._impl, self._name, self._owner, self._ws = impl, impl.name, api._owner_id, api._websock_interface
        # the message classes, called with a tuple of 4 (wxyz) or 3 (xyz) floats (cast once, here)
        self._orientation = cast("Callable[[str, tuple[float, ...]], SetOrientationMessage]",
                                 messages.SetOrientationMessage)
        self._position = cast("Callable[[str, tuple[float, ...]], SetPositionMessage]", messages.SetPositionMessage)
        if not (callable(self._ws.queue_message) and hasattr(impl, "wxyz") and hasattr(impl, "position")):
            raise AttributeError("a scene node without wxyz / position or a websocket interface")
        self._keys: list[str | None] = [None, None]

    def _queue(self, kind: int, value: tuple[float, ...]) -> None:
        msg = (self._orientation if kind == 0 else self._position)(self._name, value)
        msg.owner = self._owner
        key = self._keys[kind]
        if key is None:
            self._keys[kind] = msg.redundancy_key()
        else:
            object.__setattr__(msg, "_cached_redundancy_key", key)
        self._ws.queue_message(msg)

    def __call__(self, wxyz: list[float] | None, xyz: list[float] | None) -> bool:
        """Set and queue the orientation (``wxyz``) and/or position (``xyz``, metres); False when
        viser's internals differ (the caller then uses the public setters)."""
        try:
            if wxyz is not None:
                self._impl.wxyz[:] = wxyz
                self._queue(0, tuple(wxyz))
            if xyz is not None:
                self._impl.position[:] = xyz
                self._queue(1, tuple(xyz))
        except AttributeError as exc:
            return _fallback("pose", exc)
        return _fast("pose")


def pose_queue(handle: viser.SceneNodeHandle) -> PoseQueue | None:
    """The :class:`PoseQueue` of a scene node handle; None when viser's internals differ (counted
    and warned as the ``pose`` path's fallback: the caller uses the public setters)."""
    try:
        return PoseQueue(handle)
    except (AttributeError, ImportError) as exc:
        _fallback("pose", exc)
        return None


def queue_pose(handle: viser.SceneNodeHandle, wxyz: list[float] | None, xyz: list[float] | None) -> bool:
    """Set a scene node's orientation (``wxyz``) and/or position (``xyz``, metres) and queue
    viser's ``SetOrientationMessage`` / ``SetPositionMessage`` without its public setters
    (a :class:`PoseQueue` of the node, made for this call; the scene keeps one per node).
    Returns False when the caller must use ``handle.wxyz`` / ``handle.position``."""
    q = pose_queue(handle)
    return q is not None and q(wxyz, xyz)


# ------------------------------------------------------------------ uploads
@dataclasses.dataclass(frozen=True)
class UploadHook:
    """viser's file-transfer internals for one upload button.

    Attributes:
        uuid: the button's uuid (``source_component_uuid`` of its transfers).
        states: ``GuiApi._current_file_upload_states`` (transfer uuid -> state dict with
            ``filename``, ``transferred_bytes``, ...); dropping an entry drops the transfer.
        register: ``register(on_start, on_part)`` adds handlers ``(client_id, message)`` for the
            start and part messages, run after viser's own.
    """

    uuid: str
    states: dict[str, _FileUploadState]
    register: Callable[[Callable[[ClientId, FileTransferStartUpload], None], Callable[[ClientId, FileTransferPart], None]], None]


def upload_hook(handle: viser.GuiUploadButtonHandle) -> UploadHook | None:
    """The :class:`UploadHook` of a ``viser.GuiUploadButtonHandle`` (None: viser lacks it)."""
    try:
        from viser import _messages

        impl = handle._impl
        gui_api = impl.gui_api
        ws = gui_api._websock_interface
        states = gui_api._current_file_upload_states
        start_cls, part_cls = _messages.FileTransferStartUpload, _messages.FileTransferPart
        uuid = str(impl.uuid)
        if not isinstance(states, dict):
            raise AttributeError("_current_file_upload_states is not a dict")
    except (AttributeError, ImportError) as exc:
        _fallback("upload", exc)
        return None

    def register(on_start: Callable[[ClientId, FileTransferStartUpload], None],
                 on_part: Callable[[ClientId, FileTransferPart], None]) -> None:
        ws.register_handler(start_cls, on_start)
        ws.register_handler(part_cls, on_part)

    _fast("upload")
    return UploadHook(uuid, states, register)


@dataclasses.dataclass(frozen=True)
class UploadLimits:
    """Bounds of the uploads a server holds in memory before they are complete.

    Attributes:
        client_bytes: the most one browser may announce or send for its upload in flight; a
            browser has one upload in flight at a time (a new one drops its unfinished one).
        server_bytes: the most all browsers of one server may have in flight together; an
            upload that would pass it is refused.
        max_parts: the most parts one upload may announce.
        idle_s: an upload that received no part for this long is dropped (its memory freed).
    """

    client_bytes: int = 4_000_000
    server_bytes: int = 32_000_000
    max_parts: int = 4096
    idle_s: float = 30.0


_limits = UploadLimits()


def upload_limits(limits: UploadLimits | None = None) -> UploadLimits:
    """The upload limits of this process; ``limits`` replaces them (returns the old ones)."""
    global _limits
    old = _limits
    if limits is not None:
        _limits = limits
    return old


@dataclasses.dataclass
class _Transfer:
    client: tuple[int, int]          # (id of the server's event loop, viser client id)
    size: int                        # announced, bytes
    states: dict[str, _FileUploadState]  # viser's buffers (the GuiApi's)
    last_part: float                 # time.monotonic() of the start or the last part
    seen: list[bool]                 # part received, by index
    received: int = 0                # bytes of the parts received

    @property
    def held(self) -> int:
        """Bytes this upload may hold: its announced size, or more when it sent more."""
        return max(self.size, self.received)


# transfer uuid -> transfer, per server event loop (each viser server runs its own loop)
_transfers: weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, dict[str, _Transfer]] = weakref.WeakKeyDictionary()


def _live(loop: asyncio.AbstractEventLoop) -> dict[str, _Transfer]:
    """The transfers of one server still held by viser (finished and dropped ones forgotten)."""
    table = _transfers.setdefault(loop, {})
    for tid in [t for t, tr in table.items() if t not in tr.states]:
        del table[tid]
    return table


def uploads_in_flight(loop: asyncio.AbstractEventLoop | None = None) -> list[tuple[int, int]]:
    """``(viser client id, announced bytes)`` of the unfinished uploads viser holds (every
    server's when ``loop`` is None)."""
    loops = list(_transfers) if loop is None else [loop]
    return [(tr.client[1], tr.size) for lp in loops for tr in list(_live(lp).values())]


def _drop(table: dict[str, _Transfer], tid: str, why: str) -> None:
    tr = table.pop(tid, None)
    if tr is not None and tr.states.pop(tid, None) is not None:
        log.warning("upload from client %s dropped: %s", tr.client[1], why)


def _expire(loop: asyncio.AbstractEventLoop, tid: str) -> None:
    table = _live(loop)
    tr = table.get(tid)
    if tr is None:
        return
    idle = time.monotonic() - tr.last_part
    if idle >= _limits.idle_s:
        _drop(table, tid, f"no part for {idle:.0f} s")
    else:
        loop.call_later(_limits.idle_s - idle, _expire, loop, tid)


def _upload_start_refusal(gui_api: viser.GuiApi, client_id: ClientId, message: FileTransferStartUpload) -> str | None:
    """Admit an upload start (registering its transfer) or say why it is refused."""
    if message.source_component_uuid not in getattr(gui_api, "_gui_input_handle_from_uuid", {}):
        return None                                   # not this GUI's button: viser ignores it
    limits = _limits
    size, parts = int(message.size_bytes), int(message.part_count)
    if size < 0 or parts < 0 or parts > limits.max_parts or (size > 0 and parts == 0) or parts > max(size, 1):
        return f"an upload of {size} bytes in {parts} parts is not a file a browser sends"
    if size > limits.client_bytes:
        return f"an upload of {size} bytes is larger than {limits.client_bytes} bytes"
    loop = asyncio.get_running_loop()
    table = _live(loop)
    client = (id(loop), int(client_id))
    for tid in [t for t, tr in table.items() if tr.client == client]:
        _drop(table, tid, "the same browser started another upload")
    held = sum(tr.held for tr in table.values())
    if held + size > limits.server_bytes:
        return f"the server holds {held} bytes of unfinished uploads (limit {limits.server_bytes})"
    states = gui_api._current_file_upload_states
    table[str(message.transfer_uuid)] = _Transfer(client, size, states, time.monotonic(), [False] * parts)
    loop.call_later(limits.idle_s, _expire, loop, str(message.transfer_uuid))
    return None


def _upload_part_refusal(gui_api: viser.GuiApi, message: FileTransferPart) -> str | None:
    """A part of an admitted upload: count it; refuse it (dropping the upload) when the bytes
    received pass the per-browser limit or, counted with every other upload in flight, the
    server's. (A client may understate its size: an upload button's own limit,
    ``views.upload_guard``, then tells its session.)"""
    table = _live(asyncio.get_running_loop())
    tid = str(message.transfer_uuid)
    tr = table.get(tid)
    index = message.part_index
    if tr is None or tr.states is not getattr(gui_api, "_current_file_upload_states", None) \
            or not 0 <= index < len(tr.seen) or tr.seen[index]:
        return None                             # another GUI's, or a part viser ignores
    tr.last_part = time.monotonic()
    received = tr.received + len(message.content)
    if received > _limits.client_bytes:
        _drop(table, tid, f"its parts pass {_limits.client_bytes} bytes")
        return "the parts pass the per-browser limit"
    others = sum(t.held for k, t in table.items() if k != tid)
    if others + max(tr.size, received) > _limits.server_bytes:
        _drop(table, tid, f"the server holds {others} bytes of other unfinished uploads")
        return "the parts pass the server's limit"
    tr.seen[index] = True                       # viser ignores a repeated part: counted once
    tr.received = received
    return None


# ------------------------------------------------------------------ value checks
def _finite_number(v: object) -> TypeGuard[int | float]:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _checker(hint: object) -> Callable[[object], bool]:
    """A function telling whether a decoded msgpack value fits the annotation ``hint``
    (numbers finite; a browser's numbers are doubles, so ``720.0`` is an int); unknown
    annotations pass. Built once per message field (:func:`_fields_of`)."""
    if hint is Any or hint is object:
        return lambda v: True
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        alts = [_checker(a) for a in args]
        return lambda v: any(c(v) for c in alts)
    if hint is type(None):
        return lambda v: v is None
    if origin is typing.Literal:
        return lambda v: v in args
    if hint is bool:
        return lambda v: isinstance(v, bool)
    if hint is int:
        return lambda v: _finite_number(v) and float(v).is_integer()
    if hint is float:
        return _finite_number
    if hint is str:
        return lambda v: isinstance(v, str)
    if hint is bytes:
        return lambda v: isinstance(v, (bytes, bytearray, memoryview))
    if origin is tuple:
        if len(args) == 2 and args[1] is Ellipsis:
            each = _checker(args[0])
            return lambda v: isinstance(v, (tuple, list)) and all(each(x) for x in v)
        items = [_checker(a) for a in args]
        n = len(items)
        return lambda v: isinstance(v, (tuple, list)) and len(v) == n and all(c(x) for c, x in zip(items, v))
    if origin is dict:
        key = _checker(args[0]) if args else (lambda k: True)
        return lambda v: isinstance(v, dict) and all(key(k) for k in v)
    if origin is list:
        each = _checker(args[0]) if args else (lambda x: True)
        return lambda v: isinstance(v, list) and all(each(x) for x in v)
    return lambda v: True


_fields: dict[type, dict[str, tuple[object, Callable[[object], bool]]]] = {}


def _fields_of(cls: type) -> dict[str, tuple[object, Callable[[object], bool]]]:
    """A message class's fields: name -> (annotation, its checker)."""
    fields = _fields.get(cls)
    if fields is None:
        try:
            hints = typing.get_type_hints(cls)
            fields = {f.name: (hints.get(f.name, Any), _checker(hints.get(f.name, Any)))
                      for f in dataclasses.fields(cls)}
        except Exception:                       # an annotation this Python cannot resolve: no check
            fields = {}
        _fields[cls] = fields
    return fields


def message_refusal(mapping: object) -> str | None:
    """Why a decoded client message (the msgpack mapping, before viser builds its message
    object) is refused, or None: not a known message, a missing, extra or wrongly typed field
    (by the message class's annotations; numbers finite), or a share-URL request. The value of a
    ``GuiUpdateMessage`` is checked against its handle later (:func:`gui_value_refusal`)."""
    from viser.infra._messages import Message

    if not isinstance(mapping, dict) or not isinstance(mapping.get("type"), str):
        return f"{short(mapping, 60)} is not a viser message"
    name = mapping["type"]
    cls = Message._subclass_from_type_string().get(name)
    if cls is None:
        return f"{short(name, 60)} is not a viser message"
    if name in REFUSED_MESSAGES:
        return f"{name} is not accepted from a browser"
    fields = _fields_of(cls)
    if len(mapping) != len(fields) + 1:
        extra = set(mapping) - set(fields) - {"type"}
        if extra:
            return f"{name} has no field {short(sorted(map(str, extra))[0], 60)}"
    for field, (hint, fits) in fields.items():
        if field not in mapping:
            return f"{name}.{field} is missing"
        if not fits(mapping[field]):
            return f"{name}.{field} = {short(mapping[field])} is not {_hint_name(hint)}"
    return None


def _hint_name(hint: object) -> str:
    return "a finite number" if hint is float else getattr(hint, "__name__", None) or str(hint)


def gui_value_refusal(handle: _GuiInputHandle[object], updates: object) -> str | None:
    """Why a browser's ``GuiUpdateMessage.updates`` for the GUI input ``handle`` is refused, or
    None: only ``value`` may be sent; it must have the type of the handle's value, be finite,
    lie within the handle's ``min`` / ``max`` (and :data:`MAX_ABS_NUMBER`), be one of its
    ``options`` (with or without a leading mark such as ``"✓ "``), or be a text of at most
    :data:`MAX_TEXT_CHARS` characters; a disabled, removed or upload input takes no update."""
    impl = handle._impl
    props = impl.props
    label = short(getattr(props, "label", "?"), 60)
    if not isinstance(updates, dict) or set(updates) != {"value"}:
        return f"{label}: only a value may be sent, got {short(updates)}"
    if impl.removed or getattr(props, "disabled", False):
        return f"{label} is disabled"
    value = updates["value"]
    current = impl.value
    options = getattr(props, "options", None)
    if options is not None:                     # dropdown, button group (a button too)
        if isinstance(value, str) and (value in tuple(options) or _bare(value) in {_bare(o) for o in options}):
            return None
        return f"{label}: {short(value)} is not one of its options"
    if getattr(impl, "is_button", False):
        return None if value is True else f"{label}: a button sends true, got {short(value)}"
    if isinstance(current, bool):
        return None if isinstance(value, bool) else f"{label}: {short(value)} is not true or false"
    if isinstance(current, (int, float)):
        return _number_refusal(label, value, getattr(props, "min", None), getattr(props, "max", None),
                               isinstance(current, int))
    if isinstance(current, str):
        if not isinstance(value, str):
            return f"{label}: {short(value)} is not a text"
        if len(value) > MAX_TEXT_CHARS:
            return f"{label}: a text of {len(value)} characters is longer than {MAX_TEXT_CHARS}"
        return None
    if isinstance(current, tuple):
        if not isinstance(value, (list, tuple)) or len(value) != len(current):
            return f"{label}: {short(value)} is not {len(current)} numbers"
        lo, hi = getattr(props, "min", None), getattr(props, "max", None)
        if type(props).__name__ in ("GuiRgbProps", "GuiRgbaProps"):
            lo, hi = 0, 255
        for i, v in enumerate(value):
            why = _number_refusal(label, v, lo[i] if isinstance(lo, tuple) else lo,
                                  hi[i] if isinstance(hi, tuple) else hi,
                                  bool(current) and isinstance(current[i], int) and not isinstance(current[i], bool))
            if why is not None:
                return why
        return None
    return f"{label}: this input takes no value from a browser"


_DECORATION = re.compile(r"^[^\w.+\-]+\s*")


def _bare(option: str) -> str:
    """An option's label without a leading mark (``"✓ 10"`` -> ``"10"``): a view may mark the
    selected option in its label, and a click the browser sent before the marks moved names
    the option as it was shown then."""
    return _DECORATION.sub("", option, count=1)


def _number_refusal(label: str, value: object, lo: float | None, hi: float | None, integer: bool) -> str | None:
    if not _finite_number(value) or abs(value) > MAX_ABS_NUMBER:
        return f"{label}: {short(value)} is not a finite number of at most {MAX_ABS_NUMBER:g}"
    if integer and value != int(value):
        return f"{label}: {short(value)} is not a whole number"
    if lo is not None and value < lo or hi is not None and value > hi:
        return f"{label}: {short(value)} is outside {lo}..{hi}"
    return None


# ------------------------------------------------------------------ message dispatch
def _gui_apis(interface: WebsockMessageHandler) -> list[viser.GuiApi]:
    """The ``GuiApi`` objects whose handlers are registered on a websocket interface."""
    from viser._messages import GuiUpdateMessage

    handlers = getattr(interface, "_incoming_handlers", {}).get(GuiUpdateMessage, [])
    return [h.__self__ for h in handlers if hasattr(getattr(h, "__self__", None), "_gui_input_handle_from_uuid")]


def _resend_value(gui_api: viser.GuiApi, handle: _GuiInputHandle[object]) -> None:
    """Send an input's value back after a refused update, so the browser's widget shows what
    the server holds again (not for buttons: their value is a click, not a state)."""
    from viser._messages import GuiUpdateMessage

    impl = handle._impl
    if impl.removed or getattr(impl, "is_button", False) or not isinstance(impl.value, (bool, int, float, str, tuple)):
        return
    gui_api._websock_interface.queue_message(GuiUpdateMessage(impl.uuid, {"value": impl.value}))


def _refusal(interface: WebsockMessageHandler, client_id: ClientId, message: Message) -> str | None:
    """Why ``message`` is not handed to the handlers of ``interface``, or None."""
    name = type(message).__name__               # the class by its name: each cast below is that class
    if name == "GuiUpdateMessage":
        update = cast("GuiUpdateMessage", message)
        for api in _gui_apis(interface):
            handle = api._gui_input_handle_from_uuid.get(update.uuid)
            if handle is not None:
                why = gui_value_refusal(handle, update.updates)
                if why is not None:
                    _resend_value(api, handle)
                return why
    elif name == "GuiButtonHoldMessage":
        hold = cast("GuiButtonHoldMessage", message)
        for api in _gui_apis(interface):
            handle = api._gui_input_handle_from_uuid.get(hold.uuid)
            if handle is not None and (handle._impl.removed or getattr(handle._impl.props, "disabled", False)):
                return f"{short(getattr(handle._impl.props, 'label', '?'), 60)} is disabled: no hold"
    elif name == "FileTransferStartUpload":
        for api in _gui_apis(interface):
            why = _upload_start_refusal(api, client_id, cast("FileTransferStartUpload", message))
            if why is not None:
                return why
    elif name == "FileTransferPart" and cast("FileTransferPart", message).source_component_uuid is not None:
        for api in _gui_apis(interface):
            why = _upload_part_refusal(api, cast("FileTransferPart", message))
            if why is not None:
                return why
    return None


LOG_BUDGET = (50, 10.0)
"""At most this many refused or failed messages of one browser are logged per this many
seconds (a flood of bad messages must not fill the disk); the others are counted, and the
count is logged when the next window opens."""

_message_counts: Counter[str] = Counter()
# per server loop: sender ("client N" or the socket's peer address) -> [window start, logged, skipped]
_log_windows: weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, dict[str, list[float]]] = \
    weakref.WeakKeyDictionary()
_log_lock = threading.Lock()


def message_counts() -> dict[str, int]:
    """How many browser messages were ``refused`` (checks) or ``failed`` (viser raised)."""
    with _log_lock:
        return dict(_message_counts)


def _log_message(kind: str, sender: str, fmt: str, *args: object) -> None:
    """Count a refused / failed message of ``sender`` and log it within :data:`LOG_BUDGET`."""
    lines, window_s = LOG_BUDGET
    now = time.monotonic()
    with _log_lock:
        _message_counts[kind] += 1
        windows = _log_windows.setdefault(asyncio.get_running_loop(), {})
        if len(windows) > 1000:                     # forget the senders of closed windows
            for key in [k for k, w in windows.items() if now - w[0] >= window_s]:
                del windows[key]
        w = windows.setdefault(sender, [now, 0, 0])
        skipped = 0
        if now - w[0] >= window_s:
            skipped = int(w[2])
            w[:] = [now, 0, 0]
        log_it = w[1] < lines
        w[1 if log_it else 2] += 1
    if skipped:
        log.warning("%d more refused or failed messages from %s were not logged", skipped, sender)
    if log_it:
        log.warning(fmt, *args)


def _peer(websocket: ServerConnection) -> str:
    try:
        host, port = websocket.remote_address[:2]
        return f"{host}:{port}"
    except Exception:
        return "?"


def client_address(client: Browser | None) -> str | None:
    """The IP address a viser client's websocket connects from (its peer), None when there is
    none to read (a closed connection, a shared page, or viser's internals differ).

    viser keeps each client's connection in its websocket server's table of live connections
    (``_live_connections``, by client id): private API, read only here."""
    try:
        viser_client = cast("viser.ClientHandle", client)      # a served session's browser is viser's
        server = viser_client._viser_server._websock_server
        connection = server._live_connections[viser_client.client_id]
        return str(connection.remote_address[0])
    except (AttributeError, KeyError, IndexError, TypeError):
        return None


_install_lock = threading.Lock()
_installed = False


READ_BYTES = 16384
"""What a connection's transport reads from its socket at once (asyncio's default 256 kB holds
thousands of small messages, all parsed in one callback of the loop: measured 40-120 ms stalls
of every other browser while one client flooded)."""


class _TimedSelector:
    """An event loop's selector, keeping the start and end (monotonic s) of its last three polls
    (``arrival.earliest_from_polls``)."""

    def __init__(self, inner: selectors.BaseSelector, polls: collections.deque[tuple[float, float]]) -> None:
        self._inner = inner
        self._polls = polls

    def select(self, timeout: float | None = None) -> list[tuple[selectors.SelectorKey, int]]:
        t0 = time.monotonic()
        try:
            return self._inner.select(timeout)
        finally:
            self._polls.append((t0, time.monotonic()))

    def __getattr__(self, name: str) -> object:
        return getattr(self._inner, name)


_loop_polls: weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, collections.deque[tuple[float, float]]] = (
    weakref.WeakKeyDictionary())


def _polls_of(loop: asyncio.AbstractEventLoop) -> collections.deque[tuple[float, float]]:
    """The running loop's last polls, timed from the first call on (asyncio's ``loop._selector``,
    private: a loop without one is never timed, and its messages are stamped when read)."""
    polls = _loop_polls.get(loop)
    if polls is None:
        polls = collections.deque(maxlen=3)
        _loop_polls[loop] = polls
        selector = getattr(loop, "_selector", None)
        if selector is not None and callable(getattr(selector, "select", None)):
            loop._selector = _TimedSelector(selector, polls)  # type: ignore[attr-defined]
        else:
            log.warning("event loop without a selector: jog presses are timed from their reading")
    return polls


def _unread(websocket: ServerConnection) -> int | None:
    """What a connection has received and not yet given out as messages: frames in websockets'
    queue (``recv_messages.frames``), bytes in its parser (``protocol.reader.buffer``) and bytes
    in the kernel's socket buffer (``FIONREAD``). 0: the next message is still to come. None
    when websockets' internals differ."""
    try:
        frames = len(websocket.recv_messages.frames)
        parsing = len(websocket.protocol.reader.buffer)
        fd = websocket.transport.get_extra_info("socket").fileno()
        kernel = array.array("i", [0])
        if fd >= 0:                                # -1: closed, nothing more will come
            fcntl.ioctl(fd, termios.FIONREAD, kernel)
    except (AttributeError, TypeError, ValueError, OSError) as exc:
        _fallback("unread", exc)
        return None
    _fast("unread")
    return frames + parsing + int(kernel[0])


def _read_in_small_chunks(websocket: ServerConnection) -> None:
    """Read a connection at most :data:`READ_BYTES` at a time (asyncio's selector transport's
    ``max_size``; nothing when the transport differs)."""
    transport = getattr(websocket, "transport", None)
    if transport is not None and isinstance(getattr(transport, "max_size", None), int):
        transport.max_size = READ_BYTES


def install() -> None:
    """Check and guard every message viser receives, in this process (idempotent; see the
    module docstring)."""
    global _installed
    with _install_lock:
        if _installed:
            return
        from viser.infra import _infra

        original_handle = _infra.WebsockMessageHandler._handle_incoming_message
        original_consumer = _infra._message_consumer

        async def handle_incoming_message(self: WebsockMessageHandler, client_id: ClientId, message: Message) -> None:
            try:
                why = _refusal(self, client_id, message)
                if why is not None:
                    _log_message("refused", f"client {client_id}", "message from client %s refused: %s",
                                 client_id, why)
                    return
                await original_handle(self, client_id, message)
            except Exception as exc:             # never a traceback, never a closed socket
                _log_message("failed", f"client {client_id}", "message %s from client %s failed: %s: %s",
                             type(message).__name__, client_id, type(exc).__name__, short(str(exc)))

        async def message_consumer(websocket: ServerConnection, handle_message: Callable[[Message], None],
                                   message_class: type[Message]) -> None:
            pacer = MessagePacer()                 # this connection's pace (``message_rate``)
            floor = arrival.ArrivalFloor()         # its backlog's bound on arrivals (``arrival``)
            polls = _polls_of(asyncio.get_running_loop())
            _read_in_small_chunks(websocket)
            wait_s = 0.0
            while True:
                unread = _unread(websocket)
                backlog = unread > 0 if unread is not None else wait_s > 0.0
                raw = await websocket.recv()
                arrival.set_arrived(floor.stamp(backlog, arrival.earliest_from_polls(polls, time.monotonic())))
                wait_s = pacer.delay_s()
                if wait_s > 0.0:                   # its reading waits: the sender's socket fills
                    await asyncio.sleep(wait_s)
                try:
                    if not isinstance(raw, bytes):
                        raise TypeError("a text frame; viser speaks binary msgpack")
                    why = message_refusal(msgspec.msgpack.decode(raw))
                    message = None if why is not None else message_class.deserialize(raw)
                except Exception as exc:
                    why = f"it does not decode: {type(exc).__name__}: {short(str(exc))}"
                if why is not None:
                    peer = _peer(websocket)
                    _log_message("refused", peer, "message from %s refused: %s", peer, why)
                    continue
                handle_message(cast("Message", message))

        message_consumer.__wrapped__ = original_consumer  # type: ignore[attr-defined]
        _infra.WebsockMessageHandler._handle_incoming_message = handle_incoming_message  # type: ignore[method-assign]
        _infra._message_consumer = message_consumer
        _installed = True


_reuse_port = False
_ListenHooks = tuple["Callable[[], AbstractContextManager[object]] | None", "Callable[[list[socket.socket]], None] | None"]
_listen_hooks: _ListenHooks = (None, None)


class _ListeningServe:
    """websockets' ``serve(...)`` as viser enters it (``async with``), with the hooks of
    :func:`listen_reuse_port` around the moment its listener starts listening."""

    def __init__(self, serve: serve) -> None:
        self._serve = serve

    async def __aenter__(self) -> Server:
        around, started = _listen_hooks
        if around is None:
            server = await self._serve.__aenter__()
        else:
            with around():
                server = await self._serve.__aenter__()
        if started is not None:
            started(list(server.sockets))
        return server

    async def __aexit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                        tb: types.TracebackType | None) -> None:
        await self._serve.__aexit__(exc_type, exc, tb)

    def __await__(self) -> Generator[object, None, Server]:
        return self._serve.__await__()


def listen_reuse_port(around_listen: Callable[[], AbstractContextManager[object]] | None = None,
                      on_listening: Callable[[list[socket.socket]], None] | None = None) -> None:
    """viser's server in this process binds its port with ``SO_REUSEPORT`` from now on (module
    docstring; idempotent). ``around_listen()``: a context manager entered while the listener
    binds and starts listening; ``on_listening(sockets)``: called with its listening sockets
    (``tcp_pendant.serve.balance``; the last call's hooks serve). Raises OSError where the platform
    has no ``SO_REUSEPORT``."""
    global _reuse_port, _listen_hooks
    import socket

    import websockets.asyncio.server as ws_server

    if not hasattr(socket, "SO_REUSEPORT"):
        raise OSError("this platform has no SO_REUSEPORT: run one server process (--workers 1)")
    with _install_lock:
        _listen_hooks = (around_listen, on_listening)
        if _reuse_port:
            return
        original = ws_server.serve

        def serve(*args: Any, **kwargs: Any) -> _ListeningServe:     # websockets' serve(), any arguments
            kwargs.setdefault("reuse_port", True)
            return _ListeningServe(original(*args, **kwargs))

        serve.__wrapped__ = original  # type: ignore[attr-defined]
        ws_server.serve = serve  # type: ignore[assignment,misc]
        _reuse_port = True


def accept_language(client: viser.ClientHandle) -> str | None:
    """The ``Accept-Language`` header of ``client``'s websocket handshake (browsers send their
    language list on it as on every request), or None: no header, a client that left, or
    viser's internals differ (the websocket server's ``_live_connections``, the
    ``websockets`` connection viser keeps per client id; the caller then starts in the
    server's default language). Read once, when the browser's session is built."""
    server = getattr(getattr(client, "_viser_server", None), "_websock_server", None)
    connections = getattr(server, "_live_connections", None)
    if not isinstance(connections, dict):
        _fallback("accept_language", AttributeError("viser's websocket server keeps no _live_connections"))
        return None
    headers = getattr(getattr(connections.get(client.client_id), "request", None), "headers", None)
    if headers is None:
        return None                                   # the client left
    value = headers.get("Accept-Language")
    return None if value is None else str(value)


def set_tab_label(tab: viser.GuiTabHandle, label: str) -> bool:
    """Retitle ``tab`` (the session's language changed): viser 1.1 lets a tab's icon change but
    not its label; this sets the handle's ``_label`` and rebuilds its group's tab tuples as the
    ``icon`` setter does, which sends them. Returns False (title unchanged, a warning logged,
    raising under ``TCP_PENDANT_STRICT_VISER=1``) when viser's internals differ."""
    if getattr(tab, "_label", None) == label:
        return True
    try:
        rebuild = tab._parent._rebuild_tab_props
        tab._label = label
        rebuild()
    except AttributeError as exc:
        return _fallback("tab_label", exc)
    return True
