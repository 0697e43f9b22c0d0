"""The virtual robot controller: state, jogging, readouts, touch geometry and auto-approach.

Frames (metres and radians inside; the pendant-facing arguments say mm / deg in their names):

* WORLD: the robot's root link frame (methods.md section 1, S0). ``T_world_flange`` is the
  kinematics' ``T_world_flange`` at the current joint angles.
* BASE: the work-object frame (KUKA BASE), ``T_world_base``; used for jogging and readouts.
* FLANGE: the robot's ``flange`` link (Z out of the flange face).
* TOOL (active TCP): what the controller *believes*: the active ``tcpcal.Tool`` data,
  ``T_flange_tool`` from its ``tcp_mm`` and KUKA ``abc_deg``; the flange when no tool is active.
* true TOOL: the mounted tool's hidden ``T_flange_tool_true`` (from its URDF).

Two robot models: ``kinematics`` is the controller's NOMINAL model (readouts, recorded flange
poses, jogs, the TCP check's motion); ``true_kinematics`` is the PHYSICAL robot (default the
same object), which differs in the absolute-accuracy scenario (``scenarios.py``): where the
true tool tip really is (:meth:`VirtualController.T_world_tool_true`,
:meth:`VirtualController.touch_geometry`) and where auto-approach and
:meth:`VirtualController.move_true_tool_to` put it (their IK runs on the physical robot, as a
technician's eye does) come from it.

Jogging follows ``jog.py`` (damped least squares, sub-stepped, safety rules); see
:meth:`VirtualController.jog_cartesian` for the axis conventions.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

import numpy as np
from scipy.spatial.transform import Rotation

from tcpcal.tool import Tool
from tcp_pendant.controller.approach import approach_pose, solve_ik
from tcp_pendant.controller.beam import BeamSensor
from tcp_pendant.controller.beam_scan import BeamDevice, default_beam_sensor
from tcp_pendant.controller.checks import check_pose
from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.controller.jog import (
    DEFAULT_SETTINGS,
    CartesianPath,
    FlangeState,
    JogFrame,
    JogResult,
    JogSettings,
    follow_path,
)
from tcp_pendant.controller.kinematics import RobotKinematics
from tcp_pendant.controller.readout import PoseReadout, readout_in_frame
from tcp_pendant.controller.tools import T_flange_tool_m, ToolModel
from tcp_pendant.controller.touch import TouchGeometry, touch_geometry
from tcp_pendant.controller.words import Words
from tcp_pendant.translation import N_

__all__ = ["VirtualController"]

_AXES = {"X": 0, "Y": 1, "Z": 2, "A": 2, "B": 1, "C": 0}
_FRAMES: dict[str, JogFrame] = {f.value: f for f in JogFrame}
_WORLD_AXES = np.eye(3)
_WORLD_AXES.setflags(write=False)
_NO_ROTATION = np.zeros(3)
_NO_ROTATION.setflags(write=False)


def _check_point(p: Sequence[float] | np.ndarray, what: str) -> np.ndarray:
    v = np.asarray(p, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ControllerError(f"{what} must be 3 finite numbers (x, y, z in metres), got {p!r}.")
    return v.copy()


def _finite(value: float, what: str) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ControllerError(f"{what} must be a number, got {value!r}.") from None
    if not math.isfinite(out):
        raise ControllerError(f"{what} must be finite, got {value!r}.")
    return out


class VirtualController:
    """A robot controller in software (see the module docstring for the frames).

    Args:
        kinematics: the robot.
        tool: the physical tool mounted on the flange.
        reference_tip_world_m: the reference tip (WORLD, metres); default: below the home
            flange position, at half its height.
        active_tool: the tool data the controller believes (None: TCP = flange).
        T_world_base: BASE frame (4,4, metres).
        settings: jog tuning (``jog.JogSettings``).
        true_kinematics: the physical robot when it differs from the model (the
            absolute-accuracy scenario); default ``kinematics`` itself. Same joints.

    Not thread-safe: the app's session serialises calls with its lock.
    """

    def __init__(self, kinematics: RobotKinematics, *, tool: ToolModel,
                 reference_tip_world_m: Sequence[float] | np.ndarray | None = None,
                 active_tool: Tool | None = None, T_world_base: np.ndarray | None = None,
                 settings: JogSettings = DEFAULT_SETTINGS,
                 true_kinematics: RobotKinematics | None = None) -> None:
        self.kinematics = kinematics
        self._true_kin = kinematics
        self.set_true_kinematics(true_kinematics)
        self.settings = settings
        self._q = np.array(kinematics.home_rad, dtype=float)
        self._rest_q = np.array(kinematics.home_rad, dtype=float)
        self._state: FlangeState | None = None
        """The kinematics where the last path ended (Jacobian, pose, sigma_min, det sign): the next
        jog starts from it while the robot is still exactly there (``FlangeState.valid_for``);
        dropped whenever q, the model or the tool data are set any other way."""
        self._tool = tool
        self._active: Tool | None = None
        self._active_on: ToolModel | None = None        # the tool on the flange when the data became active
        self._T_flange_tool = np.eye(4)
        self.set_active_tool(active_tool)
        self._T_world_base = np.eye(4) if T_world_base is None else check_pose(T_world_base, "T_world_base")
        if reference_tip_world_m is None:
            p = kinematics.T_world_flange(kinematics.home_rad)[:3, 3]
            reference_tip_world_m = (p[0], p[1], 0.5 * p[2])
        self._tip = _check_point(reference_tip_world_m, "reference_tip_world_m")
        self._beam: BeamSensor | None = None  # None: default_beam_sensor(reference tip)
        self._default_beam: tuple[bytes, BeamSensor] | None = None  # (tip's bytes, its default sensor)
        self._beam_device = BeamDevice()  # the default sensor's width, repeatability, crossing

    # ----------------------------------------------------------------- state
    @property
    def q_rad(self) -> np.ndarray:
        """Joint angles (rad; m for prismatic joints), a copy."""
        return self._q.copy()

    def set_q(self, q_rad: Sequence[float] | np.ndarray) -> None:
        """Set the joint angles (teleport).

        Raises:
            ControllerError: wrong length, not finite, or outside the limits (names the axis).
        """
        q = self.kinematics.check_q(q_rad)
        viol = self.kinematics.limit_violation(q, tol=1e-9)
        if viol is not None:
            i, side = viol
            k = self.kinematics
            limit = (k.lower_rad if side == "lower" else k.upper_rad)[i]
            raise ControllerError(f"{k.joint_names[i]} = {k.format_joint(i, q[i])} is beyond its {side} "
                                  f"limit {k.format_joint(i, limit)}; give angles within the limits.")
        self._q = np.clip(q, self.kinematics.lower_rad, self.kinematics.upper_rad)
        self._state = None

    def joint_angles_deg(self) -> dict[str, float]:
        """Joint readout: name -> degrees (mm for prismatic joints), in joint order."""
        k = self.kinematics
        return {name: float(math.degrees(v) if k.revolute[i] else v * 1000.0)
                for i, (name, v) in enumerate(zip(k.joint_names, self._q))}

    def go_home(self) -> None:
        """Teleport to the home configuration."""
        self._q = np.array(self.kinematics.home_rad, dtype=float)
        self._state = None

    @property
    def rest_q_rad(self) -> np.ndarray:
        """The rest configuration a redundant (7-axis) arm's Cartesian jogs keep its self-motion
        near (``jog`` J-3; default HOME, the app sets its ready pose), a copy."""
        return self._rest_q.copy()

    def set_rest_configuration(self, q_rad: Sequence[float] | np.ndarray) -> None:
        """Set :attr:`rest_q_rad` (rad; checked like :meth:`set_q`)."""
        self._rest_q = np.array(self.kinematics.check_q(q_rad), dtype=float)

    @property
    def true_kinematics(self) -> RobotKinematics:
        """The physical robot (``kinematics`` itself unless a scenario perturbed it)."""
        return self._true_kin

    def set_true_kinematics(self, true_kinematics: RobotKinematics | None) -> None:
        """Set the physical robot (None: the nominal model itself).

        Raises:
            ControllerError: a robot with other joints than the nominal model.
        """
        self._state = None
        if true_kinematics is None:
            self._true_kin = self.kinematics
            return
        if not isinstance(true_kinematics, RobotKinematics):
            raise ControllerError(f"true_kinematics must be a RobotKinematics, got {type(true_kinematics).__name__}.")
        if tuple(true_kinematics.joint_names) != tuple(self.kinematics.joint_names):
            raise ControllerError(f"true_kinematics has joints {', '.join(true_kinematics.joint_names)} but the "
                                  f"model has {', '.join(self.kinematics.joint_names)}; give the same robot.")
        self._true_kin = true_kinematics

    def kinematics_for_worker(self) -> tuple[RobotKinematics, RobotKinematics]:
        """(nominal, physical) robots with their own pinocchio data, for a job in a worker thread
        (a check, a scan); physical is the nominal copy itself when there is no accuracy error."""
        nominal = self.kinematics.own_copy()
        physical = nominal if self._true_kin is self.kinematics else self._true_kin.own_copy()
        return nominal, physical

    @property
    def mounted_tool(self) -> ToolModel:
        """The physical tool on the flange."""
        return self._tool

    def mount_tool(self, tool: ToolModel) -> None:
        """Bolt another physical tool on (the active tool data does not change)."""
        if not isinstance(tool, ToolModel):
            raise ControllerError(f"mount_tool expects a ToolModel, got {type(tool).__name__}.")
        self._tool = tool

    @property
    def active_tool(self) -> Tool | None:
        """The tool data the controller believes (None: TCP = flange)."""
        return self._active

    def set_active_tool(self, tool: Tool | None) -> None:
        """Select the active tool data; ``T_flange_tool`` = its ``tcp_mm`` (in m) and ``abc_deg``."""
        self._state = None
        if tool is None:
            self._active, self._T_flange_tool, self._active_on = None, np.eye(4), None
            return
        if not isinstance(tool, Tool):
            raise ControllerError(f"set_active_tool expects a tcpcal.Tool or None, got {type(tool).__name__}.")
        self._active, self._T_flange_tool, self._active_on = tool, T_flange_tool_m(tool), self._tool

    @property
    def active_data_mounted_on(self) -> ToolModel | None:
        """The physical tool that was on the flange when the active tool data was selected
        (None: no data active): the data is that tool's, whatever is bolted on since."""
        return self._active_on

    @property
    def T_flange_tool(self) -> np.ndarray:
        """Active TCP in FLANGE coordinates (4,4, metres), a copy."""
        return self._T_flange_tool.copy()

    @property
    def reference_tip_world_m(self) -> np.ndarray:
        """Reference tip position, WORLD, metres (a copy)."""
        return self._tip.copy()

    def set_reference_tip(self, tip_world_m: Sequence[float] | np.ndarray) -> None:
        """Move the reference tip (WORLD, metres)."""
        self._tip = _check_point(tip_world_m, "reference_tip_world_m")

    @property
    def beam_sensor(self) -> BeamSensor:
        """The beam sensor: the one set with :meth:`set_beam_sensor`, else
        ``beam_scan.default_beam_sensor`` of the current reference tip (it follows the tip when
        that is moved). The same object until it changes (views may compare by identity)."""
        if self._beam is not None:
            return self._beam
        tip = self._tip.tobytes()     # the scene asks every jog step: a bytes compare, not array_equal
        if self._default_beam is None or self._default_beam[0] != tip:
            self._default_beam = (tip, default_beam_sensor(self._tip, self._beam_device))
        return self._default_beam[1]

    @property
    def beam_device(self) -> BeamDevice:
        """The default beam sensor's width, repeatability and crossing (``--beam-*`` options)."""
        return self._beam_device

    def set_beam_device(self, device: BeamDevice) -> None:
        """Choose the default beam sensor's width, repeatability and crossing.

        Raises:
            ControllerError: not a ``BeamDevice``.
        """
        if not isinstance(device, BeamDevice):
            raise ControllerError(f"set_beam_device expects a BeamDevice, got {type(device).__name__}.")
        self._beam_device = device
        self._default_beam = None

    @property
    def beam_sensor_is_default(self) -> bool:
        """True while the beam sensor follows the reference tip (none set explicitly)."""
        return self._beam is None

    def set_beam_sensor(self, sensor: BeamSensor | None) -> None:
        """Place the beam sensor (WORLD, m); None: back to the default, which follows the
        reference tip.

        Raises:
            ControllerError: not a ``BeamSensor``.
        """
        if sensor is not None and not isinstance(sensor, BeamSensor):
            raise ControllerError(f"set_beam_sensor expects a BeamSensor or None, got {type(sensor).__name__}.")
        self._beam = sensor

    @property
    def T_world_base(self) -> np.ndarray:
        """BASE (work object) frame in WORLD, (4,4) metres (a copy)."""
        return self._T_world_base.copy()

    def set_T_world_base(self, T_world_base: np.ndarray) -> None:
        """Set the BASE frame (4,4, metres)."""
        self._T_world_base = check_pose(T_world_base, "T_world_base")

    # ----------------------------------------------------------------- poses
    def T_world_flange(self) -> np.ndarray:
        """FLANGE pose in WORLD (4,4, metres)."""
        return self.kinematics.T_world_flange(self._q)

    def T_world_tcp(self) -> np.ndarray:
        """Active TCP (tool data) pose in WORLD: ``T_world_flange @ T_flange_tool``."""
        return self.T_world_flange() @ self._T_flange_tool

    def T_world_flange_true(self) -> np.ndarray:
        """Where the physical robot's flange really is (``true_kinematics``), (4,4) metres."""
        return self._true_kin.T_world_flange(self._q)

    def T_world_tool_true(self) -> np.ndarray:
        """Hidden true TOOL pose in WORLD on the physical robot:
        ``true_kinematics.T_world_flange(q) @ T_flange_tool_true``."""
        return self.T_world_flange_true() @ self._tool.T_flange_tool_true

    def tool_tip_true_m(self) -> list[float]:
        """The true tool tip in WORLD (m, three Python floats): ``T_world_tool_true()[:3, 3]``
        to rounding (``R t + p`` summed in another order than the matrix product: within a few
        1e-16 m, not bit for bit), for tests with a margin far above that (the stop at
        contact's pre-test on every Cartesian press).

        From the flange pose the last jog ended on (its :class:`FlangeState`) when that state is
        of the physical robot at exactly the current ``q`` (compared on every call: a ``q`` set
        any other way is never answered from it); else from one FK pass.
        """
        t = self._tool.T_flange_tool_true[:3, 3].tolist()
        st = self._state
        if st is not None and st.kin is self._true_kin and st.q_list == self._q.tolist():
            (r0, r1, r2), p = st.R_wf.tolist(), st.p_wf.tolist()
        else:
            T = self.T_world_flange_true()
            r0, r1, r2 = T[:3, :3].tolist()
            p = T[:3, 3].tolist()
        tx, ty, tz = t
        return [r0[0] * tx + r0[1] * ty + r0[2] * tz + p[0], r1[0] * tx + r1[1] * ty + r1[2] * tz + p[1],
                r2[0] * tx + r2[1] * ty + r2[2] * tz + p[2]]

    def link_poses(self) -> dict[str, np.ndarray]:
        """``T_world_link`` for every robot link (scene updates)."""
        return self.kinematics.link_poses(self._q)

    def pose_state_key(self) -> tuple[object, ...]:
        """What the robot's pose state depends on (``pose_state.pose_state_key``): the robot
        model, joint angles, active tool data, mounted tool, reference tip, BASE frame and the
        physical robot, read without the copies the properties make (a jog step asks once)."""
        return (id(self.kinematics), self._q.tobytes(), self._T_flange_tool.tobytes(), id(self._tool),
                self._tip.tobytes(), self._T_world_base.tobytes(), id(self._true_kin))

    # ----------------------------------------------------------------- jogging
    def jog_joint(self, index: int, delta_deg: float) -> JogResult:
        """Turn one axis by ``delta_deg`` degrees (mm for a prismatic joint), clamped at its limit.

        Args:
            index: 0-based joint index (0 = A1).
            delta_deg: increment, degrees.

        Returns:
            ``ok`` when the whole increment was made; at a limit the axis stops on it with
            ``stopped_by="joint_limit"`` and e.g. "A5 at its limit +120.0 deg".
        """
        k = self.kinematics
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not 0 <= index < k.n_joints:
            raise ControllerError(f"Joint index must be 0..{k.n_joints - 1} ({', '.join(k.joint_names)}), "
                                  f"got {index!r}.")
        d = _finite(delta_deg, "delta_deg")
        delta = math.radians(d) if k.revolute[index] else d / 1000.0
        if delta == 0.0:
            return JogResult(True, 1.0, None, "")
        q = self._q.copy()
        target = q[index] + delta
        lo, hi = float(k.lower_rad[index]), float(k.upper_rad[index])
        if lo <= target <= hi:
            q[index] = target
            self._q, self._state = q, None
            return JogResult(True, 1.0, None, "")
        side = "upper" if target > hi else "lower"
        limit = hi if side == "upper" else lo
        moved = max(0.0, min(1.0, (limit - q[index]) / delta))
        q[index] = limit
        self._q, self._state = q, None
        return JogResult(False, moved, "joint_limit", k.limit_message(index, side))

    def _frame_rotation(self, frame: JogFrame) -> np.ndarray:
        """``R_world_frame`` of a jog frame now (read only: WORLD's and BASE's are not copies)."""
        if frame is JogFrame.WORLD:
            return _WORLD_AXES
        if frame is JogFrame.BASE:
            return self._T_world_base[:3, :3]
        if frame is JogFrame.FLANGE:
            return self.T_world_flange()[:3, :3]
        return self.T_world_tcp()[:3, :3]

    def jog_cartesian(self, frame: JogFrame | str, axis: Literal["X", "Y", "Z", "A", "B", "C"],
                      amount: float) -> JogResult:
        """Jog the active TCP by one increment in a jog frame.

        X, Y, Z: translate the TCP by ``amount`` mm along that axis of ``frame``.
        A, B, C: rotate the tool by ``amount`` degrees about the TCP, about the Z (A), Y (B) or
        X (C) axis of ``frame`` (KUKA habit: A, B, C are the angles about Z, Y, X). FLANGE
        and TOOL axes are taken at the start of the increment.

        The motion follows ``jog.follow_path`` (J-1, J-2): the TCP stays on its line to
        < 0.01 mm with the orientation held to < 0.001 deg; a rotation keeps the TCP fixed;
        it stops at joint limits and singularities with ``stopped_by`` and the message, and
        never jumps configuration. The app makes continuous jogging from small increments
        (speed * override * dt).
        """
        jf = _FRAMES.get(frame) if isinstance(frame, str) else None   # a JogFrame is a str too
        if jf is None:
            try:
                jf = JogFrame(frame.upper() if isinstance(frame, str) else frame)
            except ValueError:
                raise ControllerError(f"Unknown jog frame {frame!r}; use WORLD, BASE, FLANGE or TOOL.") from None
        ax = str(axis).upper()
        if ax not in _AXES:
            raise ControllerError(f"Unknown jog axis {axis!r}; use X, Y, Z (mm) or A, B, C (deg).")
        amt = _finite(amount, "jog amount")
        if amt == 0.0:
            return JogResult(True, 1.0, None, "")
        # T_world_tcp() (= T_world_flange() @ T_flange_tool) once: FLANGE and TOOL axes are taken from it
        T_wf = self.T_world_flange()
        T0 = T_wf @ self._T_flange_tool
        if jf is JogFrame.FLANGE:
            direction = T_wf[:3, _AXES[ax]]
        elif jf is JogFrame.TOOL:
            direction = T0[:3, _AXES[ax]]
        else:
            direction = self._frame_rotation(jf)[:, _AXES[ax]]
        if ax in "XYZ":
            path = CartesianPath(T0[:3, 3], T0[:3, :3], direction * (amt / 1000.0), _NO_ROTATION)
        else:
            path = CartesianPath(T0[:3, 3], T0[:3, :3], _NO_ROTATION, direction * math.radians(amt))
        return self._follow(path, self._T_flange_tool)

    def _follow(self, path: CartesianPath, T_flange_tcp: np.ndarray) -> JogResult:
        # follow_path uses the state only if it is of this robot at exactly this q (valid_for)
        out = follow_path(self.kinematics, self._q, T_flange_tcp, path, self.settings, q_rest=self._rest_q,
                          start=self._state)
        self._q = out.q_rad
        self._state = out.state              # of out.q_rad (or None)
        if out.stopped_by is None:
            return JogResult(True, 1.0, None, "")
        return JogResult(False, float(out.moved), out.stopped_by, out.message)

    def move_tcp_to(self, T_world_tcp_target: np.ndarray) -> JogResult:
        """Move the active TCP to a pose (gizmo drag) along a straight line, same safety rules.

        Position moves linearly and orientation about one fixed axis (shortest rotation)
        from the current TCP pose: (J-1) with ``w = log(R_target R_now^T)``.
        """
        T = check_pose(T_world_tcp_target, "T_world_tcp_target")
        T0 = self.T_world_tcp()
        w = Rotation.from_matrix(T[:3, :3] @ T0[:3, :3].T).as_rotvec()
        path = CartesianPath(T0[:3, 3], T0[:3, :3], T[:3, 3] - T0[:3, 3], w)
        return self._follow(path, self._T_flange_tool)

    def move_true_tool_to(self, T_world_tooltrue_target: np.ndarray) -> JogResult:
        """Put the hidden true TOOL frame at a pose by inverse kinematics (demos, auto-touch).

        A direct move (no path): the IK starts from the current configuration, so the arm keeps
        its configuration when it can, then tries home and fixed seeds (``approach.solve_ik``).
        Fails with ``stopped_by="unreachable"`` and leaves the robot where it was.
        """
        T = check_pose(T_world_tooltrue_target, "T_world_tooltrue_target")
        return self._ik_move(T, Words(N_("That pose of the true TOOL frame")))

    def _ik_move(self, T_world_tooltrue: np.ndarray, what: Words) -> JogResult:
        sol = solve_ik(self._true_kin, T_world_tooltrue, self._q,
                       T_flange_tcp=self._tool.T_flange_tool_true)
        if not sol.ok:
            p = T_world_tooltrue[:3, 3] * 1000.0
            return JogResult(False, 0.0, "unreachable",
                             Words(N_("{what} cannot be reached at ({x}, {y}, {z}) mm: no configuration within "
                                      "the joint limits gets there (closest: {mm} mm, {deg} deg away)."),
                                   what=what, x=f"{p[0]:.1f}", y=f"{p[1]:.1f}", z=f"{p[2]:.1f}",
                                   mm=f"{sol.position_error_m * 1000:.1f}",
                                   deg=f"{math.degrees(sol.rotation_error_rad):.1f}"))
        self._q, self._state = sol.q_rad, None
        return JogResult(True, 1.0, None, "")

    def auto_approach(self, *, tilt_deg: float, azimuth_deg: float, spin_deg: float = 0.0,
                      sigma_mm: float = 0.0, tip_offset_tool_mm: Sequence[float] = (0.0, 0.0, 0.0),
                      rng: np.random.Generator | None = None) -> JogResult:
        """Put the true tool on the reference tip from a direction (demos, auto-touch).

        Target (AA-1, ``approach.py``): the reference tip at ``tip_offset_tool_mm`` in true TOOL
        coordinates (0 = touching; (-50, 0, 0) = on the tool's -X axis 50 mm behind the TCP),
        plus a Gaussian position error of ``sigma_mm`` per WORLD axis drawn from ``rng``.
        Tool X (the working direction) points ``tilt_deg`` away from WORLD -Z (straight down),
        turned ``azimuth_deg`` about WORLD Z; ``spin_deg`` turns the tool about its own X.
        IK converges to 1e-12 m; fails with ``stopped_by="unreachable"`` and a clear message,
        leaving the robot where it was.
        """
        tilt = _finite(tilt_deg, "tilt_deg")
        az = _finite(azimuth_deg, "azimuth_deg")
        spin = _finite(spin_deg, "spin_deg")
        sigma = _finite(sigma_mm, "sigma_mm")
        if sigma < 0.0:
            raise ControllerError(f"sigma_mm must be >= 0, got {sigma_mm!r}.")
        offset = np.asarray(tip_offset_tool_mm, dtype=float)
        if offset.shape != (3,) or not np.all(np.isfinite(offset)):
            raise ControllerError(f"tip_offset_tool_mm must be 3 finite numbers (mm), got {tip_offset_tool_mm!r}.")
        noise = np.zeros(3)
        if sigma > 0.0:
            noise = (np.random.default_rng() if rng is None else rng).normal(0.0, sigma, 3)
        T = approach_pose(self._tip, tilt_deg=tilt, azimuth_deg=az, spin_deg=spin,
                          tip_offset_tool_mm=offset, noise_world_mm=noise)
        res = self._ik_move(T, Words(N_("The reference tip (with the {tool} at tilt {tilt} deg, azimuth {azimuth} "
                                        "deg, spin {spin} deg)"), tool=self._tool.label.lower(),
                                     tilt=f"{tilt:.1f}", azimuth=f"{az:.1f}", spin=f"{spin:.1f}"))
        if res.ok:
            return res
        return JogResult(False, 0.0, "unreachable",
                         Words(N_("{stop} Try a smaller tilt or another azimuth, or move the reference tip closer "
                                  "to the robot."), stop=res.message))

    # ----------------------------------------------------------------- readouts
    def readout(self, frame: Literal["WORLD", "BASE"] = "WORLD") -> PoseReadout:
        """Active TCP pose as X, Y, Z (mm) and KUKA A, B, C (deg) in WORLD or BASE
        (``readout.readout_in_frame``, the one path the pose state uses too)."""
        return readout_in_frame(self.T_world_tcp(), self._T_world_base, frame)

    def touch_geometry(self) -> TouchGeometry:
        """Mounted tool's true tip vs the reference tip (``touch.touch_geometry``)."""
        return touch_geometry(self.T_world_tool_true(), self._tip)

    def __repr__(self) -> str:
        return (f"VirtualController({self.kinematics.urdf_path.name}, tool={self._tool.key!r}, "
                f"active={None if self._active is None else self._active.name!r})")
