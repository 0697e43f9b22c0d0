"""What the calibration wizards draw in the 3D scene of one session.

* ``/calibration/computed_tool``: the computed TOOL frame of the result, a triad at the
  computed TCP, labelled "COMPUTED";
* ``/calibration/true_tool``: training mode, after a result: the hidden true TOOL frame as
  a thin, longer "ghost" triad labelled "TRUE", so the two can be compared by eye;
* ``/calibration/sphere`` (4-point result): the fitted sphere, centre the reference point ``r``
  and radius ``|t|`` (4P-1a), with the flange origins ``f_i`` on it (``flange_points``, red for
  outliers, grey for dropped touches) and each touch's approach direction, the line from
  ``f_i`` to ``r`` along the tool (``approach``);
* ``/calibration/abc_target`` (ABC world wizard): the prescribed orientation (PA-1) drawn at
  the TCP, updated on every move, for the operator to align the tool with.

Scene units are metres (the wizards' results are in mm and converted here). Axis colours are
viser's: X red, Y green, Z blue.

The two TOOL triads are posed in WORLD (``T_world_flange @ T_flange_tool``) after every move,
like the TCP gizmo, rather than hung under the flange's scene node: in the browser, nodes
created hidden under the flange node were seen (once in several runs) drawn with their labels
at the WORLD origin, not at the tool. Their labels are shown and hidden with them.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from tcp_pendant.calibrate import CalibrationWorkflow
from tcp_pendant.session import Session
from tcp_pendant.views.scene import wxyz_xyz
from tcp_pendant.wizards import AbcWorldWizard, Xyz4Result

__all__ = ["WizardSceneView"]

MM_TO_M = 1e-3
_POINT_RGB = np.array([30, 30, 30], dtype=np.uint8)
_OUTLIER_RGB = np.array([220, 30, 30], dtype=np.uint8)
_DROPPED_RGB = np.array([170, 170, 170], dtype=np.uint8)
_APPROACH_RGB = np.array([60, 110, 220], dtype=np.uint8)


class WizardSceneView:
    """The wizards' scene nodes of one session (see the module docstring); all start hidden."""

    def __init__(self, session: Session, workflow: CalibrationWorkflow) -> None:
        self.session = session
        self.workflow = workflow
        scene = session.views["scene"].scene
        self.scene = scene
        self.computed = scene.add_frame("/calibration/computed_tool", axes_length=0.10, axes_radius=0.0045,
                                        visible=False)
        self.computed_label = scene.add_label("/calibration/computed_tool/label", "COMPUTED",
                                              position=(0.0, 0.0, -0.03), visible=False)
        self.true_tool = scene.add_frame("/calibration/true_tool", axes_length=0.16, axes_radius=0.0015,
                                         origin_color=(245, 245, 245), visible=False)
        self.true_label = scene.add_label("/calibration/true_tool/label", "TRUE", position=(0.0, -0.03, 0.0),
                                          visible=False)
        self.sphere = scene.add_icosphere("/calibration/sphere", radius=1.0, color=(90, 140, 230),
                                          subdivisions=3, wireframe=True, opacity=0.35, visible=False,
                                          cast_shadow=False, receive_shadow=False)
        self.abc_target = scene.add_frame("/calibration/abc_target", axes_length=0.13, axes_radius=0.003,
                                          origin_color=(255, 255, 255), visible=False)
        self.abc_label = scene.add_label("/calibration/abc_target/label", "TARGET (X down)",
                                         position=(0.0, 0.03, 0.0), visible=False)
        self._points: Any = None
        self._lines: Any = None
        self._shown_result: Any = None
        self._T_flange_computed: np.ndarray | None = None
        self._T_flange_true: np.ndarray | None = None

    # ------------------------------------------------------------ result
    def render(self) -> None:
        """Show what belongs to the workflow's current state (call after every action)."""
        wf = self.workflow
        self._T_flange_computed = wf.T_flange_tool_computed_m()
        self._T_flange_true = wf.T_flange_tool_true_m()
        res = wf.result
        if res is not self._shown_result:
            self._shown_result = res
            self._show_sphere(res if isinstance(res, Xyz4Result) else None)
        self.on_motion()

    @property
    def showing(self) -> bool:
        """Something of the wizards is in the scene (the triads or the ABC target)."""
        return bool(self.computed.visible or self.true_tool.visible or self.abc_target.visible)

    def on_motion(self) -> None:
        """After every move: the TOOL triads follow the flange, the ABC target the TCP."""
        T_world_flange = self.session.pose_state().T_world_flange   # the move's one FK pass
        for frame, label, T in ((self.computed, self.computed_label, self._T_flange_computed),
                                (self.true_tool, self.true_label, self._T_flange_true)):
            self._pose(frame, label, None if T is None else T_world_flange @ T)
        self.update_abc_target(T_world_flange)

    @staticmethod
    def _pose(handle: Any, label: Any, T: np.ndarray | None) -> None:
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

    # ------------------------------------------------------------ live (on every move)
    def update_abc_target(self, T_world_flange: np.ndarray) -> None:
        """Place the (PA-1) target triad at the TCP while an ABC world wizard is open."""
        wiz = self.workflow.wizard
        open_abc = isinstance(wiz, AbcWorldWizard) and wiz.status == "in_progress"
        self._pose(self.abc_target, self.abc_label,
                   wiz.target_T_world_tool_m(T_world_flange) if open_abc else None)  # type: ignore[union-attr]
