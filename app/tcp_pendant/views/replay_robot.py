"""The robot and the cell of the dashboard's 3D replay (viser scene, the trainer's browser).

:class:`ReplayRobot` draws the class's robot (the trainer session's kinematics: every trainee of a
class server has the same robot) under ``/replay/robot``, each URDF link a frame with its
meshes, posed at one recorded touch's joint angles (degrees, as the gradebook keeps them;
``RobotKinematics.link_poses`` of them in radians gives each link in WORLD, metres), and the
reference tip's stand at the replay's reference tip. ``views.dashboard_replay`` poses it at the
touch the trainer picks. The links are flat frames (no nesting): a pose sets each link's WORLD
pose.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import viser

from tcp_pendant.controller import reference_tip_model
from tcp_pendant.controller.kinematics import RobotKinematics
from tcp_pendant.views.meshes import MeshPart, link_meshes, rigid_meshes
from tcp_pendant.views.scene import wxyz_xyz

__all__ = ["ROBOT_ROOT", "ReplayRobot"]

ROBOT_ROOT = "/replay/robot"
CELL_ROOT = "/replay/cell"


def _add_parts(scene: viser.SceneApi, parent: str, parts: tuple[MeshPart, ...]) -> list[Any]:
    return [scene.add_mesh_simple(f"{parent}/mesh_{i}", p.vertices, p.faces, color=p.rgb, flat_shading=False)
            for i, p in enumerate(parts)]


class ReplayRobot:
    """The replay's robot and reference tip stand in one browser's scene.

    Attributes:
        posed_joints_deg: the joint angles shown (degrees), None: not drawn.
        link_frames: link name -> its frame (for tests).
        stand: the reference tip's stand (None: not drawn).
    """

    def __init__(self, scene: viser.SceneApi, kinematics: RobotKinematics) -> None:
        self.scene, self.kinematics = scene, kinematics
        self.link_frames: dict[str, Any] = {}
        self.handles: list[Any] = []
        self.posed_joints_deg: np.ndarray | None = None
        self.stand: Any = None

    def _build(self) -> None:
        meshes = link_meshes(self.kinematics.description)
        poses = self.kinematics.link_poses(np.zeros(self.kinematics.n_joints))
        for i, name in enumerate(poses):
            path = f"{ROBOT_ROOT}/link_{i}"
            frame = self.scene.add_frame(path, show_axes=False)
            self.link_frames[name] = frame
            self.handles.append(frame)                  # its meshes go with it
            _add_parts(self.scene, path, meshes.get(name, ()))

    def show(self, joints_deg: Sequence[float] | np.ndarray | None, reference_world_m: np.ndarray | None) -> bool:
        """Pose the robot at ``joints_deg`` (degrees; drawn on first use) and put the stand
        under ``reference_world_m`` (metres, WORLD). False (the robot hidden): no joint angles
        of this robot's length."""
        if reference_world_m is not None and self.stand is None:
            tip = reference_tip_model()
            wxyz, xyz = wxyz_xyz(tip.T_world_stand(np.asarray(reference_world_m, dtype=float)))
            self.stand = self.scene.add_frame(CELL_ROOT, show_axes=False, wxyz=wxyz, position=xyz)
            self.handles.append(self.stand)
            _add_parts(self.scene, CELL_ROOT, rigid_meshes(tip.urdf_path))
        q = None if joints_deg is None else np.asarray(joints_deg, dtype=float).reshape(-1)
        if q is None or q.shape != (self.kinematics.n_joints,) or not np.all(np.isfinite(q)):
            for frame in self.link_frames.values():
                frame.visible = False
            self.posed_joints_deg = None
            return False
        if not self.link_frames:
            self._build()
        for name, T in self.kinematics.link_poses(np.radians(q)).items():
            frame = self.link_frames.get(name)
            if frame is None:
                continue
            wxyz, xyz = wxyz_xyz(T)
            frame.wxyz, frame.position, frame.visible = wxyz, xyz, True
        self.posed_joints_deg = q
        return True

    def clear(self) -> None:
        for h in self.handles:
            try:
                h.remove()
            except Exception:          # already gone with the browser
                pass
        self.handles, self.link_frames, self.posed_joints_deg, self.stand = [], {}, None, None
