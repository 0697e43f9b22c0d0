"""Robot kinematics from a URDF with pinocchio: joint limits, home, FK, Jacobian, link poses.

Metres and radians throughout. "base" here is the URDF's root link (the robot's own base,
which the controller calls WORLD, methods.md section 1); ``T_world_flange`` maps FLANGE
coordinates to root-link (WORLD) coordinates.

Why pinocchio and not yourdfpy for the motion: one flange FK is about 1 us in pinocchio and
0.2-0.7 ms in yourdfpy (``tests/bench/bench_controller.py``); the app's scene updates use
:meth:`RobotKinematics.link_poses`. A test checks that both agree to 1e-9 m.
"""

from __future__ import annotations

import math
import operator
import re
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from tcp_pendant.controller.description import RobotDescription, load_description
from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.controller.words import Words
from tcp_pendant.translation import N_

__all__ = ["KNOWN_HOMES_DEG", "RobotKinematics", "default_flange_link", "urdf_links_and_tree"]

KNOWN_HOMES_DEG: dict[tuple[str, ...], tuple[float, ...]] = {
    # KUKA HOME: upper arm vertical, forearm and flange forward and horizontal.
    ("A1", "A2", "A3", "A4", "A5", "A6"): (0.0, -90.0, 90.0, 0.0, 0.0, 0.0),
    # Yaskawa: all pulses zero is the robot's home (upper arm vertical, forearm horizontal);
    # B -90 deg turns the flange straight down, ready to work on a table, away from the wrist
    # singularity at B = 0.
    ("S", "L", "U", "R", "B", "T"): (0.0, 0.0, 0.0, 0.0, -90.0, 0.0),
}
"""Home configurations (degrees) of the robots we know, by joint names in pinocchio order.

Any other robot's home is the all-zero configuration clipped to its limits.
"""

_PREFERRED_FLANGE_NAMES = ("flange", "tool0")


