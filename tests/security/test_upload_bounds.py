"""Unfinished uploads cannot pile up in memory: viser buffers an upload's parts until all have
come, so one socket that starts upload after upload and finishes none held them all until it
disconnected (150 x 1.9 MB). Now a browser has one upload in flight (a new one drops its
unfinished one), the uploads in flight of one server are bounded in bytes, an upload whose parts
pass its announced size is dropped, and one that gets no part for a while times out."""

from __future__ import annotations

import logging
import uuid
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from tcp_pendant.serve.server import PendantApp
from tcp_pendant.views import viser_adapter
from tcp_pendant.views.viser_adapter import UploadLimits

from support.wsclient import CAMERA, InputsClient, wait_until

LOAD = "Load session (JSON)"
MB = 1_000_000


@pytest.fixture
def app(app_factory: Callable[..., PendantApp]) -> PendantApp:
    return app_factory()


@pytest.fixture
def limits() -> Iterator[Any]:
    """``limits(**UploadLimits fields)`` for this test; the defaults back afterwards."""
    old = viser_adapter.upload_limits()
    yield lambda **kw: viser_adapter.upload_limits(UploadLimits(**kw))
    viser_adapter.upload_limits(old)


def _browser(app: PendantApp) -> InputsClient:
    c = InputsClient(app.port)
    wait_until(lambda: {LOAD, "X +"} <= c.labels(), what="the upload button and the jog keys")
    return c


def _start(c: InputsClient, size: int, parts: int) -> str:
    tid = uuid.uuid4().hex
    c.send({"type": "FileTransferStartUpload", "source_component_uuid": c.uuid_of(LOAD), "transfer_uuid": tid,
            "filename": "record.json", "mime_type": "application/json", "part_count": parts, "size_bytes": size})
    return tid


def _part(c: InputsClient, tid: str, index: int, content: bytes) -> None:
    c.send({"type": "FileTransferPart", "source_component_uuid": c.uuid_of(LOAD), "transfer_uuid": tid,
            "part_index": index, "content": content})


def _handled(app: PendantApp, c: InputsClient) -> None:
    """Wait until the server handled everything ``c`` sent so far: a camera message behind it
    (viser handles one socket's messages in order; a jog click would not do: the deadman drops a
    press that waited behind megabytes of parts, ``views.arrival``)."""
    button = c.uuid_of("X +")
    handle = next(s.client for s in app.sessions.values() if button in s.client.gui._gui_input_handle_from_uuid)
    before = handle.camera._state
    c.send(CAMERA)
    wait_until(lambda: handle.camera._state is not before, what="the camera message behind the uploads")


def _held(app: PendantApp) -> dict[str, int]:
    """viser's own buffers of unfinished uploads: transfer uuid -> bytes received."""
    out: dict[str, int] = {}
    for client in app.server.get_clients().values():
        for tid, state in client.gui._current_file_upload_states.items():
            out[tid] = int(state["transferred_bytes"])
    return out


def test_one_socket_starting_150_uploads_holds_only_its_last(app: PendantApp) -> None:
    c = _browser(app)
    try:
        tids = []
        for _ in range(150):
            tid = _start(c, size=1_900_000, parts=19)
            _part(c, tid, 0, b"x" * 100_000)
            tids.append(tid)
        _handled(app, c)
        assert _held(app) == {tids[-1]: 100_000}
        assert [size for _, size in viser_adapter.uploads_in_flight()] == [1_900_000]
        assert not c.closed.is_set()
    finally:
        c.ws.close()


def test_the_server_bounds_the_bytes_of_all_uploads_in_flight(app: PendantApp, limits: Any, caplog) -> None:
    limits(client_bytes=1_500_000, server_bytes=2_500_000)
    a, b = _browser(app), _browser(app)
    try:
        with caplog.at_level(logging.WARNING):
            ta = _start(a, size=1_500_000, parts=3)
            _handled(app, a)
            tb = _start(b, size=1_500_000, parts=3)                # 3 MB in flight would pass 2.5 MB
            _handled(app, b)
            assert set(_held(app)) == {ta}
            assert "the server holds 1500000 bytes of unfinished uploads (limit 2500000)" in caplog.text
            tb = _start(b, size=1_800_000, parts=4)                # more than one browser may send
            _handled(app, b)
            assert "an upload of 1800000 bytes is larger than 1500000 bytes" in caplog.text
            assert set(_held(app)) == {ta}
            tb = _start(b, size=1_000_000, parts=2)                # fits
            _handled(app, b)
            assert set(_held(app)) == {ta, tb}
    finally:
        a.ws.close()
        b.ws.close()


def test_parts_past_the_per_browser_limit_drop_the_upload(app: PendantApp, limits: Any) -> None:
    """A client that understates its size cannot send more than the per-browser limit either."""
    limits(client_bytes=1 * MB)
    c = _browser(app)
    try:
        tid = _start(c, size=1000, parts=3)
        _part(c, tid, 0, b"x" * 600_000)
        _handled(app, c)
        assert _held(app) == {tid: 600_000}
        _part(c, tid, 1, b"x" * 600_000)
        _handled(app, c)
        assert _held(app) == {}
        assert not c.closed.is_set()
    finally:
        c.ws.close()


def test_an_unfinished_upload_times_out_and_its_memory_is_freed(app: PendantApp, limits: Any) -> None:
    limits(idle_s=0.5)
    c = _browser(app)
    try:
        tid = _start(c, size=2 * MB, parts=2)
        _part(c, tid, 0, b"x" * MB)
        _handled(app, c)
        wait_until(lambda: tid not in _held(app), timeout=10, what="the idle upload dropped")
        assert viser_adapter.uploads_in_flight() == []
    finally:
        c.ws.close()
