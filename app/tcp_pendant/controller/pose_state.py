"""One consistent picture of the robot after a move, computed once and shared by every view.

A jog step redraws the scene (a pose per link, the gizmo on the TCP), the TCP readout, the
touch indicator and the joint readout, and the wizard views' motion listeners look at the
flange. Asking the controller for each of these separately runs forward kinematics four times
and scipy's Euler conversion once per step; :func:`pose_state` runs pinocchio's FK once
(``controller.link_poses()``, which includes the FLANGE link) and derives the rest from it:

* ``T_world_flange = T_world_link[flange_link]`` (the same pinocchio frame placement as
  ``controller.T_world_flange()``),
* ``T_world_tcp = T_world_flange @ T_flange_tool`` (active tool data),
* ``T_world_tool_true = T_world_flange @ T_flange_tool_true`` (mounted tool, hidden; on the
  physical robot ``controller.true_kinematics`` when it differs from the model: one more FK),
* the readout (``controller.readout``) and the touch geometry (``controller.touch_geometry``)
  from those, with the readout's A, B, C by :func:`tcp_pendant.controller.rotations.kuka_abc_deg`.

``tests/app/test_pose_state.py`` checks every field against the controller's own methods.
No viser.
"""

from __future__ import annotations

import operator
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import cast

import numpy as np

from tcp_pendant.controller.controller import VirtualController
from tcp_pendant.controller.readout import PoseReadout, readout_in_frame
from tcp_pendant.controller.touch import TouchGeometry, touch_geometry

__all__ = ["LinkPoses", "PoseState", "pose_state", "pose_state_key"]


@dataclass(frozen=True, eq=False)
class PoseState:
    """The robot at one joint configuration (metres, radians; WORLD = the robot's root link).

    Attributes:
        key: :func:`pose_state_key` of the controller it was computed from.
        q_rad: joint angles.
        link_names: every URDF link (pinocchio BODY frames), in pinocchio's frame order.
        T_world_links: (N,4,4) ``T_world_link`` of those links, stacked in that order.
        T_world_link: the same by link name (views into ``T_world_links``).
        T_world_flange, T_world_tcp, T_world_tool_true: FLANGE, active TCP and the mounted
            tool's hidden true TCP in WORLD.
        T_world_base: the BASE (work object) frame.
        joint_angles_deg: joint readout, name -> degrees (mm for prismatic joints).
        touch: true tool tip vs reference tip (``controller.touch_geometry()``).
    """

    key: tuple[object, ...]
    q_rad: np.ndarray
    link_names: tuple[str, ...]
    T_world_links: np.ndarray
    T_world_link: Mapping[str, np.ndarray]
    T_world_flange: np.ndarray
    T_world_tcp: np.ndarray
    T_world_tool_true: np.ndarray
    T_world_base: np.ndarray
    joint_angles_deg: Mapping[str, float]
    touch: TouchGeometry
    _readouts: dict[str, PoseReadout] = field(default_factory=dict, repr=False)

    def readout(self, frame: str = "WORLD") -> PoseReadout:
        """The active TCP as X, Y, Z (mm) and KUKA A, B, C (deg) in WORLD or BASE
        (``controller.readout``).

        Raises:
            ControllerError: another frame (a ValueError).
        """
        f = str(frame).upper()
        cached = self._readouts.get(f)
        if cached is not None:
            return cached
        out = readout_in_frame(self.T_world_tcp, self.T_world_base, f)
        self._readouts[f] = out
        return out


def pose_state_key(controller: VirtualController) -> tuple[object, ...]:
    """What a :class:`PoseState` depends on: joint angles, active tool data, mounted tool,
    reference tip, BASE frame and the robot model (nominal first, the physical robot last).
    Equal keys, equal states."""
    return controller.pose_state_key()


class LinkPoses(Mapping[str, np.ndarray]):
    """``T_world_link`` by link name: read-only views into the stacked poses, made when asked
    (a jog step's scene reads the stack; only a view being built asks by name)."""

    __slots__ = ("_rows", "_stacked")

    def __init__(self, rows: Mapping[str, int], stacked: np.ndarray) -> None:
        self._rows = rows
        self._stacked = stacked

    def __getitem__(self, name: str) -> np.ndarray:
        return cast(np.ndarray, self._stacked[self._rows[name]])

    def __iter__(self) -> Iterator[str]:
        return iter(self._rows)

    def __len__(self) -> int:
        return len(self._rows)


def pose_state(controller: VirtualController, key: tuple[object, ...] | None = None) -> PoseState:
    """Compute the :class:`PoseState` of ``controller`` (one pinocchio FK pass).

    Args:
        controller: the controller (the caller holds the session lock).
        key: its :func:`pose_state_key`, if already computed.
    """
    c = controller
    k = c.kinematics
    q = c.q_rad
    stacked = k.link_poses_array(q)
    stacked.setflags(write=False)
    rows = k.link_rows
    T_world_flange = stacked[rows[k.flange_link]]
    T_world_tcp = T_world_flange @ c.T_flange_tool
    T_true_flange = T_world_flange if c.true_kinematics is k else c.T_world_flange_true()
    T_world_true = T_true_flange @ c.mounted_tool.T_flange_tool_true
    angles = dict(zip(k.joint_names, map(operator.mul, q.tolist(), k.readout_scales)))
    for T in (T_world_tcp, T_world_true):
        T.setflags(write=False)
    return PoseState(
        key=pose_state_key(c) if key is None else key,
        q_rad=q,
        link_names=tuple(rows),
        T_world_links=stacked,
        T_world_link=LinkPoses(rows, stacked),
        T_world_flange=T_world_flange,
        T_world_tcp=T_world_tcp,
        T_world_tool_true=T_world_true,
        T_world_base=c.T_world_base,
        joint_angles_deg=angles,
        touch=touch_geometry(T_world_true, c.reference_tip_world_m),
    )