def urdf_links_and_tree(source: Path | RobotDescription) -> tuple[list[str], dict[str, list[str]]]:
    """Link names in file order and the child lists of the link tree.

    Args:
        source: a URDF file, or a loaded :class:`~tcp_pendant.controller.description.RobotDescription`
            (a xacro file is expanded only by ``load_description``).

    Raises:
        ControllerError: the file is not valid URDF XML.
    """
    if isinstance(source, RobotDescription):
        return list(source.links), {k: list(v) for k, v in source.children.items()}
    urdf_path = source
    try:
        root = ET.parse(urdf_path).getroot()
    except (ET.ParseError, OSError) as exc:
        raise ControllerError(f"Cannot read the URDF {urdf_path}: {exc}.") from exc
    if root.tag != "robot":
        raise ControllerError(f"{urdf_path} is not a URDF: its root element is <{root.tag}>, "
                              "expected <robot>.")
    links = [e.get("name", "") for e in root.findall("link")]
    children: dict[str, list[str]] = {name: [] for name in links}
    for joint in root.findall("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            continue
        children.setdefault(parent.get("link", ""), []).append(child.get("link", ""))
    return links, children


def default_flange_link(urdf_path: Path | RobotDescription) -> str:
    """The last link of the longest chain of the URDF's link tree.

    Ties (e.g. the UR5's ``ee_link`` and ``tool0``, both children of ``wrist_3_link``) go to a
    link named ``flange`` or ``tool0`` if one is among them, else to the first in file order.
    """
    links, children = urdf_links_and_tree(urdf_path)
    if not links:
        raise ControllerError(f"The URDF {urdf_path} has no <link>.")
    is_child = {c for cs in children.values() for c in cs}
    roots = [name for name in links if name not in is_child]
    depth: dict[str, int] = {}
    stack = [(r, 0) for r in roots]
    while stack:
        name, d = stack.pop()
        if name in depth:
            continue
        depth[name] = d
        stack.extend((c, d + 1) for c in children.get(name, ()))
    deepest = max(depth.values())
    candidates = [name for name in links if depth.get(name) == deepest]
    for preferred in _PREFERRED_FLANGE_NAMES:
        if preferred in candidates:
            return preferred
    return candidates[0]


_JOINT_WORDS = {
    "JointModelFreeFlyer": "floating",
    "JointModelPlanar": "planar",
    "JointModelSpherical": "spherical",
    "JointModelSphericalZYX": "spherical",
    "JointModelTranslation": "3-D translation",
}
"""pinocchio's joint model names in the URDF's words (messages never show pinocchio's names)."""


def _pinocchio_words(text: str) -> str:
    """pinocchio's error text for the user: its ``message:`` and ``hint:`` lines (not the C++
    location), joint model names in the URDF's words."""
    flat = " ".join(text.split())
    m = re.search(r"message:\s*(.*?)(?:\s*hint:\s*(.*))?$", flat)
    out = flat if m is None else m.group(1) + (f" ({m.group(2)})" if m.group(2) else "")

    def word(m: re.Match[str]) -> str:
        name = m.group(0)
        if "RUBY" in name or "RevoluteUnbounded" in name:
            return "continuous joint"
        if re.search(r"Prismatic|JointModelP[XYZ]", name):
            return "prismatic joint"
        if re.search(r"Revolute|JointModelR[XYZ]", name):
            return "revolute joint"
        if "Mimic" in name:
            return "mimic joint"
        return _JOINT_WORDS.get(name, "joint") + (" joint" if name in _JOINT_WORDS else "")

    return re.sub(r"(pinocchio::)?JointModel\w*", word, out)


def _is_mimic(joint: pin.JointModel) -> bool:
    return bool(joint.shortname() == "JointModelMimic")


class RobotKinematics:
    """The pinocchio model of one robot description (serial or tree, revolute/prismatic joints,
    mimic joints following their leader).

    Attributes:
        urdf_path: the description file given (``.urdf`` or ``.xacro``).
        description: the expanded, resolved description (``controller.description``).
        flange_link: the link used as FLANGE (Z out of the flange face for our robots).
        base_link: the URDF's root link; poses are given in its frame.
        joint_names: actuated joints in pinocchio order (depth-first, as in the URDF tree); a
            mimic joint is not one of them: pinocchio moves it with its leader,
            ``q_mimic = multiplier * q_leader + offset`` (``mimic_joints``), in FK, Jacobians
            and the link poses the scene draws.
        mimic_joints: ``{joint: (leader, multiplier, offset)}`` from the description.
        lower_rad, upper_rad: joint limits (rad, or m for prismatic joints).
        home_rad: home configuration (see :data:`KNOWN_HOMES_DEG`).
        known_home: the joint names are in :data:`KNOWN_HOMES_DEG` (our built-in robots and
            their kind); otherwise the app computes a ready pose and a reference tip from the
            model (``controller.placement``).
        link_names: every URDF link, in pinocchio frame order.
    """

    def __init__(self, model: pin.Model, urdf_path: Path, flange_link: str, base_link: str,
                 description: RobotDescription | None = None) -> None:
        self.model = model
        self.data = model.createData()
        self.urdf_path = Path(urdf_path)
        self._description = description
        self.flange_link = flange_link
        self.base_link = base_link
        actuated = [(j, name) for j, name in zip(model.joints[1:], model.names[1:]) if not _is_mimic(j)]
        self.joint_names: tuple[str, ...] = tuple(name for _, name in actuated)
        for j, name in actuated:
            if j.nq != 1 or j.nv != 1:
                kind = _JOINT_WORDS.get(j.shortname(), f"{j.nq}-variable")
                raise ControllerError(
                    f"Joint {name!r} of {self.urdf_path.name} is a {kind} joint with {j.nq} position "
                    "variables; only revolute, continuous, prismatic and mimic joints are supported."
                )
        self.mimic_joints: dict[str, tuple[str, float, float]] = (
            dict(description.mimic_joints) if description is not None else {})
        self.lower_rad = np.array(model.lowerPositionLimit, dtype=float)
        self.upper_rad = np.array(model.upperPositionLimit, dtype=float)
        if np.any(self.lower_rad > self.upper_rad):
            bad = self.joint_names[int(np.argmax(self.lower_rad > self.upper_rad))]
            raise ControllerError(f"Joint {bad!r} of {self.urdf_path.name} has lower limit above "
                                  "its upper limit; fix the URDF <limit>.")
        self.lower_rad.setflags(write=False)
        self.upper_rad.setflags(write=False)
        self._lower_tol: list[float] = (self.lower_rad - 1e-12).tolist()
        self._upper_tol: list[float] = (self.upper_rad + 1e-12).tolist()
        home_deg = KNOWN_HOMES_DEG.get(self.joint_names)
        self.known_home = home_deg is not None
        home = np.radians(home_deg) if home_deg is not None else np.zeros(self.n_joints)
        self.home_rad = np.clip(home, self.lower_rad, self.upper_rad)
        self.home_rad.setflags(write=False)
        self._flange_id = model.getFrameId(flange_link, pin.BODY)
        self._body_frames: tuple[tuple[str, int], ...] = tuple(
            (f.name, i) for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY
        )
        self.link_names: tuple[str, ...] = tuple(name for name, _ in self._body_frames)
        frame_of = {name: i for name, i in self._body_frames}     # as link_poses' dict: one entry a name
        self._link_frame_ids: tuple[int, ...] = tuple(frame_of.values())
        self.link_rows: dict[str, int] = {name: row for row, name in enumerate(frame_of)}
        """Row of each link in :meth:`link_poses_array` (the order of :meth:`link_poses`)."""
        self.revolute = np.array([re.search(r"Prismatic|JointModelP[XYZ]$", j.shortname()) is None
                                  for j, _ in actuated], dtype=bool)
        """True for revolute joints (radians), False for prismatic ones (metres)."""
        self.readout_scales: tuple[float, ...] = tuple(180.0 / math.pi if r else 1000.0
                                                       for r in self.revolute.tolist())
        """Per joint, readout units per joint unit: degrees per radian (revolute; ``math.degrees(v)``
        is ``v * (180 / pi)``, the same numbers), mm per metre (prismatic)."""

    @property
    def description(self) -> RobotDescription:
        """The expanded, resolved description (loaded from ``urdf_path`` on first use when the
        model was built elsewhere)."""
        if self._description is None:
            self._description = load_description(self.urdf_path)
        return self._description

    def own_copy(self) -> "RobotKinematics":
        """The same robot (the model is shared, read-only) with its own pinocchio data, safe to
        use in another thread."""
        return RobotKinematics(self.model, self.urdf_path, self.flange_link, self.base_link,
                               self._description)

    @classmethod
    def from_urdf(cls, urdf_path: Path | str, *, flange_link: str | None = None,
                  package_paths: Sequence[Path | str] = ()) -> "RobotKinematics":
        """Load a robot description (``.urdf`` or ``.xacro``, ``controller.description``).

        Args:
            urdf_path: the file (meshes are not needed for kinematics).
            flange_link: link to use as FLANGE; default :func:`default_flange_link` (the last
                link of the longest chain).
            package_paths: folders holding ROS packages (``--package-path``), searched before
                ``ROS_PACKAGE_PATH`` for ``package://`` and ``$(find pkg)``.

        Raises:
            ControllerError: missing or unreadable file, xacro error, unknown flange link,
                unsupported joint.
        """
        path = Path(urdf_path)
        if not path.is_file():
            raise ControllerError(f"URDF not found: {path}. Give the path of a .urdf or .xacro file.")
        description = load_description(path, package_paths)
        links, children = urdf_links_and_tree(description)
        if not links:
            raise ControllerError(f"The URDF {path.name} has no <link>.")
        flange = default_flange_link(description) if flange_link is None else flange_link
        if flange not in links:
            raise ControllerError(
                f"The URDF {path.name} has no link {flange!r}; its links are {', '.join(links)}. "
                "Choose one of them as the flange."
            )
        for joint, (leader, _, _) in description.mimic_joints.items():
            if leader in description.mimic_joints:
                raise ControllerError(f"Mimic joint {joint!r} of {path.name} follows {leader!r}, itself a "
                                      "mimic joint; make it follow the actuated joint directly.")
        try:
            model = pin.buildModelFromXML(description.urdf_xml, mimic=True)
        except Exception as exc:  # pinocchio raises RuntimeError/ValueError with its own text
            raise ControllerError(f"pinocchio cannot load {path}: {_pinocchio_words(str(exc))}") from exc
        if model.nq == 0:
            raise ControllerError(f"The URDF {path.name} has no movable joint.")
        is_child = {c for cs in children.values() for c in cs}
        base = next(name for name in links if name not in is_child)
        return cls(model, path, flange, base, description)

    @property
    def n_joints(self) -> int:
        """Number of actuated joints."""
        return int(self.model.nq)

    def check_q(self, q_rad: Sequence[float] | np.ndarray) -> np.ndarray:
        """``q_rad`` as a float array of the right length (raises ControllerError otherwise)."""
        q = np.asarray(q_rad, dtype=float)
        if q.shape != (self.n_joints,):
            raise ControllerError(f"Expected {self.n_joints} joint values "
                                  f"({', '.join(self.joint_names)}), got shape {q.shape}.")
        if not np.all(np.isfinite(q)):
            raise ControllerError(f"Joint values must be finite numbers, got {q.tolist()}.")
        return q

    def limit_violation(self, q_rad: np.ndarray, *, tol: float = 1e-12) -> tuple[int, str] | None:
        """First joint outside its limits as (index, "lower"|"upper"), or None."""
        if tol == 1e-12:      # the jog's check on every sub-step: Python floats, no numpy call
            q = np.asarray(q_rad).tolist()
            if all(map(operator.le, self._lower_tol, q)) and all(map(operator.le, q, self._upper_tol)):
                return None
        elif bool(np.all(q_rad >= self.lower_rad - tol)) and bool(np.all(q_rad <= self.upper_rad + tol)):
            return None
        below = np.nonzero(q_rad < self.lower_rad - tol)[0]
        above = np.nonzero(q_rad > self.upper_rad + tol)[0]
        firsts = [(int(i), "lower") for i in below[:1]] + [(int(i), "upper") for i in above[:1]]
        return min(firsts) if firsts else None

    def format_joint(self, index: int, value: float) -> str:
        """A joint value as the pendant shows it ("+120.0 deg" or "+0.250 m")."""
        if self.revolute[index]:
            return f"{math.degrees(value):+.1f} deg"
        return f"{value:+.3f} m"

    def limit_message(self, index: int, side: str) -> str:
        """E.g. "A5 at its limit +120.0 deg" (:class:`~tcp_pendant.controller.words.Words`: a
        view says it in its language)."""
        value = self.upper_rad[index] if side == "upper" else self.lower_rad[index]
        return Words(N_("{joint} at its limit {value}"), joint=self.joint_names[index],
                     value=self.format_joint(index, value))

    def T_world_flange(self, q_rad: np.ndarray) -> np.ndarray:
        """FLANGE pose in WORLD (the root-link frame), (4,4), metres (pinocchio frame placement)."""
        pin.forwardKinematics(self.model, self.data, q_rad)
        return pin.updateFramePlacement(self.model, self.data, self._flange_id).homogeneous

    def frame_pose(self, q_rad: np.ndarray, link: str) -> np.ndarray:
        """Pose of any link in the root-link frame, (4,4), metres."""
        if not self.model.existFrame(link, pin.BODY):
            raise ControllerError(f"No link {link!r} in {self.urdf_path.name}.")
        pin.forwardKinematics(self.model, self.data, q_rad)
        fid = self.model.getFrameId(link, pin.BODY)
        return pin.updateFramePlacement(self.model, self.data, fid).homogeneous

    def jacobian_flange(self, q_rad: np.ndarray) -> np.ndarray:
        """(6, n) flange Jacobian ``[v; w]``, LOCAL_WORLD_ALIGNED.

        ``v`` is the velocity of the flange origin and ``w`` the angular velocity, both in
        root-link axes (m/rad and rad/rad per joint).
        """
        return pin.computeFrameJacobian(self.model, self.data, q_rad, self._flange_id,
                                        pin.LOCAL_WORLD_ALIGNED)

    def jacobian_and_pose(self, q_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Flange Jacobian (as :meth:`jacobian_flange`), rotation (3,3) and position (3,).

        One pinocchio pass (``computeFrameJacobian`` also updates the frame placement).
        """
        J = pin.computeFrameJacobian(self.model, self.data, q_rad, self._flange_id,
                                     pin.LOCAL_WORLD_ALIGNED)
        # updateFramePlacement only re-reads the placement computeFrameJacobian has just set (a
        # cheaper way to it than data.oMf[id]); .homogeneous is a fresh (4,4) array: R and p are
        # views of it, no one else's
        T = pin.updateFramePlacement(self.model, self.data, self._flange_id).homogeneous
        return J, T[:3, :3], T[:3, 3]

    def link_poses(self, q_rad: np.ndarray) -> dict[str, np.ndarray]:
        """``T_base_link`` (4,4, metres) for every URDF link, for the 3D scene."""
        pin.framesForwardKinematics(self.model, self.data, q_rad)
        oMf = self.data.oMf
        return {name: oMf[i].homogeneous for name, i in self._body_frames}

    def link_poses_array(self, q_rad: np.ndarray) -> np.ndarray:
        """:meth:`link_poses` stacked, (N,4,4) metres, row :attr:`link_rows` ``[link]``: the same
        pinocchio pass and numbers, in one new array (the pose state of a jog step)."""
        pin.framesForwardKinematics(self.model, self.data, q_rad)
        oMf = self.data.oMf.tolist()       # every frame's SE3 in one call (indexing oMf costs as much per frame)
        return np.array([oMf[i].homogeneous for i in self._link_frame_ids])

    def __repr__(self) -> str:
        return (f"RobotKinematics({self.urdf_path.name!r}, joints={list(self.joint_names)}, "
                f"flange_link={self.flange_link!r})")
