"""The beam sensor's stand in the 3D scene: a fork whose two posts carry the emitter
and the receiver, the beam a thin bright line between them.

:func:`stand_geometry` is pure numpy: from a :class:`~tcp_pendant.controller.beam.BeamSensor`
(WORLD, metres) it gives the boxes of the stand (posts, heads, base bar), the column down to the
floor and the beam segments between the heads' inner faces, one pair of posts per beam (a
crossed-beam device has four). The stand's local frame: x along the beam, z "up" (WORLD +Z made
orthogonal to the beam), y = z x x. The fork is open upwards: the tool plunges into it, its
tip and shaft below the beam during the scan's sideways passes, so the posts reach
:data:`FORK_DEPTH_M` below the beam.

:class:`BeamStandNodes` puts that geometry into a viser scene under ``/beam_sensor`` and redraws
it when the sensor changes (compared by value: the controller may hand out a new but equal
sensor object). The beam is drawn in screen pixels, so it stays visible in the overview; it
turns red while it is broken (:meth:`BeamStandNodes.set_broken`, a scan's film).
"""

from __future__ import annotations

from dataclasses import dataclass
import numpy as np
import viser

from tcp_pendant.controller.beam import BeamSensor
from tcp_pendant.controller.rotations import quaternion_wxyz
from tcp_pendant.translation import ENGLISH, N_, Translator

__all__ = ["BEAM_RGB", "BEAM_SENSOR_LABEL", "BROKEN_RGB", "FORK_DEPTH_M", "HALF_GAP_M", "BeamStandNodes", "StandBox", "StandGeometry",
           "sensor_key", "stand_frame", "stand_geometry"]

HALF_GAP_M = 0.05
"""Half the clear gap between emitter and receiver, m (a 100 mm fork)."""
FORK_DEPTH_M = 0.10
"""How far the posts reach below the beam, m (room for the sideways passes' tool tip)."""
POST_TOP_M = 0.02
"""How far the posts reach above the beam, m."""
POST_THICKNESS_M = 0.016
POST_WIDTH_M = 0.03
BAR_HEIGHT_M = 0.016
COLUMN_RADIUS_M = 0.018
BEAM_RGB = (0, 160, 40)
"""The intact beam: bright green (red is kept for a broken beam)."""
BROKEN_RGB = (225, 0, 0)
"""A broken beam (:meth:`BeamStandNodes.set_broken`)."""
STAND_RGB = (70, 82, 104)
HEAD_RGB = (28, 28, 32)
BEAM_PX = 5.0
"""Line width of the beam, screen pixels."""


@dataclass(frozen=True)
class StandBox:
    """One box of the stand: centre (WORLD, m), rotation WORLD <- box (3,3), dimensions (m)."""

    name: str
    centre: np.ndarray
    R_world_box: np.ndarray
    dimensions: tuple[float, float, float]
    rgb: tuple[int, int, int]


@dataclass(frozen=True)
class StandGeometry:
    """What :class:`BeamStandNodes` draws for one sensor (WORLD, metres).

    Attributes:
        boxes: posts, heads and base bars.
        column: (bottom, top) of the vertical column to the floor, or None when the fork's base
            is at or below the floor.
        beams: (K, 2, 3) each beam's segment between the heads' inner faces.
        label_position: (3,) where the "beam sensor" label goes (below the fork, beside it).
    """

    boxes: tuple[StandBox, ...]
    column: tuple[np.ndarray, np.ndarray] | None
    beams: np.ndarray
    label_position: np.ndarray


def stand_frame(direction: np.ndarray) -> np.ndarray:
    """(3,3) rotation WORLD <- stand for a beam along ``direction`` (unit, WORLD): x the beam,
    z WORLD +Z made orthogonal to it (WORLD +X if the beam is vertical), y = z x x."""
    x = np.asarray(direction, dtype=float)
    x = x / np.linalg.norm(x)
    up = np.array([0.0, 0.0, 1.0])
    if abs(float(up @ x)) > 0.99:
        up = np.array([1.0, 0.0, 0.0])
    z = up - (up @ x) * x
    z /= np.linalg.norm(z)
    y = np.cross(z, x)
    return np.column_stack([x, y, z])


def stand_geometry(sensor: BeamSensor) -> StandGeometry:
    """The stand of ``sensor``: for each beam two posts at ``+-`` (:data:`HALF_GAP_M` + half a post)
    along it, a head on each post's inner face at the beam's height, a base bar joining the
    posts :data:`FORK_DEPTH_M` below the beam, and a column from the bars down to the floor."""
    b = np.asarray(sensor.point, dtype=float)
    boxes: list[StandBox] = []
    segments = []
    post_h = FORK_DEPTH_M + POST_TOP_M
    bar_z = -FORK_DEPTH_M - BAR_HEIGHT_M / 2.0
    for k, (_, u) in enumerate(sensor.beams):
        R = stand_frame(u)
        x, z = R[:, 0], R[:, 2]
        offset = HALF_GAP_M + POST_THICKNESS_M / 2.0
        for side, sign in (("emitter", -1.0), ("receiver", 1.0)):
            post_c = b + sign * offset * x + (POST_TOP_M - FORK_DEPTH_M) / 2.0 * z
            boxes.append(StandBox(f"beam{k}_{side}_post", post_c, R,
                                  (POST_THICKNESS_M, POST_WIDTH_M, post_h), STAND_RGB))
            head_c = b + sign * (HALF_GAP_M - 0.004) * x
            boxes.append(StandBox(f"beam{k}_{side}_head", head_c, R, (0.008, 0.022, 0.022), HEAD_RGB))
        bar_len = 2.0 * offset + POST_THICKNESS_M
        boxes.append(StandBox(f"beam{k}_bar", b + bar_z * z, R, (bar_len, POST_WIDTH_M, BAR_HEIGHT_M),
                              STAND_RGB))
        segments.append([b - (HALF_GAP_M - 0.008) * x, b + (HALF_GAP_M - 0.008) * x])
    R0 = stand_frame(sensor.direction)
    base = b + (bar_z - BAR_HEIGHT_M / 2.0) * R0[:, 2]
    column = None
    if base[2] > 0.005:
        column = (np.array([base[0], base[1], 0.0]), base.copy())
    label = b - (FORK_DEPTH_M + 0.04) * R0[:, 2] + (HALF_GAP_M + 0.03) * R0[:, 1]
    return StandGeometry(tuple(boxes), column, np.asarray(segments, dtype=float), label)


