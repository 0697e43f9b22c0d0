"""The change signal's fan-out skips no change kind: every flag, jog outcome and event a
command signals reaches the subscribers, with the pose state whenever the pose or the tool
changed; and the tip close-up, which skips its work while the tool tip is far, still shows
and redraws as soon as the tip comes near and hides again when it leaves."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tcp_pendant.calibrate import CalibrationWorkflow
from tcp_pendant.controller import JogResult, VirtualController
from tcp_pendant.events import Crash
from tcp_pendant.pendant.tip_insets import FAR, NEAR_MM
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.views.tip_insets import CAPTION, CAPTION_ZOOMED
from tcpcal.library import ToolLibrary

from support.app_page import true_tip_at
from support.wsclient import DrainingClient, wait_until

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

FLAGS = ("pose", "tool", "touches", "wizard", "library", "notice")


@pytest.fixture
def session(controller: VirtualController, tmp_path) -> Session:
    library = ToolLibrary(tmp_path / "tools.json")
    rng = np.random.default_rng(0)
    return Session(controller, library, CalibrationWorkflow(controller, library, robot="kr6", rng=rng), rng=rng)


@pytest.mark.parametrize("with_motion", [False, True], ids=["alone", "with a move"])
@pytest.mark.parametrize("flag", FLAGS)
def test_each_change_kind_reaches_the_subscribers_with_what_it_carries(session: Session, flag: str,
                                                                       with_motion: bool) -> None:
    s = session
    seen: list[SessionChange] = []
    s.subscribe(seen.append)
    jog = JogResult(False, 0.5, "limit", "A5 at its limit")
    event = Crash(1.5, None)
    given = {flag: True, **({"pose": True} if with_motion else {})}
    s.changed(SessionChange(**given, jog=jog, events=(event,)))
    (got,) = seen
    moved = "pose" in given or flag == "tool"                # a tool change re-renders the pose too
    for f in FLAGS:
        assert getattr(got, f) is (f in given or (f == "pose" and moved)), f
    assert got.jog is jog
    assert got.events == (event,)
    if moved:
        assert got.state is s.pose_state()   # the one pose state, computed for all subscribers
    else:
        assert got.state is None


def test_a_batch_merges_every_kind_into_one_signal(session: Session) -> None:
    s = session
    seen: list[SessionChange] = []
    s.subscribe(seen.append)
    jog = JogResult(True, 1.0, None, "")
    with s.batch():
        s.changed(touches=True)
        s.changed(library=True, notice=True)
        s.moved(jog)
    (got,) = seen
    assert (got.pose, got.tool, got.touches, got.wizard, got.library, got.notice) == \
        (True, False, True, False, True, True)
    assert got.jog is jog and got.state is s.pose_state()


def test_tip_close_up_shows_near_redraws_and_hides_far(app_factory) -> None:
    """Far (ready pose, then 60 mm and just beyond NEAR_MM): hidden, no image sent; near:
    shown with the image of the geometry; moved while near: a new image; far again: hidden."""
    app = app_factory()
    client = DrainingClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 1, what="session built")
        (s,) = app.sessions.values()
        insets = s.views["pendant"].insets
        assert insets._key == FAR and not insets.image.visible
        for offset in ((0.0, 0.0, 60.0), (0.0, 0.0, NEAR_MM + 0.05)):
            true_tip_at(s, offset)
            assert s.pose_state().touch.distance_mm == pytest.approx(math.hypot(*offset), abs=1e-6)
            assert insets._key == FAR and not insets.image.visible
        true_tip_at(s, (0.0, 0.0, NEAR_MM - 0.05))       # just inside: shown at once
        assert insets._key != FAR and insets.image.visible and insets.image.label == CAPTION_ZOOMED
        true_tip_at(s, (0.4, -0.3, 1.6))
        assert insets.image.label == CAPTION                 # in the window: not zoomed
        key, image = insets._key, insets.image.image
        true_tip_at(s, (0.4, -0.3, 1.1))                 # 0.5 mm lower: another picture
        assert insets._key != key and not np.array_equal(insets.image.image, image)
        true_tip_at(s, (0.0, 0.0, 60.0))
        assert insets._key == FAR and not insets.image.visible
    finally:
        client.close()
