"""A damaged tool library in the running pendant: every browser still gets its
Calibrate tab and the valid tools, and is told, by a notification it really receives, what
was set aside and where the backup is -- once per recovery, not on every reload."""

from __future__ import annotations

import json
import threading

from support.wsclient import DrainingClient, decode_window, wait_until


class RecordingClient(DrainingClient):
    """A headless browser that keeps the notifications and the tab labels it is sent."""

    def __init__(self, port: int) -> None:
        self.notifications: list[dict] = []
        self.tab_labels: dict[str, tuple[str, ...]] = {}
        self.button_labels: set[str] = set()
        self._lock = threading.Lock()
        super().__init__(port)

    def _received(self, msg: bytes | str) -> None:
        if not isinstance(msg, bytes):
            return
        for m in decode_window(msg):
            kind, props = m.get("type"), m.get("props") or {}
            with self._lock:
                if kind == "NotificationShowMessage":
                    self.notifications.append(props)
                elif kind == "GuiTabGroupMessage":
                    self.tab_labels[m["uuid"]] = tuple(props.get("_tab_labels", ()))
                elif kind == "GuiUpdateMessage" and "_tab_labels" in m["updates"]:
                    self.tab_labels[m["uuid"]] = tuple(m["updates"]["_tab_labels"])
                elif kind == "GuiButtonMessage":
                    self.button_labels.add(props.get("label"))

    def titled(self, title: str) -> list[dict]:
        with self._lock:
            return [n for n in self.notifications if n["title"] == title]


def _library_doc(entries: dict, active=None) -> str:
    return json.dumps({"format": "tcp-pendant-tool-library", "version": 1,
                       "active_slot": active, "tools": entries})


def _four_good_one_nan() -> str:
    entries = {str(s): {"name": f"tool{s}", "tcp_mm": [s, 0, 100]} for s in (1, 2, 4, 5)}
    entries["3"] = {"name": "<b>broken</b>", "tcp_mm": [float("nan"), 0, 100]}
    return _library_doc(entries, active=2)


def _open(app) -> tuple[RecordingClient, object]:
    c = RecordingClient(app.port)
    wait_until(lambda: len(app.sessions) == 1, what="session built")
    (session,) = app.sessions.values()
    wait_until(lambda: "Calibrate" in sum(c.tab_labels.values(), ()), what="the Calibrate tab")
    wait_until(lambda: "Start" in c.button_labels, what="the Calibrate menu's Start button")
    return c, session


def test_one_bad_entry_keeps_the_others_and_the_browser_is_told(app_factory, tmp_path) -> None:
    path = tmp_path / "tools.json"
    path.write_text(_four_good_one_nan(), encoding="utf-8")
    app = app_factory()
    c, session = _open(app)
    try:
        assert "calibrate" in session.views
        panel = session.views["tools"]
        assert panel.slots.options == ("1: tool1", "2: tool2", "4: tool4", "5: tool5")
        assert session.tools.active_slot is None  # per-browser: the library's active slot is not the session's
        title = "Tool library: bad entries set aside"
        wait_until(lambda: c.titled(title), what="the recovery notification")
        (note,) = c.titled(title)
        backup = app.library.recovery.backup
        assert backup.exists() and "NaN" in backup.read_text(encoding="utf-8")
        assert str(backup) in note["body"] and "slot 3: tcp_mm[0] must be a finite" in note["body"]
        assert "slots 1, 2, 4, 5" in note["body"]
        # once per recovery: a reload (the watcher's, or another browser's save) says nothing
        app.library_changed()
        panel.reload()
        wait_until(lambda: c.n_messages > 0)
        c2 = RecordingClient(app.port)  # a second browser on the same server is told as well
        try:
            wait_until(lambda: len(app.sessions) == 2, what="second session")
            wait_until(lambda: c2.titled(title), what="the second browser's notification")
        finally:
            c2.close()
        assert len(c.titled(title)) == 1
        # a later recovery is new: told once more
        path.write_text(_library_doc({"1": {"name": "tool1", "tcp_mm": [1, 0, 100]},
                                      "2": {"name": 7, "tcp_mm": [0, 0, 0]}}), encoding="utf-8")
        wait_until(lambda: len(c.titled(title)) == 2, what="the second recovery's notification")
        assert "slot 2: tool name must be a string, got 7" in c.titled(title)[1]["body"]
        assert app.library.recovery.backup != backup and backup.exists()
        wait_until(lambda: panel.slots.options == ("1: tool1",), what="the reloaded list")
    finally:
        c.close()


def test_deeply_nested_library_still_gives_the_calibrate_tab(app_factory, tmp_path) -> None:
    path = tmp_path / "tools.json"
    path.write_bytes(b"[" * 100_000)
    app = app_factory()
    c, session = _open(app)
    try:
        assert "calibrate" in session.views and session.tools.active_slot is None
        wait_until(lambda: c.titled("Tool library moved aside"), what="the notification")
        (note,) = c.titled("Tool library moved aside")
        assert "nested too deeply" in note["body"] and str(app.library.recovered_backup) in note["body"]
        assert app.library.recovered_backup.read_bytes() == b"[" * 100_000
    finally:
        c.close()


def test_unreadable_library_leaves_the_tool_panel_working_and_says_why(app_factory,
                                                                        tmp_path) -> None:
    (tmp_path / "tools.json").mkdir()  # cannot be read as a file, even by root
    app = app_factory()
    c, session = _open(app)
    try:
        assert session.views["tools"].slots.options == ("(library empty)",)
        # the Calibrate menu is built too (it lists the session's copy, it does not read the file)
        assert "calibrate" in session.views
        assert session.views["calibrate"].library_tool.options == ("(library empty)",)
        assert session.views["calibrate"].menu_folder.visible
        wait_until(lambda: c.titled("Tool library unavailable"), what="the error notification")
        (note,) = c.titled("Tool library unavailable")
        assert "cannot read the tool library" in note["body"]
        session.views["tools"].reload()  # the same reason is not repeated
        assert len(c.titled("Tool library unavailable")) == 1
    finally:
        c.close()
