"""Mystery tools: a tool per trainee whose true TCP and orientation are drawn
from the exercise seed and the trainee's name, so answers differ between trainees. The seed of
a class is a secret (``Gradebook.settings.exercise_seed``: random, kept in the gradebook): this code is
public, so whoever knows the seed and a name computes that trainee's tool.

:func:`draw_mystery_tool` draws (deterministically: same seed, name and base tool, same tool on
every run and machine) a true TOOL frame within realistic bounds:

- the TCP is ``TCP_DISTANCE_MM`` = 80..250 mm from the flange origin, in a direction within
  ``CONE_HALF_ANGLE_DEG`` = 35 deg of the base tool's TCP direction (flange +Z for a tool whose
  TCP is at the flange), uniform on that spherical cap;
- tool X (the working direction, KUKA) leans ``X_TILT_DEG`` = 0..30 deg away from that
  direction (a bent neck, as on a welding torch), at a random azimuth;
- the tool turns about its X by ``SPIN_DEG`` = -180..180 deg (Y and Z of the TOOL frame).

It returns an ordinary :class:`~tcp_pendant.controller.tools.ToolModel` read from a generated
URDF, exactly as the built-in tools are: the URDF is the one source of both the drawing and the
hidden truth, so the controller mounts it (``VirtualController.mount_tool``) and the scene draws
it (``views.meshes.rigid_meshes(urdf_path)``) with no change to either. The URDF and its two
STL meshes are written once per drawn tool into ``mystery_cache_dir()``
(``platformdirs.user_cache_dir("tcp-pendant")/mystery-tools/<hash>/``; the name of the folder is a
hash and tells nothing about the truth; written to a temporary folder and renamed, so a
concurrent draw never sees half a tool) and reused afterwards.

The mesh is neutral: a mount disc on the flange, a shaft from the flange face to the neck and a
cone, the nozzle, about tool X, ending in a flat tip face ``_TIP_FACE_RADIUS_M`` = 0.2 mm in
radius, square to tool X and centred on the TCP (a real pointer's or contact tip's end is never
a mathematical point). The nozzle is defined in the URDF's ``tcp`` link, its tip face centred on
that link's origin, so the drawn tip is at the true TCP up to the float64 transform. Touching the
spike anywhere on that face is within 0.2 mm of the TCP, inside the exercise's "good" 0.5 mm. No
vertex lies at the TCP: the face is a fan from one of its own ring's vertices, each 0.2 mm from
it, so no number the browser gets is the TCP; its centre is, for a program that fits the face
(docs/security.md: what a determined trainee can still see).

What the drawing gives away is what a real tool shows: the tip and the shaft. The browser gets
the meshes in FLANGE coordinates (``rigid_meshes``), so the tip face's centre is the TCP and the
nozzle's axis is tool X, as the wire of a real torch is. Tool Y and Z (the spin about X) are not
in it: the nozzle is a surface of revolution about X, and the first of each of its rings'
``_SECTIONS`` vertices sits at ``ring_phase_deg``, drawn with the secret seed (uniform on
0..360 deg), not on tool Y; every other part is built from the flange and the shaft line alone.
The cache folder is named by a hash of the tool's digest and ``_DRAWING`` (the drawing's
version), so a tool drawn by an older drawing is not reused.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import tempfile
import unicodedata
import warnings
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import cast

import numpy as np
import platformdirs
import trimesh
from scipy.spatial.transform import Rotation

from tcp_pendant.classroom.names import validate_trainee_name
from tcp_pendant.controller.tools import ToolModel, load_tool

__all__ = [
    "CONE_HALF_ANGLE_DEG",
    "MYSTERY_LABEL",
    "SPIN_DEG",
    "TCP_DISTANCE_MM",
    "X_TILT_DEG",
    "MysteryFrame",
    "draw_mystery_frame",
    "draw_mystery_tool",
    "mystery_cache_dir",
    "true_frame",
]

TCP_DISTANCE_MM: tuple[float, float] = (80.0, 250.0)
CONE_HALF_ANGLE_DEG: float = 35.0
X_TILT_DEG: tuple[float, float] = (0.0, 30.0)
SPIN_DEG: tuple[float, float] = (-180.0, 180.0)
MYSTERY_LABEL = "Mystery tool"

_VERSION = "mystery-2"           # part of the seed material: change it and every tool (and cache folder) changes
_MOUNT_RADIUS_M = 0.030
_MOUNT_HEIGHT_M = 0.012
_SHAFT_RADIUS_M = 0.010
_NOZZLE_LENGTH_M = 0.030
_NOZZLE_RADIUS_M = 0.009
_TIP_FACE_RADIUS_M = 0.0002     # the drawn tip: a flat 0.4 mm across, centred on the TCP
_DRAWING = "tip-face-1"         # part of the cache folder's name: a new drawing is written anew
_SECTIONS = 24


def true_frame(tool: ToolModel) -> np.ndarray:
    """The hidden true TOOL frame of a tool (4x4, metres), ``T_flange_tool_true`` (or the
    pre-issue-9 name ``T_flange_tcp_true``)."""
    T = getattr(tool, "T_flange_tool_true", None)
    return np.asarray(getattr(tool, "T_flange_tcp_true") if T is None else T, dtype=float)


def mystery_cache_dir() -> Path:
    """Where generated mystery tools are kept: ``user_cache_dir("tcp-pendant")/mystery-tools``."""
    return Path(platformdirs.user_cache_dir("tcp-pendant", appauthor=False)) / "mystery-tools"


@dataclass(frozen=True, eq=False)
class MysteryFrame:
    """A drawn true TOOL frame and the numbers it was drawn from (for tests and the trainer).

    Attributes:
        digest: hex SHA-256 of the seed material (names the cache folder and the tool key).
        T_flange_tool: (4,4) true TOOL frame in FLANGE, metres.
        distance_mm: |TCP|, mm.
        cone_angle_deg: angle between the TCP direction and the base tool's direction.
        x_tilt_deg: angle between tool X and the TCP direction.
        spin_deg: turn about tool X.
        ring_phase_deg: where the nozzle ring's first vertex sits about tool X, from tool Y
            towards tool Z (the drawing's phase, so that no vertex marks tool Y).
    """

    digest: str
    T_flange_tool: np.ndarray
    distance_mm: float
    cone_angle_deg: float
    x_tilt_deg: float
    spin_deg: float
    ring_phase_deg: float


def _perpendicular(v: np.ndarray) -> np.ndarray:
    helper = np.array([1.0, 0.0, 0.0]) if abs(v[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    p = np.cross(v, helper)
    return p / np.linalg.norm(p)


def _tilt(axis: np.ndarray, angle_rad: float, azimuth_rad: float) -> np.ndarray:
    """``axis`` turned by ``angle_rad`` away from itself, towards the azimuth ``azimuth_rad``."""
    e1 = _perpendicular(axis)
    e2 = np.cross(axis, e1)
    out = (np.cos(angle_rad) * axis
           + np.sin(angle_rad) * (np.cos(azimuth_rad) * e1 + np.sin(azimuth_rad) * e2))
    return out / np.linalg.norm(out)


def _base_direction(base: ToolModel) -> np.ndarray:
    t = true_frame(base)[:3, 3]
    n = float(np.linalg.norm(t))
    return np.array([0.0, 0.0, 1.0]) if n < 1e-3 else t / n


def draw_mystery_frame(seed: int, trainee_name: str, base: ToolModel) -> MysteryFrame:
    """Draw the true TOOL frame of a trainee's mystery tool (no files written).

    Args:
        seed: the exercise seed (an int).
        trainee_name: the trainee's name (normalised by ``validate_trainee_name`` first, so
            "Anna " and "Anna" get the same tool).
        base: the tool the mystery tool is modelled on (its TCP direction is the cone axis).

    Raises:
        ValueError: ``seed`` is not an int, or the name is refused (``TraineeNameError``).
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise ValueError(f"seed must be a whole number, got {seed!r:.40}.")
    name = validate_trainee_name(trainee_name)
    material = "\0".join((_VERSION, str(int(seed)), unicodedata.normalize("NFC", name), base.key))
    digest = hashlib.sha256(material.encode("utf-8")).hexdigest()
    rng = np.random.default_rng(int(digest, 16))
    lo, hi = TCP_DISTANCE_MM
    distance_mm = float(rng.uniform(lo, hi))
    cos_cone = float(rng.uniform(np.cos(np.radians(CONE_HALF_ANGLE_DEG)), 1.0))
    cone_rad = float(np.arccos(min(1.0, cos_cone)))
    direction = _tilt(_base_direction(base), cone_rad, float(rng.uniform(0.0, 2.0 * np.pi)))
    x_tilt_rad = float(np.radians(rng.uniform(*X_TILT_DEG)))
    x_axis = _tilt(direction, x_tilt_rad, float(rng.uniform(0.0, 2.0 * np.pi)))
    spin_deg = float(rng.uniform(*SPIN_DEG))
    ring_phase_deg = float(rng.uniform(0.0, 360.0))
    y0 = _perpendicular(x_axis)
    y_axis = Rotation.from_rotvec(np.radians(spin_deg) * x_axis).apply(y0)
    R = np.column_stack([x_axis, y_axis, np.cross(x_axis, y_axis)])
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = direction * distance_mm / 1000.0
    return MysteryFrame(digest, T, distance_mm, float(np.degrees(cone_rad)), float(np.degrees(x_tilt_rad)),
                        spin_deg, ring_phase_deg)


