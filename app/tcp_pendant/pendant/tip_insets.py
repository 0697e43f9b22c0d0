"""Two fixed, orthogonal, magnified views of the tip region, drawn as one image (no viser).

Judging a touch by eye needs to see a fraction of a millimetre in every direction, and one
perspective view cannot show depth along its own line of sight. So the pendant shows the two
tips as a technician would look at them from the front and from the side, magnified:

* left, **front**: looking along WORLD +Y (screen right = +X, up = +Z);
* right, **side**: looking along WORLD -X (screen right = +Y, up = +Z).

Each view is a fixed window centred on the reference tip (:data:`VIEW_W_MM` wide,
:data:`VIEW_H_MM` high, the spike's point :data:`BELOW_MM` above its bottom edge) at a fixed
:data:`PX_PER_MM`, with a 1 mm grid (every 5th line darker) and a 1 mm scale bar in its lower
left corner: the scale. A 0.5 mm move is 12 image pixels in at least one view for any
direction (X: front; Y: side; Z: both), about 10 screen pixels at 1400x900 where the panel
shows the image ~300 px wide (tests/browser/test_tip_insets_browser.py measures it).

Finding the tool tip from farther away (a trainee steers in from 40 mm by the views alone):
when the tool tip is outside the window, both views zoom out :data:`ZOOM_OUT` times
(:func:`inset_zoom`: a window of +-17.5 mm, the grid and the scale bar 5 mm, the same pixels
apart, each view framed in orange so the zoom is plain to see); when it is outside that window
too, a magenta arrow from the reference tip points the way to it in every view where it is
outside (:func:`arrow_direction`, the tip's offset as that view sees it). Within 40 mm
(:data:`NEAR_MM`) the trainee thus always sees the tool tip or the way to it.

What is drawn is geometry only, as the eye sees it - no number, two fixed scales (not a zoom
that follows the distance), so the views keep "Hide distance" honest in an exercise: the spike (a steel cone, :data:`SPIKE_LENGTH_MM` long, radius
:data:`SPIKE_RADIUS_MM` at its base, axis WORLD +Z, as ``robots/generate.py`` builds it) and the
tool's tip as a pointed cone along its working direction (tool X; the body behind, along -X;
:data:`TOOL_CONE_LENGTH_MM` long, radius :data:`TOOL_CONE_RADIUS_MM`, the pointer's tip),
orthographic silhouettes, the nearer one drawn over the farther one.

Why images rendered here and not viser cameras: viser 1.x draws one 3D view per browser (no
second viewport or camera inset); a server-side image is fixed, identical in every browser
and cheap (two 168x192 rasters with numpy, rendered only when the tool tip is in or near the
window; :func:`insets_key` lets the view skip unchanged frames).

Units: metres in (WORLD), millimetres for the window; the image is (H, W, 3) uint8 RGB.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import ConvexHull, QhullError

__all__ = [
    "BACKGROUND",
    "FAR",
    "NEAR_MM",
    "PX_PER_MM",
    "SPIKE_COLOR",
    "TOOL_COLOR",
    "VIEW_H_MM",
    "VIEW_W_MM",
    "ZOOM_OUT",
    "arrow_direction",
    "inset_zoom",
    "insets_key",
    "tip_insets_image",
    "view_pixel",
]

PX_PER_MM = 24
"""Image pixels per millimetre in both views."""
VIEW_W_MM = 7.0
VIEW_H_MM = 8.0
BELOW_MM = 3.0
"""The spike's point is this far above the bottom edge of each view (mm)."""
GAP_PX = 8
SPIKE_LENGTH_MM, SPIKE_RADIUS_MM = 45.0, 7.0
TOOL_CONE_LENGTH_MM, TOOL_CONE_RADIUS_MM = 12.0, 2.5
TOOL_SHAFT_MM = 30.0
"""The tool's body drawn behind its tip cone (a cylinder of the cone's base radius)."""
BACKGROUND = (248, 248, 246)
GRID, GRID5 = (226, 226, 224), (196, 196, 194)
SPIKE_COLOR = (112, 118, 128)
TOOL_COLOR = (222, 38, 170)
"""A colour found nowhere else on the page (the browser test finds the tool tip by it)."""
SCALE_COLOR = (30, 30, 30)
ZOOM_FRAME_COLOR = (240, 140, 0)
"""The frame of a zoomed-out view."""
ZOOM_OUT = 5
"""The zoomed-out views show this many times the field (+-17.5 mm wide), grid and bar 5 mm."""
EDGE_MARGIN_MM = 0.4
"""The tool tip counts as in a window when it is at least this far (mm, at the view's scale)
inside its edges."""

