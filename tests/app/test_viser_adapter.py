"""views.viser_adapter: each fast path into viser's private API is taken on this viser (a test
per path that fails when it falls back), and a fallback warns once (raises under the tests'
strict flag) instead of passing silently."""

from __future__ import annotations

import logging
import sys
from pathlib import Path

import numpy as np
import pytest
import viser
from tcp_pendant.views import viser_adapter
from tcp_pendant.views.pendant_panel import set_markdown
from tcp_pendant.views.upload_guard import limit_upload_size
from tcp_pendant.views.viser_adapter import ViserInternalsChanged, path_counts, reset_path_counts

sys.path.insert(0, str(Path(__file__).parent))
from conftest import wait_until  # noqa: E402
from wsclient import ButtonClient  # noqa: E402


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
        client.click("X +")
        wait_until(lambda: path_counts().get(("pose", "fast"), 0) > 0, what="the jog's pose messages")
        wait_until(lambda: path_counts().get(("markdown", "fast"), 0) > 0, what="the jog's readout")
        assert not [k for k in path_counts() if k[1] == "fallback"]
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
    assert len(warnings) == 2 and "markdown uses viser's public setters" in warnings[0]


def test_a_fallback_raises_under_the_strict_flag() -> None:
    with pytest.raises(ViserInternalsChanged, match="viser fast path 'markdown' fell back"):
        set_markdown(_Other(), "a")
    with pytest.raises(ViserInternalsChanged, match="viser fast path 'upload' fell back"):
        viser_adapter.upload_hook(_Other())