def sensor_key(sensor: BeamSensor | None) -> bytes | None:
    """A value key of the sensor's geometry (point, directions, width), or None."""
    if sensor is None:
        return None
    parts = [np.asarray(sensor.point, dtype=float), np.asarray(sensor.direction, dtype=float),
             np.array([sensor.width])]
    if sensor.second_direction is not None:
        parts.append(np.asarray(sensor.second_direction, dtype=float))
    return np.concatenate(parts).tobytes()


BEAM_SENSOR_LABEL = N_("beam sensor")
"""The stand's 3D label (shown in the session's language)."""


class BeamStandNodes:
    """The stand and the beam(s) under ``/beam_sensor`` of one scene.

    Args:
        scene: viser's scene API of the session.
        sensor: the sensor to draw first (None: nothing drawn until :meth:`show`).
        tr: the language of the label (:meth:`show` takes the current one).
    """

    ROOT = "/beam_sensor"

    def __init__(self, scene: viser.SceneApi, sensor: BeamSensor | None, *, tr: Translator = ENGLISH) -> None:
        self.scene = scene
        self._nodes: list[viser.SceneNodeHandle] = []
        self.shown_key: bytes | None = None
        self.geometry: StandGeometry | None = None
        self.beam_handle: viser.LineSegmentsHandle | None = None
        self.label: viser.LabelHandle | None = None
        self.broken: int | None = None
        """The beam drawn red (broken; ``views.beam_replay``), or None."""
        self._shown_sensor: BeamSensor | None = None
        self._label_text = tr.gettext(BEAM_SENSOR_LABEL)
        self.show(sensor, tr=tr)

    def _colors(self) -> np.ndarray:
        n = 0 if self.geometry is None else len(self.geometry.beams)
        colors = np.tile(np.array(BEAM_RGB, dtype=np.uint8), (n, 2, 1))
        if self.broken is not None and 0 <= self.broken < n:
            colors[self.broken] = BROKEN_RGB
        return colors

    def set_broken(self, beam: int | None) -> None:
        """Draw beam ``beam`` (0, or 1 for a second beam) red, the others green; None: all green."""
        if beam == self.broken:
            return
        self.broken = beam
        if self.beam_handle is not None:
            self.beam_handle.colors = self._colors()

    def _relabel(self, tr: Translator) -> None:
        """The label in ``tr``'s language (sent only when its words change)."""
        text = tr.gettext(BEAM_SENSOR_LABEL)
        if text != self._label_text:
            self._label_text = text
            if self.label is not None:
                self.label.text = text

    def show(self, sensor: BeamSensor | None, *, tr: Translator = ENGLISH) -> bool:
        """Draw ``sensor`` if it differs from what is drawn (returns whether it redrew), its label
        in ``tr``'s language. Called on every change signal (each jog step): the same sensor
        object returns at once."""
        self._relabel(tr)
        if sensor is self._shown_sensor and sensor is not None:
            return False
        self._shown_sensor = sensor
        key = sensor_key(sensor)
        if key == self.shown_key:
            return False
        for h in self._nodes:
            h.remove()
        self._nodes = []
        self.beam_handle = self.label = None
        self.broken = None
        self.shown_key = key
        self.geometry = None
        if sensor is None:
            return True
        g = self.geometry = stand_geometry(sensor)
        s, root = self.scene, self.ROOT
        for box in g.boxes:
            self._nodes.append(s.add_box(f"{root}/{box.name}", color=box.rgb, dimensions=box.dimensions,
                                         wxyz=np.array(quaternion_wxyz(box.R_world_box)), position=box.centre,
                                         cast_shadow=False, receive_shadow=False))
        if g.column is not None:
            bottom, top = g.column
            self._nodes.append(s.add_cylinder(f"{root}/column", radius=COLUMN_RADIUS_M,
                                              height=float(top[2] - bottom[2]), color=STAND_RGB,
                                              position=(bottom + top) / 2.0, cast_shadow=False,
                                              receive_shadow=False))
        self.beam_handle = s.add_line_segments(f"{root}/beam", points=g.beams, colors=self._colors(),
                                               thickness=BEAM_PX, thickness_units="screen")
        self.label = s.add_label(f"{root}/label", self._label_text, position=g.label_position)
        self._nodes.extend([self.beam_handle, self.label])
        return True
