"""Camera framing and label placement for a calibration result, without viser.

After Finish the 3D view should show the whole result (the fitted sphere, the flange
positions on it, the TOOL triads) filling the view, with the labels near the tool tip
(COMPUTED, TRUE, TOOL, TARGET, "reference tip", FLANGE) readable instead of drawn on top of one
another. Two pure functions do the geometry:

* :func:`frame_spheres`: the bounding sphere of points with radii (a sphere, frame origins
  with their axis length) and a camera pose from which it fills the view of a pinhole
  camera (viser's: vertical field of view ``fov``, ``aspect`` = width / height);
* :func:`spread_labels`: viser draws a label at a fixed size on screen, its text to the right
  of and below its anchor (``anchor="top-left"``); labels whose boxes would overlap as seen
  from the framed camera are moved up the screen, one above the other, and the new anchors
  returned in WORLD.

Units: WORLD metres, angles in radians where viser uses them (``fov``), pixels on screen.
"""

from __future__ import annotations

import math
import unicodedata
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "CHAR_WIDTH_PX",
    "LABEL_HEIGHT_PX",
    "VIEW_DIRECTION",
    "Framing",
    "bounding_sphere",
    "frame_spheres",
    "label_box_px",
    "spread_labels",
    "text_columns",
]

VIEW_DIRECTION = np.array([1.15, -1.25, 0.55]) / np.linalg.norm([1.15, -1.25, 0.55])
"""From the framed point toward the camera: the overview's direction (front right, above)."""
LABEL_HEIGHT_PX = 24.0
"""Height of a viser label's box on screen (14 px text and its padding, with a little air)."""
CHAR_WIDTH_PX = 8.5
"""Width per character of a label's text (viser's default sans font at 14 px), plus padding below."""
_LABEL_PAD_PX = 14.0
LABEL_GAP_PX = 6.0
"""Air between two labels moved apart (screen px): boxes that only touch read as one line."""
_WORLD_UP = np.array([0.0, 0.0, 1.0])


def text_columns(text: str) -> int:
    """Columns ``text`` takes: a wide character (CJK, Unicode's East Asian Width W or F) two,
    any other one."""
    return sum(2 if unicodedata.east_asian_width(ch) in "WF" else 1 for ch in text)


def label_box_px(text: str, font_scale: float = 1.0) -> tuple[float, float]:
    """(width, height) of a label's box on screen, pixels, at viser's ``font_screen_scale``
    ``font_scale`` (the box grows with the font; a wide character counts two columns:
    :func:`text_columns`)."""
    s = float(font_scale)
    return (CHAR_WIDTH_PX * text_columns(text) + _LABEL_PAD_PX) * s, LABEL_HEIGHT_PX * s


