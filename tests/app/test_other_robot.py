"""The pendant on a robot of someone else's URDF: the UR5 of example-robot-data (any
URDF given on the command line loads, flange = the last link of the longest chain)."""

from __future__ import annotations


import numpy as np
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.controller import JogFrame, builtin_tools, example_robot_urdf
from tcp_pendant.serve.server import MIN_TIP_HEIGHT_M

from support.wsclient import wait_until
from support.wsclient import DrainingClient


def test_ur5_session_starts_over_a_visible_tip_and_calibrates(app_factory) -> None:
    app = app_factory(robot=str(example_robot_urdf()), seed=1)
    assert app.kinematics.flange_link == "tool0"
    tip = app.reference_tip_m
    assert tip[2] >= MIN_TIP_HEIGHT_M                        # the stand is above the floor
    client = DrainingClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 1, what="session built")
        (s,) = app.sessions.values()
        c = s.controller
        T = c.T_world_flange()
        assert T[2, 2] < -0.999                              # flange pointing down ...
        np.testing.assert_allclose(T[:3, 3], tip + [0.0, 0.0, 0.25], atol=1e-9)   # ... above the tip
        with s.lock:                                         # jogs like the KR 6 (not singular)
            for axis in ("X", "Y", "Z"):
                assert c.jog_cartesian(JogFrame.WORLD, axis, -10.0).ok, axis
        # a 4-point calibration by the session's commands gives the pointer's true TCP
        wf = s.workflow
        with s.lock:
            s.wizard_commands.start("xyz4")
            for _ in range(4):
                assert s.wizard_commands.auto_touch(AutoTouchRequest()).ok
        true_tcp = builtin_tools()["pointer"].T_flange_tool_true[:3, 3] * 1000.0
        np.testing.assert_allclose(wf.result.tcp_mm, true_tcp, atol=1e-6)
        assert wf.export_record()["robot"]["name"] == "ur5_robot"
    finally:
        client.close()
