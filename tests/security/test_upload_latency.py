"""No browser can stall the others. A session record is uploaded over a real
websocket (viser's file-transfer messages, as a browser sends them) while a second browser jogs:
its jog latency stays below 0.5 s (p99), a record over the limit is dropped as its transfer
starts with one notification, and one session loads one record at a time."""

from __future__ import annotations

import asyncio
import json
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from types import SimpleNamespace
from typing import Any

import msgspec.msgpack
import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.serve.server import AppConfig, PendantApp
from tcp_pendant.views.wizard_menu import RECORD_REFUSED
from tcp_pendant.wizards.session_record import MAX_RECORD_BYTES, MAX_WIZARDS
from viser import _messages
from viser._gui_handles import UploadedFile

from support.wsclient import ButtonClient, DrainingClient, wait_until

PLUS_X = "X +"
P99_LIMIT_S = 0.5


@pytest.fixture(scope="module")
def wizard_entry(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """One finished XYZ 4-point calibration of 20 touches, as a record stores it."""
    app = PendantApp(AppConfig(port=0, tool_library=tmp_path_factory.mktemp("lib") / "tools.json"))
    wf = CalibrationWorkflow(app.new_controller(), app.library, robot="kr6", rng=np.random.default_rng(2))
    wf.start("xyz4", n_points=20)
    while wf.result is None:
        assert wf.auto_touch(AutoTouchRequest(sigma_mm=0.3)).ok
    return {"record": wf.export_record(), "entry": wf.export_record()["wizards"][0]}


def _record(wizard_entry: dict[str, Any], n_wizards: int) -> bytes:
    rec = dict(wizard_entry["record"])
    rec["wizards"] = [wizard_entry["entry"]] * n_wizards
    return json.dumps(rec, separators=(",", ":")).encode()


class Browsers:
    """An uploading browser (A) and a jogging one (B) on a pendant server."""

    def __init__(self, app: PendantApp) -> None:
        self.app = app
        self.a = DrainingClient(self.app.port)
        wait_until(lambda: len(self.app.sessions) == 1, what="session A")
        (self.sa,) = self.app.sessions.values()
        self.b = ButtonClient(self.app.port, (PLUS_X,))
        assert self.b.found.wait(30), "B never saw the jog keys"
        wait_until(lambda: len(self.app.sessions) == 2, what="session B")
        self.sb = [s for s in self.app.sessions.values() if s is not self.sa][0]
        self.view = self.sa.views["calibrate"]
        self.notes: list[tuple[str, str]] = []
        self.dropped = 0
        """B's presses that the deadman dropped (pressed again by :meth:`jog_latency_s`)."""
        self.sa.notify = lambda title, body, kind="info": self.notes.append((title, body))  # type: ignore[method-assign]
        with self.sb.lock:
            self.sb.jogger.settings = self.sb.jogger.settings.with_(increment="0.1", frame="WORLD")

    def send_upload(self, name: str, data: bytes, *, part_bytes: int = 256 * 1024,
                    announced: int | None = None) -> str:
        """Send ``data`` as a browser does: FileTransferStartUpload, then the parts."""
        button = self.view.load._impl.uuid
        transfer = uuid.uuid4().hex
        parts = [data[i:i + part_bytes] for i in range(0, len(data), part_bytes)]
        msgs: list[Any] = [_messages.FileTransferStartUpload(
            source_component_uuid=button, transfer_uuid=transfer, filename=name,
            mime_type="application/json", part_count=len(parts),
            size_bytes=len(data) if announced is None else announced)]
        msgs += [_messages.FileTransferPart(source_component_uuid=button, transfer_uuid=transfer,
                                            part_index=i, content=p) for i, p in enumerate(parts)]
        for m in msgs:
            self.a.ws.send(msgspec.msgpack.encode(m.as_serializable_dict()))
        return transfer

    def jog_latency_s(self, sign: int) -> float:
        """Click X+ in browser B and wait until B's robot moved: seconds from the first click.
        A press the server's deadman dropped (it reached the jog more than 250 ms after it
        arrived; B is told "press again") is pressed again, as the trainee would, so its
        latency counts the drop, and :attr:`dropped` counts it."""
        x0 = self.sb.controller.T_world_tcp()[0, 3]
        with self.sb.lock:
            self.sb.jogger.settings = self.sb.jogger.settings.with_(increment="0.1")
        gate = self.sb.jogger.gate
        dropped_before = gate.dropped_total
        t0 = time.perf_counter()
        self.b.click(PLUS_X)
        while abs(self.sb.controller.T_world_tcp()[0, 3] - x0) < 5e-5:
            if time.perf_counter() - t0 > 10:
                raise AssertionError("a jog of browser B never arrived")
            if gate.dropped_total > dropped_before:          # dropped: press again
                self.dropped += gate.dropped_total - dropped_before
                dropped_before = gate.dropped_total
                self.b.click(PLUS_X)
            time.sleep(0.001)
        return time.perf_counter() - t0

    def upload_states(self) -> dict[str, Any]:
        return self.view.load._impl.gui_api._current_file_upload_states

    def close(self) -> None:
        self.a.close()
        self.b.close()


@pytest.fixture
def browsers(app_factory: Callable[..., PendantApp]) -> Iterator[Browsers]:
    b = Browsers(app_factory())
    yield b
    b.close()


def test_a_second_browser_jogs_normally_while_a_record_just_under_the_limits_is_loaded(
        browsers: Browsers, wizard_entry: dict[str, Any]) -> None:
    # as many calibrations of 20 touches (with their joint values) as fit under the byte limit
    n = next(n for n in range(MAX_WIZARDS, 0, -5) if len(_record(wizard_entry, n)) < MAX_RECORD_BYTES)
    data = _record(wizard_entry, n)
    assert n >= 0.8 * MAX_WIZARDS and 0.9 * MAX_RECORD_BYTES < len(data) < MAX_RECORD_BYTES
    br = browsers
    baseline = [br.jog_latency_s(1) for _ in range(5)]
    sender = threading.Thread(target=br.send_upload, args=("lesson.json", data))
    sender.start()
    latencies: list[float] = []
    during = 0
    deadline = time.monotonic() + 60
    while not br.view.record_md.content.startswith("**Loaded"):
        assert time.monotonic() < deadline, f"the record was never loaded: {br.notes}"
        loading = br.view._loading_record
        latencies.append(br.jog_latency_s(1))
        during += loading and br.view._loading_record         # the whole jog fell in the load
    sender.join()
    assert br.notes == []
    assert len(br.view.workflow.runs) == n
    assert during >= 3, f"only {during} jogs while the record was replayed"
    p99 = float(np.percentile(latencies, 99))
    print(f"\njog latency of browser B: baseline max {max(baseline) * 1e3:.0f} ms; during the load "
          f"({len(latencies)} jogs, {during} inside the replay) p50 {np.median(latencies) * 1e3:.0f} ms, "
          f"p99 {p99 * 1e3:.0f} ms, max {max(latencies) * 1e3:.0f} ms, {br.dropped} presses dropped and pressed again")
    assert p99 < P99_LIMIT_S


def test_a_record_over_the_size_limit_is_dropped_as_its_transfer_starts(
        browsers: Browsers, wizard_entry: dict[str, Any]) -> None:
    br = browsers
    data = _record(wizard_entry, 300)
    assert len(data) > MAX_RECORD_BYTES
    sender = threading.Thread(target=br.send_upload, args=("huge.json", data))
    sender.start()
    latencies = [br.jog_latency_s(1) for _ in range(20)]
    sender.join()
    wait_until(lambda: len(br.notes) >= 1, what="the refusal")
    br.a.sync(br.sa.client)                               # every part was handled (and ignored)
    assert br.notes == [(RECORD_REFUSED, f"huge.json: The session record is {len(data):,} bytes "
                         f"({len(data) / 1e6:.1f} MB); the pendant loads records with at most "
                         f"{MAX_RECORD_BYTES:,} bytes (2 MB) (a full training session is far below that). "
                         "Load a record exported by the pendant, or split the session into several records.")]
    assert br.upload_states() == {}                       # nothing buffered
    assert br.view.workflow.runs == [] and br.view.record_md.content == ""
    assert float(np.percentile(latencies, 99)) < P99_LIMIT_S


def test_a_client_that_understates_its_size_is_dropped_once_it_sends_more(browsers: Browsers) -> None:
    br = browsers
    data = b" " * (MAX_RECORD_BYTES + 300_000)
    br.send_upload("liar.json", data, announced=100)
    wait_until(lambda: len(br.notes) >= 1, what="the refusal")
    br.a.sync(br.sa.client)                               # every part was handled (the rest ignored)
    assert len(br.notes) == 1 and br.notes[0][0] == RECORD_REFUSED and "liar.json" in br.notes[0][1]
    assert br.upload_states() == {} and br.view.workflow.runs == []


def test_one_load_per_session_at_a_time(browsers: Browsers, wizard_entry: dict[str, Any]) -> None:
    br = browsers
    view = br.view
    big = _record(wizard_entry, 50)

    def event(name: str, data: bytes) -> Any:
        target = SimpleNamespace(value=UploadedFile(name, data))
        return SimpleNamespace(client=br.sa.client, client_id=br.sa.client.client_id, target=target)

    async def both() -> None:
        await asyncio.gather(view._on_upload(event("first.json", big)), view._on_upload(event("second.json", big)))

    loop = view.load._impl.gui_api._event_loop
    asyncio.run_coroutine_threadsafe(both(), loop).result(timeout=60)
    assert br.notes == [(RECORD_REFUSED, "second.json: another session record is still being loaded here; "
                                         "wait until it is shown, then load this one.")]
    assert len(view.workflow.runs) == 50 and view.record_md.content.startswith("**Loaded first\\.json**")
    assert view._loading_record is False
    # after it, a load is accepted again, once the session's share of the server's time is back
    # (a load under a loaded machine can spend more than the 0.25 s burst: job_pool's share)
    wait_until(lambda: br.sa.jobs.credit_s(br.sa) > 0.0, what="session A's job share refilled", timeout=60)
    asyncio.run_coroutine_threadsafe(view._on_upload(event("again.json", big)), loop).result(timeout=60)
    assert len(view.workflow.runs) == 100 and len(br.notes) == 1
