"""The dashboard's 3D replay of a trainee's calibration (the trainer's own scene).

Draws a :class:`~tcp_pendant.classroom.replay.CalibrationReplay` under ``/replay`` in the
trainer browser's scene: the robot posed at one touch (the last counted one first; the trainer
steps through them, :meth:`ReplayScene.show_touch`) with the reference tip's stand
(``views.replay_robot``), each touch as a small flange triad (numbered; an overwritten one
half-size), the approach of the tool at it as a line from the flange to where the tip was
(blue: by hand, orange: Auto-touch), the reference tip as a dark sphere, and at the last
counted touch the computed TOOL frame ("result") and the true one ("true"). The camera looks at
the reference tip. Metres, WORLD. Labels are our own text (numbers and fixed words).
"""

from __future__ import annotations

import numpy as np
import viser
from scipy.spatial.transform import Rotation

from tcp_pendant.classroom.replay import CalibrationReplay
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.views.replay_robot import ReplayRobot

__all__ = ["ReplayScene", "wxyz"]

ROOT = "/replay"
TOUCH_AXES_M = 0.03
RESULT_AXES_M = 0.06
HAND_RGB = (40, 90, 220)
AUTO_RGB = (240, 140, 20)


def wxyz(R: np.ndarray) -> tuple[float, float, float, float]:
    """viser's quaternion (w, x, y, z) of a rotation matrix."""
    x, y, z, w = Rotation.from_matrix(np.asarray(R, dtype=float)[:3, :3]).as_quat()
    return (float(w), float(x), float(y), float(z))


FRAME_WORDS = {"result": N_("result"), "true": N_("true")}
"""The replay's two TOOL frames' labels (English msgids): the computed one and the true one."""


class ReplayScene:
    """The replay's scene nodes in one browser (``scene``: ``client.scene``).

    Attributes:
        shown: the replay on show (None: none).
        handles: the scene handles drawn (for tests).
    """

    def __init__(self, scene: viser.SceneApi, camera: viser.CameraHandle | None = None,
                 robot: ReplayRobot | None = None) -> None:
        self.scene = scene
        self.camera = camera
        self.robot = robot
        self.shown: CalibrationReplay | None = None
        self.handles: list[viser.SceneNodeHandle] = []
        self.touch_shown: int | None = None

    def clear(self) -> None:
        for h in self.handles:
            try:
                h.remove()
            except Exception:          # already gone with the browser
                pass
        self.handles = []
        self.shown = None
        self.touch_shown = None
        if self.robot is not None:
            self.robot.clear()

    def show(self, replay: CalibrationReplay, *, tr: Translator = ENGLISH) -> None:
        """Draw ``replay`` (the previous one removed) and look at its reference tip; the frames'
        labels in ``tr``'s language."""
        self.clear()
        sc = self.scene
        add = self.handles.append
        counted = [t for t in replay.touches if not t.overwritten]
        for i, t in enumerate(replay.touches):
            T = t.T_world_flange_m
            size = TOUCH_AXES_M * (0.5 if t.overwritten else 1.0)
            add(sc.add_frame(f"{ROOT}/touch_{i}", wxyz=wxyz(T), position=tuple(T[:3, 3]), axes_length=size,
                             axes_radius=size / 25.0, origin_radius=size / 12.0))
            add(sc.add_label(f"{ROOT}/touch_{i}_label", f"{i + 1}", position=tuple(T[:3, 3] + T[:3, 2] * -size * 1.3)))
        segments = [(t.T_world_flange_m[:3, 3], t.tip_world_m) for t in replay.touches if t.tip_world_m is not None]
        if segments:
            points = np.array([[a, b] for a, b in segments], dtype=np.float32)
            colours = np.array([[AUTO_RGB if t.auto else HAND_RGB] * 2 for t in replay.touches
                                if t.tip_world_m is not None], dtype=np.uint8)
            add(sc.add_line_segments(f"{ROOT}/approach", points=points, colors=colours, thickness=2.0,
                                     thickness_units="screen"))
        if replay.reference_world_m is not None:
            add(sc.add_icosphere(f"{ROOT}/reference", radius=0.004, color=(30, 30, 30),
                                 position=tuple(replay.reference_world_m)))
        if counted:
            T_last = counted[-1].T_world_flange_m
            for name, T_ft in (("result", replay.T_flange_tool_result_m), ("true", replay.T_flange_tool_true_m)):
                if T_ft is None:
                    continue
                T = T_last @ T_ft
                length = RESULT_AXES_M if name == "result" else RESULT_AXES_M * 0.7
                add(sc.add_frame(f"{ROOT}/{name}", wxyz=wxyz(T), position=tuple(T[:3, 3]), axes_length=length,
                                 axes_radius=length / 30.0))
                add(sc.add_label(f"{ROOT}/{name}_label", tr.gettext(FRAME_WORDS[name]),
                                 position=tuple(T[:3, 3] + T[:3, 0] * length)))
        self.shown = replay
        if counted:
            self.show_touch(replay.touches.index(counted[-1]))
        self._look(replay)

    def show_touch(self, index: int) -> bool:
        """The robot at touch ``index`` (0-based in ``shown.touches``), the stand at the reference
        tip. False: no replay, no such touch, or its joint angles were not kept (robot hidden)."""
        replay = self.shown
        if replay is None or self.robot is None or not 0 <= index < len(replay.touches):
            return False
        self.touch_shown = index
        return self.robot.show(replay.touches[index].joints_deg, replay.reference_world_m)

    def _look(self, replay: CalibrationReplay) -> None:
        if self.camera is None:
            return
        target = replay.reference_world_m
        if target is None and replay.touches:
            target = replay.touches[-1].T_world_flange_m[:3, 3]
        if target is None:
            return
        target = np.asarray(target, dtype=float)
        try:
            self.camera.position = target + np.array([0.45, -0.45, 0.35])
            self.camera.look_at = target
        except Exception:                   # no camera state from that browser yet
            pass
