"""The virtual robot controller. No viser.

Modules, one job each:

* ``description``: a robot description as ROS packages ship it (xacro, ``package://``, missing
  meshes, mimic and continuous joints) -> one resolved URDF text.
* ``kinematics``: :class:`RobotKinematics` (URDF -> pinocchio: limits, home, FK, Jacobian).
* ``placement``: a foreign robot's reference tip and ready pose, computed from its model.
* ``assets``: where ``robots/`` (or the packaged ``_robots``) and example-robot-data live.
* ``tools``: :class:`ToolModel` (physical tool with its hidden true TOOL frame),
  :func:`builtin_tools`, :func:`builtin_robots`, the reference tip model.
* ``jog``: Cartesian path following by damped least squares with the safety rules.
* ``approach``: inverse kinematics and the auto-approach target.
* ``readout``, ``touch``: the pendant's pose readout and the touch/crash geometry.
* ``beam``, ``beam_scan``: the virtual beam sensor (BullsEye / TRACC style) and its automatic
  scan (:func:`run_beam_scan`).
* ``controller``: :class:`VirtualController`, the state and the commands.
"""

from tcp_pendant.controller.approach import approach_pose, approach_rotation, solve_ik
from tcp_pendant.controller.assets import example_robot_urdf, robots_dir
from tcp_pendant.controller.beam import BeamEvent, BeamSensor, ToolShape
from tcp_pendant.controller.beam_scan import (
    BeamDevice,
    BeamScan,
    BeamScanConfig,
    ScanMove,
    default_beam_sensor,
    run_beam_scan,
    tool_shape,
)
from tcp_pendant.controller.controller import VirtualController
from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.controller.jog import JogFrame, JogResult, JogSettings
from tcp_pendant.controller.kinematics import RobotKinematics
from tcp_pendant.controller.readout import PoseReadout
from tcp_pendant.controller.tools import (
    ReferenceTipModel,
    T_flange_tool_m,
    ToolModel,
    builtin_robots,
    builtin_tools,
    load_tool,
    reference_tip_model,
)
from tcp_pendant.controller.touch import TouchGeometry

__all__ = [
    "BeamEvent",
    "BeamDevice",
    "BeamScan",
    "BeamScanConfig",
    "BeamSensor",
    "ScanMove",
    "ToolShape",
    "ControllerError",
    "JogFrame",
    "JogResult",
    "JogSettings",
    "PoseReadout",
    "ReferenceTipModel",
    "RobotKinematics",
    "T_flange_tool_m",
    "ToolModel",
    "TouchGeometry",
    "VirtualController",
    "approach_pose",
    "approach_rotation",
    "builtin_robots",
    "builtin_tools",
    "default_beam_sensor",
    "example_robot_urdf",
    "load_tool",
    "reference_tip_model",
    "robots_dir",
    "run_beam_scan",
    "solve_ik",
    "tool_shape",
]
