"""The jog hot path's shortcuts against the definitions they replace: the readout's A, B, C and
the scene's quaternions (pinocchio) against tcpcal/scipy, the shared pose state against the
controller's own methods, and the scene the browser composes from the nested link frames
against the controller's link poses."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcpcal.tool import Tool, abc_deg_from_rotation
from tcp_pendant.controller import VirtualController, builtin_tools
from tcp_pendant.pendant.formatting import tcp_readout_markdown, touch_indicator_markdown
from tcp_pendant.controller.pose_state import pose_state, pose_state_key
from tcp_pendant.controller.rotations import GIMBAL_LOCK_COS_B, kuka_abc_deg, quaternion_wxyz, quaternions_wxyz

from support.wsclient import wait_until
from support.wsclient import DrainingClient

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _angle_diff_deg(a: float, b: float) -> float:
    return abs((a - b + 180.0) % 360.0 - 180.0)


def _rotations() -> np.ndarray:
    rng = np.random.default_rng(7)
    mats = list(Rotation.random(300, random_state=11).as_matrix())
    # near and at gimbal lock (B = +-90 deg), on both sides of the fallback threshold
    for b in (90.0, -90.0, 89.9999, -89.9999, 89.999, 89.99, 89.0):
        for a, c in ((30.0, 20.0), (-170.0, 175.0), (0.0, 0.0)):
            mats.append(Rotation.from_euler("ZYX", [a, b, c], degrees=True).as_matrix())
    # A = +-180 and C = +-180 edges, half turns, identity
    for abc in ((180.0, 0.0, 0.0), (-180.0, 10.0, 0.0), (0.0, 0.0, 180.0), (45.0, 0.0, -180.0), (0.0, 0.0, 0.0)):
        mats.append(Rotation.from_euler("ZYX", abc, degrees=True).as_matrix())
    for axis in np.eye(3):
        mats.append(Rotation.from_rotvec(np.pi * axis).as_matrix())
    mats.append(Rotation.from_rotvec(rng.normal(size=3) * 1e-9).as_matrix())
    return np.array(mats)


def test_kuka_abc_matches_tcpcal_and_rebuilds_the_rotation() -> None:
    n_locked = 0
    for i, R in enumerate(_rotations()):
        a, b, c = kuka_abc_deg(R)
        ref = abc_deg_from_rotation(R)
        # A, B, C reproduce R (R = Rz(A) Ry(B) Rx(C)), independently of either implementation
        np.testing.assert_allclose(Rotation.from_euler("ZYX", [a, b, c], degrees=True).as_matrix(), R,
                                   atol=2e-9, err_msg=f"rotation {i}")
        assert -90.0 <= b <= 90.0 and -180.0 < a <= 180.0 and -180.0 <= c <= 180.0, (i, a, b, c)
        # and are the angles the controller's readout (tcpcal) shows, to far below 0.01 deg
        assert _angle_diff_deg(b, ref[1]) < 1e-7, (i, (a, b, c), ref)
        assert _angle_diff_deg(a, ref[0]) < 1e-6 and _angle_diff_deg(c, ref[2]) < 1e-6, (i, (a, b, c), ref)
        if math.hypot(R[0, 0], R[1, 0]) < GIMBAL_LOCK_COS_B:   # at the lock: tcpcal's own split
            n_locked += 1
            assert (a, b, c) == tuple(float(v) for v in ref), i
    assert n_locked >= 6                                        # the lock cases were exercised


def test_quaternion_is_scipys_rotation() -> None:
    for i, R in enumerate(_rotations()):
        w, x, y, z = quaternion_wxyz(R)
        q_ref = Rotation.from_matrix(R).as_quat()               # x, y, z, w
        assert abs(abs(np.dot([x, y, z, w], q_ref)) - 1.0) < 1e-12, i   # same rotation (q ~ -q)
        assert abs(w * w + x * x + y * y + z * z - 1.0) < 1e-12, i


def test_quaternion_is_pinocchios_bit_for_bit_from_an_array_or_rows() -> None:
    """The scene's quaternion repeats Eigen's float operations: the very numbers pinocchio gives,
    in both of its branches (trace > 0, and each largest diagonal entry), from the matrix or its rows."""
    import pinocchio as pin

    mats = list(_rotations()) + list(Rotation.random(20000, random_state=5).as_matrix())
    for axis in np.eye(3):                           # near the half turns: the trace <= 0 branches
        mats += [Rotation.from_rotvec(a * axis).as_matrix() for a in (np.pi - 1e-9, 2.5, 2.0 * np.pi / 3.0)]
    branches: set[object] = set()
    for i, R in enumerate(mats):
        x, y, z, w = pin.Quaternion(np.ascontiguousarray(R)).coeffs().tolist()
        assert quaternion_wxyz(R) == [w, x, y, z], i
        T = np.eye(4)
        T[:3, :3] = R
        assert quaternion_wxyz(T.tolist()) == [w, x, y, z], i
        d = np.diag(R)
        branches.add("trace" if R[0, 0] + (R[1, 1] + R[2, 2]) > 0.0 else int(np.argmax(d)))
    assert branches == {"trace", 0, 1, 2}


def test_quaternions_of_a_stack() -> None:
    R = _rotations()[:20]
    Q = quaternions_wxyz(R)
    assert Q.shape == (20, 4)
    np.testing.assert_array_equal(Q[3], quaternion_wxyz(R[3]))


def _configurations(c: VirtualController, n: int = 12) -> list[np.ndarray]:
    rng = np.random.default_rng(3)
    k = c.kinematics
    return [rng.uniform(k.lower_rad, k.upper_rad) for _ in range(n)]


def test_pose_state_equals_the_controllers_own_answers(controller: VirtualController) -> None:
    c = controller
    c.set_active_tool(Tool(name="bent", tcp_mm=(20.0, -5.0, 150.0), abc_deg=(10.0, -60.0, 5.0)))
    T_base = np.eye(4)
    T_base[:3, :3] = Rotation.from_euler("ZYX", [30.0, 5.0, -10.0], degrees=True).as_matrix()
    T_base[:3, 3] = [0.4, -0.2, 0.1]
    c.set_T_world_base(T_base)
    c.mount_tool(builtin_tools()["torch"])
    for q in _configurations(c):
        c.set_q(q)
        st = pose_state(c)
        np.testing.assert_allclose(st.T_world_flange, c.T_world_flange(), atol=1e-14)
        np.testing.assert_allclose(st.T_world_tcp, c.T_world_tcp(), atol=1e-14)
        np.testing.assert_allclose(st.T_world_tool_true, c.T_world_tool_true(), atol=1e-14)
        links = c.link_poses()
        assert set(st.T_world_link) == set(links) == set(st.link_names)
        for name, T in links.items():
            np.testing.assert_allclose(st.T_world_link[name], T, atol=1e-14)
        assert st.joint_angles_deg == pytest.approx(c.joint_angles_deg(), abs=1e-12)
        assert st.touch == c.touch_geometry()
        for frame in ("WORLD", "BASE"):
            fast, ref = st.readout(frame), c.readout(frame)
            assert fast.frame == ref.frame
            for f in ("x_mm", "y_mm", "z_mm"):
                assert getattr(fast, f) == pytest.approx(getattr(ref, f), abs=1e-9)
            for f in ("a_deg", "b_deg", "c_deg"):
                assert _angle_diff_deg(getattr(fast, f), getattr(ref, f)) < 1e-6
            # what the pendant shows is the same text
            assert tcp_readout_markdown(fast, "bent") == tcp_readout_markdown(ref, "bent")
        assert touch_indicator_markdown(st.touch, hide_distance=False) == \
            touch_indicator_markdown(c.touch_geometry(), hide_distance=False)
    with pytest.raises(ValueError, match="WORLD or BASE"):
        pose_state(c).readout("TOOL")


def _yardstick():
    from bench import scene_yardstick

    return scene_yardstick


def test_pose_state_is_the_code_it_replaced_bit_for_bit(controller: VirtualController, kr6) -> None:
    """Every field equal to the yardstick's (``tests/bench/scene_yardstick.py``, the code before
    the speed work): the same numbers, not close ones; with tool data, BASE, another tool, and a
    physical robot that differs from the model."""
    legacy_pose_state = _yardstick().legacy_pose_state
    c = controller
    perturbed = kr6.own_copy()
    perturbed.model = kr6.model.copy()
    perturbed.model.jointPlacements[2].translation += np.array([0.0005, -0.0003, 0.0002])
    perturbed.data = perturbed.model.createData()
    for setup in range(3):
        if setup == 1:
            c.set_active_tool(Tool(name="bent", tcp_mm=(20.0, -5.0, 150.0), abc_deg=(10.0, -60.0, 5.0)))
            T_base = np.eye(4)
            T_base[:3, 3] = [0.4, -0.2, 0.1]
            c.set_T_world_base(T_base)
            c.mount_tool(builtin_tools()["torch"])
        if setup == 2:
            c.set_true_kinematics(perturbed)
        for q in _configurations(c, 6):
            c.set_q(q)
            new, old = pose_state(c), legacy_pose_state(c)
            assert new.key == old.key == _yardstick().legacy_pose_state_key(c) == pose_state_key(c)
            assert new.link_names == old.link_names
            for f in ("q_rad", "T_world_links", "T_world_flange", "T_world_tcp", "T_world_tool_true", "T_world_base"):
                np.testing.assert_array_equal(getattr(new, f), getattr(old, f), err_msg=f)
            assert list(new.T_world_link) == list(old.T_world_link)
            for name in old.T_world_link:
                np.testing.assert_array_equal(new.T_world_link[name], old.T_world_link[name])
            assert not new.T_world_links.flags.writeable
            assert not new.T_world_link[new.link_names[0]].flags.writeable
            assert list(new.joint_angles_deg.items()) == list(old.joint_angles_deg.items())
            assert new.touch == old.touch
            assert new.readout("BASE") == old.readout("BASE")


def test_touch_geometry_is_the_code_it_replaced_bit_for_bit_at_the_crash_zone_edges() -> None:
    """Random true TOOL poses with the reference tip all around the TCP, many of them at the
    crash zone's edges (2 mm radius, 20 mm depth) and the touch tolerance: the yardstick's
    numbers and verdicts."""
    from tcp_pendant.controller.touch import touch_geometry

    legacy = _yardstick().legacy_touch_geometry
    rng = np.random.default_rng(12)
    Rs = Rotation.random(3000, random_state=13).as_matrix()
    crashed = inside = 0
    for i, R in enumerate(Rs):
        T = np.eye(4)
        T[:3, :3] = R
        T[:3, 3] = rng.uniform(-0.8, 0.8, 3)
        depth = rng.choice([rng.uniform(-1.0, 25.0), 20.0, 0.5, rng.uniform(19.9, 20.1)])
        rho = rng.choice([rng.uniform(0.0, 3.0), 2.0, rng.uniform(1.99, 2.01), 0.0])
        phi = rng.uniform(0.0, 2.0 * np.pi)
        u_mm = np.array([-depth, rho * np.cos(phi), rho * np.sin(phi)]) * rng.choice([1.0, 1.0, 30.0])
        tip = T[:3, 3] + R @ (u_mm / 1000.0)
        new, old = touch_geometry(T, tip), legacy(T, tip)
        assert new == old, (i, new, old)
        crashed += new.crashed
        inside += new.penetration_mm > 0.0
    assert crashed > 100 and inside > crashed                   # the zone and its edges were exercised


def test_pose_state_key_follows_every_input(controller: VirtualController) -> None:
    c = controller
    keys = [pose_state_key(c)]
    c.jog_joint(1, 1.0)
    keys.append(pose_state_key(c))
    c.set_active_tool(Tool(name="t", tcp_mm=(0.0, 0.0, 100.0)))
    keys.append(pose_state_key(c))
    c.mount_tool(builtin_tools()["gripper"])
    keys.append(pose_state_key(c))
    c.set_reference_tip(c.reference_tip_world_m + 0.01)
    keys.append(pose_state_key(c))
    T = np.eye(4)
    T[0, 3] = 0.1
    c.set_T_world_base(T)
    keys.append(pose_state_key(c))
    c.set_true_kinematics(c.kinematics.own_copy())            # another physical robot
    keys.append(pose_state_key(c))
    assert len(set(keys)) == len(keys)
    assert pose_state_key(c) == keys[-1]                      # nothing changed: same key


# ------------------------------------------------------------------ in a served session
def _session(app):
    client = DrainingClient(app.port)
    wait_until(lambda: len(app.sessions) == 1, what="session built")
    (s,) = app.sessions.values()
    return client, s


def _world_pose(handle_chain: list) -> np.ndarray:
    """Compose the local poses of nested scene nodes (root first), as the browser does."""
    T = np.eye(4)
    for h in handle_chain:
        L = np.eye(4)
        w, x, y, z = (float(v) for v in h.wxyz)
        L[:3, :3] = Rotation.from_quat([x, y, z, w]).as_matrix()
        L[:3, 3] = np.asarray(h.position, dtype=float)
        T = T @ L
    return T


def _check_scene_matches_controller(s, tol: float) -> None:
    view = s.views["scene"]
    c = s.controller
    by_path = {view.link_paths[n]: view.link_frames[n] for n in view.link_frames}
    for name, T_ref in c.link_poses().items():
        path = view.link_paths[name]
        parts = path.split("/")
        chain = [by_path["/".join(parts[:i])] for i in range(3, len(parts) + 1) if "/".join(parts[:i]) in by_path]
        np.testing.assert_allclose(_world_pose(chain), T_ref, atol=tol, err_msg=name)
    np.testing.assert_allclose(_world_pose([view.gizmo]), c.T_world_tcp(), atol=tol)


def test_nested_scene_shows_the_controllers_link_poses(app_factory) -> None:
    """What the browser composes (nested link frames, gizmo) is the controller's robot, after
    Cartesian and joint jogs, to below the pendant's resolution (0.01 mm; poses that moved
    less than that are not re-sent)."""
    shown = 1e-5                                                # 0.01 mm; 1e-5 in R entries
    app = app_factory()
    client, s = _session(app)
    try:
        view = s.views["scene"]
        k = s.controller.kinematics
        # nested like the URDF tree
        assert view.link_paths["link_6"] == "/robot/base_link/link_1/link_2/link_3/link_4/link_5/link_6"
        assert view.flange_path == view.link_paths[k.flange_link] == view.link_paths["link_6"] + "/flange"
        _check_scene_matches_controller(s, 1e-12)
        moves = [("X", 1, "10"), ("A", 1, "10"), ("C", -1, "1"), ("Z", -1, "100"), ("B", 1, "0.1")]
        for axis, sign, inc in moves:
            with s.lock:
                s.jogger.settings = s.jogger.settings.with_(increment=inc)
                res = s.jogger.key(axis, sign)
                assert res is not None and res.ok, res
                s.moved()
            _check_scene_matches_controller(s, shown)
        with s.lock:
            s.controller.jog_joint(0, 5.0)
            s.moved()
        _check_scene_matches_controller(s, shown)
    finally:
        client.close()


def test_only_changed_poses_are_sent(app_factory) -> None:
    """A joint jog of A1 re-sends one orientation (link_1's) and the gizmo, which hangs in
    WORLD; nothing moves: nothing is sent."""
    app = app_factory()
    client, s = _session(app)
    try:
        view = s.views["scene"]
        sent: list[tuple[str, str]] = []                           # (node, message) queued
        ws = view.gizmo._impl.api._websock_interface
        real = ws.queue_message

        def spy(message):
            if type(message).__name__ in ("SetOrientationMessage", "SetPositionMessage"):
                sent.append((message.name, type(message).__name__))
            return real(message)

        ws.queue_message = spy
        try:
            with s.lock:
                s.moved()                                          # nothing moved
            assert sent == []
            with s.lock:
                s.controller.jog_joint(0, 3.0)
                s.moved()
        finally:
            del ws.queue_message
        names = {n for n, _ in sent}
        assert names == {view.link_paths["link_1"], "/tcp_gizmo"}, sent
        assert [m for n, m in sent if n == view.link_paths["link_1"]] == ["SetOrientationMessage"]   # orientation only
    finally:
        client.close()


def test_session_pose_state_is_shared_until_the_robot_moves(app_factory) -> None:
    app = app_factory()
    client, s = _session(app)
    try:
        st = s.pose_state()
        assert s.pose_state() is st
        with s.lock:
            s.controller.jog_joint(2, 1.0)
        st2 = s.pose_state()
        assert st2 is not st
        np.testing.assert_allclose(st2.T_world_flange, s.controller.T_world_flange(), atol=1e-14)
    finally:
        client.close()
