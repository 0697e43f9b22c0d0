"""The 3D scene of one session: robot, mounted tool, reference tip, floor, frames, gizmo.

Scene tree (names are per browser; ``--shared`` uses the server's scene):

* ``/floor`` grid; ``/world`` the WORLD frame (the robot's root link) with its label;
* ``/robot/<base>/<link_1>/.../<link_6>/<flange>``: one frame per URDF link, nested like the
  URDF's link tree (:attr:`SceneView.link_paths`), each posed relative to its parent link from
  pinocchio's link poses (``Session.pose_state()``, one FK pass per move; no yourdfpy FK),
  with the link's meshes as children. Nesting makes a jog step cheap to send: a revolute
  joint only turns its child link, so each moving link needs one orientation message (its
  offset from the parent never changes) and links on fixed joints (the flange) none;
  :class:`PoseSender` sends only poses that changed. The flange frame
  (:attr:`SceneView.flange_path`) holds the FLANGE triad, the mounted tool's meshes and the
  active TOOL triad at ``T_flange_tool``, which ride on the flange without updates;
* ``/reference_tip``: the stand posed so that its spike is at the reference tip;
* ``/beam_sensor``: the beam sensor's stand (a fork, emitter and receiver) with the beam(s) as
  thin bright lines (``views.beam_stand``), redrawn when ``controller.beam_sensor`` changes;
  a scan's replay (the broken beam in red, event markers) is ``views.beam_replay``'s ``/beam_scan``,
  during which the gizmo and the TOOL triad step aside;
The scene reconciles from the session's state: it subscribes to the session's change signal
(``Session.subscribe``) and, on a ``tool`` change, swaps the mounted tool's meshes and moves the
TOOL triad when they differ from what the session now has; on a ``pose`` change it poses the
links and the gizmo from the change's pose state. No other view tells it anything.

* ``/tcp_gizmo``: transform controls on the active TCP; dragging it moves the TCP by
  ``VirtualController.move_tcp_to`` (straight line, same safety rules as jogging), on viser's
  event loop (``SessionLoop.on_loop``), a backlog of drag messages coalesced into one move.

Axis colours are viser's: X red, Y green, Z blue. Quaternions (w, x, y, z) come from
``tcp_pendant.controller.rotations.quaternions_wxyz`` (pinocchio; checked against scipy).
"""

from __future__ import annotations

import asyncio
import logging
import math
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np
import viser
from scipy.spatial.transform import Rotation

from tcp_pendant.controller.tools import shown_tool_label
from tcp_pendant.controller import ToolModel, reference_tip_model
from tcp_pendant.controller.description import RobotDescription
from tcp_pendant.controller.kinematics import urdf_links_and_tree
from tcp_pendant.controller.rotations import quaternion_wxyz, quaternions_wxyz
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.views.beam_replay import ScanPlayer
from tcp_pendant.views.beam_stand import BeamStandNodes
from tcp_pendant.views.framing import VIEW_DIRECTION, Framing, frame_spheres
from tcp_pendant.views.meshes import MeshPart, link_meshes, rigid_meshes
from tcp_pendant.views.gui_util import target_of
from tcp_pendant.views.viser_adapter import pose_queue, queue_pose
from tcpcal.tool import Tool

if TYPE_CHECKING:
    from tcp_pendant.controller.pose_state import PoseState

__all__ = ["POSE_EPS", "PoseSender", "SceneView", "camera_shape", "closeup_camera", "frame_cameras",
           "link_tree_paths", "overview_camera", "overview_pose", "relative_poses", "tool_label_text", "wxyz_xyz"]

log = logging.getLogger(__name__)

OVERVIEW_OFFSET_M = np.array([1.15, -1.25, 0.55])
CLOSEUP_OFFSET_M = np.array([0.22, -0.26, 0.12])

POSE_EPS = 1e-6
"""A node's orientation (position) is re-sent when an entry of its rotation matrix (a
coordinate, m) changed by more than this since the last one sent: ~1e-6 rad (0.00006 deg)
and 1 um, a hundred times below what the pendant shows (0.01 mm, 0.01 deg) and below any
motion it commands (the smallest increment is 0.1 mm / 0.1 deg; continuous jog at 1 %
override moves 0.0025 mm / 0.015 deg per tick). Below it are float noise (the constant offset
of a revolute joint recomputed from two link poses) and the drift of an orientation held
during a translation jog. The error does not accumulate: it is measured against what was sent."""

