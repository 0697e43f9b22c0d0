"""What the calibration wizards draw in the 3D scene of one session.

* ``/calibration/computed_tool``: the computed TOOL frame of the result, a triad at the
  computed TCP, labelled "COMPUTED";
* ``/calibration/true_tool``: training mode, after a result: the hidden true TOOL frame as
  a thin, longer "ghost" triad labelled "TRUE", so the two can be compared by eye;
* ``/calibration/sphere`` (4-point result): the fitted sphere, centre the reference point ``r``
  and radius ``|t|`` (4P-1a), with the flange origins ``f_i`` on it (``flange_points``, red for
  outliers, grey for dropped touches) and each touch's approach direction, the line from
  ``f_i`` to ``r`` along the tool (``approach``);
* ``/calibration/abc_target`` (ABC world wizard, or any wizard whose
  ``scene_target_T_world_tool_m`` gives a pose): the prescribed orientation (PA-1) drawn at
  the TCP, updated on every move, for the operator to align the tool with.

* the "Automatic (beam)" wizard's result (a result with a ``scan``): the scan replayed on the
  robot (``views.beam_replay.ScanPlayer``: the robot goes through the scan's moves, the beam
  red at each event, a marker where each event met the beam), then the robot stays at the
  scan's end; "Replay scan" (result panel) plays it again. The camera frames the events, the
  flange poses at the events and the sensor.

Scene units are metres (the wizards' results are in mm and converted here). Axis colours are
viser's: X red, Y green, Z blue.

After a new result (Finish, a recomputation, a resumed or loaded result) the camera of the
session's browser(s) is framed on it (``views.framing``: the fitted sphere, the flange
positions, the TOOL triads, the flange and the reference tip fill the view) and the labels
near the tip (COMPUTED, TRUE, TOOL, FLANGE, "reference tip") are moved apart as seen from that
camera; they go back to their places when the result is gone.

The two TOOL triads are posed in WORLD (``T_world_flange @ T_flange_tool``) after every move,
like the TCP gizmo, rather than hung under the flange's scene node: in the browser, nodes
created hidden under the flange node were seen (once in several runs) drawn with their labels
at the WORLD origin, not at the tool. Their labels are shown and hidden with them.
"""

from __future__ import annotations

import logging
import math
from typing import cast

import numpy as np
import viser

from tcp_pendant.calibrate import CalibrationWorkflow
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.session_views import SceneLabel
from tcp_pendant.controller.words import Words
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.views.beam_replay import ScanPlayer, beam_view_direction, scan_spheres
from tcp_pendant.views.framing import VIEW_DIRECTION, Framing, spread_labels
from tcp_pendant.views.scene import frame_cameras, wxyz_xyz
from tcp_pendant.wizards import WizardResult, Xyz4Result
from tcp_pendant.views.gui_util import clients_of, target_of

__all__ = ["WizardSceneView", "computed_label_text", "target_label_text", "true_label_text"]

log = logging.getLogger(__name__)
MM_TO_M = 1e-3
_LABEL_TEXTS = {"computed": "COMPUTED", "true": "TRUE", "target": "TARGET (X down)", "tool": "TOOL",
                "tip": "reference tip", "flange": "FLANGE"}
_POINT_RGB = np.array([30, 30, 30], dtype=np.uint8)
_OUTLIER_RGB = np.array([220, 30, 30], dtype=np.uint8)
_DROPPED_RGB = np.array([170, 170, 170], dtype=np.uint8)
_APPROACH_RGB = np.array([60, 110, 220], dtype=np.uint8)


def computed_label_text(tr: Translator = ENGLISH) -> str:
    """The computed TOOL triad's 3D label."""
    return tr.gettext("COMPUTED")


def true_label_text(tr: Translator = ENGLISH) -> str:
    """The true tool's ghost triad's 3D label (shown only where the truth may be shown)."""
    return tr.gettext("TRUE")


def target_label_text(tr: Translator = ENGLISH) -> str:
    """The ABC wizard's target frame's 3D label (X is the frame's axis name)."""
    return tr.gettext("TARGET (X down)")


