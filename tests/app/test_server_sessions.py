"""Server and sessions in-process: a real viser server on a free port, headless websocket
clients (tests/support/wsclient.py) standing in for browsers."""

from __future__ import annotations

import gc
import weakref
from pathlib import Path

import numpy as np
import pytest

from tcpcal.formats import export_tool
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

from support.wsclient import wait_until
from support.wsclient import DrainingClient

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _connect(app, n_before: int) -> DrainingClient:
    c = DrainingClient(app.port)
    wait_until(lambda: len(app.sessions) > n_before, what="session built")
    return c


def test_each_browser_gets_its_own_robot(app_factory) -> None:
    app = app_factory()
    c1 = _connect(app, 0)
    c2 = _connect(app, 1)
    try:
        s1, s2 = list(app.sessions.values())
        assert s1.controller is not s2.controller
        assert s1.controller.kinematics.data is not s2.controller.kinematics.data
        q2 = s2.controller.q_rad
        T2 = s2.controller.T_world_flange()
        with s1.lock:
            s1.controller.jog_joint(0, 25.0)
            s1.moved()
        assert np.degrees(s1.controller.q_rad[0]) == pytest.approx(25.0)
        np.testing.assert_array_equal(s2.controller.q_rad, q2)
        np.testing.assert_array_equal(s2.controller.T_world_flange(), T2)
        # the readout of session 1 shows the move, the one of session 2 does not
        assert s1.views["pendant"].tcp_md.content != s2.views["pendant"].tcp_md.content
    finally:
        c1.close()
        c2.close()


@pytest.mark.slow  # 100 connections
def test_no_leak_after_100_connect_disconnect_cycles(app_factory) -> None:
    """100 real websocket connects/disconnects: every session is closed, forgotten and freed."""
    app = app_factory()
    refs: list[weakref.ref] = []
    for _ in range(100):
        c = _connect(app, 0)
        (session,) = app.sessions.values()
        refs.append(weakref.ref(session))
        del session
        c.close()
        wait_until(lambda: not app.sessions, what="session dropped")
    wait_until(lambda: not app.server.get_clients(), what="viser clients dropped")
    gc.collect()
    alive = [r for r in refs if r() is not None]
    assert not alive, f"{len(alive)} of 100 sessions still referenced"


def test_shared_mode_one_robot_for_all(app_factory) -> None:
    app = app_factory(shared=True)
    c1 = DrainingClient(app.port)
    c2 = DrainingClient(app.port)
    try:
        wait_until(lambda: len(app.server.get_clients()) == 2, what="two clients")
        assert app.sessions == {} and app.shared_session is not None
        assert app.all_sessions() == [app.shared_session]
    finally:
        c1.close()
        c2.close()


def test_tools_saved_elsewhere_appear(app_factory, tmp_path: Path) -> None:
    app = app_factory()
    c = _connect(app, 0)
    try:
        (s,) = app.sessions.values()
        other = ToolLibrary(tmp_path / "tools.json")           # another trainee / process
        other.save(3, Tool(name="Torch A", tcp_mm=(1.0, 2.0, 3.0)))
        panel = s.views["tools"]
        wait_until(lambda: "3: Torch A" in panel.slots.options, what="library refresh")
    finally:
        c.close()


def test_slider_sync_does_not_feed_back(app_factory) -> None:
    """Rendering sets the joint sliders (rounded to 0.01 deg); that must not move the robot."""
    app = app_factory()
    c = _connect(app, 0)
    try:
        (s,) = app.sessions.values()
        s.views["pendant"].mode.value = "Joint"          # sliders are synced while shown
        wait_until(lambda: s.views["pendant"].joint_folder.visible, what="joint mode (on viser's loop)")
        q = s.controller.q_rad
        q[1] += 0.123456789e-3
        with s.lock:
            s.controller.set_q(q)
            s.moved()
        np.testing.assert_array_equal(s.controller.q_rad, q)
        slider = s.views["pendant"].joint_sliders[1]
        assert slider.value == pytest.approx(np.degrees(q[1]), abs=0.006)
    finally:
        c.close()


def test_numeric_entry_saves_all_or_nothing_and_exports(app_factory, tmp_path: Path) -> None:
    app = app_factory()
    c = _connect(app, 0)
    try:
        (s,) = app.sessions.values()
        p = s.views["tools"]
        p.entry_name.value = "Gun"
        for f, v in zip("XYZABC", ("12.5", "-3", "abc", "0", "90", "0")):
            p.entry_fields[f].value = v
        s.loop.guard(p._on_entry_save)(None)
        assert s.library.tools() == {}                        # nothing saved half-way
        assert p.entry_errors["Z"].visible and "not a number" in p.entry_errors["Z"].content
        assert not p.entry_errors["X"].visible
        p.entry_fields["Z"].value = "180"
        s.loop.guard(p._on_entry_save)(None)
        tools = s.library.tools()
        assert list(tools) == [1] and tools[1].tcp_mm == (12.5, -3.0, 180.0)
        assert not p.entry_errors["Z"].visible
        # same name again: refused, with the error next to the name
        s.loop.guard(p._on_entry_save)(None)
        assert len(s.library.tools()) == 1 and p.entry_name_err.visible
        p.slots.value = "1: Gun"
        p.export_fmt.value = "KUKA"
        s.loop.guard(p._on_export)(None)
        assert p.export_text.value == export_tool(tools[1], "kuka", slot=1)
        # activate: the controller's TCP becomes the tool's
        s.loop.guard(p._on_activate)(None)
        T = s.controller.T_world_flange()
        expected = T[:3, :3] @ (np.array([12.5, -3.0, 180.0]) / 1000.0) + T[:3, 3]
        np.testing.assert_allclose(s.controller.T_world_tcp()[:3, 3], expected, atol=1e-12)
        assert "TOOL Gun" in s.views["pendant"].tcp_md.content
    finally:
        c.close()


def test_touches_record_delete_and_guard(app_factory) -> None:
    app = app_factory()
    c = _connect(app, 0)
    try:
        (s,) = app.sessions.values()
        t1 = s.record_touch()
        np.testing.assert_array_equal(t1.T_world_flange, s.controller.T_world_flange())
        s.controller.jog_joint(0, 10.0)
        s.record_touch()
        s.record_touch()
        assert [t.label[:2] for t in s.touches] == ["P1", "P2", "P3"]
        T3 = s.touches[2].T_world_flange
        s.delete_touch(1)
        assert len(s.touches) == 2 and s.touches[1].label.startswith("P2")
        np.testing.assert_array_equal(s.touches[1].T_world_flange, T3)
        rows = s.views["touches"]._rows
        assert len(rows) == 4                                   # label + delete button per touch
        # a bad event is reported, not raised
        assert s.loop.guard(lambda: s.delete_touch(7))() is None
        assert len(s.touches) == 2
    finally:
        c.close()
    wait_until(lambda: not app.sessions, what="session closed")
    assert s.closed and s.loop.guard(lambda: 1 / 0)() is None         # after close: ignored
