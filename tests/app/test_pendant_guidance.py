"""No viser: the Δ offset, its words and the magnified close-up of the tips,
and Record's check of the touch on a fake clock."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from tcp_pendant.controller import VirtualController
from tcp_pendant.pendant.guidance import (
    direction_words,
    jog_frame_rotation,
    offset_markdown,
    side_view_markdown,
    tip_offset_mm,
)
from tcp_pendant.pendant.record_check import CONFIRM_WINDOW_S, RecordCheck
from tcp_pendant.controller.pose_state import pose_state

from support.jogging import FakeClock

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _grid(md: str) -> list[str]:
    body = md.split("```")[1].strip("\n").splitlines()
    return body[:-1]                                   # the last line is the axes and the scale


def _where(md: str, ch: str) -> tuple[int, int]:
    """(row, column) of ``ch`` in the left panel."""
    for r, line in enumerate(_grid(md)):
        left = line[:15]
        if ch in left:
            return r, left.index(ch)
    raise AssertionError(f"{ch!r} not drawn:\n{md}")


def test_close_up_magnifies_half_a_millimetre_to_several_characters() -> None:
    md = side_view_markdown(np.array([0.5, 0.0, 0.0]), "WORLD")
    assert "0.1 mm/char" in md
    (r_tool, c_tool), (r_ref, c_ref) = _where(md, "+"), _where(md, "o")
    assert r_ref == r_tool and c_ref - c_tool == 5        # 0.5 mm = 5 characters to the right
    md = side_view_markdown(np.array([0.0, 0.0, -0.2]), "WORLD")
    (r_tool, c_tool), (r_ref, c_ref) = _where(md, "+"), _where(md, "o")
    assert c_ref == c_tool and r_ref - r_tool == 2        # below the tool tip: 2 rows down
    far = side_view_markdown(np.array([60.0, 0.0, 0.0]), "WORLD")
    assert "10 mm/char" in far                           # coarser when far
    assert "@" in side_view_markdown(np.array([0.01, 0.0, 0.02]), "WORLD")


def test_offset_text_and_words() -> None:
    d = np.array([2.104, 0.0, -0.6])
    assert offset_markdown(d, "TOOL") == "`ΔX +2.10  ΔY 0.00  ΔZ -0.60 mm` to the tip (TOOL)"
    assert direction_words(d, "TOOL") == "2.10 mm +X, 0.60 mm −Z (TOOL)"
    assert direction_words(np.zeros(3), "WORLD") == "0.00 mm (WORLD)"


def test_tip_offset_is_the_reference_tip_in_the_jog_frame(controller: VirtualController) -> None:
    c = controller
    c.jog_joint(4, 30.0)
    st = pose_state(c)
    d_world_mm = (c.reference_tip_world_m - c.T_world_tool_true()[:3, 3]) * 1000.0
    np.testing.assert_allclose(tip_offset_mm(st, c.reference_tip_world_m, "WORLD"), d_world_mm, atol=1e-9)
    R = c.T_world_tcp()[:3, :3]
    np.testing.assert_allclose(tip_offset_mm(st, c.reference_tip_world_m, "TOOL"), R.T @ d_world_mm, atol=1e-9)
    np.testing.assert_allclose(jog_frame_rotation(st, "FLANGE"), c.T_world_flange()[:3, :3], atol=1e-12)
    assert Rotation.from_matrix(jog_frame_rotation(st, "BASE")).magnitude() == pytest.approx(
        Rotation.from_matrix(c.T_world_base[:3, :3]).magnitude())
    with pytest.raises(ValueError, match="Unknown jog frame"):
        jog_frame_rotation(st, "CAMERA")


def test_record_check_asks_once_then_records_and_hidden_records_at_once() -> None:
    clock = FakeClock()
    check = RecordCheck(clock)
    q = np.zeros(6)
    first = check.decide(2.0, hidden=False, q_rad=q, where="2.00 mm +X (WORLD)")
    assert not first.record and "2.00 mm" in first.message and "+X (WORLD)" in first.message
    clock.t += 1.0
    assert check.decide(2.0, hidden=False, q_rad=q, where="").record          # confirmed
    assert not check.decide(2.0, hidden=False, q_rad=q, where="").record      # a new touch asks again
    clock.t += CONFIRM_WINDOW_S + 0.1
    assert not check.decide(2.0, hidden=False, q_rad=q, where="").record      # too late: asks again
    assert not check.decide(2.0, hidden=False, q_rad=q + 0.01, where="").record   # moved: asks again
    assert check.decide(0.4, hidden=False, q_rad=q, where="").record          # within 0.5 mm
    assert check.decide(9.0, hidden=True, q_rad=q, where="").record           # the exercise: by eye
