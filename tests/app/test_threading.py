"""Every GUI callback runs on viser's event loop, in the order the browser's messages
arrived, and no render writes a widget value older than the newest one the browser sent.

Real viser server in-process, headless websocket clients (tests/support/wsclient.py) that send what
a browser sends (GUI updates, clicks, gizmo drags) and record every GUI update they receive.
"""

from __future__ import annotations

import asyncio
import math
import threading
import time
from pathlib import Path
from typing import Any

import msgspec.msgpack
import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from viser import _messages
from viser.infra._async_message_buffer import AsyncMessageBuffer

from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool
from tcp_pendant.pendant import joint_readout_markdown

from support.wsclient import DrainingClient, decode_window, loop_ran_for, wait_until


class Browser(DrainingClient):
    """A headless browser: sends GUI updates, clicks and gizmo drags the way viser's client
    does, and records every ``GuiUpdateMessage`` the server sends it, in order."""

    def __init__(self, port: int) -> None:
        self.received: list[tuple[str, dict[str, Any]]] = []
        self._send_lock = threading.Lock()
        super().__init__(port)

    def _received(self, msg: bytes | str) -> None:
        if isinstance(msg, bytes):
            for m in decode_window(msg):
                if m.get("type") == "GuiUpdateMessage":
                    self.received.append((m["uuid"], dict(m["updates"])))

    def values_of(self, handle: Any) -> list[Any]:
        """Every value the server sent this browser for ``handle``, in order."""
        uuid = handle._impl.uuid
        return [u["value"] for i, u in list(self.received) if i == uuid and "value" in u]

    def send(self, message: Any) -> None:
        with self._send_lock:
            self.ws.send(msgspec.msgpack.encode(message.as_serializable_dict()))

    def set(self, handle: Any, value: Any) -> None:
        """The user sets a slider, text box, dropdown or button group to ``value``."""
        self.send(_messages.GuiUpdateMessage(handle._impl.uuid, {"value": value}))

    def click(self, button: Any) -> None:
        self.send(_messages.GuiUpdateMessage(button._impl.uuid, {"value": True}))

    def drag_gizmo(self, owner: str, positions: list[np.ndarray], wxyz: np.ndarray) -> None:
        """A drag of the TCP gizmo through ``positions`` (WORLD, m), start to end."""
        self.send(_messages.TransformControlsDragStartMessage(name="/tcp_gizmo", owner=owner))
        for p in positions:
            self.send(_messages.TransformControlsUpdateMessage(name="/tcp_gizmo", wxyz=tuple(map(float, wxyz)),
                                                               position=tuple(map(float, p)), owner=owner))
            time.sleep(0.01)
        self.send(_messages.TransformControlsDragEndMessage(name="/tcp_gizmo", owner=owner))


def _browser_session(app: Any, n_before: int = 0) -> tuple[Browser, Any]:
    b = Browser(app.port)
    wait_until(lambda: len(app.sessions) > n_before, what="session built")
    session = next(s for s in app.sessions.values() if s.client is not None
                   and s.client.client_id == max(app.sessions))
    return b, session


def _joint_mode(b: Browser, s: Any) -> None:
    p = s.views["pendant"]
    b.set(p.mode, "Joint")
    wait_until(lambda: p.joint_folder.visible, what="joint mode")


class _WatcherPolls:
    """The library stamps the app's library watcher reads from now on, one a poll, in order."""

    def __init__(self, app: Any) -> None:
        self.app, self.read, self.polls = app, app._library_stamp, []
        app._library_stamp = self._poll

    def _poll(self) -> Any:
        self.polls.append(self.read())
        return self.polls[-1]

    def caught_up(self) -> None:
        """Barrier behind the library file's last change: two polls read the file as it is
        now (a change the watcher had not seen yet is handed to the loop right after the first),
        then the loop runs everything queued so far, that hand-over included."""
        final, n = self.read(), len(self.polls)
        wait_until(lambda: len(self.polls) >= n + 2 and self.polls[-2] == self.polls[-1] == final,
                   what="two polls of the library watcher behind the file's last change")
        loop_ran_for(self.app.server.get_event_loop(), 0.0)


