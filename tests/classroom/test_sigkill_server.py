"""A kill -9 of the *server* mid-exercise loses no touch acknowledged on screen.

A real ``tcp-pendant`` process with a gradebook; a headless websocket client behaves as a
browser: it types a name in "Your name", joins, starts an XYZ 4-point calibration and presses
Auto-touch, waiting after each press for the screen's acknowledgement (the Auto-touch message the
server pushes after the touch). After the third acknowledgement it presses once more and the
server is killed with SIGKILL at once; the gradebook must hold the three acknowledged touches.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import msgspec.msgpack
import pytest
from viser import _messages

from support.wsclient import ButtonClient, decode_window, wait_until

from tcp_pendant.classroom.gradebook import Gradebook


class BrowserLike(ButtonClient):
    """Learns buttons and text fields by label; counts the Auto-touch acknowledgements."""

    def __init__(self, port: int) -> None:
        self.text_uuids: dict[str, str] = {}
        self.acks = 0
        super().__init__(port, ("Join the class", "Start", "Auto-touch"))

    def _received(self, msg: bytes | str) -> None:
        if not isinstance(msg, bytes):
            return
        for m in decode_window(msg):
            self._decoded(m)
        if len(self.button_uuids) == len(self.labels):
            self.found.set()

    def _decoded(self, m: dict) -> None:
        super()._decoded(m)
        kind = m.get("type")
        if kind == "GuiTextMessage":
            self.text_uuids.setdefault((m.get("props") or {}).get("label"), m["uuid"])
        elif kind == "GuiUpdateMessage" and "Operator error σ" in str(m["updates"].get("_markdown", "")):
            self.acks += 1

    def type_text(self, label: str, text: str) -> None:
        msg = _messages.GuiUpdateMessage(self.text_uuids[label], {"value": text})
        with self._send_lock:
            self.ws.send(msgspec.msgpack.encode(msg.as_serializable_dict()))


@pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="SIGKILL is POSIX only")
def test_sigkill_of_the_server_keeps_every_acknowledged_touch(tmp_path: Path) -> None:
    db = tmp_path / "class.sqlite3"
    proc = subprocess.Popen([sys.executable, "-m", "tcp_pendant", "--port", "0", "--tool-library",
                             str(tmp_path / "tools.json"), "--class-db", str(db), "--trainer-token",
                             "trainer-secret-of-16"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    client = None
    try:
        lines: list[str] = []
        for line in proc.stdout:
            lines.append(line)
            if line.startswith("Trainer view:"):
                break
        text = "".join(lines)
        assert "trainer token trai… (the --trainer-token you gave)" in text, text + proc.stderr.read()
        assert "trainer-secret" not in text           # the terminal is often the projected screen
        port = int(re.search(r"http://127\.0\.0\.1:(\d+)", text).group(1))
        threading.Thread(target=proc.stdout.read, daemon=True).start()      # keep the pipe drained
        client = BrowserLike(port)
        assert client.found.wait(60), client.button_uuids
        wait_until(lambda: "Your name" in client.text_uuids, what="the name field")
        client.type_text("Your name", "Kim")
        time.sleep(0.2)
        client.click("Join the class")
        wait_until(lambda: _trainees(db) == ["Kim"], what="the trainee in the gradebook")
        client.click("Start")
        for k in range(1, 4):
            client.click("Auto-touch")
            wait_until(lambda k=k: client.acks >= k, timeout=60, what=f"acknowledgement {k}")
        client.click("Auto-touch")               # the server may be inside this write when killed
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        if client is not None:
            client.close()
        proc.kill()
        proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL
    with Gradebook(db, create=False) as book, book.store.read() as db_:
        touches = db_.execute("SELECT step_index, auto FROM touches ORDER BY id").fetchall()
    assert len(touches) >= 3, touches
    assert touches[:3] == [(0, 1), (1, 1), (2, 1)]


def _trainees(db: Path) -> list[str]:
    if not db.exists():
        return []
    with Gradebook(db, create=False) as book, book.store.read() as c:
        return [r[0] for r in c.execute("SELECT name FROM trainees")]


@pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="SIGKILL is POSIX only")
def test_a_finished_unsaved_result_outlasts_a_sigkill_of_the_server(tmp_path: Path) -> None:
    """Kim finishes an XYZ 4-point and does not save it; the server is killed with SIGKILL.
    The gradebook gives the finished result back for her next join (``classroom.restore``),
    recomputed to the TCP it recorded."""
    from tcp_pendant.classroom.restore import runs_to_restore

    db = tmp_path / "class.sqlite3"
    proc = subprocess.Popen([sys.executable, "-m", "tcp_pendant", "--port", "0", "--tool-library",
                             str(tmp_path / "tools.json"), "--class-db", str(db), "--trainer-token",
                             "trainer-secret-of-16"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    client = None
    try:
        lines: list[str] = []
        for line in proc.stdout:
            lines.append(line)
            if line.startswith("Trainer view:"):
                break
        port = int(re.search(r"http://127\.0\.0\.1:(\d+)", "".join(lines)).group(1))
        threading.Thread(target=proc.stdout.read, daemon=True).start()
        client = BrowserLike(port)
        assert client.found.wait(60), client.button_uuids
        wait_until(lambda: "Your name" in client.text_uuids, what="the name field")
        client.type_text("Your name", "Kim")
        time.sleep(0.2)
        client.click("Join the class")
        wait_until(lambda: _trainees(db) == ["Kim"], what="the trainee in the gradebook")
        client.click("Start")
        for k in range(1, 5):
            client.click("Auto-touch")
            wait_until(lambda k=k: client.acks >= k, timeout=60, what=f"acknowledgement {k}")
        wait_until(lambda: _result_kept(db), timeout=60, what="the finished result in the gradebook")
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        if client is not None:
            client.close()
        proc.kill()
        proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL
    with Gradebook(db, create=False) as book:
        (back,) = runs_to_restore(book, "Kim")
        (row,) = book.grades.rows()
        assert back.finished and back.calibration_id == row.calibration_id
        assert back.run.wizard.status == "complete" and back.run.wizard.saves_to_library
        assert tuple(back.run.wizard.finished_result.tcp_mm) == pytest.approx(row.tcp_mm, abs=1e-9)


def _result_kept(db: Path) -> bool:
    with Gradebook(db, create=False) as book, book.store.read() as c:
        return c.execute("SELECT COUNT(*) FROM run_states r JOIN calibrations k ON k.id = r.calibration_id "
                         "WHERE r.step = 'result' AND k.status = 'finished'").fetchone()[0] == 1
