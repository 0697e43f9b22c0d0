"""After Finish the camera is framed on the result (the fitted sphere,
the flange positions, the frames) and the labels at the tip (COMPUTED, TRUE, TOOL, FLANGE,
"reference tip") are placed apart so they can be read."""

from __future__ import annotations

import math
from collections.abc import Iterator
from itertools import combinations

import numpy as np
import pytest
from tcp_pendant.views.framing import (
    LABEL_HEIGHT_PX,
    bounding_sphere,
    frame_spheres,
    label_box_px,
    spread_labels,
)
from support.calib_page import Page

pytestmark = pytest.mark.app_page(cls=Page, seed=5)


def sphere_surface(c: np.ndarray, r: float, n: int = 200) -> np.ndarray:
    rng = np.random.default_rng(0)
    v = rng.normal(size=(n, 3))
    return c + r * v / np.linalg.norm(v, axis=1)[:, None]


def test_bounding_sphere_contains_every_sphere() -> None:
    centres = np.array([[0.5, 0.0, 0.2], [0.7, 0.1, 0.3], [0.6, -0.2, 0.1]])
    radii = np.array([0.18, 0.0, 0.05])
    c, r = bounding_sphere(centres, radii)
    assert np.all(np.linalg.norm(centres - c, axis=1) + radii <= r + 1e-12)
    with pytest.raises(ValueError, match="finite point"):
        bounding_sphere(np.array([[np.nan, 0, 0]]))


@pytest.mark.parametrize("fov_deg,aspect", [(50.0, 16 / 9), (57.3, 1280 / 720), (75.0, 0.6)])
def test_framing_shows_the_whole_sphere_and_fills_the_view(fov_deg, aspect) -> None:
    centre, radius = np.array([0.62, 0.05, 0.25]), 0.18            # a 4-point sphere, 180 mm
    flanges = sphere_surface(centre, radius, 6)
    f = frame_spheres(np.vstack([centre, flanges]), [radius] + [0.012] * 6,
                      fov_rad=math.radians(fov_deg), aspect=aspect, image_height_px=720)
    xy, depth = f.project(sphere_surface(centre, radius, 2000))
    half_h, half_w = 360.0, 360.0 * aspect
    assert np.all(depth > 0)
    assert np.all(np.abs(xy[:, 0]) <= half_w) and np.all(np.abs(xy[:, 1]) <= half_h)   # not cut off
    # ... and not tiny: the sphere spans at least 60 % of the narrower side of the view
    extent = max(np.ptp(xy[:, 0]) / (2 * half_w), np.ptp(xy[:, 1]) / (2 * half_h))
    assert extent > 0.6
    np.testing.assert_allclose(f.look_at, f.centre)


TIP_LABELS = {"computed": "COMPUTED", "true": "TRUE", "tool": "TOOL Pen 4P", "tip": "reference tip",
              "flange": "FLANGE"}
"""The labels drawn at the tool tip after Finish: name -> text."""


def label_pairs(xy: np.ndarray, names: list[str], texts: dict[str, str],
                x_slack_px: float = 0.0) -> Iterator[tuple[int, str, int, str, bool, bool]]:
    """Each pair of labels at screen anchors ``xy`` (row per name, px): (i, a, j, b, apart
    across the screen, apart up it). Across counts boxes within ``x_slack_px`` of touching as
    apart (``spread_labels`` leaves those where they are)."""
    for (i, a), (j, b) in combinations(enumerate(names), 2):
        wa, h = label_box_px(texts[a])
        wb, _ = label_box_px(texts[b])
        apart_x = xy[i, 0] >= xy[j, 0] + wb - x_slack_px or xy[j, 0] >= xy[i, 0] + wa - x_slack_px
        yield i, a, j, b, apart_x, abs(xy[i, 1] - xy[j, 1]) >= h


def test_overlapping_labels_are_moved_apart_on_screen() -> None:
    f = frame_spheres(np.array([[0.6, 0.0, 0.2]]), [0.2], fov_rad=1.0, image_height_px=720)
    tip = np.array([0.6, 0.0, 0.2])
    anchors = {"computed": tip + [0, 0, -0.001], "true": tip + [0.002, 0, 0], "tool": tip + [0, 0, 0.003],
               "tip": tip + [0, 0, -0.004], "flange": tip + [0, 0, 0.12]}
    texts = TIP_LABELS
    placed = spread_labels(f, anchors, texts)
    assert list(placed) == list(anchors)
    np.testing.assert_allclose(placed["computed"], anchors["computed"])       # the first stays
    xy, depth = f.project(np.array(list(placed.values())))
    names = list(placed)
    for i, a, j, b, apart_x, apart_y in label_pairs(xy, names, texts):
        assert apart_x or apart_y, (a, b)
        if not apart_x:                         # stacked: at least a label's height apart in WORLD
            mm = 1000 * np.linalg.norm(placed[a] - placed[b])
            assert mm >= 1000 * LABEL_HEIGHT_PX * f.metres_per_px(min(depth[i], depth[j])) * 0.99
    # the labels moved only up the screen (same depth, same screen x)
    _, _, up = f.basis()
    for n in names:
        d = placed[n] - anchors[n]
        assert np.linalg.norm(d - up * (d @ up)) < 1e-9 and d @ up >= 0