def _slow_first_call(obj: Any, name: str, seconds: float) -> list[Any]:
    """Make ``obj.name`` sleep ``seconds`` on its first call; returns the list of call args."""
    real = getattr(obj, name)
    calls: list[Any] = []

    def slow(*args: Any, **kwargs: Any) -> Any:
        calls.append(args)
        if len(calls) == 1:
            time.sleep(seconds)
        return real(*args, **kwargs)

    setattr(obj, name, slow)
    return calls


def test_newest_slider_value_wins_when_the_first_apply_is_slow(app_factory) -> None:
    """The issue's forced reproduction: A1 = 10.0 then 20.0 50 ms later while applying the
    first takes 200 ms. Robot, readout and slider end at 20.0 and the server never sends the
    browser the older 10.0 (before: both callbacks applied 10.0 and the slider jumped back)."""
    app = app_factory()
    b, s = _browser_session(app)
    try:
        _joint_mode(b, s)
        p = s.views["pendant"]
        a1 = p.joint_sliders[0]
        calls = _slow_first_call(s.controller, "set_q", 0.2)
        b.set(a1, 10.0)
        time.sleep(0.05)
        b.set(a1, 20.0)
        wait_until(lambda: len(calls) >= 2, what="both slider values applied")
        wait_until(lambda: "20.00" in p.joints_md.content, what="readout")
        b.sync(s.client)                                 # both handled, and all they sent received
        assert math.degrees(s.controller.q_rad[0]) == pytest.approx(20.0, abs=1e-9)
        assert p.joints_md.content == joint_readout_markdown(s.controller.joint_angles_deg())
        assert a1.value == pytest.approx(20.0)
        assert 10.0 not in b.values_of(a1), b.values_of(a1)   # no stale write-back
        assert len(calls) == 2
    finally:
        b.close()


def test_a_dragged_slider_is_not_echoed_but_a_jog_is_sent(app_factory) -> None:
    """A value between the 0.01 deg steps (what a browser may send) moves the robot exactly and
    is not written back rounded (that pulls a dragged slider to an older value); once a jog
    key moves the joint, the slider gets the new angle."""
    app = app_factory()
    b, s = _browser_session(app)
    try:
        _joint_mode(b, s)
        p = s.views["pendant"]
        a1 = p.joint_sliders[0]
        b.set(a1, 10.004)
        wait_until(lambda: abs(math.degrees(s.controller.q_rad[0]) - 10.004) < 1e-9, what="A1 at 10.004")
        b.set(p.increment, "1")                          # for the jog below
        wait_until(lambda: s.jogger.settings.increment == "1", what="increment 1")
        b.sync(s.client)                                  # all the slider's handling sent, received
        assert b.values_of(a1) == []                      # nothing echoed
        b.click(p.joint_buttons[(0, 1)])                  # A1 +: a jog key moves the joint
        wait_until(lambda: abs(math.degrees(s.controller.q_rad[0]) - 11.004) < 1e-9, what="A1 + 1 deg")
        wait_until(lambda: b.values_of(a1) == [11.0], what="the jog's angle sent to the slider")
        b.click(p.joint_buttons[(0, -1)])                 # and back: 10.004 shown as 10.0
        wait_until(lambda: b.values_of(a1) == [11.0, 10.0], what="the jog back sent")
    finally:
        b.close()


