"""views.viser_adapter: each fast path into viser's private API is taken on this viser (a test
per path that fails when it falls back), and a fallback warns once (raises under the tests'
strict flag) instead of passing silently."""

from __future__ import annotations

import logging

import numpy as np
import pytest
import viser
from tcp_pendant.views import viser_adapter
from tcp_pendant.views.pendant_panel import set_markdown
from tcp_pendant.views.upload_guard import limit_upload_size
from tcp_pendant.views.viser_adapter import ViserInternalsChanged, path_counts, reset_path_counts

from support.wsclient import wait_until
from support.wsclient import ButtonClient, click_until_carried_out


@pytest.fixture
def server():
    s = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    reset_path_counts()
    yield s
    s.stop()


def test_the_tests_run_with_the_strict_flag() -> None:
    """A fallback anywhere in tests/app or tests/security raises (conftest sets the flag)."""
    import os

    assert os.environ.get(viser_adapter.STRICT_ENV) == "1"


def test_markdown_fast_path_is_taken(server) -> None:
    md = server.gui.add_markdown("start")
    set_markdown(md, "**TCP** `X 1.00 mm`")
    set_markdown(md, "**TCP** `X 2.00 mm`")
    assert path_counts() == {("markdown", "fast"): 2}
    assert md.content == "**TCP** `X 2.00 mm`" and md._impl.props._markdown == "**TCP** `X 2.00 mm`"


def test_pose_fast_path_is_taken(server) -> None:
    from tcp_pendant.views.scene import _set_pose

    frame = server.scene.add_frame("/f", show_axes=False)
    assert _set_pose(frame, [0.0, 1.0, 0.0, 0.0], [0.1, 0.2, 0.3]) == 2
    assert _set_pose(frame, None, [0.4, 0.5, 0.6]) == 1
    assert path_counts() == {("pose", "fast"): 2}
    np.testing.assert_allclose(frame.wxyz, [0.0, 1.0, 0.0, 0.0])
    np.testing.assert_allclose(frame.position, [0.4, 0.5, 0.6])


def test_the_pose_fast_path_queues_what_the_public_setters_queue(server, monkeypatch) -> None:
    """Message class, node, values, owner, wire form and redundancy key (cached by a node's
    PoseQueue from its first message on) are the public setters' own, for two nodes interleaved."""
    from tcp_pendant.views.viser_adapter import pose_queue

    frames = [server.scene.add_frame(name, show_axes=False) for name in ("/g", "/g/h")]
    queues = [pose_queue(f) for f in frames]
    ws = frames[0]._impl.api._websock_interface
    queued: list[object] = []
    real = ws.queue_message
    monkeypatch.setattr(ws, "queue_message", lambda m: (queued.append(m), real(m))[1])
    rng = np.random.default_rng(3)
    for _ in range(3):
        for f, q in zip(frames, queues):
            for fast in (False, True):
                wxyz = rng.normal(size=4)
                wxyz = (wxyz / np.linalg.norm(wxyz)).tolist()
                xyz = rng.normal(size=3).tolist()
                if fast:
                    assert q is not None and q(wxyz, xyz)
                else:
                    f.wxyz, f.position = wxyz, xyz
                np.testing.assert_array_equal(f.wxyz, wxyz)
                np.testing.assert_array_equal(f.position, xyz)
                *_, orientation, position = queued
                assert (orientation.wxyz, position.position) == (tuple(wxyz), tuple(xyz))
    assert len(queued) == 3 * 2 * 2 * 2
    for public, fast in zip(queued[0::4] + queued[1::4], queued[2::4] + queued[3::4]):
        assert type(fast) is type(public) and fast.name == public.name and fast.owner == public.owner
        assert fast.redundancy_key() == public.redundancy_key()
        assert set(fast.as_serializable_dict()) == set(public.as_serializable_dict())


def test_upload_hook_is_taken(server) -> None:
    button = server.gui.add_upload_button("Load")
    assert limit_upload_size(button, 1000, lambda name, size: None) is True
    assert path_counts() == {("upload", "fast"): 1}


def test_a_jog_over_the_websocket_takes_the_fast_paths_only(app_factory) -> None:
    app = app_factory()
    client = ButtonClient(app.port, ("X +",))
    try:
        assert client.found.wait(30)
        wait_until(lambda: len(app.sessions) == 1, what="session built")
        (s,) = app.sessions.values()
        reset_path_counts()
        # a press the deadman dropped (the loop reached it more than 250 ms late, e.g. while it
        # still sent the new client's scene) is pressed again, as a trainee would
        click_until_carried_out(client, "X +", s.jogger.gate, what="the jog's pose messages",
                                done=lambda: path_counts().get(("pose", "fast"), 0) > 0)
        wait_until(lambda: path_counts().get(("markdown", "fast"), 0) > 0, what="the jog's readout")
        assert not [k for k in path_counts() if k[1] == "fallback"]
        assert path_counts().get(("unread", "fast"), 0) > 0          # each press stamped from its backlog
        assert s.controller.T_world_tcp()[0, 3] != 0.0
    finally:
        client.close()