_W = int(round(VIEW_W_MM * PX_PER_MM))
_H = int(round(VIEW_H_MM * PX_PER_MM))
# view name -> (screen-right axis, depth axis towards the viewer) in WORLD; up is +Z in both
_VIEWS = {"front": (np.array([1.0, 0.0, 0.0]), np.array([0.0, -1.0, 0.0])),
          "side": (np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0]))}
_UP = np.array([0.0, 0.0, 1.0])
NEAR_MM = 40.0
"""Farther than this from the reference tip (mm) the tool tip cannot reach the window."""
FAR: tuple[object, ...] = ("far",)
"""The :func:`insets_key` of a tool tip farther than :data:`NEAR_MM`."""


def view_pixel(view: str, point_mm: np.ndarray, zoom: int = 1) -> tuple[float, float]:
    """Image (column, row) of a point given relative to the reference tip (WORLD, mm) in view
    ``view`` ("front" or "side") at ``zoom`` (1, or :data:`ZOOM_OUT`), in the whole image's
    pixels (the side view starts after the front one and the gap)."""
    right, _ = _VIEWS[view]
    p = np.asarray(point_mm, dtype=float)
    x0 = 0 if view == "front" else _W + GAP_PX
    col = x0 + (VIEW_W_MM / 2 + float(p @ right) / zoom) * PX_PER_MM
    row = (VIEW_H_MM - BELOW_MM - float(p @ _UP) / zoom) * PX_PER_MM
    return col, row


def _in_window(view: str, apex_mm: np.ndarray, zoom: int) -> bool:
    right, _ = _VIEWS[view]
    h, v = float(apex_mm @ right) / zoom, float(apex_mm @ _UP) / zoom
    m = EDGE_MARGIN_MM
    return abs(h) <= VIEW_W_MM / 2 - m and -BELOW_MM + m <= v <= VIEW_H_MM - BELOW_MM - m


def inset_zoom(apex_mm: np.ndarray) -> int:
    """The views' zoom for a tool tip at ``apex_mm`` (WORLD, mm from the reference tip): 1 while
    it is in both views' windows, else :data:`ZOOM_OUT`."""
    apex = np.asarray(apex_mm, dtype=float)
    return 1 if all(_in_window(v, apex, 1) for v in _VIEWS) else ZOOM_OUT


def arrow_direction(view: str, apex_mm: np.ndarray) -> tuple[float, float] | None:
    """The unit direction (image column, row: right and down) from the reference tip to the
    tool tip at ``apex_mm`` (WORLD, mm) as view ``view`` sees it, when the tip is outside that
    view's zoomed-out window; None when the view shows the tip itself (or sees it straight
    along its line of sight)."""
    apex = np.asarray(apex_mm, dtype=float)
    if _in_window(view, apex, inset_zoom(apex)):
        return None
    right, _ = _VIEWS[view]
    d = np.array([float(apex @ right), -float(apex @ _UP)])
    n = float(np.linalg.norm(d))
    return None if n < 1e-9 else (float(d[0] / n), float(d[1] / n))


