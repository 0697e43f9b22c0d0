"""The jog keys over a real websocket (their callbacks run on viser's event loop), the readout
texts and the joint sliders on the hot path."""

from __future__ import annotations

import re
import time

import numpy as np
import pytest

from support.wsclient import wait_until
from support.wsclient import ButtonClient, click_until_carried_out

PLUS_X, MINUS_Z = "X +", "Z −"


def _session(app, labels=(PLUS_X, MINUS_Z)):
    client = ButtonClient(app.port, labels)
    assert client.found.wait(30), "the client never saw the jog keys"
    wait_until(lambda: len(app.sessions) == 1, what="session built")
    (s,) = app.sessions.values()
    return client, s


def test_clicking_a_key_over_the_websocket_jogs_one_increment(app_factory) -> None:
    app = app_factory()
    client, s = _session(app)
    try:
        with s.lock:
            s.jogger.settings = s.jogger.settings.with_(increment="10", frame="WORLD")
            T0 = s.controller.T_world_tcp()
            text0 = s.views["pendant"].tcp_md.content
        gate = s.jogger.gate
        click_until_carried_out(client, PLUS_X, gate, what="X + 10 mm",
                                done=lambda: abs(s.controller.T_world_tcp()[0, 3] - T0[0, 3] - 0.010) < 1e-8)
        click_until_carried_out(client, MINUS_Z, gate, what="Z - 10 mm",
                                done=lambda: abs(s.controller.T_world_tcp()[2, 3] - T0[2, 3] + 0.010) < 1e-8)
        T1 = s.controller.T_world_tcp()
        np.testing.assert_allclose(T1[:3, 3] - T0[:3, 3], [0.010, 0.0, -0.010], atol=1e-8)
        # the readout followed: X and Z 10 mm off, Y unchanged, as text
        text1 = s.views["pendant"].tcp_md.content
        assert text1 != text0
        x0, x1 = (float(re.search(r"\bX\s+(-?\d+\.\d\d) mm", t).group(1)) for t in (text0, text1))
        assert x1 - x0 == pytest.approx(10.0, abs=0.011)
    finally:
        client.close()


def test_holding_a_key_jogs_continuously_and_the_click_that_ends_it_does_not(app_factory) -> None:
    from tcp_pendant.views.pendant_panel import HOLD_HZ

    app = app_factory()
    client, s = _session(app)
    try:
        with s.lock:
            s.jogger.settings = s.jogger.settings.with_(increment="Cont.", override_pct=10, frame="WORLD")
            x0 = s.controller.T_world_tcp()[0, 3]
        moves: list[int] = []
        s.add_motion_listener(lambda: moves.append(1))
        for _ in range(3):                                 # a browser's hold messages
            client.hold_tick(PLUS_X, HOLD_HZ)
            time.sleep(1.0 / HOLD_HZ)
        wait_until(lambda: len(moves) >= 3, what="three jog ticks")
        z0 = s.controller.T_world_tcp()[2, 3]
        client.click(PLUS_X)                               # the release click: no extra move
        client.hold_tick(MINUS_Z, HOLD_HZ)                 # a marker behind it on the same socket
        # only Z - moves Z (1.25 mm a tick at 10 %): the release before it has been handled
        wait_until(lambda: s.controller.T_world_tcp()[2, 3] < z0 - 5e-4, what="the marker's first Z - tick")
        x3 = s.controller.T_world_tcp()[0, 3]
        assert x3 > x0                                     # moved along +X while held
        n = len(moves)                                     # Z - still held: the server's clock
        wait_until(lambda: len(moves) >= n + 3, what="three more ticks of the held Z -")
        assert s.controller.T_world_tcp()[0, 3] == pytest.approx(x3, abs=2e-5)   # and X stays
        client.click(MINUS_Z)
    finally:
        client.close()


def test_readout_markdown_fast_path_and_image_fallback() -> None:
    import viser

    from tcp_pendant.views.pendant_panel import set_markdown

    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        md = server.gui.add_markdown("start")
        set_markdown(md, "**TCP** `X 1.00 mm`")
        assert md.content == "**TCP** `X 1.00 mm`"
        assert md._impl.props._markdown == "**TCP** `X 1.00 mm`"      # what the browser receives
        # an image needs viser's own parsing (inlined as a data URL): public setter
        set_markdown(md, "![x](http://example.invalid/x.png)")
        assert md.content == "![x](http://example.invalid/x.png)"
        md.remove()
        with pytest.raises(RuntimeError):
            set_markdown(md, "after removal")                            # as viser's setter
    finally:
        server.stop()


def test_joint_mode_syncs_only_the_slider_that_moved(app_factory) -> None:
    app = app_factory()
    client, s = _session(app)
    try:
        p = s.views["pendant"]
        p.mode.value = "Joint"
        wait_until(lambda: p.joint_folder.visible, what="joint mode (on viser's loop)")
        updates: list[int] = []
        for i, slider in enumerate(p.joint_sliders):
            slider.on_update(lambda _e, i=i: updates.append(i))
        with s.lock:
            s.controller.jog_joint(2, 4.0)
            s.moved()
        assert updates == [2]
        angles = s.controller.joint_angles_deg()
        for slider, v in zip(p.joint_sliders, angles.values()):
            assert slider.value == pytest.approx(round(v, 2), abs=1e-9)
    finally:
        client.close()


def test_shared_mode_one_browser_jogs_every_browser_sees_it(app_factory) -> None:
    """--shared: one robot; a click in one browser moves it and the readout every browser
    receives is the new one."""
    app = app_factory(shared=True)
    c1 = ButtonClient(app.port, (PLUS_X,), record_updates=True)
    c2 = ButtonClient(app.port, (PLUS_X,), record_updates=True)
    try:
        assert c1.found.wait(30) and c2.found.wait(30)
        s = app.shared_session
        assert s is not None and app.sessions == {}
        with s.lock:
            s.jogger.settings = s.jogger.settings.with_(increment="10", frame="WORLD")
            x0 = s.controller.T_world_tcp()[0, 3]
        c1.click(PLUS_X)
        wait_until(lambda: abs(s.controller.T_world_tcp()[0, 3] - x0 - 0.010) < 1e-8, what="X + 10 mm")
        md = s.views["pendant"].tcp_md
        uuid = md._impl.uuid
        for c in (c1, c2):
            wait_until(lambda c=c: c.gui_props.get(uuid, {}).get("_markdown") == md.content,
                       what="the new readout in both browsers")
    finally:
        c1.close()
        c2.close()