class _Other:
    """A handle of a viser whose internals differ (no ``_impl``)."""

    content = ""
    wxyz = (1.0, 0.0, 0.0, 0.0)
    position = (0.0, 0.0, 0.0)


def test_a_fallback_warns_once_and_uses_the_public_setters(monkeypatch, caplog) -> None:
    from tcp_pendant.views.scene import _set_pose

    monkeypatch.delenv(viser_adapter.STRICT_ENV)
    monkeypatch.setattr(viser_adapter, "_warned", set())
    reset_path_counts()
    h = _Other()
    with caplog.at_level(logging.WARNING, logger=viser_adapter.__name__):
        set_markdown(h, "a")
        set_markdown(h, "b")
        assert _set_pose(h, [0.0, 0.0, 1.0, 0.0], None) == 1
    assert h.content == "b" and h.wxyz == [0.0, 0.0, 1.0, 0.0]
    assert path_counts() == {("markdown", "fallback"): 2, ("pose", "fallback"): 1}
    warnings = [r.getMessage() for r in caplog.records]
    assert len(warnings) == 2 and "markdown takes its fallback" in warnings[0]


def test_the_scene_pose_sender_falls_back_to_the_public_setters(monkeypatch) -> None:
    """A node whose handle has no viser internals gets no PoseQueue (one fallback counted at
    build) and is posed through ``handle.wxyz`` / ``handle.position``, with the same values."""
    from tcp_pendant.views.scene import PoseSender

    monkeypatch.delenv(viser_adapter.STRICT_ENV)
    monkeypatch.setattr(viser_adapter, "_warned", set())
    reset_path_counts()
    h = _Other()
    sender = PoseSender([h], np.eye(4)[None])
    assert path_counts() == {("pose", "fallback"): 1}
    T = np.eye(4)
    T[:3, :3] = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]     # 90 deg about Z
    T[:3, 3] = [0.1, 0.2, 0.3]
    assert sender.send(T[None]) == 2
    np.testing.assert_allclose(h.wxyz, [np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5)], atol=1e-15)
    assert h.position == [0.1, 0.2, 0.3]
    assert sender.send(T[None]) == 0                                     # unchanged: nothing


def test_a_fallback_raises_under_the_strict_flag() -> None:
    with pytest.raises(ViserInternalsChanged, match="viser fast path 'markdown' fell back"):
        set_markdown(_Other(), "a")
    with pytest.raises(ViserInternalsChanged, match="viser fast path 'upload' fell back"):
        viser_adapter.upload_hook(_Other())


def test_the_value_check_of_each_kind_of_input(server) -> None:
    """What each GUI input accepts from a browser (what viser's own widgets send) and refuses."""
    from tcp_pendant.views.viser_adapter import MAX_TEXT_CHARS, gui_value_refusal

    gui = server.gui
    cases = [
        (gui.add_button("B"), [True], [False, 1, "x"]),
        (gui.add_button_group("G", ("a", "b")), ["a", "b"], ["c", True, 1]),
        # the selected option marked in its label: a click sent before the mark moved still counts
        (gui.add_button_group("M", ("✓ 10", "1", "0.1")), ["✓ 10", "10", "1", "✓ 1"], ["100", "0", "✓ 5", ""]),
        (gui.add_dropdown("D", ("a", "b")), ["b"], ["c", None]),
        (gui.add_checkbox("C", False), [True, False], [1, "true", None]),
        (gui.add_slider("S", min=0.0, max=10.0, step=0.1, initial_value=1.0), [0, 10.0, 5.55],
         [-0.1, 10.1, float("nan"), "5", True]),
        (gui.add_number("N", 3, min=0, step=1), [0, 7, 8.0, 10**9], [-1, 2.5, -1e308, 1e308, float("inf")]),
        (gui.add_number("F", 1.0, step=0.1), [-1e6, 1e6], [1e13, -1e308]),
        (gui.add_text("T", ""), ["", "a" * MAX_TEXT_CHARS], ["a" * (MAX_TEXT_CHARS + 1), 12, None]),
        (gui.add_vector3("V", (0.0, 0.0, 0.0), min=(-1.0, -1.0, -1.0), max=(1.0, 1.0, 1.0)),
         [[0.5, -0.5, 1.0], (0, 0, 0)], [[0.0, 0.0], [2.0, 0.0, 0.0], [0.0, "0", 0.0]]),
        (gui.add_rgb("R", (1, 2, 3)), [[0, 128, 255]], [[0, 0], [0.5, 0, 0], [256, 0, 0], [-1, 0, 0]]),
        (gui.add_upload_button("U"), [], [{"name": "x"}, "x", b"x"]),
    ]
    for handle, good, bad in cases:
        for v in good:
            assert gui_value_refusal(handle, {"value": v}) is None, (handle.label, v)
        for v in bad:
            assert gui_value_refusal(handle, {"value": v}) is not None, (handle.label, v)
        assert gui_value_refusal(handle, {"value": None, "disabled": False}) is not None
        assert gui_value_refusal(handle, {"removed": True}) is not None
    off = gui.add_button("Off", disabled=True)
    assert gui_value_refusal(off, {"value": True}) == "'Off' is disabled"