def _nozzle_mesh(phase_deg: float) -> trimesh.Trimesh:
    """The nozzle in the TOOL frame: a cone about X from its base (radius ``_NOZZLE_RADIUS_M`` at
    x = -L) to a flat tip face of radius ``_TIP_FACE_RADIUS_M`` in the plane x = 0, centred on the
    origin (the TCP); both rings' first vertex at ``phase_deg`` about X from +Y (towards +Z).

    The tip face is a fan from one of its own ring's vertices, so no vertex lies at the TCP:
    every vertex is at least ``_TIP_FACE_RADIUS_M`` from it, and what the mesh tells of the TCP is
    the centre of the drawn tip, as the eye sees it."""
    a = np.radians(phase_deg) + np.linspace(0.0, 2.0 * np.pi, _SECTIONS, endpoint=False)
    tip = np.column_stack([np.zeros(_SECTIONS), _TIP_FACE_RADIUS_M * np.cos(a), _TIP_FACE_RADIUS_M * np.sin(a)])
    ring = np.column_stack([np.full(_SECTIONS, -_NOZZLE_LENGTH_M), _NOZZLE_RADIUS_M * np.cos(a),
                            _NOZZLE_RADIUS_M * np.sin(a)])
    vertices = np.vstack([tip, ring, [[-_NOZZLE_LENGTH_M, 0.0, 0.0]]])
    centre = 2 * _SECTIONS
    faces = []
    for i in range(_SECTIONS):
        j = (i + 1) % _SECTIONS
        faces.append((i, j, _SECTIONS + j))                       # side, outward
        faces.append((i, _SECTIONS + j, _SECTIONS + i))
        faces.append((centre, _SECTIONS + i, _SECTIONS + j))      # base disc, facing -X
    for i in range(1, _SECTIONS - 1):
        faces.append((0, i + 1, i))                               # tip face, facing +X
    mesh = trimesh.Trimesh(vertices=vertices, faces=np.array(faces), process=False)
    mesh.fix_normals()
    return mesh


