"""No viser: the tip views find the tool tip (``pendant.tip_insets``) from up to 40 mm away.

* in the window (+-3.5 mm across, 3 mm below to 5 mm above the reference tip): zoom 1, no arrow;
* outside it, within the zoomed-out window (5x): both views zoom out, framed in orange, and the
  tool tip is drawn where the zoomed geometry puts it;
* outside that too: in each view that cannot show the tip an arrow from the reference tip
  points the way to it, in that view's own screen axes (front: X right, side: Y right, Z up);
  its pixels lie on that side of the reference tip in the image;
* along each WORLD axis, both signs, 5 to 40 mm, a trainee sees the tip or the way to it in
  at least one view.
"""

from __future__ import annotations

import numpy as np
import pytest
from tcp_pendant.pendant.tip_insets import (
    GAP_PX,
    NEAR_MM,
    PX_PER_MM,
    TOOL_COLOR,
    VIEW_W_MM,
    ZOOM_OUT,
    arrow_direction,
    inset_zoom,
    tip_insets_image,
    view_pixel,
)

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

REF_M = np.array([0.5, 0.0, 0.4])
W = int(round(VIEW_W_MM * PX_PER_MM))


def tool_at(offset_mm: tuple[float, float, float]) -> np.ndarray:
    """A pointer pointing down (tool X = WORLD -Z), its tip at the reference tip + offset (mm)."""
    T = np.eye(4)
    T[:3, :3] = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    T[:3, 3] = REF_M + np.asarray(offset_mm, dtype=float) / 1000.0
    return T


def magenta(img: np.ndarray, view: str) -> np.ndarray:
    """(row, col) of the tool colour's pixels in one view, in that view's own columns."""
    part = img[:, :W] if view == "front" else img[:, W + GAP_PX:]
    return np.argwhere(np.all(part == np.array(TOOL_COLOR), axis=2))


@pytest.mark.parametrize("offset", [(0.0, 0.0, 0.5), (1.5, -1.0, 2.0), (-3.0, 3.0, 4.5), (0.0, 0.0, -2.5)])
def test_in_the_window_no_zoom_no_arrow(offset) -> None:
    assert inset_zoom(np.array(offset)) == 1
    assert arrow_direction("front", np.array(offset)) is None and arrow_direction("side", np.array(offset)) is None


@pytest.mark.parametrize("offset", [(8.0, 0.0, 2.0), (-12.0, 0.0, 0.0), (0.0, 15.0, 1.0), (0.0, -9.0, 0.0),
                                    (0.0, 0.0, 20.0), (0.0, 0.0, -8.0)])
def test_outside_the_window_both_views_zoom_out_and_draw_the_tip_there(offset) -> None:
    apex = np.array(offset)
    assert inset_zoom(apex) == ZOOM_OUT
    assert arrow_direction("front", apex) is None and arrow_direction("side", apex) is None
    img = tip_insets_image(REF_M, tool_at(offset))
    assert np.all(img[1, 10] == (240, 140, 0))                         # the orange frame
    for view in ("front", "side"):
        col, row = view_pixel(view, apex, ZOOM_OUT)
        col -= 0 if view == "front" else W + GAP_PX
        px = magenta(img, view)
        assert px.size, f"no tool in the {view} view"
        low = px[px[:, 0] == px[:, 0].max()]          # the apex (a point thinner than a pixel: within 4 rows)
        assert abs(low[:, 0].max() - row) <= 4 and abs(low[:, 1].mean() - col) <= 3, (view, offset)


EXPECTED = {                      # offset axis and sign -> (front arrow, side arrow), (col, row) unit
    (0, +1): ((1.0, 0.0), None), (0, -1): ((-1.0, 0.0), None),
    (1, +1): (None, (1.0, 0.0)), (1, -1): (None, (-1.0, 0.0)),
    (2, +1): ((0.0, -1.0), (0.0, -1.0)),
}


@pytest.mark.parametrize(("axis", "sign"), sorted(EXPECTED))
@pytest.mark.parametrize("mm", [25.0, 39.0])
def test_far_outside_an_arrow_points_the_way_in_each_view(axis: int, sign: int, mm: float) -> None:
    offset = np.zeros(3)
    offset[axis] = sign * mm
    want = EXPECTED[(axis, sign)]
    img = tip_insets_image(REF_M, tool_at(tuple(offset)))
    for view, expected in zip(("front", "side"), want):
        got = arrow_direction(view, offset)
        if expected is None:
            assert got is None, (view, offset, got)      # this view sees the tip along its line of sight
            continue
        assert got is not None and np.allclose(got, expected, atol=1e-9), (view, offset, got)
        c0, r0 = view_pixel(view, np.zeros(3), ZOOM_OUT)
        c0 -= 0 if view == "front" else W + GAP_PX
        px = magenta(img, view)
        assert px.size, f"no arrow in the {view} view"
        centre = np.array([px[:, 1].mean() - c0, px[:, 0].mean() - r0])   # (col, row) from the reference tip
        assert float(centre @ np.array(expected)) > 20.0, (view, offset, centre)   # drawn on that side


def test_a_diagonal_offset_gives_the_diagonal_direction() -> None:
    offset = np.array([24.0, -30.0, 18.0])
    front, side = arrow_direction("front", offset), arrow_direction("side", offset)
    assert np.allclose(front, np.array([24.0, -18.0]) / np.hypot(24.0, 18.0))
    assert np.allclose(side, np.array([-30.0, -18.0]) / np.hypot(30.0, 18.0))


@pytest.mark.parametrize("axis", [0, 1, 2])
@pytest.mark.parametrize("sign", [1, -1])
def test_from_40_mm_in_every_direction_the_tip_or_the_way_to_it_is_in_sight(axis: int, sign: int) -> None:
    for mm in np.arange(5.0, 40.0, 1.0):
        offset = np.zeros(3)
        offset[axis] = sign * mm
        if axis == 2 and sign < 0 and mm > 3.0:
            offset[0] = 10.0                         # below the tip is inside the spike: come from beside it
        if np.linalg.norm(offset) > NEAR_MM:
            continue                                 # the views are hidden there (the 3D view shows it)
        img = tip_insets_image(REF_M, tool_at(tuple(offset)))
        assert any(magenta(img, v).size for v in ("front", "side")), offset
