"""The pendant on robot descriptions as ROS and ROS-Industrial publish them (layouts and
sources: tests/support/ros_layouts.py, robots/README.md): a 7-axis xacro description with
package:// meshes and a mimic joint starts, draws, jogs and calibrates; a KR 16 whose meshes are
missing is still drawn and says so; a reference tip out of reach is said at start."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import urllib.request

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.controller import JogFrame, builtin_tools
from tcp_pendant.controller.jog import DEFAULT_SETTINGS, smallest_singular_value
from tcp_pendant.controller.placement import READY_HOVER_M
from tcp_pendant.translation import PSEUDO_LANGUAGE, translator
from tcp_pendant.views.meshes import SHAPE_RGB, link_meshes

from support.wsclient import wait_until
from support.ros_layouts import ACME7_MIMIC, acme7_workspace, kr16_2_urdf
from support.wsclient import RecordingClient


def notifications(client: RecordingClient) -> list[tuple[str, str]]:
    out = []
    for m in client.of_type("NotificationShowMessage"):
        props = m.get("props", m)
        out.append((props.get("title"), props.get("body")))
    return out


def test_seven_axis_xacro_starts_draws_jogs_and_auto_touch_finds_the_tcp(app_factory, tmp_path, monkeypatch) -> None:
    ws = acme7_workspace(tmp_path / "robot")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(ws.ros_package_path))       # acme_description
    app = app_factory(robot=str(ws.xacro), package_paths=(ws.package_path,), seed=3)  # acme_meshes
    assert app.warnings == [] and app.robot_label == "acme7"
    kin = app.kinematics
    assert kin.n_joints == 7 and ACME7_MIMIC[0] in kin.mimic_joints
    # every link is drawn from its own STL, found in the two packages
    meshes = link_meshes(kin.description)
    for link, stl in ws.meshes.items():
        (part,) = meshes[link]
        assert len(part.vertices) == len(trimesh.load(stl).vertices)
        assert part.rgb == (255, 102, 0)                               # the xacro's material
    client = RecordingClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 1, what="session built")
        (s,) = app.sessions.values()
        c = s.controller
        wait_until(lambda: any(str(m.get("name", "")).endswith("acme_link_guide/mesh_0")
                               for m in client.of_type("MeshMessage")), what="the guide's mesh sent")
        sent = {str(m["name"]) for m in client.of_type("MeshMessage")}
        assert all(any(n.endswith(f"{link}/mesh_0") for n in sent) for link in ws.meshes)
        assert notifications(client) == []
        # ready: flange down over the tip, well conditioned, not the all-zero stretch
        T = c.T_world_flange()
        assert T[2, 2] < -0.999
        np.testing.assert_allclose(T[:3, 3], app.reference_tip_m + [0, 0, READY_HOVER_M], atol=1e-9)
        assert smallest_singular_value(kin, c.q_rad) > 2 * DEFAULT_SETTINGS.singular_eps
        with s.lock:
            for axis in ("X", "Y", "Z"):
                p0 = c.T_world_tcp()[:3, 3]
                assert c.jog_cartesian(JogFrame.WORLD, axis, -10.0).ok, axis
                moved = c.T_world_tcp()[:3, 3] - p0
                assert abs(moved["XYZ".index(axis)] + 0.010) < 1e-9 and np.linalg.norm(moved) < 0.010 + 1e-9
            # the mimic joint follows joint 2 in what is drawn (the session's pose state)
            assert c.jog_joint(1, 10.0).ok
            state = s.pose_state()
            R = state.T_world_link["acme_link_1"][:3, :3].T @ state.T_world_link["acme_link_guide"][:3, :3]
            np.testing.assert_allclose(R, Rotation.from_euler("y", -0.5 * c.q_rad[1] + 0.1).as_matrix(), atol=1e-9)
        # Auto-touch XYZ 4-point by the session's commands: the pointer's true TCP
        with s.lock:
            s.wizard_commands.start("xyz4")
            for _ in range(4):
                out = s.wizard_commands.auto_touch(AutoTouchRequest())
                assert out.ok, out.message
        true_tcp = builtin_tools()["pointer"].T_flange_tool_true[:3, 3] * 1000.0
        np.testing.assert_allclose(s.workflow.result.tcp_mm, true_tcp, atol=1e-6)
        assert s.workflow.export_record()["robot"]["name"] == "acme7"
    finally:
        client.close()


def test_kr16_with_missing_meshes_is_drawn_and_says_so(app_factory, tmp_path, monkeypatch) -> None:
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    urdf = kr16_2_urdf(tmp_path / "src")                  # its .dae visuals are not there
    app = app_factory(robot=str(urdf))
    assert len(app.warnings) == 7 and all("drawn from its collision geometry" in w for w in app.warnings)
    meshes = link_meshes(app.kinematics.description)
    for link in ["base_link"] + [f"link_{i}" for i in range(1, 7)]:
        (part,) = meshes[link]
        assert len(part.faces) == 12                      # the 150 mm collision box
    # the start pose: flange down over a tip it reaches (no tip warning)
    assert app.tip_warning is None
    assert app.kinematics.T_world_flange(app.ready_q_rad)[2, 2] < -0.999
    assert np.abs(app.ready_q_rad).max() > 0.3
    client = RecordingClient(app.port)
    try:
        wait_until(lambda: notifications(client), what="the start notice")
        ((title, body),) = notifications(client)
        assert title == "Robot meshes not found"
        assert body.startswith("7 meshes of the robot were not found (base_link.dae, link_1.dae")
    finally:
        client.close()


def test_robot_with_no_mesh_at_all_is_drawn_as_link_shapes(app_factory, tmp_path, monkeypatch) -> None:
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    urdf = kr16_2_urdf(tmp_path / "src", meshes=False)
    app = app_factory(robot=str(urdf))
    assert all("drawn as simple link shapes" in w for w in app.warnings) and len(app.warnings) == 7
    meshes = link_meshes(app.kinematics.description)
    for link in ["base_link"] + [f"link_{i}" for i in range(1, 6)]:
        parts = meshes[link]
        assert parts and all(p.rgb == SHAPE_RGB for p in parts)
    # link_1's rod reaches joint_a2 (0.26 m forward), base_link's joint_a1 (0.675 m up)
    assert float(meshes["link_1"][1].vertices[:, 0].max()) == pytest.approx(0.26, abs=1e-6)
    assert float(meshes["base_link"][1].vertices[:, 2].max()) == pytest.approx(0.675, abs=1e-6)


def test_unreachable_reference_tip_is_said_at_start_and_on_the_pendant(app_factory, tmp_path) -> None:
    urdf = kr16_2_urdf(tmp_path / "src")
    app = app_factory(robot=str(urdf), reference_tip_mm=(1768.0, 0.0, 320.0))
    assert app.tip_warning is not None and app.tip_warning in app.warnings
    assert app.tip_warning.startswith("the reference tip (1768, 0, 320) mm is out of reach of the kr16_2: ")
    client = RecordingClient(app.port)
    try:
        wait_until(lambda: len(notifications(client)) == 2, what="the start notices")
        assert ("Reference tip out of reach", app.tip_warning) in notifications(client)
    finally:
        client.close()
    qps = translator(PSEUDO_LANGUAGE)                  # a pendant in another language: its words
    said = dict(app.start_notices(tr=qps))[qps.gettext("Reference tip out of reach")]
    assert said == app.tip_warning.text(qps) and said.startswith("⟦") and "out of reach" not in said
    reachable = app_factory(robot="kr6", reference_tip_mm=(525.0, 0.0, 445.0))
    assert reachable.tip_warning is None and reachable.warnings == []


def test_command_prints_a_warning_line_for_each_missing_mesh(tmp_path) -> None:
    urdf = kr16_2_urdf(tmp_path / "src")
    proc = subprocess.Popen([sys.executable, "-m", "tcp_pendant", "--port", "0", "--tool-library",
                             str(tmp_path / "tools.json"), "--robot", str(urdf),
                             "--package-path", str(tmp_path / "src"), "--reference-tip", "1768,0,320"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))   # Ctrl-C under nohup too
    assert proc.stdout is not None
    seen = []
    try:
        for line in proc.stdout:
            seen.append(line)
            if line.startswith("TCP Pendant ready"):
                break
        url = re.search(r"http://\S+", seen[-1])
        assert url is not None, seen
        with urllib.request.urlopen(url.group(0), timeout=10) as r:   # serving (Ctrl-C now stops it)
            assert r.status == 200
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            out, err = proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:          # a server left running would outlive the test
            proc.kill()
            proc.communicate(timeout=30)
            raise
    lines = [line for line in err.splitlines() if line.startswith("WARNING: ")]
    assert len([x for x in lines if x.startswith("WARNING: robot mesh not found: package://kuka_kr16_support/")]) == 7
    assert any(x.startswith("WARNING: the reference tip (1768, 0, 320) mm is out of reach") for x in lines)
    assert proc.returncode == 0, (seen, out, err)
