"""The Calibrate tab in a real viser server (in-process), with a headless websocket client as the
browser: clicks and choices reach the views as browser events do (``guiclick``)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from tcp_pendant.calibrate import error_bars
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.wizard_menu import CalibrateView
from tcp_pendant.wizards import ESTIMATOR_LABELS

from support.calib_helpers import library_tool_with_true_tcp, true_frame
from support.calib_page import Page
from support.guiclick import click, upload
from support.wsclient import DrainingClient, wait_until
from tcpcal.library import ToolLibrary
from tcpcal.origin import solve_xyz4

pytestmark = pytest.mark.app_page(cls=Page, seed=5)


def test_four_auto_touches_run_a_4point_calibration_and_every_view_follows(page) -> None:
    p = page()
    v, s = p.view, p.session
    assert v.menu_folder.visible and not v.steps.folder.visible and not v.result.folder.visible
    p.click(v.start)
    assert not v.menu_folder.visible and v.steps.folder.visible             # the wizard alone
    assert v.steps.record.disabled is False and v.steps.next.disabled is True
    assert v.steps.meter_bar.visible and "Pose diversity" in v.steps.meter_md.content
    assert "Not determinable yet. " in v.steps.meter_md.content         # with tcpcal's advice
    progress = [v.steps.progress.value]
    for k in range(4):
        assert f"Step {k + 1} of 4" in v.steps.head_md.content
        assert v.steps.next.label == ("Finish" if k == 3 else "Next")
        p.click(v.steps.auto_touch)
        progress.append(v.steps.progress.value)
    assert progress == pytest.approx([0.0, 20.0, 40.0, 60.0, 100.0])
    res = v.workflow.result
    assert v.result.folder.visible and not v.steps.record.visible and not v.steps.meter_bar.visible
    assert v.steps.cancel.label == "Close (not saved)"
    tcp_true, _, _ = true_frame("pointer")
    assert f"X {tcp_true[0]:.2f} · Y {tcp_true[1]:.2f} · Z {tcp_true[2]:.2f} mm" in v.result.result_md.content.replace("-0.00", "0.00")
    assert "Against the true TOOL frame: good" in v.result.truth_md.content and v.result.truth_md.visible
    # chart: the bars of this result
    expected = error_bars([i + 1 for i in res.used_indices], res.per_touch_error_mm)
    for got, want in zip(v.result.chart.data, expected.columns):
        np.testing.assert_allclose(got, want)
    # scene: sphere at r with radius |t|; both triads at T_world_flange @ T_flange_tool
    assert v.scene.sphere.visible
    np.testing.assert_allclose(v.scene.sphere.position, np.asarray(res.sphere_centre_mm) / 1000, atol=1e-9)
    assert float(np.atleast_1d(v.scene.sphere.scale)[0]) == pytest.approx(res.sphere_radius_mm / 1000)
    T_wt = s.controller.T_world_flange() @ s.controller.mounted_tool.T_flange_tool_true
    np.testing.assert_allclose(v.scene.computed.position, T_wt[:3, 3], atol=1e-9)
    np.testing.assert_allclose(v.scene.true_tool.position, T_wt[:3, 3], atol=1e-9)
    assert v.scene.computed.visible and v.scene.true_tool.visible and v.scene.true_label.visible
    # the triads ride with the flange on a jog
    with s.lock:
        s.controller.jog_joint(0, 5.0)
        s.moved()
    T_wt = s.controller.T_world_flange() @ s.controller.mounted_tool.T_flange_tool_true
    np.testing.assert_allclose(v.scene.computed.position, T_wt[:3, 3], atol=1e-9)

    # training mode off: truth, ghost triad and auto-touch go away
    p.choose(v.training, False)
    assert not v.result.truth_md.visible and not v.scene.true_tool.visible and not v.scene.true_label.visible
    assert v.scene.computed.visible

    # save: name echoed in the preview, saved, active in the Tool tab
    p.choose(v.result.save_name, "Pen 4P")
    assert v.result.save_preview.content.startswith("Will save **Pen 4P** · X 0.00 Y 0.00 Z 180.00 mm")
    p.click(v.result.save)
    assert "Saved **Pen 4P** in slot 1" in v.result.save_md.content
    assert s.tools.active_slot == 1 and s.controller.active_tool.name == "Pen 4P"
    assert "Active tool:** Pen 4P (slot 1)" in s.views["tools"].active_md.content
    assert ToolLibrary(s.library.path).active_slot() is None     # per-browser: the file's is not touched

    # close: the menu is back; the saved run is done, so nothing waits to be resumed
    assert v.steps.cancel.label == "Close"
    p.click(v.steps.cancel)
    assert v.menu_folder.visible and not v.resume.visible and not v.scene.computed.visible
    assert v.workflow.resumable() == []


def test_reference_wizard_disables_record_until_the_tool_change(page) -> None:
    p = page()
    v, s = p.view, p.session
    s.library.save(1, library_tool_with_true_tcp("pointer", "Pointer"))
    s.views["tools"].reload()                         # as the server's library watcher does
    assert v.library_tool.options == ("1: Pointer",)
    p.choose(v.method, "XYZ reference")
    assert v.library_tool.visible and v.new_physical.visible and not v.n_points.visible
    p.choose(v.new_physical, "Bent-neck welding torch")
    assert f"touch 2 with the *{escape_markdown('bent-neck welding torch')}*" in v.menu_md.content
    p.click(v.start)
    assert s.tools.active_slot == 1 and "Active tool:** Pointer (slot 1)" in s.views["tools"].active_md.content
    p.click(v.steps.auto_touch)
    assert v.steps.record.disabled and v.steps.mount.visible
    assert v.steps.mount.label == "Mount the bent-neck welding torch"
    assert escape_markdown("Mount the bent-neck welding torch first: the straight pointer") in \
        v.steps.blocked_md.content
    p.click(v.steps.mount)
    assert s.controller.mounted_tool.key == "torch"
    assert s.views["tools"].mounted.value == "Bent-neck welding torch"     # the Tool tab follows
    assert not v.steps.record.disabled and not v.steps.mount.visible
    p.click(v.steps.record)                           # a real Record, wherever the tip is now
    p.click(v.steps.next)
    assert v.workflow.result is not None and v.result.folder.visible


def test_outliers_are_marked_and_can_be_dropped_and_estimators_compared(page) -> None:
    p = page()
    v, s = p.view, p.session
    p.choose(v.n_points, 8)
    p.click(v.start)
    p.choose(v.steps.auto_sigma, 0.1)                 # a careful operator: 0.1 mm per axis
    assert v.steps.auto_request().sigma_mm == pytest.approx(0.1)
    for _ in range(7):
        p.click(v.steps.auto_touch)
    assert v.steps.auto_md.content.startswith(escape_markdown("Step 7 recorded: Touch 7 (tilt "))
    assert v.steps.auto_md.content.endswith("Operator error σ 0.10 mm.")
    # touch 8: a careless one, 5 mm off the reference tip
    with s.lock:
        assert s.controller.auto_approach(tilt_deg=40.0, azimuth_deg=200.0, tip_offset_tool_mm=(0.0, 5.0, 0.0)).ok
        s.moved()
    p.click(v.steps.record)
    p.click(v.steps.next)
    res = v.workflow.result
    assert res.outliers == (7,) and not v.result.drop.disabled
    assert v.result.chart.data[2].max() == pytest.approx(res.per_touch_error_mm[7])   # red series
    p.click(v.result.drop)
    res2 = v.workflow.result
    assert res2.excluded == (7,) and res2.outliers == ()
    poses = [v.workflow.wizard.recorded_poses[i].T_world_flange_m for i in range(7)]
    alone = solve_xyz4(np.array([T[:3, :3] for T in poses]), np.array([T[:3, 3] for T in poses]) * 1000.0)
    np.testing.assert_allclose(res2.tcp_mm, alone.tcp, atol=1e-9)           # = the 7 good touches alone
    assert np.linalg.norm(np.asarray(res2.tcp_mm) - true_frame("pointer")[0]) < \
        np.linalg.norm(np.asarray(res.tcp_mm) - true_frame("pointer")[0])
    assert not v.result.restore.disabled
    reads: list[int] = []
    real_tools = s.library.tools
    s.library.tools = lambda: reads.append(1) or real_tools()       # type: ignore[method-assign]
    p.choose(v.result.save_name, "Pen")                  # typing: a re-render, no file read
    assert reads == [] and "Will save **Pen**" in v.result.save_preview.content
    p.choose(v.result.estimator, ESTIMATOR_LABELS["sphere"])
    assert v.workflow.result.estimator == "sphere" and v.workflow.result.method == "xyz4-sphere"
    assert v.result.save_name.value == "Pen"             # a recomputed result keeps the typed name
    bars = error_bars([i + 1 for i in v.workflow.result.used_indices], v.workflow.result.per_touch_error_mm)
    np.testing.assert_allclose(v.result.chart.data[1], bars.normal_mm)     # the chart follows it
    p.choose(v.result.compare, True)
    assert v.result.compare_md.visible and v.result.compare_md.content.count("\n| ") == 3
    assert "best-fit sphere ◀ reported" in v.result.compare_md.content


def test_meter_follows_the_jog(page) -> None:
    p = page()
    v, s = p.view, p.session
    p.choose(v.estimator, ESTIMATOR_LABELS["pairwise"])   # the menu's estimator reaches the wizard
    p.click(v.start)
    assert v.workflow.wizard.estimator == "pairwise"
    p.click(v.steps.auto_touch)
    assert "Too close" in v.steps.meter_md.content and v.steps.meter_bar.color == "red"
    with s.lock:
        assert s.controller.auto_approach(tilt_deg=45.0, azimuth_deg=180.0, tip_offset_tool_mm=(-30.0, 0, 0)).ok
        s.moved()                                     # the motion listener updates the meter
    assert "Too close" not in v.steps.meter_md.content and v.steps.meter_bar.color != "red"


def test_session_export_and_load_through_the_gui(page) -> None:
    p = page()
    v = p.view
    sent: list[tuple[str, bytes]] = []
    p.client.send_file_download = lambda name, data, *a, **k: sent.append((name, data))  # type: ignore[method-assign]
    p.click(v.start)
    for _ in range(4):
        p.click(v.steps.auto_touch)
    p.click(v.export)
    ((name, data),) = sent
    record = json.loads(data)
    assert name == "tcp-pendant-session.json" and record["format"] == "tcp-pendant-session"
    assert record["wizards"][0]["truth"]["grade"] == "good"
    # load it in another browser: replayed, graded, shown
    q = page()
    upload(q.view.load, "session.json", data, q.client)
    assert "replayed result matches the record" in q.view.record_md.content
    np.testing.assert_allclose(q.view.workflow.result.tcp_mm, v.workflow.result.tcp_mm, atol=1e-9)
    assert q.view.result.folder.visible
    # a broken file: one clear notification, nothing changed
    runs = len(q.view.workflow.runs)
    upload(q.view.load, "bad.json", b"\xff\xfe not json", q.client)
    upload(q.view.load, "other.json", b'{"format": "x"}', q.client)
    assert len(q.view.workflow.runs) == runs
    assert [t for t, _ in q.notes] == ["Session record not loaded"] * 2
    assert "bad.json: The session record is not a text (JSON) file" in q.notes[0][1]
    assert "Not a TCP Pendant session record" in q.notes[1][1]


def test_orientation_wizards_need_a_library_tool(page) -> None:
    p = page(tool="torch")
    v, s = p.view, p.session
    p.choose(v.method, "Three-point orientation")
    assert v.start.disabled and "library is empty" in v.menu_md.content
    s.library.save(2, library_tool_with_true_tcp("torch", "Torch"))
    # saved "elsewhere": the watcher re-lists the library, then the menu is rendered
    wait_until(lambda: v.library_tool.options == ("2: Torch",) and not v.start.disabled, what="the library watcher")
    assert "orientation of **2: Torch**" in v.menu_md.content
    p.click(v.start)
    assert v.steps.variant.visible and v.steps.variant.value.startswith("Variant 1")
    p.choose(v.steps.variant, "Variant 2: tip in the +Y half-plane")
    assert v.workflow.wizard.variant == 2 and escape_markdown("+Y half-plane") in v.steps.steps_md.content
    for _ in range(3):
        p.click(v.steps.auto_touch)
    _, _, abc_true = true_frame("torch")
    np.testing.assert_allclose(v.workflow.result.abc_deg, abc_true, atol=1e-6)
    assert v.result.save_name.value == "Torch"


def test_abc_world_shows_the_world_aligned_target_at_the_tcp(page) -> None:
    p = page(tool="torch")
    v, s = p.view, p.session
    s.library.save(1, library_tool_with_true_tcp("torch", "Torch"))
    s.views["tools"].reload()
    p.choose(v.method, "ABC world (parallel axes)")
    assert not v.scene.abc_target.visible
    p.click(v.start)
    assert v.scene.abc_target.visible and v.scene.abc_label.visible
    # (PA-1): tool X down, Y along WORLD Y, Z along WORLD X, at the TCP of the library data
    R_target = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    q = np.asarray(v.scene.abc_target.wxyz)
    R_shown = Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix()
    np.testing.assert_allclose(R_shown, R_target, atol=1e-9)
    tcp_m = s.controller.T_world_flange() @ np.r_[true_frame("torch")[0] / 1000.0, 1.0]
    np.testing.assert_allclose(v.scene.abc_target.position, tcp_m[:3], atol=1e-9)
    with s.lock:                                      # it follows the TCP while jogging
        s.controller.jog_joint(0, -4.0)
        s.moved()
    tcp_m = s.controller.T_world_flange() @ np.r_[true_frame("torch")[0] / 1000.0, 1.0]
    np.testing.assert_allclose(v.scene.abc_target.position, tcp_m[:3], atol=1e-9)
    p.click(v.steps.auto_touch)
    assert v.workflow.result is not None and not v.scene.abc_target.visible


def test_closing_the_page_loses_nothing_saved(page) -> None:
    p = page()
    v, s = p.view, p.session
    p.click(v.start)
    for _ in range(4):
        p.click(v.steps.auto_touch)
    p.choose(v.result.save_name, "Kept")
    p.click(v.result.save)
    before = s.library.path.read_bytes()
    p.click(v.steps.cancel)                           # closed the result, then started another one
    p.click(v.start)
    p.click(v.steps.auto_touch)
    p.ws.close()                                      # the browser goes away mid-session
    wait_until(lambda: s.closed, what="session closed")
    assert s.library.path.read_bytes() == before
    assert ToolLibrary(s.library.path).get(1).name == "Kept"


def test_shared_mode_export_goes_to_the_browser_that_clicked(app_factory) -> None:
    app = app_factory(shared=True)
    ws = [DrainingClient(app.port), DrainingClient(app.port)]
    try:
        wait_until(lambda: len(app.server.get_clients()) == 2, what="two browsers")
        a, b = app.server.get_clients().values()
        got: dict[int, list[str]] = {a.client_id: [], b.client_id: []}
        for c in (a, b):
            c.send_file_download = lambda name, data, *_, _id=c.client_id, **__: got[_id].append(name)
        view: CalibrateView = app.shared_session.views["calibrate"]
        click(view.start, a)
        click(view.steps.auto_touch, b)                   # one robot: anyone may drive it
        click(view.export, b)
        assert got == {a.client_id: [], b.client_id: ["tcp-pendant-session.json"]}
    finally:
        for w in ws:
            w.close()


def test_resume_names_what_it_brings_back_and_offers_the_choice(page) -> None:
    """Resume said neither which calibration nor where; with two left, the button names the
    chosen one and brings back exactly that one."""
    p = page()
    v, s = p.view, p.session
    p.click(v.start)                                              # 1: XYZ 4-point, one touch
    p.click(v.steps.auto_touch)
    p.click(v.steps.cancel)
    assert v.resume.visible and v.resume.label == "Resume 1: XYZ 4-point, at step 2 of 4 (1 recorded)"
    p.choose(v.method, "TCP & Z, X (ABB)")
    p.click(v.start)                                              # 2: TCP & Z, X, nothing recorded
    p.click(v.steps.cancel)
    options = tuple(v.resume_list.options)
    assert [o.split(", started")[0] for o in options] == [
        "2: TCP & Z, X (ABB), at step 1 of 6 (0 recorded)", "1: XYZ 4-point, at step 2 of 4 (1 recorded)"]
    assert v.resume.label == "Resume 2: TCP & Z, X (ABB), at step 1 of 6 (0 recorded)"
    p.choose(v.resume_list, options[1])
    assert v.resume.label == "Resume 1: XYZ 4-point, at step 2 of 4 (1 recorded)"
    p.click(v.resume)
    assert s.workflow.run is s.workflow.runs[0] and s.workflow.wizard.step_index == 1


def test_a_refused_save_says_so_in_the_result_panel(page) -> None:
    """A Save the library refuses (here a name longer than a controller takes, as the torch's
    built-in label was) was said only in a toast; the panel kept offering Save as if nothing
    had happened."""
    p = page()
    v, s = p.view, p.session
    p.click(v.start)
    for _ in range(4):
        p.click(v.steps.auto_touch)
    p.choose(v.result.save_name, "A tool name of thirty chars")
    p.click(v.result.save)
    assert "**Not saved:**" in v.result.save_md.content and "24" in v.result.save_md.content
    assert p.notes and p.notes[-1][0] == "Not done"
    assert s.library.tools() == {} and s.workflow.last_save is None
    p.choose(v.result.save_name, "Pen 4P")
    p.click(v.result.save)                            # a good name: saved, the refusal is gone
    assert "Not saved" not in v.result.save_md.content and "Saved **Pen 4P**" in v.result.save_md.content