class WizardSceneView:
    """The wizards' scene nodes of one session (see the module docstring); all start hidden."""

    def __init__(self, session: Session, workflow: CalibrationWorkflow, player: ScanPlayer) -> None:
        self.session = session
        self.workflow = workflow
        self.player = player
        scene = target_of(session).scene
        self.scene = scene
        self.computed = scene.add_frame("/calibration/computed_tool", axes_length=0.10, axes_radius=0.0045,
                                        visible=False)
        tr = session.translator
        self.computed_label = scene.add_label("/calibration/computed_tool/label", computed_label_text(tr),
                                              position=(0.0, 0.0, -0.03), visible=False)
        self.true_tool = scene.add_frame("/calibration/true_tool", axes_length=0.16, axes_radius=0.0015,
                                         origin_color=(245, 245, 245), visible=False)
        self.true_label = scene.add_label("/calibration/true_tool/label", true_label_text(tr), position=(0.0, -0.03, 0.0),
                                          visible=False)
        self.sphere = scene.add_icosphere("/calibration/sphere", radius=1.0, color=(90, 140, 230),
                                          subdivisions=3, wireframe=True, opacity=0.35, visible=False,
                                          cast_shadow=False, receive_shadow=False)
        self.abc_target = scene.add_frame("/calibration/abc_target", axes_length=0.13, axes_radius=0.003,
                                          origin_color=(255, 255, 255), visible=False)
        self.abc_label = scene.add_label("/calibration/abc_target/label", target_label_text(tr),
                                         position=(0.0, 0.03, 0.0), visible=False)
        self._points: viser.PointCloudHandle | None = None
        self._lines: viser.LineSegmentsHandle | None = None
        self._shown_result: WizardResult | None = None
        self._T_flange_computed: np.ndarray | None = None
        self._T_flange_tool_true: np.ndarray | None = None
        self.last_framing: Framing | None = None
        """The camera framing of the last result (None before one), for tests."""
        self._label_defaults: dict[str, tuple[SceneLabel, tuple[float, float, float]]] = {}
        self._labels_moved = False
        self._target_T: np.ndarray | None = None
        self._camera_watched: set[int] = set()
        self._relayout = session.loop.on_loop(self._on_camera)
        # in the session's labels too, so a view that restyles the scene's labels (presenter
        # mode: larger) reaches these; the boxes are spread at the size they are drawn
        labels = session.views.labels
        labels.computed, labels.true, labels.target = self.computed_label, self.true_label, self.abc_label
        session.subscribe(self.on_change)

    def on_change(self, change: SessionChange) -> None:
        """A ``language`` change relabels the triads and the ABC target; labels moved apart for
        a result are moved apart again (their boxes' widths changed with the words)."""
        if change.language:
            tr = self.session.translator
            for label, text in ((self.computed_label, computed_label_text(tr)), (self.true_label, true_label_text(tr)),
                                (self.abc_label, target_label_text(tr))):
                if label.text != text:
                    label.text = text
            if self._labels_moved:
                self.layout_labels()

    # ------------------------------------------------------------ result
    def _has_sphere(self) -> bool:
        """The wizard on show draws its result's sphere fit (``Wizard.result_extras``)."""
        wiz = self.workflow.wizard
        return wiz is not None and "sphere" in type(wiz).result_extras

    def render(self) -> None:
        """Show what belongs to the workflow's current state (call after every action)."""
        wf = self.workflow
        self._T_flange_computed = wf.T_flange_tool_computed_m()
        # an exercise (classroom: ``hide_truth``) shows no TRUE triad: it would give the answer
        self._T_flange_tool_true = None if wf.hide_truth else wf.T_flange_tool_true_m()
        res = wf.result
        framed: Framing | None = None
        if res is not self._shown_result:
            self._shown_result = res
            self._show_sphere(cast(Xyz4Result, res) if res is not None and self._has_sphere() else None)
            self._show_scan(res)
            if res is not None:
                framed = self.frame_result()
        self.on_motion()
        if self.workflow.is_open or res is not None:
            # just framed: the browsers' cameras still report the old view, so the labels are
            # moved apart for the new one (the next camera report re-lays them: _on_camera)
            self._place_labels(framed) if framed is not None else self.layout_labels()
        else:
            self._restore_labels()

    def _show_scan(self, res: WizardResult | None) -> None:
        """A beam result: replay its scan (its markers stay); otherwise clear our replay."""
        player = self.player
        scan = getattr(res, "scan", None)
        if scan is None:
            player.clear(owner=self)
        else:
            player.play(scan, owner=self, points=self._scan_points(res))

    @staticmethod
    def _scan_points(res: WizardResult | None) -> np.ndarray | None:
        """The markers' points: the scan's own (where the physical tool met the beam) when it
        has them, else (a stored scan) where the result's tool met it."""
        points_of = getattr(res, "event_points_world_m", None)          # a beam result's
        if callable(getattr(getattr(res, "scan", None), "tip_world_m", None)) or not callable(points_of):
            return None
        return np.asarray(points_of(), dtype=float).reshape(-1, 3)

    def replay_scan(self) -> None:
        """"Replay scan": the result's scan again, from its first move."""
        scan = getattr(self.workflow.result, "scan", None)
        if scan is None:
            raise ValueError(Words(N_("This result has no beam scan to replay.")))
        self.player.play(scan, owner=self, points=self._scan_points(self.workflow.result))

    @property
    def showing(self) -> bool:
        """Something of the wizards is in the scene (the triads, the ABC target, a beam result's
        film or markers)."""
        return bool(self.computed.visible or self.true_tool.visible or self.abc_target.visible
                    or self._film_playing())

    def _film_playing(self) -> bool:
        """Our beam scan's film is playing (its end re-renders: ``Session.refresh``)."""
        film = self.player
        return film.owner is self and film.playing

    def on_motion(self) -> None:
        """After every move: the TOOL triads follow the flange, the ABC target the TCP. While a
        beam result's film plays the triads are hidden: on the tool they would hide the beam
        (a triad's axis can lie along it) and its break."""
        T_world_flange = self.session.pose_state().T_world_flange   # the move's one FK pass
        film = self._film_playing()
        for frame, label, T in ((self.computed, self.computed_label, self._T_flange_computed),
                                (self.true_tool, self.true_label, self._T_flange_tool_true)):
            self._pose(frame, label, None if T is None or film else T_world_flange @ T)
        self.update_abc_target(T_world_flange)
        if self._target_T is not None:      # ABC world: TARGET, TOOL and the tip cluster at the TCP
            self.layout_labels()

    @staticmethod
    def _pose(handle: viser.FrameHandle, label: viser.LabelHandle | None, T: np.ndarray | None) -> None:
        if T is None:
            handle.visible = False
            if label is not None:
                label.visible = False
            return
        wxyz, xyz = wxyz_xyz(T)
        handle.wxyz = wxyz
        handle.position = xyz
        handle.visible = True
        if label is not None:
            label.visible = True

    def _show_sphere(self, res: Xyz4Result | None) -> None:
        for h in (self._points, self._lines):
            if h is not None:
                h.remove()
        self._points = self._lines = None
        if res is None:
            self.sphere.visible = False
            return
        centre_m = np.asarray(res.sphere_centre_mm, dtype=float) * MM_TO_M
        self.sphere.position = centre_m
        self.sphere.scale = max(res.sphere_radius_mm * MM_TO_M, 1e-4)   # unit icosphere, scaled
        self.sphere.visible = True
        f_m = np.asarray(res.flange_positions_mm, dtype=float) * MM_TO_M
        colors = np.tile(_POINT_RGB, (len(f_m), 1))
        colors[list(res.excluded)] = _DROPPED_RGB
        colors[list(res.outliers)] = _OUTLIER_RGB
        self._points = self.scene.add_point_cloud("/calibration/flange_points", points=f_m, colors=colors,
                                                  point_size=0.012, point_shape="circle")
        ends = f_m + np.asarray(res.approach_directions_world, dtype=float) * res.sphere_radius_mm * MM_TO_M
        segs = np.stack([f_m, ends], axis=1)
        seg_colors = np.repeat(np.where(np.isin(np.arange(len(f_m)), res.outliers)[:, None],
                                        _OUTLIER_RGB, _APPROACH_RGB)[:, None, :], 2, axis=1)
        self._lines = self.scene.add_line_segments("/calibration/approach", points=segs, colors=seg_colors,
                                                   thickness=0.003)

    # ------------------------------------------------------------ camera and labels
    def _label_nodes(self) -> dict[str, tuple[SceneLabel, np.ndarray | None]]:
        """Label name -> (handle, T_world_parent now; None: the label is in WORLD), visible ones."""
        T_wf = self.session.pose_state().T_world_flange
        out: dict[str, tuple[SceneLabel, np.ndarray | None]] = {}
        film = self._film_playing()                 # the triads and their labels step aside
        if self._T_flange_computed is not None and not film:
            out["computed"] = (self.computed_label, T_wf @ self._T_flange_computed)
        if self._T_flange_tool_true is not None and not film:
            out["true"] = (self.true_label, T_wf @ self._T_flange_tool_true)
        others = self.session.views.labels          # the robot scene's labels at the tool and tip
        if others.tool is not None and self.session.controller.active_tool is not None:
            out["tool"] = (others.tool, T_wf @ np.asarray(self.session.controller.T_flange_tool, dtype=float))
        if others.tip is not None:
            out["tip"] = (others.tip, None)
        if others.flange is not None:
            out["flange"] = (others.flange, T_wf)
        if self._target_T is not None:
            out["target"] = (self.abc_label, self._target_T)
        for name, (handle, _) in out.items():
            if name not in self._label_defaults:
                x, y, z = (float(v) for v in np.asarray(handle.position))
                self._label_defaults[name] = (handle, (x, y, z))
        return out

    def _restore_labels(self) -> None:
        if not self._labels_moved:
            return
        for name, (handle, position) in self._label_defaults.items():
            if name == "tip":           # the scene view re-places it when the tip moves
                position = tuple(np.asarray(self.session.controller.reference_tip_world_m) + [0.0, 0.0, -0.06])
            handle.position = position
        self._labels_moved = False

    def _framed_geometry(self) -> tuple[np.ndarray, np.ndarray]:
        """(centres, radii) in WORLD m: the sphere and flange positions of a 4-point result,
        the TOOL triads (their axis lengths), the flange and the reference tip."""
        T_wf = self.session.pose_state().T_world_flange
        scan = getattr(self._shown_result, "scan", None)
        if scan is not None and len(scan.events):   # a beam scan: its events and the sensor, not the tip
            T_wf = np.asarray(scan.events[-1].T_world_flange, dtype=float)   # where the film ends
            c, r = scan_spheres(scan, self._scan_points(self._shown_result))
            centres, radii = list(c), list(r)
        else:
            centres = [T_wf[:3, 3], np.asarray(self.session.controller.reference_tip_world_m, dtype=float)]
            radii = [0.09, 0.02]
        for T, length in ((self._T_flange_computed, 0.10), (self._T_flange_tool_true, 0.16)):
            if T is not None:
                centres.append((T_wf @ T)[:3, 3])
                radii.append(length)
        res = cast(Xyz4Result | None, self._shown_result)   # the sphere's figures: a "sphere" result
        if res is not None and self._has_sphere():
            centres.append(np.asarray(res.sphere_centre_mm, dtype=float) * MM_TO_M)
            radii.append(float(res.sphere_radius_mm) * MM_TO_M)
            f_m = np.asarray(res.flange_positions_mm, dtype=float).reshape(-1, 3) * MM_TO_M
            centres.extend(f_m)
            radii.extend([0.012] * len(f_m))
        return np.array(centres, dtype=float), np.array(radii, dtype=float)

    def frame_result(self) -> Framing | None:
        """Frame every browser's camera on the result and move the labels near the tip apart
        as seen from the (first) framed camera. Returns that framing (None: nothing to frame)."""
        centres, radii = self._framed_geometry()
        if not np.all(np.isfinite(centres)) or not np.all(np.isfinite(radii)):
            return None
        d = self._view_direction()
        framing = frame_cameras(clients_of(self.session), centres, radii,
                                direction=VIEW_DIRECTION if d is None else d)
        self.last_framing = framing
        return framing

    def _view_direction(self) -> np.ndarray | None:
        """A beam result: look at the beam broadside (``beam_replay.beam_view_direction``), so the
        passes and the events are seen side by side; None: the overview's direction."""
        scan = getattr(self._shown_result, "scan", None)
        if scan is None or not len(scan.events):
            return None
        return beam_view_direction(scan.events[0].beam_point, scan.events[0].beam_dir)

    @staticmethod
    def _camera_framing(client: viser.ClientHandle) -> Framing | None:
        """The browser's camera as it is now (None before it reported one)."""
        try:
            cam = client.camera
            position = np.asarray(cam.position, dtype=float)
            look_at = np.asarray(cam.look_at, dtype=float)
            fov, aspect, height = float(cam.fov), float(cam.aspect), float(cam.image_height)
        except Exception:
            return None
        distance = float(np.linalg.norm(look_at - position))
        if not (np.all(np.isfinite(position)) and np.all(np.isfinite(look_at)) and distance > 1e-6
                and math.isfinite(fov) and 0.05 < fov < 3.0 and math.isfinite(aspect) and aspect > 0.05
                and math.isfinite(height) and height > 50):
            return None
        return Framing(position=position, look_at=look_at, centre=look_at, radius_m=0.0, distance_m=distance,
                       fov_rad=fov, aspect=aspect, image_height_px=height)

    def _watch_cameras(self, clients: list[viser.ClientHandle]) -> None:
        """Re-lay the labels whenever the first browser's camera reports a new view (an orbit,
        a zoom, a resized window, the end of a framing move): boxes spread for another view
        can overlap in this one."""
        for client in clients[:1]:
            if client.client_id not in self._camera_watched:
                self._camera_watched.add(client.client_id)
                client.camera.on_update(self._relayout)

    def _on_camera(self, _camera: viser.CameraHandle | None = None) -> None:
        if self._labels_moved and (self.workflow.is_open or self.workflow.result is not None):
            self.layout_labels()

    def layout_labels(self) -> None:
        """Move the labels at the tip apart as seen by the (first) browser's camera now, or by
        the last result's framing when no camera has been reported."""
        clients = clients_of(self.session)
        self._watch_cameras(clients)
        framing = self._camera_framing(clients[0]) if clients else None
        framing = framing or self.last_framing
        if framing is not None:
            self._place_labels(framing)

    def _place_labels(self, framing: Framing) -> None:
        nodes = self._label_nodes()
        anchors: dict[str, np.ndarray] = {}
        for name, (_, T) in nodes.items():
            local = np.asarray(self._label_defaults[name][1], dtype=float)
            if name == "tip":
                local = np.asarray(self.session.controller.reference_tip_world_m, dtype=float) + [0.0, 0.0, -0.06]
            anchors[name] = local if T is None else T[:3, :3] @ local + T[:3, 3]
        texts = {n: str(getattr(nodes[n][0], "text", None) or _LABEL_TEXTS[n]) for n in anchors}
        scale = max((float(getattr(nodes[n][0], "font_screen_scale", 1.0) or 1.0) for n in anchors), default=1.0)
        placed = spread_labels(framing, anchors, texts, font_scale=scale)
        for name, world in placed.items():
            handle, T = nodes[name]
            local = world if T is None else T[:3, :3].T @ (world - T[:3, 3])
            if not np.allclose(np.asarray(handle.position, dtype=float), local, rtol=0.0, atol=1e-7):
                x, y, z = (float(v) for v in local)
                handle.position = (x, y, z)                          # only changes are sent
        self._labels_moved = True

    # ------------------------------------------------------------ live (on every move)
    def update_abc_target(self, T_world_flange: np.ndarray) -> None:
        """Place the target triad the open wizard asks for (``Wizard.scene_target_T_world_tool_m``:
        the (PA-1) orientation at the TCP while an ABC world wizard is in progress)."""
        wiz = self.workflow.wizard
        self._target_T = None if wiz is None else wiz.scene_target_T_world_tool_m(T_world_flange)
        self._pose(self.abc_target, self.abc_label, self._target_T)
