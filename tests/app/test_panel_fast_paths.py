"""The jog panel's readouts on their fast paths are the texts of the code before them
(``tests/bench/panel_yardstick.py``) to the last character: the TCP and joint readouts, the
touch indicator, the Δ line and the tip offset, for ordinary, rounding-edge, negative-zero,
large and non-finite numbers and odd joint names; and what the panel no longer re-reads or
re-sends (the close-up, the status line) still follows every change."""

from __future__ import annotations

import math

import numpy as np
import pytest

from support.app_page import AppPage, true_tip_at
from bench.panel_yardstick import (
    legacy_fmt_num,
    legacy_joint_readout_markdown,
    legacy_offset_markdown,
    legacy_tcp_readout_markdown,
    legacy_tip_offset_mm,
    legacy_touch_indicator_markdown,
)

from tcp_pendant.controller import PoseReadout, TouchGeometry, VirtualController, builtin_robots, builtin_tools
from tcp_pendant.controller.kinematics import RobotKinematics
from tcp_pendant.controller.pose_state import pose_state
from tcp_pendant.pendant.formatting import (
    fmt_num,
    joint_readout_markdown,
    tcp_readout_markdown,
    touch_indicator_markdown,
)
from tcp_pendant.pendant.guidance import offset_markdown, tip_offset_mm, tip_offset_xyz_mm

EDGES = [0.0, -0.0, -0.004, 0.004, -0.005, 0.005, -0.0049999, 0.0050001, 99.995, -99.995, 99.994999,
         99.9999, 100.0, -100.0, -100.04, 1e6, -1e6, 1e20, math.nan, math.inf, -math.inf, 12.345,
         -12.345, 0.015, -0.015, 179.999, -180.0, -1000.0, -0.01, 1e-300, -1e-300]


def _numbers(n: int, seed: int) -> list[float]:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        k = rng.integers(0, 4)
        out.append(float(rng.choice(EDGES)) if k == 0 else float(rng.normal(0, 0.01)) if k == 1
                   else float(rng.normal(0, 300)) if k == 2 else float(np.round(rng.normal(0, 100), 3)))
    return out


def test_readout_texts_are_the_previous_ones_to_the_last_character() -> None:
    v = _numbers(6000, 1)
    names_of = [("A1", "A2", "A3", "A4", "A5", "A6"), ("j%1", "j 2", "%s", "y", "z", "q", "r7"),
                ("a -0.00", "b", "c"), ("x",)]
    for i in range(0, len(v) - 7, 3):
        r = PoseReadout("WORLD" if i % 2 else "BASE", *v[i:i + 6])
        for tool in (None, "pointer", "a *b* <x> %s 100%"):
            assert tcp_readout_markdown(r, tool) == legacy_tcp_readout_markdown(r, tool), (r, tool)
        names = names_of[i % len(names_of)]
        angles = dict(zip(names, v[i:i + len(names)]))
        assert joint_readout_markdown(angles) == legacy_joint_readout_markdown(angles), angles
        d = v[i:i + 3]
        for frame in ("WORLD", "TOOL"):
            want = legacy_offset_markdown(np.array(d), frame)
            assert offset_markdown(tuple(d), frame) == want and offset_markdown(np.array(d), frame) == want, d
        for x in d:
            for decimals in (0, 1, 2, 3):
                assert fmt_num(x, decimals) == legacy_fmt_num(x, decimals)
            a = abs(x)
            for crashed, touching in ((True, False), (False, True), (False, False)):
                t = TouchGeometry(a, touching, crashed, a)
                for hide in (True, False):
                    assert (touch_indicator_markdown(t, hide_distance=hide)
                            == legacy_touch_indicator_markdown(t, hide_distance=hide))


def test_the_tip_offset_is_the_previous_one_in_every_frame() -> None:
    c = VirtualController(RobotKinematics.from_urdf(builtin_robots()["kr6"]), tool=builtin_tools()["torch"])
    c.set_T_world_base(np.array([[0.0, -1.0, 0.0, 0.3], [1.0, 0.0, 0.0, -0.1], [0.0, 0.0, 1.0, 0.05],
                                 [0.0, 0.0, 0.0, 1.0]]))
    rng = np.random.default_rng(5)
    for _ in range(20):
        c.set_q(c.q_rad + np.radians(rng.normal(0.0, 3.0, 6)))
        st = pose_state(c)
        for ref in (c.reference_tip_world_m, st.T_world_tool_true[:3, 3].copy(),
                    st.T_world_tool_true[:3, 3] + rng.normal(0.0, 1e-4, 3)):
            for frame in ("WORLD", "BASE", "FLANGE", "TOOL", "world"):
                want = legacy_tip_offset_mm(st, ref, frame)
                got = tip_offset_xyz_mm(st, ref, frame)
                assert all(type(x) is float for x in got)
                assert np.array_equal(np.array(got), want) and np.array_equal(tip_offset_mm(st, ref, frame), want)
                assert offset_markdown(got, frame) == legacy_offset_markdown(want, frame)
    with pytest.raises(ValueError, match="Unknown jog frame"):
        tip_offset_xyz_mm(st, c.reference_tip_world_m, "CAMERA")


class Page(AppPage):
    def __init__(self, app) -> None:
        super().__init__(app)
        self.pendant = self.session.views["pendant"]


pytestmark = [pytest.mark.app_page(cls=Page, seed=3), pytest.mark.shares_cpu]  # asserts no time, latency or load (tests/conftest.py)


def test_the_close_up_and_the_status_line_follow_every_change(page) -> None:
    p = page()
    s, panel = p.session, p.pendant
    assert not panel.closeup_md.visible and panel.closeup_md.content == ""
    for offset, near in (((0.0, 0.0, 5.0), True), ((0.0, 0.0, 30.0), False), ((3.0, 0.0, 0.0), True),
                         ((0.0, 0.0, 3.0), True), ((50.0, 0.0, 0.0), False)):
        true_tip_at(s, offset)
        assert panel.closeup_md.visible is near
        assert ("```" in panel.closeup_md.content) is near             # shown with its drawing, or empty
    with s.lock:
        s.jogger.settings = s.jogger.settings.with_(increment="1", frame="WORLD")
    true_tip_at(s, (-0.6, 0.0, 0.0))                                 # 0.6 mm -X of the tip: +X 1 mm meets it
    res = s.motion.jog("X", 1)
    assert res is not None and res.stopped_by == "contact"
    assert panel.status_md.content.startswith("⚠ Stopped at the reference tip")
    assert any(title == "Jog stopped" for title, _ in p.notes)
    s.motion.jog("X", -1)                                                   # a press that goes through
    assert panel.status_md.content == ""
    s.motion.jog("X", -1)
    assert panel.status_md.content == ""                             # and stays clear
    with s.lock:                                                     # a dropped press's report ...
        s.jogger.gate.dropped = 2
        panel._report_drops()
    assert panel.status_md.content == "⚠ 2 jog presses dropped: the server was busy."
    s.motion.jog("X", -1)                                                   # ... is cleared by the next press
    assert panel.status_md.content == ""