_EYE4 = np.eye(4)
_EYE4.setflags(write=False)


def wxyz_xyz(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(w, x, y, z) quaternion and position of a (4,4) pose, or (N,4) and (N,3) of (N,4,4)."""
    T = np.asarray(T, dtype=float)
    q = quaternions_wxyz(T[..., :3, :3])
    return (q[0] if T.ndim == 2 else q), T[..., :3, 3]


def relative_poses(T_world_parent: np.ndarray, T_world_child: np.ndarray,
                   out: np.ndarray | None = None, work: np.ndarray | None = None, *,
                   bottom_rows_set: bool = False) -> np.ndarray:
    """``T_parent_child = inv(T_world_parent) @ T_world_child`` for stacks (N,4,4) of rigid
    poses: ``R_p^T [R_c | p_c - p_p]`` in one product, written into ``out`` ((N,4,4), e.g. a
    view of a buffer reused every jog step) when given, else into a new array; ``work`` is an
    (N,3,4) scratch buffer for ``[R_c | p_c - p_p]`` (the caller's, reused; else a new one).
    ``bottom_rows_set``: ``out``'s rows ``[:, 3]`` already hold ``(0, 0, 0, 1)`` and only this
    function writes them (the scene's buffer): not rewritten."""
    if out is None:
        out, bottom_rows_set = np.empty_like(T_world_child), False
    if work is None:
        work = np.empty((len(T_world_child), 3, 4))
    np.copyto(work, T_world_child[:, :3, :])
    offset = work[:, :, 3]
    np.subtract(offset, T_world_parent[:, :3, 3], out=offset)
    np.matmul(T_world_parent[:, :3, :3].transpose(0, 2, 1), work, out=out[:, :3, :])
    if not bottom_rows_set:
        out[:, 3, :] = (0.0, 0.0, 0.0, 1.0)
    return out


def _as_slice(rows: np.ndarray) -> slice | np.ndarray:
    """``rows`` as the slice ``a:b`` when they are ``a, a+1, ..., b-1`` (indexing with it gives a
    view, not a copy), else ``rows`` itself."""
    if len(rows) and np.array_equal(rows, np.arange(rows[0], rows[0] + len(rows))):
        return slice(int(rows[0]), int(rows[0]) + len(rows))
    return rows


def link_tree_paths(urdf_path: Path | RobotDescription, links: tuple[str, ...] | list[str]) -> dict[str, tuple[str, str | None]]:
    """Scene path and parent link of every link, nested like the URDF's link tree.

    Args:
        urdf_path: the robot's URDF (its link tree).
        links: the links to place.

    Returns:
        ``{link: (path, parent_link or None)}`` in parent-before-child order; links missing
        from the tree (or whose parent is not in ``links``) hang at ``/robot`` too.
    """
    names = set(links)
    _, children = urdf_links_and_tree(urdf_path)
    parent: dict[str, str] = {}
    for p, cs in children.items():
        for ch in cs:
            if p in names and ch in names:
                parent.setdefault(ch, p)
    out: dict[str, tuple[str, str | None]] = {}

    def place(name: str, seen: frozenset[str]) -> None:
        if name in out:
            return
        p = parent.get(name)
        if p is None or p in seen:
            out[name] = (f"/robot/{name.replace('/', '_')}", None)
            return
        place(p, seen | {name})
        out[name] = (f"{out[p][0]}/{name.replace('/', '_')}", p)

    for n in links:
        place(n, frozenset())
    return out


class PoseSender:
    """Poses a fixed list of scene nodes, sending only what changed (per-jog-step hot path).

    :meth:`send` takes every node's pose relative to its scene parent, compares it with the
    last one sent and queues a SetOrientation (SetPosition) message only for the nodes whose
    rotation (position) moved by more than :data:`POSE_EPS`. The comparison is one numpy pass
    over all nodes; quaternions are computed for the changed ones only. The messages are
    viser's own, queued as its public ``handle.wxyz = ...`` setters would, minus their
    per-call validation and ``allclose`` (4x the cost of the message here), by one
    ``views.viser_adapter.PoseQueue`` per node; the node's stored pose is updated too. Falls
    back to the public setters if viser's internals differ.

    Args:
        handles: scene node handles.
        T_parent_node: their current poses (as created), (N,4,4).
    """

    def __init__(self, handles: list[viser.SceneNodeHandle], T_parent_node: np.ndarray) -> None:
        self.handles = list(handles)
        self._sent = np.array(T_parent_node, dtype=float).reshape(len(self.handles), 4, 4)
        self._sent_rows = self._sent[:, :3, :]            # the compared part (a view, made once)
        self._queues = [pose_queue(h) for h in self.handles]   # None: viser differs, public setters
        self._diff = np.empty((len(self.handles), 3, 4))

    def send(self, T_parent_node: np.ndarray, *, skip: tuple[int, ...] = (), force: tuple[int, ...] = ()) -> int:
        """Queue the poses that changed.

        Args:
            T_parent_node: (N,4,4) new poses.
            skip: nodes not to touch (e.g. the gizmo while the browser drags it).
            force: nodes to send even if unchanged (e.g. the gizmo after a drag).

        Returns:
            The number of messages queued.
        """
        T = np.asarray(T_parent_node, dtype=float)
        d = self._diff
        np.subtract(T[:, :3, :], self._sent_rows, out=d)
        np.abs(d, out=d)
        # per node and column: did any entry move? columns 0-2 are the rotation, 3 the position
        moved = cast("list[list[bool]]", (d > POSE_EPS).any(axis=1).tolist())
        for i in force:
            moved[i] = [True] * 4
        for i in skip:
            moved[i] = [False] * 4
        n = 0
        for i, (c0, c1, c2, p) in enumerate(moved):
            r = c0 or c1 or c2
            if not (r or p):
                continue
            rows = T[i].tolist()                  # the node's pose as floats, one call
            sent = self._sent[i]
            if r and p:
                sent[:3] = T[i, :3]
            elif r:
                sent[:3, :3] = T[i, :3, :3]
            else:
                sent[:3, 3] = T[i, :3, 3]
            wxyz = quaternion_wxyz(rows) if r else None
            xyz = [rows[0][3], rows[1][3], rows[2][3]] if p else None
            q = self._queues[i]
            if q is None or not q(wxyz, xyz):
                _public_setters(self.handles[i], wxyz, xyz)
            n += int(r) + int(p)
        return n


def _set_pose(handle: viser.SceneNodeHandle, wxyz: list[float] | None, xyz: list[float] | None) -> int:
    """Send a node's orientation and/or position (``views.viser_adapter.queue_pose``; the public
    setters if viser's internals differ); returns how many messages."""
    if not queue_pose(handle, wxyz, xyz):
        _public_setters(handle, wxyz, xyz)
    return int(wxyz is not None) + int(xyz is not None)


def _public_setters(handle: viser.SceneNodeHandle, wxyz: list[float] | None, xyz: list[float] | None) -> None:
    if wxyz is not None:                     # viser's setters take any sequence of floats
        handle.wxyz = cast("tuple[float, float, float, float]", wxyz)
    if xyz is not None:
        handle.position = cast("tuple[float, float, float]", xyz)


def overview_pose(tip_world_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(camera position, look-at point) of the overview of the cell, WORLD metres."""
    target = np.array([0.5 * float(tip_world_m[0]), 0.0, 0.45])
    return target + OVERVIEW_OFFSET_M, target


def overview_camera(client: viser.ClientHandle, tip_world_m: np.ndarray) -> None:
    """One browser's camera on the whole cell."""
    position, look_at = overview_pose(tip_world_m)
    with client.atomic():                    # position first: its setter shifts look_at
        client.camera.position = position
        client.camera.look_at = look_at


def camera_shape(client: viser.ClientHandle) -> tuple[float, float, float]:
    """(fov rad, aspect, image height px) of a browser's camera; defaults before it reported."""
    try:
        cam = client.camera
        return float(cam.fov), float(cam.aspect), float(cam.image_height)
    except Exception:                    # no camera message from that browser yet
        return math.radians(50.0), 16.0 / 9.0, 720.0


def frame_cameras(clients: list[viser.ClientHandle], centres: np.ndarray, radii: np.ndarray,
                  direction: np.ndarray = VIEW_DIRECTION, margin: float = 1.15) -> Framing:
    """Frame each browser's camera on the spheres (``framing.frame_spheres`` with that camera's
    shape, ``direction`` and ``margin``). Returns the first browser's
    framing (a default camera's when there is none)."""
    framings = [frame_spheres(centres, radii, fov_rad=fov, aspect=aspect, image_height_px=height,
                              direction=direction, margin=margin)
                for fov, aspect, height in (camera_shape(c) for c in clients)]
    for client, f in zip(clients, framings):
        try:
            with client.atomic():        # position first: its setter shifts look_at
                client.camera.position = f.position
                client.camera.look_at = f.look_at
        except Exception:                # a browser that left, or has not sent its camera yet
            log.debug("camera of a client not framed", exc_info=True)
    return framings[0] if framings else frame_spheres(centres, radii, direction=direction, margin=margin)


def closeup_camera(client: viser.ClientHandle, tip_world_m: np.ndarray) -> None:
    """One browser's close-up camera on the reference tip (fine approach)."""
    tip = np.asarray(tip_world_m, dtype=float)
    with client.atomic():                    # position first: its setter shifts look_at
        client.camera.position = tip + CLOSEUP_OFFSET_M
        client.camera.look_at = tip


def _add_parts(scene: viser.SceneApi, parent: str, parts: tuple[MeshPart, ...], *,
               opacity: float | None = None) -> list[viser.MeshHandle]:
    out = []
    for i, p in enumerate(parts):
        out.append(scene.add_mesh_simple(f"{parent}/mesh_{i}", p.vertices, p.faces, color=p.rgb,
                                         flat_shading=False, opacity=opacity))
    return out


def tool_label_text(active: Tool | None, mounted: ToolModel, activated_on: ToolModel | None = None, *,
                    tr: Translator = ENGLISH) -> str:
    """The TOOL triad's label: the active tool data's name and, when the physical tool on the
    flange is another than the one that was on when the data was made active (a wizard bolted
    the new tool on while the reference tool's data is still active), the tool that is on now:
    the triad sits where that data puts the TCP, which on another tool is not its tip (the
    frame name TOOL and the names stay as they are in every language)."""
    if active is None:
        return "TOOL"
    if activated_on is None or activated_on.key == mounted.key:
        return f"TOOL {active.name}"
    return tr.gettext("TOOL {tool} · on {mounted}").format(tool=active.name, mounted=shown_tool_label(mounted.label, tr))


def reference_tip_label_text(tr: Translator = ENGLISH) -> str:
    """The reference tip's 3D label in ``tr``'s language."""
    return tr.gettext("reference tip")


class SceneView:
    """Builds and updates the scene of one session (see the module docstring).

    Args:
        session: the session; the scene is ``session.target.scene``.
    """

    def __init__(self, session: Session) -> None:
        self.session = session
        self.player: ScanPlayer | None = None
        """The session's scan film (set once the views are built): the scene steps aside while it plays."""
        c = session.controller
        scene = target_of(session).scene
        self.scene = scene
        k = c.kinematics
        self.flange_link = k.flange_link
        self._dragging = False
        self._aside = False                     # gizmo and TOOL triad hidden for a beam scan's film
        self._gizmo_pending: tuple[np.ndarray, np.ndarray] | None = None  # (wxyz, xyz) not yet applied
        self._gizmo_scheduled = False
        self._apply_scheduled_gizmo = session.loop.guard(self._apply_scheduled)

        scene.set_up_direction("+z")
        scene.add_grid("/floor", width=3.0, height=3.0, cell_size=0.1, section_size=0.5,
                       plane="xy", position=(0.0, 0.0, 0.0))
        scene.add_frame("/world", axes_length=0.25, axes_radius=0.006)
        self._world_label = scene.add_label("/world/label", "WORLD", position=(0.0, 0.0, -0.04))

        meshes = link_meshes(k.description)
        state = session.pose_state()
        tree = link_tree_paths(k.description, state.link_names)
        self.link_paths: dict[str, str] = {name: path for name, (path, _) in tree.items()}
        self.link_frames: dict[str, viser.FrameHandle] = {}
        self._parent = {name: parent for name, (_, parent) in tree.items()}
        # posed nodes: every link but the root (the sender skips those that did not move), then
        # the gizmo; rows of (node, parent) in [links..., T_world_tcp, identity] (render)
        self._moving = [n for n in tree if n != k.base_link]
        self._index_names: tuple[str, ...] = ()
        self._child_idx = self._parent_idx = self._out_rows = np.zeros(0, dtype=int)
        self._parent_rows: slice | np.ndarray = self._parent_idx
        self._child_rows: slice | np.ndarray = self._child_idx
        self._root_rows: list[tuple[int, int]] = []          # (row, link index) of links without a parent
        self._contiguous = True
        self._local_out = np.zeros((0, 4, 4))
        self._local_work = np.zeros((0, 3, 4))
        T_local = self._local_poses(state)
        local = {n: T_local[i] for i, n in enumerate(self._moving)}
        for name, (path, _) in tree.items():
            wxyz, xyz = wxyz_xyz(local.get(name, state.T_world_link[name]))
            self.link_frames[name] = scene.add_frame(path, show_axes=False, wxyz=wxyz, position=xyz)
            _add_parts(scene, path, meshes.get(name, ()))
        self.flange_path = self.link_paths[self.flange_link]
        fl = self.flange_path
        scene.add_frame(f"{fl}/flange_axes", axes_length=0.09, axes_radius=0.004)
        self._flange_label = scene.add_label(f"{fl}/flange_axes/label", "FLANGE", position=(0.0, 0.05, 0.0))
        self._tool_root = f"{fl}/tool"
        self._tool_frame: viser.FrameHandle | None = None
        self._shown_mounted: ToolModel | None = None
        self._shown_active: tuple[Tool | None, bytes, ToolModel] | None = None   # (active tool, T_flange_tool, mounted)
        self._data_on: ToolModel | None = None
        self.set_mounted_tool(c.mounted_tool)
        self._active_axes = scene.add_frame(f"{fl}/active_tool", axes_length=0.12, axes_radius=0.005)
        self._active_label = scene.add_label(f"{fl}/active_tool/label", "TOOL", position=(0.0, 0.0, 0.04))
        self.update_active_tool()

        tip = reference_tip_model()
        wxyz, xyz = wxyz_xyz(tip.T_world_stand(c.reference_tip_world_m))
        self._tip_frame = scene.add_frame("/reference_tip", show_axes=False, wxyz=wxyz, position=xyz)
        self._shown_tip = np.array(c.reference_tip_world_m, dtype=float)
        self._shown_tip_bytes = self._shown_tip.tobytes()
        _add_parts(scene, "/reference_tip", rigid_meshes(tip.urdf_path))
        self._tip_label = scene.add_label("/reference_tip_label", reference_tip_label_text(session.translator),
                                          position=tuple(c.reference_tip_world_m + [0.0, 0.0, -0.06]))
        labels = session.views.labels                       # the wizards' scene moves them apart
        labels.flange, labels.tool, labels.tip = self._flange_label, self._active_label, self._tip_label
        labels.world = self._world_label                    # restyled with them (presenter mode)
        self.beam_stand = BeamStandNodes(scene, c.beam_sensor, tr=session.translator)

        wxyz, xyz = wxyz_xyz(state.T_world_tcp)
        self.gizmo = scene.add_transform_controls("/tcp_gizmo", scale=0.14, line_width=2.0, wxyz=wxyz,
                                                  position=xyz, depth_test=False, opacity=0.85)
        self._gizmo_row = len(self._moving)
        self._poses = PoseSender([self.link_frames[n] for n in self._moving] + [self.gizmo], T_local)
        self.gizmo.on_update(session.loop.on_loop(self._on_gizmo))
        session.subscribe(self.on_change)

    def on_change(self, change: SessionChange) -> None:
        """The change signal: reconcile the tool meshes and the TOOL triad (``tool``), pose the
        links and the gizmo (``pose``), from the session's state; a ``language`` change relabels
        the TOOL triad and the reference tip."""
        if change.language:
            self._tip_label.text = reference_tip_label_text(self.session.translator)
            self.update_active_tool()
        if change.tool:
            self.reconcile_tools()
        c = self.session.controller
        if c.reference_tip_world_m.tobytes() != self._shown_tip_bytes:
            self.update_reference_tip()                   # knocked (a scenario) or set anew
        self.beam_stand.show(c.beam_sensor, tr=self.session.translator)   # redraws only a changed sensor
        film = self.player
        self._step_aside(film is not None and film.playing)
        if change.pose and change.state is not None:
            skip = (self._gizmo_row,) if self._dragging else ()
            self._poses.send(self._local_poses(change.state), skip=skip)

    def reconcile_tools(self) -> None:
        """Show the session's mounted tool and active TOOL frame if they are not shown yet."""
        c = self.session.controller
        if c.mounted_tool is not self._shown_mounted:
            self.set_mounted_tool(c.mounted_tool)
        if self._shown_active != (c.active_tool, c.T_flange_tool.tobytes(), c.mounted_tool):
            self.update_active_tool()

    # ------------------------------------------------------------ updates
    def _local_poses(self, state: PoseState) -> np.ndarray:
        """(N+1,4,4): ``T_parent_link`` of the moving links (``T_world_link`` for a link
        without a parent), then ``T_world_tcp`` (the gizmo), from one pose state
        (:func:`relative_poses`, batched into a buffer reused by the next call:
        :class:`PoseSender` copies what it sends). Parent and child rows that are runs of
        consecutive links (a serial arm in pinocchio's order: parent = child - 1) are read as
        slices, views of the state's stacked poses, instead of fancy-indexed copies."""
        if state.link_names != self._index_names:             # index rows once per link list
            row = {n: i for i, n in enumerate(state.link_names)}
            with_parent = [i for i, n in enumerate(self._moving) if self._parent[n] is not None]
            self._out_rows = np.array(with_parent, dtype=int)
            self._child_idx = np.array([row[self._moving[i]] for i in with_parent], dtype=int)
            self._parent_idx = np.array([row[cast(str, self._parent[self._moving[i]])] for i in with_parent],
                                        dtype=int)
            self._parent_rows = _as_slice(self._parent_idx)
            self._child_rows = _as_slice(self._child_idx)
            self._root_rows = [(i, row[n]) for i, n in enumerate(self._moving) if self._parent[n] is None]
            self._contiguous = with_parent == list(range(len(with_parent)))
            self._local_out = np.zeros((len(self._moving) + 1, 4, 4))
            self._local_out[:, 3, 3] = 1.0            # rigid poses' bottom rows, never written again
            self._local_work = np.empty((len(self._child_idx), 3, 4))
            self._index_names = state.link_names
        out = self._local_out
        W = state.T_world_links
        P = W[self._parent_rows]
        C = W[self._child_rows]
        if self._contiguous:                                  # a tree without loose links: in place
            relative_poses(P, C, out=out[:len(self._child_idx)], work=self._local_work, bottom_rows_set=True)
        else:
            out[self._out_rows] = relative_poses(P, C, work=self._local_work)
        for i, j in self._root_rows:
            out[i] = W[j]
        out[-1] = state.T_world_tcp
        return out

    def render(self) -> None:
        """Pose the moving link frames and the gizmo on the TCP (not while dragged) from the
        session's pose state; only poses that changed are sent."""
        skip = (self._gizmo_row,) if self._dragging else ()
        self._poses.send(self._local_poses(self.session.pose_state()), skip=skip)

    def _snap_gizmo(self) -> None:
        # the browser moved the gizmo: always resend its pose
        self._poses.send(self._local_poses(self.session.pose_state()), force=(self._gizmo_row,))

    def set_mounted_tool(self, tool: ToolModel) -> None:
        """Show another physical tool on the flange (:meth:`reconcile_tools` calls it)."""
        self._shown_mounted = tool
        if self._tool_frame is not None:
            self._tool_frame.remove()
        self._tool_frame = self.scene.add_frame(self._tool_root, show_axes=False)
        _add_parts(self.scene, self._tool_root, rigid_meshes(tool.urdf_path))

    def _step_aside(self, aside: bool) -> None:
        """While a beam scan's film plays (``views.beam_replay``) the TCP gizmo and the TOOL
        triad on the tool are hidden: they sit where the tool meets the beam and would hide it
        and its break; the film's end (a ``pose`` change) shows them again."""
        if aside == self._aside:
            return
        self._aside = aside
        self.gizmo.visible = not aside
        self._active_axes.visible = not aside and self.session.controller.active_tool is not None
        self._active_label.visible = not aside

    def update_active_tool(self) -> None:
        """Move the TOOL triad to the active tool data (``T_flange_tool``) and relabel it."""
        c = self.session.controller
        self._data_on = c.active_data_mounted_on    # the controller's: a view built later knows it too
        self._shown_active = (c.active_tool, c.T_flange_tool.tobytes(), c.mounted_tool)
        wxyz, xyz = wxyz_xyz(c.T_flange_tool)
        self._active_axes.wxyz = wxyz
        self._active_axes.position = xyz
        tool = c.active_tool
        self._active_axes.visible = tool is not None and not self._aside   # no tool data: TOOL = FLANGE
        text = tool_label_text(tool, c.mounted_tool, self._data_on, tr=self.session.translator)
        if self._active_label.text != text:
            self._active_label.text = text

    def update_reference_tip(self) -> None:
        """Re-place the stand after the reference tip moved (:meth:`on_change` calls it)."""
        c = self.session.controller
        self._shown_tip = np.array(c.reference_tip_world_m, dtype=float)
        self._shown_tip_bytes = self._shown_tip.tobytes()
        wxyz, xyz = wxyz_xyz(reference_tip_model().T_world_stand(c.reference_tip_world_m))
        self._tip_frame.wxyz = wxyz
        self._tip_frame.position = xyz
        self._tip_label.position = tuple(c.reference_tip_world_m + [0.0, 0.0, -0.06])

    def tool_labels(self) -> dict[str, viser.LabelHandle]:
        """The labels at the tool and the tip: FLANGE (in the flange frame), TOOL (in the active
        TOOL frame), "reference tip" (WORLD); the wizards' scene places them apart after a result."""
        return {"flange": self._flange_label, "tool": self._active_label, "tip": self._tip_label}

    # ------------------------------------------------------------ camera
    def look_at_tip(self, client: viser.ClientHandle) -> None:
        """Close-up camera on the reference tip (fine approach) for one browser."""
        closeup_camera(client, self.session.controller.reference_tip_world_m)

    def overview(self, client: viser.ClientHandle) -> None:
        """Camera on the whole cell."""
        overview_camera(client, self.session.controller.reference_tip_world_m)

    overview_pose = staticmethod(overview_pose)

    # ------------------------------------------------------------ gizmo
    def _on_gizmo(self, event: viser.TransformControlsEvent) -> None:
        """A drag of the gizmo (on viser's event loop, under the session guard).

        Drag updates are coalesced: the first one queues a move with ``call_soon``, which runs
        after the messages viser has already received; the later ones only replace the pose
        that move will use, so a backlog of drag messages costs one IK solve, towards the
        newest pose. The end of a drag applies its pose at once and snaps the gizmo back onto
        the TCP (where the robot could follow)."""
        phase = getattr(event, "phase", "update")
        if phase == "start":
            self._dragging = True
            return
        handle = event.target
        self._gizmo_pending = (np.asarray(handle.wxyz, dtype=float), np.asarray(handle.position, dtype=float))
        if phase == "end":
            self._dragging = False
            self._apply_gizmo()
            self._snap_gizmo()
            return
        if self._gizmo_scheduled:
            return
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:                     # called off the loop (a test): move now
            self._apply_gizmo()
            return
        self._gizmo_scheduled = True
        loop.call_soon(self._apply_scheduled_gizmo)

    def _apply_scheduled(self) -> None:
        self._gizmo_scheduled = False
        self._apply_gizmo()

    def _apply_gizmo(self) -> None:
        """Move the TCP to the newest dragged pose (WORLD, m), if one is pending."""
        pending, self._gizmo_pending = self._gizmo_pending, None
        if pending is None:
            return
        wxyz, xyz = pending
        if not (np.all(np.isfinite(wxyz)) and np.all(np.isfinite(xyz))) or np.linalg.norm(wxyz) < 1e-9:
            self._snap_gizmo()
            return
        s = self.session
        T = np.eye(4)
        T[:3, :3] = Rotation.from_quat(np.roll(wxyz, -1)).as_matrix()
        T[:3, 3] = xyz
        s.motion.move_tcp_to(T)
