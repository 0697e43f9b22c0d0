"""The 3D scene of one session: robot, mounted tool, reference tip, floor, frames, gizmo.

Scene tree (names are per browser; ``--shared`` uses the server's scene):

* ``/floor`` grid; ``/world`` the WORLD frame (the robot's root link) with its label;
* ``/robot/<link>``: one flat frame per URDF link, posed directly from pinocchio's
  ``link_poses`` (``T_world_link``) - no yourdfpy FK per jog step - with the link's meshes
  as children; ``/robot/<flange>/...`` holds the FLANGE triad, the mounted tool's meshes and
  the active TOOL triad at ``T_flange_tool`` (they ride on the flange without updates);
* ``/reference_tip``: the stand posed so that its spike is at the reference tip;
* ``/tcp_gizmo``: transform controls on the active TCP; dragging it moves the TCP by
  ``VirtualController.move_tcp_to`` (straight line, same safety rules as jogging).

Axis colours are viser's: X red, Y green, Z blue. Quaternions (w, x, y, z) come from scipy.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from tcp_pendant.controller import ToolModel, reference_tip_model
from tcp_pendant.session import Session
from tcp_pendant.views.meshes import MeshPart, link_meshes, rigid_meshes

__all__ = ["SceneView", "wxyz_xyz"]

OVERVIEW_OFFSET_M = np.array([1.15, -1.25, 0.55])
CLOSEUP_OFFSET_M = np.array([0.22, -0.26, 0.12])


def wxyz_xyz(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(w, x, y, z) quaternion and position of a (4,4) pose (or stacks (N,4,4))."""
    T = np.asarray(T, dtype=float)
    q = Rotation.from_matrix(T[..., :3, :3]).as_quat()          # (x, y, z, w)
    return np.roll(q, 1, axis=-1), T[..., :3, 3]


def set_poses(handles: list[Any], wxyz: np.ndarray, xyz: np.ndarray) -> None:
    """Pose many scene nodes at once (per-jog-step hot path).

    Equivalent to ``h.wxyz = ...; h.position = ...`` for each handle, without the per-setter
    validation and ``allclose`` of viser's public setters (about 4x the cost here): the node's
    stored pose is updated in place and the same Set{Orientation,Position}Message is queued.
    Falls back to the public setters if viser's internals differ.
    """
    try:
        from viser import _messages

        for h, q, p in zip(handles, wxyz.tolist(), xyz.tolist()):
            impl = h._impl
            impl.wxyz[:] = q
            impl.position[:] = p
            impl.api._queue_scene_message(_messages.SetOrientationMessage(impl.name, tuple(q)))
            impl.api._queue_scene_message(_messages.SetPositionMessage(impl.name, tuple(p)))
    except AttributeError:
        for h, q, p in zip(handles, wxyz, xyz):
            h.wxyz = q
            h.position = p


def _add_parts(scene: Any, parent: str, parts: tuple[MeshPart, ...], *, opacity: float | None = None) -> list[Any]:
    out = []
    for i, p in enumerate(parts):
        kw = {} if opacity is None else {"opacity": opacity}
        out.append(scene.add_mesh_simple(f"{parent}/mesh_{i}", p.vertices, p.faces, color=p.rgb,
                                         flat_shading=False, **kw))
    return out