@dataclass(frozen=True)
class Framing:
    """A camera pose that shows a bounding sphere whole.

    Attributes:
        position, look_at: camera position and the point it looks at (WORLD, m).
        centre, radius_m: the bounding sphere (WORLD, m).
        distance_m: from the camera to ``centre``.
        fov_rad: vertical field of view; aspect: width / height; image_height_px: pixels.
    """

    position: np.ndarray
    look_at: np.ndarray
    centre: np.ndarray
    radius_m: float
    distance_m: float
    fov_rad: float
    aspect: float
    image_height_px: float

    def basis(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(forward, right, up) unit vectors of the camera, WORLD (up: screen up)."""
        f = self.look_at - self.position
        f = f / np.linalg.norm(f)
        r = np.cross(f, _WORLD_UP)
        if np.linalg.norm(r) < 1e-9:                      # looking straight down or up
            r = np.cross(f, np.array([0.0, 1.0, 0.0]))
        r = r / np.linalg.norm(r)
        return f, r, np.cross(r, f)

    @property
    def focal_px(self) -> float:
        """Pinhole focal length in pixels."""
        return 0.5 * self.image_height_px / math.tan(0.5 * self.fov_rad)

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Screen coordinates (N, 2) in pixels from the image centre (x right, y up) and the
        depth (N,) in metres along the view direction."""
        p = np.asarray(points, dtype=float).reshape(-1, 3) - self.position
        f, r, u = self.basis()
        depth = p @ f
        xy = np.stack([p @ r, p @ u], axis=1) * (self.focal_px / depth)[:, None]
        return xy, depth

    def metres_per_px(self, depth_m: float) -> float:
        """Size of one pixel, at ``depth_m`` from the camera, in metres."""
        return float(depth_m) / self.focal_px


def bounding_sphere(centres: np.ndarray, radii: np.ndarray | Sequence[float] | None = None) -> tuple[np.ndarray, float]:
    """A sphere containing every sphere (centre, radius); points have radius 0.

    Centre: the middle of the axis-aligned box around the spheres; radius: the farthest
    sphere surface from it (not the smallest enclosing sphere, but at most sqrt(3) times it
    and never too small).

    Raises:
        ValueError: no points, or a non-finite one.
    """
    c = np.asarray(centres, dtype=float).reshape(-1, 3)
    r = np.zeros(len(c)) if radii is None else np.asarray(radii, dtype=float).reshape(-1)
    if len(c) == 0 or len(r) != len(c) or not (np.all(np.isfinite(c)) and np.all(np.isfinite(r))):
        raise ValueError("Framing needs at least one finite point (and one radius per point).")
    lo, hi = (c - r[:, None]).min(axis=0), (c + r[:, None]).max(axis=0)
    centre = 0.5 * (lo + hi)
    return centre, float(np.max(np.linalg.norm(c - centre, axis=1) + r))


def frame_spheres(centres: np.ndarray, radii: np.ndarray | Sequence[float] | None = None, *,
                  fov_rad: float = math.radians(50.0), aspect: float = 16.0 / 9.0,
                  image_height_px: float = 720.0, direction: np.ndarray = VIEW_DIRECTION,
                  margin: float = 1.15, min_radius_m: float = 0.05) -> Framing:
    """The camera pose from ``direction`` that fits the bounding sphere of the spheres in the
    view with ``margin`` (1.15: 15 % space around it).

    Args:
        centres: the centres of the spheres to show (WORLD, m); see :func:`bounding_sphere`.
        radii: their radii (m).
        fov_rad: vertical field of view; aspect: width / height (the narrower one counts).
        image_height_px: the view's height in pixels (for :func:`spread_labels`).
        direction: from the framed point toward the camera (normalised here).
        margin: distance factor over a tight fit.
        min_radius_m: smallest sphere framed (a single point is not zoomed into).
    """
    centre, radius = bounding_sphere(centres, radii)
    radius = max(radius, min_radius_m)
    fov = float(fov_rad) if math.isfinite(fov_rad) and 0.05 < fov_rad < 3.0 else math.radians(50.0)
    asp = float(aspect) if math.isfinite(aspect) and aspect > 0.05 else 16.0 / 9.0
    half = min(0.5 * fov, math.atan(math.tan(0.5 * fov) * asp))
    distance = margin * radius / math.sin(half)
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    height = float(image_height_px) if math.isfinite(image_height_px) and image_height_px > 50 else 720.0
    return Framing(position=centre + distance * d, look_at=centre, centre=centre, radius_m=radius,
                   distance_m=distance, fov_rad=fov, aspect=asp, image_height_px=height)


_TOUCH_PX = 1e-6
"""Boxes closer than this to touching (screen px) count as touching, not overlapping: a label
moved to exactly ``h`` above another is apart, whatever the rounding of ``(y + h) - h``."""


def _overlap(a: np.ndarray, wa: float, b: np.ndarray, wb: float, h: float) -> bool:
    """Boxes anchored top-left at a and b (pixels, y up) overlap by more than ``_TOUCH_PX``."""
    e = _TOUCH_PX
    return bool(a[0] < b[0] + wb - e and b[0] < a[0] + wa - e and a[1] - h < b[1] - e and b[1] - h < a[1] - e)


def spread_labels(framing: Framing, anchors: Mapping[str, np.ndarray],
                  texts: Mapping[str, str], *, font_scale: float = 1.0) -> dict[str, np.ndarray]:
    """New WORLD anchors for labels so that, seen from ``framing``, no two boxes overlap.

    Labels are placed in the order of ``anchors``: each stays where it is unless its box
    overlaps one already placed, then it moves up the screen (along the camera's up vector, at
    its own depth) to ``LABEL_GAP_PX`` above that box, until it overlaps none (boxes grown by
    that gap, so the labels never touch).

    Args:
        framing: the camera the labels are seen from.
        anchors: label name -> its anchor (WORLD, m) as drawn now.
        texts: label name -> its text (its box's width).
        font_scale: the labels' ``font_screen_scale`` (presenter mode draws them larger).
    """
    _, _, up = framing.basis()
    placed: list[tuple[np.ndarray, float]] = []
    out: dict[str, np.ndarray] = {}
    for name, anchor in anchors.items():
        p = np.asarray(anchor, dtype=float).reshape(3)
        xy, depth = framing.project(p)
        xy, px_depth = xy[0].copy(), float(depth[0])
        w, h = label_box_px(texts[name], font_scale)
        h += LABEL_GAP_PX
        start = xy[1]
        for _ in range(4 * len(anchors) + 4):
            hit = next((q for q, wq in placed if _overlap(xy, w, q, wq, h)), None)
            if hit is None:
                break
            xy[1] = hit[1] + h                          # a gap above the box it hit
        placed.append((xy, w))
        out[name] = p + up * (xy[1] - start) * framing.metres_per_px(px_depth)
    return out