def _body_mesh(T_flange_tool: np.ndarray) -> trimesh.Trimesh:
    """Mount disc on the flange and a shaft from the flange face to the nozzle's base (FLANGE)."""
    mount = trimesh.creation.cylinder(radius=_MOUNT_RADIUS_M, height=_MOUNT_HEIGHT_M, sections=_SECTIONS)
    mount.apply_translation([0.0, 0.0, _MOUNT_HEIGHT_M / 2.0])
    neck = T_flange_tool[:3, 3] - _NOZZLE_LENGTH_M * T_flange_tool[:3, 0]
    start = np.array([0.0, 0.0, _MOUNT_HEIGHT_M * 0.5])
    shaft = trimesh.creation.cylinder(radius=_SHAFT_RADIUS_M, segment=np.vstack([start, neck]),
                                      sections=_SECTIONS)
    joint = trimesh.creation.icosphere(subdivisions=1, radius=_SHAFT_RADIUS_M)
    joint.apply_translation(neck)
    return cast(trimesh.Trimesh, trimesh.util.concatenate([mount, shaft, joint]))  # meshes give a mesh


def _xyz(v: np.ndarray) -> str:
    return " ".join(repr(float(x)) for x in v)


def _urdf_text(name: str, T_flange_tool: np.ndarray) -> str:
    with warnings.catch_warnings():         # gimbal lock: the angles still give the same matrix
        warnings.simplefilter("ignore", UserWarning)
        rpy = Rotation.from_matrix(T_flange_tool[:3, :3]).as_euler("xyz")   # URDF: R = Rz(y) Ry(p) Rx(r)
    return f"""<?xml version="1.0"?>
<!-- A generated mystery tool (tcp_pendant.classroom.mystery): its true TOOL frame is secret. -->
<robot name="{name}">
  <material name="steel"><color rgba="0.6667 0.6824 0.7059 1"/></material>
  <material name="violet"><color rgba="0.4902 0.2353 0.5961 1"/></material>
  <link name="tool_mount">
    <visual name="{name}_body">
      <origin xyz="0 0 0" rpy="0 0 0"/>
      <geometry><mesh filename="body.stl"/></geometry>
      <material name="steel"/>
    </visual>
  </link>
  <link name="tcp">
    <visual name="{name}_nozzle">
      <origin xyz="0 0 0" rpy="0 0 0"/>
      <geometry><mesh filename="nozzle.stl"/></geometry>
      <material name="violet"/>
    </visual>
  </link>
  <joint name="tcp_joint" type="fixed">
    <parent link="tool_mount"/>
    <child link="tcp"/>
    <origin xyz="{_xyz(T_flange_tool[:3, 3])}" rpy="{_xyz(rpy)}"/>
  </joint>
</robot>
"""