def test_no_message_is_pushed_off_the_event_loop_under_mixed_load(app_factory, tmp_path: Path) -> None:
    """Three browsers drive joint sliders, jog keys, the gizmo, the tool panel (type, choose,
    activate, rename, export, numeric entry) and Record point while another process saves a
    tool to the library file: every message the server queues is pushed from viser's event
    loop thread (before: the pool callbacks and the library watcher pushed from theirs)."""
    app = app_factory()
    library = ToolLibrary(tmp_path / "tools.json")
    library.save(1, Tool(name="Pointer cal", tcp_mm=(0.0, 0.0, 150.0)))
    browsers: list[tuple[Browser, Any]] = []
    try:
        for i in range(3):
            browsers.append(_browser_session(app, i))
        sessions = [s for _, s in browsers]
        for b, s in browsers:
            wait_until(lambda s=s: "1: Pointer cal" in s.views["tools"].slots.options, what="library listed")
            _joint_mode(b, s)
        loop = app.server.get_event_loop()
        loop_thread: list[int] = []
        loop.call_soon_threadsafe(lambda: loop_thread.append(threading.get_ident()))
        wait_until(lambda: bool(loop_thread), what="loop thread")
        watcher = _WatcherPolls(app)
        for b, s in browsers:                             # connect-time work done and sent
            b.sync(s.client)

        pushes: list[tuple[int, str]] = []
        real_push = AsyncMessageBuffer.push

        def recording_push(self: Any, message: Any) -> None:
            pushes.append((threading.get_ident(), threading.current_thread().name))
            real_push(self, message)

        AsyncMessageBuffer.push = recording_push           # type: ignore[method-assign]
        try:
            q0 = [s.controller.q_rad for s in sessions]
            tcp0 = [s.controller.T_world_tcp() for s in sessions]

            def drive(k: int, b: Browser, s: Any) -> None:
                p, tools = s.views["pendant"], s.views["tools"]
                for j in range(20):
                    b.set(p.joint_sliders[1], float(np.degrees(q0[k][1])) + 0.5 * (j + 1))
                    time.sleep(0.005)
                b.click(p.joint_buttons[(2, 1)])
                b.set(p.mode, "Cartesian")
                T = s.controller.T_world_tcp()
                wxyz = np.roll(Rotation.from_matrix(T[:3, :3]).as_quat(), 1)
                b.drag_gizmo(str(s.client.client_id), [T[:3, 3] + [0.0, 0.0, -0.002 * (j + 1)] for j in range(10)],
                             wxyz)
                b.set(tools.slots, "1: Pointer cal")
                b.click(tools.activate)
                b.set(tools.new_name, f"Pointer {k}")
                b.click(tools.rename)
                b.click(tools.export)
                b.set(tools.entry_name, f"Gun {k}")
                b.set(tools.entry_fields["Z"], "120")
                b.click(tools.entry_save)
                b.click(s.views["touches"].record)

            threads = [threading.Thread(target=drive, args=(k, b, s)) for k, (b, s) in enumerate(browsers)]
            for t in threads:
                t.start()
            ToolLibrary(tmp_path / "tools.json").save(9, Tool(name="Saved elsewhere", tcp_mm=(1.0, 2.0, 3.0)))
            for t in threads:
                t.join()
            for _, s in browsers:                         # the watcher's reload reached every session
                wait_until(lambda s=s: "9: Saved elsewhere" in s.views["tools"].slots.options, what="reload")
            wait_until(lambda: sum(t.name.startswith("Gun ") for t in library.tools().values()) == 3,
                       what="three numeric entries saved")
            for b, s in browsers:                         # every message handled, all it queued sent
                b.sync(s.client)
            watcher.caught_up()                           # and the library's last change reloaded
        finally:
            AsyncMessageBuffer.push = real_push           # type: ignore[method-assign]
        # the load did what it says
        for k, s in enumerate(sessions):
            assert s.controller.q_rad[1] != q0[k][1] and s.controller.q_rad[2] != q0[k][2]
            assert s.controller.T_world_tcp()[2, 3] < tcp0[k][2, 3] - 0.005     # the gizmo drag moved it down
        names = {t.name for t in library.tools().values()}
        assert any(n.startswith("Pointer ") for n in names) and "Saved elsewhere" in names
        off = [name for ident, name in pushes if ident != loop_thread[0]]
        assert len(pushes) > 200
        assert off == [], f"{len(off)} of {len(pushes)} pushes off the event loop, from {sorted(set(off))}"
    finally:
        for b, _ in browsers:
            b.close()