def test_labels_clustered_anywhere_at_the_tip_end_up_apart() -> None:
    # a label moved to exactly a box's height above another must count as apart whatever the
    # rounding of (y + h) - h: before, the search hit the same box again until it gave up and
    # left two labels on top of one another (it did with numpy 2.4's projection)
    f = frame_spheres(np.array([[0.6, 0.0, 0.2]]), [0.2], fov_rad=1.0, image_height_px=720)
    texts = TIP_LABELS
    rng = np.random.default_rng(7)
    for _ in range(300):
        tip = np.array([0.6, 0.0, 0.2]) + rng.uniform(-0.05, 0.05, 3)
        anchors = {n: tip + rng.uniform(-0.004, 0.004, 3) for n in texts}
        placed = spread_labels(f, anchors, texts)
        xy, _ = f.project(np.array(list(placed.values())))
        for _, a, _, b, apart_x, apart_y in label_pairs(xy, list(placed), texts, x_slack_px=1e-6):
            assert apart_x or apart_y, (a, b, anchors)


def test_labels_already_apart_stay_where_they_are() -> None:
    f = frame_spheres(np.array([[0.6, 0.0, 0.2]]), [0.2], fov_rad=1.0, image_height_px=720)
    anchors = {"a": np.array([0.6, 0.0, 0.35]), "b": np.array([0.6, 0.0, 0.05])}
    placed = spread_labels(f, anchors, {"a": "COMPUTED", "b": "TRUE"})
    for n in anchors:
        np.testing.assert_allclose(placed[n], anchors[n])


def test_finish_frames_the_camera_and_spreads_the_labels(page) -> None:
    p = page()
    v, s = p.view, p.session
    cam_before = np.array(p.client.camera.position)
    p.click(v.start)
    for _ in range(4):
        p.click(v.steps.auto_touch)                  # the 4th one finishes
    res = v.workflow.result
    f = v.scene.last_framing
    assert res is not None and f is not None
    # the camera of the browser was framed on the result
    np.testing.assert_allclose(p.client.camera.look_at, f.look_at, atol=1e-6)
    np.testing.assert_allclose(p.client.camera.position, f.position, atol=1e-6)
    assert not np.allclose(cam_before, f.position)
    # the framing holds the fitted sphere and every flange position
    centre = np.asarray(res.sphere_centre_mm) / 1000
    r = res.sphere_radius_mm / 1000
    assert np.linalg.norm(centre - f.centre) + r <= f.radius_m + 1e-9
    flanges = np.asarray(res.flange_positions_mm) / 1000
    assert np.all(np.linalg.norm(flanges - f.centre, axis=1) <= f.radius_m + 1e-9)
    assert f.fov_rad == pytest.approx(1.0) and f.image_height_px == 720     # the browser's camera
    # labels of the tip cluster, in WORLD, as placed: no two boxes overlap on screen
    T_wf = s.pose_state().T_world_flange
    labels = {"COMPUTED": (v.scene.computed_label, T_wf @ v.workflow.T_flange_tool_computed_m()),
              "TRUE": (v.scene.true_label, T_wf @ v.workflow.T_flange_tool_true_m())}
    others = s.views["scene"].tool_labels()
    labels[others["tool"].text] = (others["tool"], T_wf @ s.controller.T_flange_tool)
    labels["reference tip"] = (others["tip"], np.eye(4))
    labels["FLANGE"] = (others["flange"], T_wf)
    world = {t: T[:3, :3] @ np.asarray(h.position) + T[:3, 3] for t, (h, T) in labels.items()}
    xy, _ = f.project(np.array(list(world.values())))
    texts = list(world)
    for i, j in combinations(range(len(texts)), 2):
        wa, h = label_box_px(texts[i])
        wb, _ = label_box_px(texts[j])
        assert (xy[i, 0] >= xy[j, 0] + wb or xy[j, 0] >= xy[i, 0] + wa
                or abs(xy[i, 1] - xy[j, 1]) >= h - 1e-6), (texts[i], texts[j])
    # closing the result puts the labels back where they were
    p.click(v.steps.cancel)
    assert tuple(v.scene.computed_label.position) == pytest.approx((0.0, 0.0, -0.03))
    assert tuple(others["tool"].position) == pytest.approx((0.0, 0.0, 0.04))


