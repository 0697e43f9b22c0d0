"""The scene and pose-state part of a jog step as it was before the per-step speed work on it:
the yardstick of ``bench_scene_step.py`` (the new code must send the same poses, the same
messages, and build the same pose state).

``legacy_pose_state`` is ``tcp_pendant.controller.pose_state.pose_state`` of that version (a
dict of ``.homogeneous`` per link, stacked, a dict of views, numpy touch geometry) and
``legacy_pose_state_key`` its key (through the controller's copying properties);
:class:`LegacyScenePoses` is ``SceneView.on_change`` with its ``_local_poses`` (fancy-indexed
parent and child rows, ``relative_poses``) and ``PoseSender.send`` (a pinocchio quaternion per
moved node, viser's messages through ``_queue_scene_message``) as they were, its default beam
sensor lookup's ``np.array_equal`` of the reference tip included. Not used by the app.
"""

from __future__ import annotations

import math
import typing
from typing import Any, cast

import numpy as np
import pinocchio as pin

from tcp_pendant.controller.controller import VirtualController
from tcp_pendant.controller.pose_state import PoseState
from tcp_pendant.controller.touch import (
    CRASH_DEPTH_MM,
    CRASH_RADIUS_MM,
    CRASH_ZONE_DEPTH_MM,
    TOUCH_TOLERANCE_MM,
    TouchGeometry,
)

__all__ = ["LegacyScenePoses", "legacy_pose_state", "legacy_pose_state_key", "legacy_quaternion_wxyz",
           "legacy_touch_geometry"]

POSE_EPS = 1e-6


def legacy_touch_geometry(T_world_tooltrue: np.ndarray, tip_world_m: np.ndarray) -> TouchGeometry:
    T = np.asarray(T_world_tooltrue, dtype=float)
    u_mm = T[:3, :3].T @ (np.asarray(tip_world_m, dtype=float) - T[:3, 3]) * 1000.0
    distance = math.hypot(*u_mm.tolist())
    rho = math.hypot(float(u_mm[1]), float(u_mm[2]))
    depth = -float(u_mm[0])
    penetration = depth if (depth > 0.0 and rho <= CRASH_RADIUS_MM and depth <= CRASH_ZONE_DEPTH_MM) else 0.0
    return TouchGeometry(distance_mm=distance, touching=distance <= TOUCH_TOLERANCE_MM,
                         crashed=penetration > CRASH_DEPTH_MM, penetration_mm=penetration)


def legacy_pose_state_key(controller: VirtualController) -> tuple[object, ...]:
    c = controller
    return (id(c.kinematics), c.q_rad.tobytes(), c.T_flange_tool.tobytes(), id(c.mounted_tool),
            c.reference_tip_world_m.tobytes(), c.T_world_base.tobytes(), id(c.true_kinematics))


def legacy_pose_state(controller: VirtualController, key: tuple[object, ...] | None = None) -> PoseState:
    c = controller
    k = c.kinematics
    q = c.q_rad
    pin.framesForwardKinematics(k.model, k.data, q)
    oMf = k.data.oMf
    poses = {name: oMf[i].homogeneous for name, i in k._body_frames}
    names = tuple(poses)
    stacked = np.array(list(poses.values()))
    stacked.setflags(write=False)
    links = dict(zip(names, stacked))
    T_world_flange = links[k.flange_link]
    T_world_tcp = T_world_flange @ c.T_flange_tool
    T_true_flange = T_world_flange if c.true_kinematics is k else c.T_world_flange_true()
    T_world_true = T_true_flange @ c.mounted_tool.T_flange_tool_true
    angles = {name: (math.degrees(v) if revolute else v * 1000.0)
              for name, v, revolute in zip(k.joint_names, q.tolist(), k.revolute.tolist())}
    for T in (T_world_tcp, T_world_true):
        T.setflags(write=False)
    return PoseState(
        key=legacy_pose_state_key(c) if key is None else key,
        q_rad=q,
        link_names=names,
        T_world_links=stacked,
        T_world_link=links,
        T_world_flange=T_world_flange,
        T_world_tcp=T_world_tcp,
        T_world_tool_true=T_world_true,
        T_world_base=c.T_world_base,
        joint_angles_deg=angles,
        touch=legacy_touch_geometry(T_world_true, c.reference_tip_world_m),
    )


def legacy_quaternion_wxyz(R: np.ndarray) -> list[float]:
    x, y, z, w = pin.Quaternion(np.ascontiguousarray(R, dtype=float)).coeffs().tolist()
    return [w, x, y, z]


def _legacy_relative_poses(T_world_parent: np.ndarray, T_world_child: np.ndarray,
                           out: np.ndarray | None = None) -> np.ndarray:
    if out is None:
        out = np.empty_like(T_world_child)
    Rp_T = T_world_parent[:, :3, :3].transpose(0, 2, 1)
    np.matmul(Rp_T, T_world_child[:, :3, :3], out=out[:, :3, :3])
    np.matmul(Rp_T, (T_world_child[:, :3, 3] - T_world_parent[:, :3, 3])[..., None], out=out[:, :3, 3:])
    out[:, 3, :] = (0.0, 0.0, 0.0, 1.0)
    return out