def _write_tool(folder: Path, name: str, T_flange_tool: np.ndarray, ring_phase_deg: float) -> Path:
    """The tool's URDF in ``folder`` (made if missing: temp folder, then rename)."""
    urdf = folder / "tool.urdf"
    if urdf.is_file():
        return urdf
    folder.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=".tmp-", dir=folder.parent))
    try:
        _body_mesh(T_flange_tool).export(tmp / "body.stl")
        _nozzle_mesh(ring_phase_deg).export(tmp / "nozzle.stl")
        (tmp / "tool.urdf").write_text(_urdf_text(name, T_flange_tool), encoding="utf-8")
        try:
            os.replace(tmp, folder)
        except OSError:
            if not urdf.is_file():          # not a concurrent writer that won the race
                raise
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return urdf


@lru_cache(maxsize=256)
def _cached_tool(seed: int, name: str, base: ToolModel, cache_dir: Path) -> ToolModel:
    frame = draw_mystery_frame(seed, name, base)
    key = f"mystery-{frame.digest[:10]}"
    folder = hashlib.sha256(f"{frame.digest}\0{_DRAWING}".encode()).hexdigest()[:32]
    urdf = _write_tool(cache_dir / folder, key.replace("-", "_"), frame.T_flange_tool, frame.ring_phase_deg)
    return load_tool(urdf, key=key, label=MYSTERY_LABEL)


def draw_mystery_tool(seed: int, trainee_name: str, base: ToolModel, *,
                      cache_dir: Path | None = None) -> ToolModel:
    """The mystery tool of one trainee in one exercise (deterministic; cached).

    Args:
        seed: the exercise seed.
        trainee_name: the trainee's name (normalised as the gradebook stores it).
        base: a built-in tool it is modelled on (``builtin_tools()["pointer"]``, ...).
        cache_dir: where the generated URDF and meshes go (default :func:`mystery_cache_dir`).

    Returns:
        A ``ToolModel`` with key ``"mystery-<10 hex>"`` (a hash: it names the tool, not its
        truth), label "Mystery tool", ``urdf_path`` the generated URDF and its true TOOL frame
        read from that URDF (metres).

    Raises:
        ValueError: a seed that is not an int or a refused name.
        OSError: the cache folder cannot be written.
    """
    folder = mystery_cache_dir() if cache_dir is None else Path(cache_dir)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise ValueError(f"seed must be a whole number, got {seed!r:.40}.")
    return _cached_tool(int(seed), validate_trainee_name(trainee_name), base, folder.resolve())
