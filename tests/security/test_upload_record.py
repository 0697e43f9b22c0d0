"""Parsing: an uploaded session record is bytes parsed as JSON, never a
server path, and the limits (size, nesting depth, counts) are checked before the work they bound.
"""

from __future__ import annotations

import builtins
import json
import os
import threading
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.wizards import Wizard
from tcp_pendant.wizards import session_record as sr
from tcp_pendant.wizards.session_record import (
    MAX_NESTING_DEPTH,
    MAX_POSES_PER_WIZARD,
    MAX_RECORD_BYTES,
    MAX_TOUCHES,
    MAX_WIZARDS,
    SessionRecordError,
    check_session_record,
    dumps,
    json_nesting_depth,
    load_and_replay,
    parse_session_record,
    read_session_file,
)

from tcpcal.library import ToolLibrary

from support.calib_helpers import make_controller


def _workflow(tmp_path: Path, seed: int = 0) -> CalibrationWorkflow:
    return CalibrationWorkflow(make_controller("kr6", "pointer"), ToolLibrary(tmp_path / "tools.json"),
                               robot="kr6", rng=np.random.default_rng(seed))


@pytest.fixture(scope="module")
def real_record(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    """A record exported after a lesson's worth of XYZ 4-point runs (4 to 20 touches)."""
    wf = _workflow(tmp_path_factory.mktemp("lib"), seed=1)
    for n in (4, 8, 12, 20, 20, 6):
        wf.start("xyz4", n_points=n)
        while wf.result is None:
            assert wf.auto_touch(AutoTouchRequest(sigma_mm=0.3)).ok
    return dumps(wf.export_record([(np.eye(4), f"P{i}") for i in range(30)])).encode()


class _NoOpen:
    """Fails the test if anything opens or reads one of ``paths`` (builtins.open, os.open,
    Path.read_text / read_bytes / open)."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch, *paths: str) -> None:
        self.paths = {os.path.abspath(p) for p in paths}
        self.opened: list[str] = []
        real_open, real_os_open = builtins.open, os.open

        def watch(p: Any) -> None:
            if isinstance(p, (str, os.PathLike)) and os.path.abspath(os.fspath(p)) in self.paths:
                self.opened.append(os.fspath(p))
                raise AssertionError(f"{p} was opened")

        def fake_open(file: Any, *a: Any, **k: Any) -> Any:
            watch(file)
            return real_open(file, *a, **k)

        def fake_os_open(path: Any, *a: Any, **k: Any) -> Any:
            watch(path)
            return real_os_open(path, *a, **k)

        monkeypatch.setattr(builtins, "open", fake_open)
        monkeypatch.setattr(os, "open", fake_os_open)
        for name in ("read_text", "read_bytes", "open"):
            real = getattr(Path, name)
            monkeypatch.setattr(Path, name, lambda self, *a, _real=real, **k: (watch(self), _real(self, *a, **k))[1])


@pytest.mark.parametrize("as_type", [bytes, str])
def test_an_upload_whose_content_is_a_server_path_is_not_json_and_the_file_is_never_opened(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, real_record: bytes, as_type: type) -> None:
    record_file = tmp_path / "someone_elses_record.json"
    record_file.write_bytes(real_record)            # a valid record on the server's disk
    guard = _NoOpen(monkeypatch, str(record_file), "/etc/passwd", "/etc/shadow")
    wf = _workflow(tmp_path)
    for content in (str(record_file), "/etc/passwd", "/etc/shadow", f"  {record_file}\n"):
        data = content if as_type is str else content.encode()
        with pytest.raises(SessionRecordError, match="not valid JSON"):
            wf.load_record(data)                    # the Calibrate tab's path
        with pytest.raises(SessionRecordError, match="not valid JSON"):
            load_and_replay(data)
    assert guard.opened == [] and wf.runs == []


def test_a_path_object_is_refused_by_the_upload_api_and_only_read_by_read_session_file(
        tmp_path: Path, real_record: bytes) -> None:
    f = tmp_path / "r.json"
    f.write_bytes(real_record)
    with pytest.raises(TypeError, match="read_session_file"):
        load_and_replay(f)                          # type: ignore[arg-type]
    with pytest.raises(TypeError, match="bytes"):
        parse_session_record(str(f))                # type: ignore[arg-type]
    with pytest.raises(TypeError, match="pathlib.Path"):
        read_session_file(str(f))                   # type: ignore[arg-type]
    assert read_session_file(f) == json.loads(real_record)      # the server-side loader


def test_a_fifo_path_neither_hangs_the_upload_nor_the_server_side_reader(tmp_path: Path) -> None:
    fifo = tmp_path / "fifo.json"
    os.mkfifo(fifo)
    outcome: dict[str, BaseException] = {}

    def attempt() -> None:
        for fn, arg in ((parse_session_record, str(fifo).encode()), (read_session_file, fifo)):
            try:
                fn(arg)
            except SessionRecordError as exc:
                outcome[fn.__name__] = exc

    t = threading.Thread(target=attempt, daemon=True)
    t.start()
    t.join(timeout=5)
    assert not t.is_alive(), "reading a FIFO blocked"
    assert "not valid JSON" in str(outcome["parse_session_record"])
    assert "not a regular file" in str(outcome["read_session_file"])


def test_a_real_exported_record_is_far_below_every_limit_and_loads(tmp_path: Path, real_record: bytes) -> None:
    data = json.loads(real_record)
    assert len(real_record) < MAX_RECORD_BYTES / 10
    assert json_nesting_depth(real_record) <= 8 < MAX_NESTING_DEPTH
    assert max(len(w["state"]["poses"]) for w in data["wizards"]) == 20 < MAX_POSES_PER_WIZARD
    loaded = load_and_replay(real_record)
    assert len(loaded.checks) == 6 and all(c.matches for c in loaded.checks)
    wf = _workflow(tmp_path)
    assert len(wf.load_record(real_record)) == 6 and len(wf.runs) == 6


def _no_json_parse(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*_a: Any, **_k: Any) -> Any:
        raise AssertionError("json.loads ran on a record that breaks a limit")

    monkeypatch.setattr(sr.json, "loads", refuse)


def test_size_limit_is_checked_on_the_bytes_before_any_parsing(monkeypatch: pytest.MonkeyPatch) -> None:
    body = b'{"format": "tcp-pendant-session", "version": 1, "wizards": [], "pad": "'
    big = body + b"x" * (MAX_RECORD_BYTES - len(body)) + b'"}'
    assert len(big) == MAX_RECORD_BYTES + 2
    assert parse_session_record(big[:-4] + b'"}')["wizards"] == []        # at the limit: parsed
    _no_json_parse(monkeypatch)
    with pytest.raises(SessionRecordError, match=r"is 2,000,002 bytes \(2\.0 MB\); .* at most 2,000,000 bytes \(2 MB\)"):
        parse_session_record(big)
    with pytest.raises(SessionRecordError, match="2,000,001 bytes"):
        sr.check_record_size(MAX_RECORD_BYTES + 1)
    sr.check_record_size(MAX_RECORD_BYTES)


@pytest.mark.parametrize("bomb", [b"[" * 100_000, b'{"a":' * 50_000, b"[" * 1000 + b"]" * 1000,
                                  b'{"format": "tcp-pendant-session", "x": ' + b"[" * 33 + b"]" * 33 + b"}"])
def test_nesting_depth_is_checked_before_json_loads(monkeypatch: pytest.MonkeyPatch, bomb: bytes) -> None:
    _no_json_parse(monkeypatch)
    with pytest.raises(SessionRecordError, match=f"levels deep; .* at most {MAX_NESTING_DEPTH} levels"):
        parse_session_record(bomb)


def test_depth_scan_ignores_brackets_inside_strings_and_is_linear_on_escaped_quotes() -> None:
    assert json_nesting_depth(b'{"a": "[[[[{{{{", "b": ["\\"[[["]}') == 2
    assert json_nesting_depth(b'["\\\\"]') == 1                   # an escaped backslash ends the string
    assert json_nesting_depth(b'"\\"' * 600_000) == 0              # no restart inside a string
    assert json_nesting_depth(b'"' + b"[" * 1000) == 0             # unterminated string to the end


def _minimal_record(n_wizards: int = 1, n_poses: int = 4, n_touches: int = 0) -> dict[str, Any]:
    pose = {"T_world_flange_m": np.eye(4).tolist(), "recorded_at": "2026-01-01T00:00:00Z"}
    state = {"kind": "xyz4", "params": {"n_points": 4}, "poses": {str(i): pose for i in range(n_poses)},
             "step_index": 0, "status": "in_progress", "resume_status": "in_progress", "started_at": ""}
    return {"format": "tcp-pendant-session", "version": 1,
            "touches": [{"label": "P", "T_world_flange_m": np.eye(4).tolist()}] * n_touches,
            "wizards": [{"state": state, "result": None, "true_tool": None, "truth": None}] * n_wizards}


@pytest.mark.parametrize("kind, n, match", [
    ("wizards", MAX_WIZARDS + 1, f"{MAX_WIZARDS + 1} calibrations; .* at most {MAX_WIZARDS} calibrations"),
    ("poses", MAX_POSES_PER_WIZARD + 1, f"in wizard 1, {MAX_POSES_PER_WIZARD + 1} touches"),
    ("touches", MAX_TOUCHES + 1, f"{MAX_TOUCHES + 1} pendant touches"),
])
def test_counts_are_checked_before_any_wizard_is_replayed(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                          kind: str, n: int, match: str) -> None:
    rec = _minimal_record(**{f"n_{kind}": n})
    data = json.dumps(rec, separators=(",", ":")).encode()
    assert len(data) < MAX_RECORD_BYTES and json_nesting_depth(data) < MAX_NESTING_DEPTH

    def refuse(*_a: Any, **_k: Any) -> Any:
        raise AssertionError("a wizard was rebuilt from a record that breaks a limit")

    monkeypatch.setattr(Wizard, "from_dict", refuse)
    wf = _workflow(tmp_path)
    for source in (data, rec):
        with pytest.raises(SessionRecordError, match=match):
            wf.load_record(source)
    assert wf.runs == []


def test_at_the_count_limits_a_record_is_accepted() -> None:
    rec = _minimal_record(n_wizards=MAX_WIZARDS, n_poses=4, n_touches=MAX_TOUCHES)
    assert check_session_record(rec)["wizards"] == rec["wizards"]


@pytest.mark.parametrize("entry, match", [
    ({"state": None}, "no \"state\" object"),
    ({"state": {"kind": "xyz4", "poses": []}}, "\"poses\" must be an object"),
    ({"state": {"kind": "xyz4"}, "true_tool": [1, 2]}, "bad \"true_tool\""),
    ({"state": {"kind": "xyz4"}, "true_tool": {"key": None, "T_flange_tcp_true_m": [[1]]}}, "bad \"true_tool\""),
    ({"state": {"kind": "xyz4", "params": []}}, "cannot be rebuilt"),
])
def test_malformed_entries_are_clear_errors_and_change_nothing(tmp_path: Path, entry: dict, match: str) -> None:
    wf = _workflow(tmp_path)
    wf.start("xyz4")
    wf.auto_touch(AutoTouchRequest())
    rec = {"format": "tcp-pendant-session", "version": 1, "wizards": [entry]}
    with pytest.raises(SessionRecordError, match=match):
        wf.load_record(json.dumps(rec).encode())
    assert len(wf.runs) == 1 and wf.is_open and wf.wizard.step_index == 1


def test_a_stored_result_of_the_wrong_shape_is_a_record_error(tmp_path: Path, real_record: bytes) -> None:
    rec = json.loads(real_record)
    rec["wizards"][0]["result"]["tcp_mm"] = "abc"
    with pytest.raises(SessionRecordError, match="Wizard 1 of the record: its stored result"):
        load_and_replay(json.dumps(rec).encode())
    rec["wizards"][0]["result"] = [1, 2]
    with pytest.raises(SessionRecordError, match="Wizard 1 of the record: its stored result"):
        load_and_replay(json.dumps(rec).encode())