def _boxes_apart(f, world: dict[str, np.ndarray]) -> list[tuple[str, str]]:
    xy, _ = f.project(np.array(list(world.values())))
    texts = list(world)
    clashes = []
    for i, j in combinations(range(len(texts)), 2):
        wa, h = label_box_px(texts[i])
        wb, _ = label_box_px(texts[j])
        if not (xy[i, 0] >= xy[j, 0] + wb or xy[j, 0] >= xy[i, 0] + wa or abs(xy[i, 1] - xy[j, 1]) >= h - 1e-6):
            clashes.append((texts[i], texts[j]))
    return clashes


def test_abc_world_target_tool_and_tip_labels_do_not_collide(page, tmp_path) -> None:
    from support.calib_helpers import library_tool_with_true_tcp
    from tcp_pendant.views.wizard_scene import WizardSceneView

    p = page()
    v, s = p.view, p.session
    s.library.save(2, library_tool_with_true_tcp("pointer", "Pen"))
    s.tools.reload_library()                               # as the server's library watcher does
    p.choose(v.method, "ABC world (parallel axes)")
    p.click(v.start)
    with s.lock:                                     # the trainee jogs the tip onto the reference tip
        assert s.controller.auto_approach(tilt_deg=0.0, azimuth_deg=0.0).ok
        s.moved()
    assert v.scene.abc_label.visible
    f = WizardSceneView._camera_framing(p.client)    # the browser's camera as reported
    assert f is not None
    T_wf = s.pose_state().T_world_flange
    others = s.views["scene"].tool_labels()
    T_target = v.scene.abc_target
    from scipy.spatial.transform import Rotation
    R_t = Rotation.from_quat(np.roll(np.asarray(T_target.wxyz), -1)).as_matrix()
    world = {
        "TARGET (X down)": R_t @ np.asarray(v.scene.abc_label.position) + np.asarray(T_target.position),
        others["tool"].text: (T_wf @ s.controller.T_flange_tool)[:3, :3] @ np.asarray(others["tool"].position)
        + (T_wf @ s.controller.T_flange_tool)[:3, 3],
        "reference tip": np.asarray(others["tip"].position),
        "FLANGE": T_wf[:3, :3] @ np.asarray(others["flange"].position) + T_wf[:3, 3],
    }
    assert others["tool"].text == "TOOL Pen"
    assert _boxes_apart(f, world) == []


def test_frame_cameras_frames_each_browser_with_its_own_camera() -> None:
    """``scene.frame_cameras``: every browser framed with its camera's shape, a browser that has
    not reported a camera yet (or left) is skipped without failing; the first one's framing back."""
    from types import SimpleNamespace

    from tcp_pendant.views.scene import camera_shape, frame_cameras

    class Client:
        def __init__(self, camera: object) -> None:
            self.camera = camera

        def atomic(self):
            from contextlib import nullcontext
            return nullcontext()

    class NoCamera:
        @property
        def camera(self):
            raise RuntimeError("no camera message yet")

        def atomic(self):
            from contextlib import nullcontext
            return nullcontext()

    wide = Client(SimpleNamespace(fov=1.2, aspect=2.0, image_height=900.0, position=None, look_at=None))
    narrow = Client(SimpleNamespace(fov=0.5, aspect=1.0, image_height=600.0, position=None, look_at=None))
    centres, radii = np.array([[0.5, 0.0, 0.4], [0.7, 0.1, 0.3]]), np.array([0.05, 0.05])
    f = frame_cameras([wide, NoCamera(), narrow], centres, radii, margin=1.4)
    expect = [frame_spheres(centres, radii, fov_rad=c.camera.fov, aspect=c.camera.aspect,
                            image_height_px=c.camera.image_height, margin=1.4) for c in (wide, narrow)]
    for client, e in zip((wide, narrow), expect):
        np.testing.assert_allclose(client.camera.position, e.position)
        np.testing.assert_allclose(client.camera.look_at, e.look_at)
    np.testing.assert_allclose(f.position, expect[0].position)
    assert expect[1].distance_m > expect[0].distance_m                # the narrow camera stands back
    assert camera_shape(NoCamera()) == (pytest.approx(np.radians(50.0)), pytest.approx(16 / 9), 720.0)
    np.testing.assert_allclose(frame_cameras([], centres, radii).position, frame_spheres(centres, radii).position)