class SceneView:
    """Builds and updates the scene of one session (see the module docstring).

    Args:
        session: the session; the scene is ``session.target.scene``.
    """

    def __init__(self, session: Session) -> None:
        self.session = session
        c = session.controller
        scene = session.target.scene
        self.scene = scene
        k = c.kinematics
        self.flange_link = k.flange_link
        self._dragging = False
        self._drag_seq = 0
        self._drag_lock = threading.Lock()

        scene.set_up_direction("+z")
        scene.add_grid("/floor", width=3.0, height=3.0, cell_size=0.1, section_size=0.5,
                       plane="xy", position=(0.0, 0.0, 0.0))
        scene.add_frame("/world", axes_length=0.25, axes_radius=0.006)
        scene.add_label("/world/label", "WORLD", position=(0.0, 0.0, -0.04))

        meshes = link_meshes(k.urdf_path)
        self.link_frames: dict[str, Any] = {}
        poses = c.link_poses()
        for name, T in poses.items():
            wxyz, xyz = wxyz_xyz(T)
            self.link_frames[name] = scene.add_frame(f"/robot/{name}", show_axes=False, wxyz=wxyz, position=xyz)
            _add_parts(scene, f"/robot/{name}", meshes.get(name, ()))
        self._moving = [n for n in self.link_frames if n != k.base_link]
        fl = f"/robot/{self.flange_link}"
        scene.add_frame(f"{fl}/flange_axes", axes_length=0.09, axes_radius=0.004)
        scene.add_label(f"{fl}/flange_axes/label", "FLANGE", position=(0.0, 0.05, 0.0))
        self._tool_root = f"{fl}/tool"
        self._tool_frame: Any = None
        self.set_mounted_tool(c.mounted_tool)
        self._active_axes = scene.add_frame(f"{fl}/active_tool", axes_length=0.12, axes_radius=0.005)
        self._active_label = scene.add_label(f"{fl}/active_tool/label", "TOOL", position=(0.0, 0.0, 0.04))
        self.update_active_tool()

        tip = reference_tip_model()
        wxyz, xyz = wxyz_xyz(tip.T_world_stand(c.reference_tip_world_m))
        self._tip_frame = scene.add_frame("/reference_tip", show_axes=False, wxyz=wxyz, position=xyz)
        _add_parts(scene, "/reference_tip", rigid_meshes(tip.urdf_path))
        self._tip_label = scene.add_label("/reference_tip_label", "reference tip",
                                          position=tuple(c.reference_tip_world_m + [0.0, 0.0, -0.06]))

        wxyz, xyz = wxyz_xyz(c.T_world_tcp())
        self.gizmo = scene.add_transform_controls("/tcp_gizmo", scale=0.14, line_width=2.0, wxyz=wxyz,
                                                  position=xyz, depth_test=False, opacity=0.85)
        self.gizmo.on_update(self._on_gizmo)
        session.add_renderer(self.render)

    # ------------------------------------------------------------ updates
    def render(self) -> None:
        """Pose every moving link frame from pinocchio and the gizmo on the TCP (not while dragged)."""
        c = self.session.controller
        poses = c.link_poses()
        mats = [poses[n] for n in self._moving]
        handles = [self.link_frames[n] for n in self._moving]
        if not self._dragging:
            mats.append(c.T_world_tcp())
            handles.append(self.gizmo)
        wxyz, xyz = wxyz_xyz(np.stack(mats))
        set_poses(handles, wxyz, xyz)

    def _snap_gizmo(self) -> None:
        wxyz, xyz = wxyz_xyz(self.session.controller.T_world_tcp())
        self.gizmo.wxyz = wxyz
        self.gizmo.position = xyz

    def set_mounted_tool(self, tool: ToolModel) -> None:
        """Show another physical tool on the flange."""
        if self._tool_frame is not None:
            self._tool_frame.remove()
        self._tool_frame = self.scene.add_frame(self._tool_root, show_axes=False)
        _add_parts(self.scene, self._tool_root, rigid_meshes(tool.urdf_path))

    def update_active_tool(self) -> None:
        """Move the TOOL triad to the active tool data (``T_flange_tool``) and relabel it."""
        c = self.session.controller
        wxyz, xyz = wxyz_xyz(c.T_flange_tool)
        self._active_axes.wxyz = wxyz
        self._active_axes.position = xyz
        tool = c.active_tool
        self._active_axes.visible = tool is not None      # no tool data: TOOL = FLANGE
        self._active_label.text = "TOOL" if tool is None else f"TOOL {tool.name}"

    def update_reference_tip(self) -> None:
        """Re-place the stand after the reference tip moved."""
        c = self.session.controller
        wxyz, xyz = wxyz_xyz(reference_tip_model().T_world_stand(c.reference_tip_world_m))
        self._tip_frame.wxyz = wxyz
        self._tip_frame.position = xyz
        self._tip_label.position = tuple(c.reference_tip_world_m + [0.0, 0.0, -0.06])

    # ------------------------------------------------------------ camera
    def look_at_tip(self, client: Any) -> None:
        """Close-up camera on the reference tip (fine approach) for one browser."""
        tip = self.session.controller.reference_tip_world_m
        with client.atomic():                    # position first: its setter shifts look_at
            client.camera.position = tip + CLOSEUP_OFFSET_M
            client.camera.look_at = tip

    def overview(self, client: Any) -> None:
        """Camera on the whole cell."""
        position, look_at = self.overview_pose(self.session.controller.reference_tip_world_m)
        with client.atomic():                    # position first: its setter shifts look_at
            client.camera.position = position
            client.camera.look_at = look_at

    @staticmethod
    def overview_pose(tip_world_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(camera position, look-at point) of the overview, WORLD metres."""
        target = np.array([0.5 * float(tip_world_m[0]), 0.0, 0.45])
        return target + OVERVIEW_OFFSET_M, target

    # ------------------------------------------------------------ gizmo
    def _on_gizmo(self, event: Any) -> None:
        phase = getattr(event, "phase", "update")
        with self._drag_lock:
            self._drag_seq += 1
            seq = self._drag_seq
        if phase == "start":
            self._dragging = True
            return
        handle = event.target
        wxyz = np.asarray(handle.wxyz, dtype=float)
        xyz = np.asarray(handle.position, dtype=float)
        s = self.session

        @s.guard
        def move() -> None:
            if phase != "end" and seq != self._drag_seq:
                return                           # a newer drag event is queued: skip this one
            if phase == "end":
                self._dragging = False
            if not (np.all(np.isfinite(wxyz)) and np.all(np.isfinite(xyz))) or np.linalg.norm(wxyz) < 1e-9:
                self._snap_gizmo()
                return
            T = np.eye(4)
            T[:3, :3] = Rotation.from_quat(np.roll(wxyz, -1)).as_matrix()
            T[:3, 3] = xyz
            res = s.controller.move_tcp_to(T)
            pendant = s.views.get("pendant")
            if pendant is not None:
                pendant.show_jog_result(res)
            s.moved()
            if phase == "end":
                self._snap_gizmo()

        move()
