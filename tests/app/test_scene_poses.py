"""The scene's link poses: ``relative_poses`` against ``inv(T_parent) @ T_child``, and the
poses the scene sends for a jog step chained back to the pose state's ``T_world_link``."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

import pytest
from tcp_pendant.views.scene import relative_poses
from support.wsclient import DrainingClient, wait_until

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _rigid(rng: np.random.Generator, n: int) -> np.ndarray:
    T = np.tile(np.eye(4), (n, 1, 1))
    T[:, :3, :3] = Rotation.random(n, random_state=rng).as_matrix()
    T[:, :3, 3] = rng.normal(size=(n, 3))
    return T


def test_relative_poses_are_the_parent_inverse_times_the_child_into_a_buffer_or_not() -> None:
    rng = np.random.default_rng(4)
    P, C = _rigid(rng, 7), _rigid(rng, 7)
    expected = np.linalg.inv(P) @ C
    np.testing.assert_allclose(relative_poses(P, C), expected, atol=1e-12)
    buffer = np.full((9, 4, 4), np.nan)                   # a view of a larger buffer, stale values
    got = relative_poses(P, C, out=buffer[:7])
    assert np.shares_memory(got, buffer)                  # written in place
    np.testing.assert_allclose(buffer[:7], expected, atol=1e-12)
    assert np.isnan(buffer[7:]).all()                    # nothing written beyond the view
    again = np.full((7, 4, 4), np.nan)                    # the scene's buffer: bottom rows left as they are
    relative_poses(P, C, out=again, work=np.full((7, 3, 4), np.nan), bottom_rows_set=True)
    np.testing.assert_allclose(again[:, :3], expected[:, :3], atol=1e-12)
    assert np.isnan(again[:, 3]).all()


def test_the_scene_poses_chain_back_to_the_links_world_poses_after_jogs(app_factory) -> None:
    app = app_factory()
    client = DrainingClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 1, what="session built")
        (s,) = app.sessions.values()
        scene = s.views["scene"]
        for axis, amount in (("X", 5.0), ("Z", -3.0), ("A", 10.0)):
            with s.lock:
                assert s.controller.jog_cartesian("WORLD", axis, amount).ok
                s.moved()
            state = s.pose_state()
            local = scene._local_poses(state).copy()
            row = {n: i for i, n in enumerate(state.link_names)}
            world: dict[str, np.ndarray] = {}
            for i, name in enumerate(scene._moving):         # parents come before children
                parent = scene._parent[name]
                world[name] = local[i] if parent is None else world.get(
                    parent, state.T_world_links[row[parent]]) @ local[i]
                np.testing.assert_allclose(world[name], state.T_world_links[row[name]], atol=1e-12)
            np.testing.assert_allclose(local[-1], state.T_world_tcp, atol=0)
    finally:
        client.close()


def test_the_scene_queues_the_same_messages_as_the_code_it_replaced(app_factory, monkeypatch) -> None:
    """``SceneView.on_change`` against its yardstick (``tests/bench/scene_yardstick.py``, the
    code before the speed work) on the same change, from the same last sent poses: the same
    messages (class, node, values bit for bit), none for an unchanged node, over the class's
    0.1 mm steps, larger jogs, rotations and the gizmo forced after a drag."""
    from bench.scene_yardstick import LegacyScenePoses

    from tcp_pendant.session import SessionChange

    app = app_factory()
    client = DrainingClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 1, what="session built")
        (s,) = app.sessions.values()
        scene = s.views["scene"]
        legacy = LegacyScenePoses(scene)
        ws = scene.gizmo._impl.api._websock_interface
        queued: list[object] = []
        real = ws.queue_message
        monkeypatch.setattr(ws, "queue_message", lambda m: (queued.append(m), real(m))[1])

        def messages(fn: object, change: SessionChange) -> list[tuple[object, ...]]:
            queued.clear()
            fn(change)                                    # type: ignore[operator]
            return [(type(m).__name__, m.name, getattr(m, "wxyz", None), getattr(m, "position", None))
                    for m in queued if type(m).__name__ in ("SetOrientationMessage", "SetPositionMessage")]

        moves = [("X", 0.1)] * 6 + [("X", -0.1)] * 3 + [("Z", 2.0), ("Y", -5.0), ("A", 3.0), ("C", -0.1),
                                                           ("X", 0.0)]
        counts = []
        for axis, amount in moves:
            with s.lock:
                assert s.controller.jog_cartesian("WORLD", axis, amount).ok
                change = SessionChange(pose=True, state=s.pose_state())
                legacy.take_sent()
                old = messages(legacy.on_change, change)
                new = messages(scene.on_change, change)
                assert new == old, (axis, amount)
                assert messages(scene.on_change, change) == []     # nothing moved since
                counts.append(len(new))
        assert min(counts[:-1]) >= 2 and counts[-1] == 0           # every step moved links and the gizmo
        with s.lock:                                               # the gizmo after a drag: always resent
            legacy.take_sent()
            queued.clear()
            legacy.send(legacy._local_poses(s.pose_state()), force=(scene._gizmo_row,))
            old = [(type(m).__name__, m.name) for m in queued]
            queued.clear()
            scene._snap_gizmo()
            assert [(type(m).__name__, m.name) for m in queued] == old == [
                ("SetOrientationMessage", "/tcp_gizmo"), ("SetPositionMessage", "/tcp_gizmo")]
    finally:
        client.close()


def test_runs_of_rows_are_read_as_slices_other_rows_as_indices() -> None:
    """The scene reads a serial arm's parent and child rows as slices (views); a tree's (a UR's
    ee_link and tool0 on one parent) or a reordered list stay index arrays: the same rows."""
    from tcp_pendant.views.scene import _as_slice

    W = np.arange(10 * 16, dtype=float).reshape(10, 4, 4)
    for rows in ([1, 2, 3], [0], [4, 5, 6, 7, 8, 9]):
        got = _as_slice(np.array(rows))
        assert isinstance(got, slice) and np.shares_memory(W[got], W)
        np.testing.assert_array_equal(W[got], W[rows])
    for rows in ([0, 2, 3], [3, 2], [5, 5], []):
        got = _as_slice(np.array(rows, dtype=int))
        assert isinstance(got, np.ndarray)
        np.testing.assert_array_equal(W[got], W[np.array(rows, dtype=int)])