def _legacy_queue_pose(handle: Any, wxyz: list[float] | None, xyz: list[float] | None) -> None:
    from viser import _messages

    impl = handle._impl
    api = impl.api
    if wxyz is not None:
        impl.wxyz[:] = wxyz
        api._queue_scene_message(_messages.SetOrientationMessage(
            impl.name, typing.cast("tuple[float, float, float, float]", tuple(wxyz))))
    if xyz is not None:
        impl.position[:] = xyz
        api._queue_scene_message(_messages.SetPositionMessage(
            impl.name, typing.cast("tuple[float, float, float]", tuple(xyz))))


class LegacyScenePoses:
    """``SceneView.on_change`` as it was, on a built ``SceneView`` (its handles, link tree and
    last sent poses: :meth:`take_sent` / :meth:`give_sent` hand those over between the two)."""

    def __init__(self, scene: Any) -> None:
        self.scene = scene
        self.handles = list(scene._poses.handles)
        self._sent = np.array(scene._poses._sent, dtype=float)
        self._diff = np.empty((len(self.handles), 3, 4))
        self._index_names: tuple[str, ...] = ()
        self._moving = list(scene._moving)
        self._parent = dict(scene._parent)
        self._beam_tip = scene.session.controller.reference_tip_world_m

    def take_sent(self) -> None:
        """Start from what the app's sender sent last."""
        self._sent[:] = self.scene._poses._sent

    def give_sent(self) -> None:
        """Hand what this one sent back to the app's sender."""
        self.scene._poses._sent[:] = self._sent

    def on_change(self, change: Any) -> None:
        sv = self.scene
        if change.tool:
            sv.reconcile_tools()
        if sv.session.controller.reference_tip_world_m.tobytes() != sv._shown_tip_bytes:
            sv.update_reference_tip()
        c = sv.session.controller
        if not np.array_equal(self._beam_tip, c._tip):     # the old lookup's compare (then the new one's)
            self._beam_tip = c._tip.copy()
        sv.beam_stand.show(c.beam_sensor)
        film = sv.player
        sv._step_aside(film is not None and film.playing)
        if change.pose and change.state is not None:
            skip = (sv._gizmo_row,) if sv._dragging else ()
            self.send(self._local_poses(change.state), skip=skip)

    def _local_poses(self, state: Any) -> np.ndarray:
        if state.link_names != self._index_names:
            row = {n: i for i, n in enumerate(state.link_names)}
            with_parent = [i for i, n in enumerate(self._moving) if self._parent[n] is not None]
            self._out_rows = np.array(with_parent, dtype=int)
            self._child_idx = np.array([row[self._moving[i]] for i in with_parent], dtype=int)
            self._parent_idx = np.array([row[cast(str, self._parent[self._moving[i]])] for i in with_parent],
                                        dtype=int)
            self._root_rows = [(i, row[n]) for i, n in enumerate(self._moving) if self._parent[n] is None]
            self._contiguous = with_parent == list(range(len(with_parent)))
            self._local_out = np.zeros((len(self._moving) + 1, 4, 4))
            self._index_names = state.link_names
        out = self._local_out
        W = state.T_world_links
        P = W[self._parent_idx]
        C = W[self._child_idx]
        if self._contiguous:
            _legacy_relative_poses(P, C, out=out[:len(self._child_idx)])
        else:
            out[self._out_rows] = _legacy_relative_poses(P, C)
        for i, j in self._root_rows:
            out[i] = W[j]
        out[-1] = state.T_world_tcp
        return out

    def send(self, T_parent_node: np.ndarray, *, skip: tuple[int, ...] = (), force: tuple[int, ...] = ()) -> int:
        T = np.asarray(T_parent_node, dtype=float)
        d = self._diff
        np.subtract(T[:, :3, :], self._sent[:, :3, :], out=d)
        np.abs(d, out=d)
        moved = cast("list[list[bool]]", (d > POSE_EPS).any(axis=1).tolist())
        for i in force:
            moved[i] = [True] * 4
        for i in skip:
            moved[i] = [False] * 4
        n = 0
        xyz: list[list[float]] | None = None
        for i, (c0, c1, c2, p) in enumerate(moved):
            r = c0 or c1 or c2
            if not (r or p):
                continue
            sent = self._sent[i]
            wxyz = None
            if r:
                R = T[i, :3, :3]
                wxyz = legacy_quaternion_wxyz(R)
                sent[:3, :3] = R
            if p and xyz is None:
                xyz = T[:, :3, 3].tolist()
            _legacy_queue_pose(self.handles[i], wxyz, xyz[i] if p and xyz is not None else None)
            n += int(wxyz is not None) + int(p)
            if p:
                sent[:3, 3] = T[i, :3, 3]
        return n