def test_shared_rename_keeps_the_name_another_browser_typed(app_factory, tmp_path: Path) -> None:
    """--shared: browser A renames slot 1 (the library write is slow) while browser B fills the
    New-name box for slot 2; B's Rename then uses B's name (before: A's Rename cleared the box
    B had just filled, and B got "Not done: Type the new name in 'New name' first.")."""
    library = ToolLibrary(tmp_path / "tools.json")
    library.save(1, Tool(name="T1", tcp_mm=(0.0, 0.0, 100.0)))
    library.save(2, Tool(name="T2", tcp_mm=(0.0, 0.0, 200.0)))
    app = app_factory(shared=True)
    a = Browser(app.port)
    b = None
    try:
        wait_until(lambda: len(app.server.get_clients()) == 1, what="browser A")
        (handle_a,) = app.server.get_clients().values()
        b = Browser(app.port)
        wait_until(lambda: len(app.server.get_clients()) == 2, what="two browsers")
        (handle_b,) = (h for h in app.server.get_clients().values() if h is not handle_a)
        s = app.shared_session
        tools = s.views["tools"]
        wait_until(lambda: tools.slots.options == ("1: T1", "2: T2"), what="library listed")
        notes: list[tuple[str, str]] = []
        real_notify = s.notify
        s.notify = lambda title, body, **kw: (notes.append((title, body)), real_notify(title, body, **kw))
        calls = _slow_first_call(app.library, "rename", 0.3)
        a.set(tools.slots, "1: T1")
        a.set(tools.new_name, "Alpha")
        a.click(tools.rename)
        time.sleep(0.05)
        b.set(tools.slots, "2: T2")
        b.set(tools.new_name, "Beta")
        wait_until(lambda: len(calls) == 1 and tools.new_name.value == "Beta", what="A renaming, B typed")
        a.sync(handle_a)                                  # A's rename handled to its end
        assert tools.new_name.value == "Beta"
        b.click(tools.rename)
        wait_until(lambda: len(calls) == 2 or any(t == "Not done" for t, _ in notes), what="B's rename")
        wait_until(lambda: {t.name for t in library.tools().values()} == {"Alpha", "Beta"}, timeout=5,
                   what=f"both renamed (notifications: {notes})")
        assert not [n for n in notes if n[0] == "Not done"]
        b.sync(handle_b)                                  # B received all its rename sent
        assert "" not in b.values_of(tools.new_name)      # B's box was never cleared under B
    finally:
        a.close()
        if b is not None:
            b.close()


def test_per_browser_rename_clears_the_box_of_the_browser_that_clicked(app_factory, tmp_path: Path) -> None:
    ToolLibrary(tmp_path / "tools.json").save(1, Tool(name="T1", tcp_mm=(0.0, 0.0, 100.0)))
    app = app_factory()
    b, s = _browser_session(app)
    try:
        tools = s.views["tools"]
        wait_until(lambda: tools.slots.value == "1: T1", what="library listed")
        b.set(tools.new_name, "Renamed")
        b.click(tools.rename)
        wait_until(lambda: s.library.get(1).name == "Renamed", what="renamed")
        wait_until(lambda: b.values_of(tools.new_name) == [""], what="the box cleared")
        assert tools.slots.value == "1: Renamed"
    finally:
        b.close()


def test_on_loop_runs_callbacks_on_the_loop_under_the_guard(app_factory) -> None:
    """``SessionLoop.on_loop``: an ``async`` callback (viser awaits it on its loop) that holds the
    session lock, ignores a closed session and turns an error into a notification."""
    app = app_factory()
    b, s = _browser_session(app)
    try:
        seen: list[tuple[bool, bool]] = []

        def fn(_event: Any) -> None:
            seen.append((asyncio.get_running_loop() is app.server.get_event_loop(), s.lock._is_owned()))
            raise ValueError("no such slot")

        notes: list[tuple[str, str]] = []
        s.notify = lambda title, body, **kw: notes.append((title, body))
        cb = s.loop.on_loop(fn)
        assert asyncio.iscoroutinefunction(cb)
        asyncio.run_coroutine_threadsafe(cb(None), app.server.get_event_loop()).result(10)
        assert seen == [(True, True)] and notes == [("Not done", "no such slot")]
        s.close()
        asyncio.run_coroutine_threadsafe(cb(None), app.server.get_event_loop()).result(10)
        assert len(seen) == 1                             # closed: ignored
    finally:
        b.close()


