"""Drawing a ROS description's meshes says nothing to the console but what concerns the robot:
yourdfpy's own use of trimesh's deprecated ``Scene.dump(concatenate=True)`` (it joins a link's
geometries) raises no DeprecationWarning through us (``tcp_pendant.views.meshes``)."""

from __future__ import annotations

import warnings
from pathlib import Path

from support.ros_layouts import acme7_workspace
from tcp_pendant.controller.description import load_description
from tcp_pendant.views.meshes import link_meshes


def test_drawing_a_xacro_robot_raises_no_deprecation_warning(tmp_path: Path, monkeypatch) -> None:
    ws = acme7_workspace(tmp_path / "robot")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(ws.ros_package_path))
    description = load_description(ws.xacro, (ws.package_path,))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        meshes = link_meshes(description)
    assert set(ws.meshes) <= set(meshes)                      # every link drawn from its mesh
    assert [str(w.message) for w in caught if issubclass(w.category, DeprecationWarning)] == []