def _cone_points(apex_mm: np.ndarray, into_body: np.ndarray, length: float, radius: float,
                 shaft: float = 0.0, n: int = 16) -> np.ndarray:
    """Points whose convex hull is a cone (apex, base circle) and an optional cylinder behind
    its base, mm."""
    u = into_body / np.linalg.norm(into_body)
    a = np.cross(u, [1.0, 0.0, 0.0])
    if np.linalg.norm(a) < 1e-6:
        a = np.cross(u, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(u, a)
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    ring = np.outer(np.cos(t), a) + np.outer(np.sin(t), b)
    rings = [apex_mm + u * length + radius * ring]
    if shaft > 0.0:
        rings.append(apex_mm + u * (length + shaft) + radius * ring)
    return np.vstack([apex_mm[None, :], *rings])


def _mask(poly: np.ndarray) -> tuple[np.ndarray, int, int] | None:
    """The convex hull of the 2D points ``poly`` (col, row) rasterised within its bounding box
    clipped to a view: (mask, row0, col0), or None when it misses the view."""
    try:
        hull = ConvexHull(poly)
    except (QhullError, ValueError):
        return None
    v = poly[hull.vertices]                       # counter-clockwise in (col, row)
    c0, r0 = max(0, int(np.floor(v[:, 0].min()))), max(0, int(np.floor(v[:, 1].min())))
    c1, r1 = min(_W, int(np.ceil(v[:, 0].max())) + 1), min(_H, int(np.ceil(v[:, 1].max())) + 1)
    if c0 >= c1 or r0 >= r1:
        return None
    y = np.arange(r0, r1, dtype=float)[:, None] + 0.5      # pixel centres, row by row
    p0, p1 = v, np.roll(v, -1, axis=0)
    dy = p1[:, 1] - p0[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (y - p0[:, 1]) / dy                               # where each edge crosses the row
        x = p0[:, 0] + t * (p1[:, 0] - p0[:, 0])
    crosses = (t >= 0.0) & (t <= 1.0) & (dy != 0.0)
    lo = np.where(crosses, x, np.inf).min(axis=1)[:, None]   # a convex hull: one span per row
    hi = np.where(crosses, x, -np.inf).max(axis=1)[:, None]
    cols = np.arange(c0, c1, dtype=float)[None, :] + 0.5
    inside = (cols >= lo) & (cols <= hi)
    return inside, r0, c0


def _project(points: np.ndarray, view: str, zoom: int = 1) -> np.ndarray:
    right, _ = _VIEWS[view]
    return np.column_stack([(VIEW_W_MM / 2 + points @ right / zoom) * PX_PER_MM,
                            (VIEW_H_MM - BELOW_MM - points @ _UP / zoom) * PX_PER_MM])


def _paint(img: np.ndarray, mask: tuple[np.ndarray, int, int] | None, color: tuple[int, int, int]) -> None:
    if mask is not None:
        inside, r0, c0 = mask
        img[r0:r0 + inside.shape[0], c0:c0 + inside.shape[1]][inside] = color


_BASES: dict[tuple[str, int], tuple[np.ndarray, tuple[np.ndarray, int, int] | None]] = {}


def _base(view: str, zoom: int = 1) -> tuple[np.ndarray, tuple[np.ndarray, int, int] | None]:
    """The view without the tool (grid every ``zoom`` mm, scale bar, spike, the orange frame of
    a zoomed-out view) and the spike's mask (cached)."""
    cached = _BASES.get((view, zoom))
    if cached is not None:
        return cached
    img = np.empty((_H, _W, 3), dtype=np.uint8)
    img[:] = BACKGROUND
    for k in range(int(VIEW_W_MM) + 1):           # 1 mm grid, lines through the reference tip
        for offset in (k, -k):
            c = int(round((VIEW_W_MM / 2 + offset) * PX_PER_MM))
            if 0 <= c < _W:
                img[:, c] = GRID5 if offset % 5 == 0 else GRID
    for k in range(-int(BELOW_MM) - 1, int(VIEW_H_MM) + 1):
        r = int(round((VIEW_H_MM - BELOW_MM - k) * PX_PER_MM))
        if 0 <= r < _H:
            img[r, :] = GRID5 if k % 5 == 0 else GRID
    bar_r = _H - 10                                # the 1 mm scale bar, lower left
    img[bar_r - 2:bar_r + 2, 8:8 + PX_PER_MM] = SCALE_COLOR
    img[bar_r - 6:bar_r + 6, 8:10] = SCALE_COLOR
    img[bar_r - 6:bar_r + 6, 6 + PX_PER_MM:8 + PX_PER_MM] = SCALE_COLOR
    spike = _mask(_project(_cone_points(np.zeros(3), -_UP, SPIKE_LENGTH_MM, SPIKE_RADIUS_MM), view, zoom))
    _paint(img, spike, SPIKE_COLOR)
    if zoom != 1:
        f = 3
        img[:f, :], img[-f:, :], img[:, :f], img[:, -f:] = (ZOOM_FRAME_COLOR,) * 4
    img.setflags(write=False)
    _BASES[(view, zoom)] = (img, spike)
    return img, spike


def _arrow(img: np.ndarray, view: str, direction: tuple[float, float], zoom: int) -> None:
    """A magenta arrow from near the reference tip toward the image's edge along ``direction``
    (image column, row)."""
    c0, r0 = view_pixel(view, np.zeros(3), zoom)
    c0 -= 0 if view == "front" else _W + GAP_PX
    d = np.asarray(direction, dtype=float)
    n = np.array([-d[1], d[0]])
    # how far the ray from the reference tip runs inside the view (px), less a margin
    limits = []
    for comp, lo, hi, at in ((d[0], 0.0, float(_W), c0), (d[1], 0.0, float(_H), r0)):
        if abs(comp) > 1e-9:
            limits.append(((hi if comp > 0 else lo) - at) / comp)
    reach = max(20.0, min(limits) - 10.0)
    start, tip = np.array([c0, r0]) + d * 18.0, np.array([c0, r0]) + d * reach
    head = tip - d * 16.0
    shaft = np.array([start + n * 3, start - n * 3, head + n * 3, head - n * 3])
    _paint(img, _mask(shaft), TOOL_COLOR)
    _paint(img, _mask(np.array([tip, head + n * 10, head - n * 10])), TOOL_COLOR)


def _view(tool_apex_mm: np.ndarray | None, tool_into_body: np.ndarray | None, view: str) -> np.ndarray:
    zoom = 1 if tool_apex_mm is None else inset_zoom(tool_apex_mm)
    base, spike = _base(view, zoom)
    img = base.copy()
    if tool_apex_mm is None or tool_into_body is None:
        return img
    tool = _cone_points(tool_apex_mm, tool_into_body, TOOL_CONE_LENGTH_MM, TOOL_CONE_RADIUS_MM, TOOL_SHAFT_MM)
    _paint(img, _mask(_project(tool, view, zoom)), TOOL_COLOR)
    if float(tool_apex_mm @ _VIEWS[view][1]) < 0.0:    # the tool behind the spike: the spike in front
        _paint(img, spike, SPIKE_COLOR)
    direction = arrow_direction(view, tool_apex_mm)
    if direction is not None:
        _arrow(img, view, direction, zoom)
    return img


def _tool_in_mm(reference_tip_world_m: np.ndarray, T_world_tooltrue: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    T = np.asarray(T_world_tooltrue, dtype=float)
    apex = (T[:3, 3] - np.asarray(reference_tip_world_m, dtype=float)) * 1000.0
    if not np.isfinite(apex).all() or math.hypot(*apex.tolist()) > NEAR_MM:
        return None                                # out of every window (drawn without it)
    return apex, -T[:3, 0]                         # the body lies behind the tip, along -X


def insets_key(reference_tip_world_m: np.ndarray, T_world_tooltrue: np.ndarray) -> tuple[object, ...]:
    """What the image depends on, rounded below a tenth of a pixel (equal keys: same image)."""
    tool = _tool_in_mm(reference_tip_world_m, T_world_tooltrue)
    if tool is None:
        return FAR
    apex, axis = tool
    return (tuple(np.round(apex * PX_PER_MM * 10).astype(int)), tuple(np.round(axis * 1e4).astype(int)))


def tip_insets_image(reference_tip_world_m: np.ndarray, T_world_tooltrue: np.ndarray) -> np.ndarray:
    """Front and side views side by side (module docstring): (H, 2W + gap, 3) uint8 RGB.

    Args:
        reference_tip_world_m: (3,) the reference tip, WORLD, m.
        T_world_tooltrue: (4,4) the mounted tool's true TOOL frame in WORLD, m.
    """
    tool = _tool_in_mm(reference_tip_world_m, T_world_tooltrue)
    apex, axis = (None, None) if tool is None else tool
    gap = np.empty((_H, GAP_PX, 3), dtype=np.uint8)
    gap[:] = (255, 255, 255)
    return np.concatenate([_view(apex, axis, "front"), gap, _view(apex, axis, "side")], axis=1)