def test_sessions_are_built_and_closed_on_the_event_loop_while_others_jog(app_factory) -> None:
    """Browsers that connect and leave while another one jogs: every message of the new
    sessions' builds (scene, panels, first state) and of the closes is pushed from viser's
    event loop thread (before: ``on_client_connect`` built the session in viser's thread pool),
    the build is spread over several loop turns, and a browser that leaves mid-build leaves no
    session behind."""
    app = app_factory()
    jogger, session = _browser_session(app)
    _joint_mode(jogger, session)
    loop = app.server.get_event_loop()
    loop_thread: list[int] = []
    loop.call_soon_threadsafe(lambda: loop_thread.append(threading.get_ident()))
    wait_until(lambda: bool(loop_thread), what="loop thread")

    pushes: list[int] = []
    real_push = AsyncMessageBuffer.push

    def recording_push(self: Any, message: Any) -> None:
        pushes.append(threading.get_ident())
        real_push(self, message)

    turns = 0
    stop_ticks = threading.Event()

    def tick() -> None:                                   # counts loop turns during the builds
        nonlocal turns
        turns += 1
        if not stop_ticks.is_set():
            loop.call_soon(tick)

    builds: list[Any] = []                                # the session builds under way
    real_steps = app.session_steps

    def counted_steps(*args: Any, **kwargs: Any) -> Any:
        steps = real_steps(*args, **kwargs)
        builds.append(steps)
        try:
            yield from steps
        finally:
            builds.remove(steps)

    app.session_steps = counted_steps
    AsyncMessageBuffer.push = recording_push              # type: ignore[method-assign]
    visitors: list[Browser] = []
    try:
        loop.call_soon_threadsafe(tick)
        q0 = float(np.degrees(session.controller.q_rad[1]))
        stop = threading.Event()

        def jog() -> None:
            j = 0
            while not stop.is_set() and j < 400:
                j += 1
                jogger.set(session.views["pendant"].joint_sliders[1], q0 + 0.05 * (j % 40))
                time.sleep(0.01)

        t = threading.Thread(target=jog)
        t.start()
        try:
            for i in range(3):
                visitors.append(Browser(app.port))
                wait_until(lambda i=i: len(app.sessions) == 2 + i, what="visitor session built")
            leaver = Browser(app.port)                    # leaves at once, likely mid-build
            leaver.close()
            for b in visitors:
                b.close()
            wait_until(lambda: len(app.sessions) == 1, what="visitors' sessions closed")
        finally:
            stop.set()
            t.join()
        # barrier: the server is done with every connection but the jogger's and no session build
        # is under way; a round trip on the jogger's socket lets the loop start any task those
        # connections left, and such a build, once started, finishes
        live = app.server._websock_server._live_connections
        wait_until(lambda: list(live) == [session.client.client_id] and not builds,
                   what="the visitors' connections gone and no session build under way")
        jogger.sync(session.client)
        wait_until(lambda: not builds, what="no session build under way")
    finally:
        stop_ticks.set()
        AsyncMessageBuffer.push = real_push               # type: ignore[method-assign]
        for b in visitors:
            b.close()
    assert list(app.sessions.values()) == [session]
    assert len(pushes) > 100
    off = [ident for ident in pushes if ident != loop_thread[0]]
    assert off == [], f"{len(off)} of {len(pushes)} pushes off the event loop"
    assert turns > 10                                      # the loop kept turning meanwhile
