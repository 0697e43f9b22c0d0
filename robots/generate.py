#!/usr/bin/env python3
"""Write every URDF and mesh under ``robots/`` from the dimensions in this one file.

Run from anywhere::

    python robots/generate.py            # rewrites robots/ in place
    python robots/generate.py --out DIR  # writes the same tree into DIR (used by the tests)

The output is deterministic: running the script again reproduces the committed files byte for
byte (``tests/robots/test_generator_and_budget.py`` checks it).

Units: every dimension in this file is in **millimetres and degrees** (as in the data sheets
they come from); the URDF text is written in metres and radians.

Frame conventions (see ``robots/README.md``):

* ``base_link`` lies on the floor under the first axis; X forward, Z up.
* Each robot has an explicit ``flange`` link (fixed joint from the last link) whose Z axis
  points out of the flange face, along the last joint axis, away from the wrist; its X axis
  points up when the wrist is in its straight position with the forearm horizontal (KR 6:
  HOME; GP12: all zero), so Y = Z x X points to the robot's right (-Y of ``base_link``).
* A tool URDF has the root link ``tool_mount`` (= ``flange`` when mounted) and a link ``tcp``
  whose frame is the true TOOL frame: origin at the tool tip, X = the working direction.
"""

from __future__ import annotations

import argparse
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

HERE = Path(__file__).resolve().parent
MM = 1e-3  # metres per millimetre
VERTEX_DECIMALS = 6  # mesh vertices rounded to 1 micrometre before writing (reproducibility)

# --------------------------------------------------------------------------------------------
# Colours (sRGB, 0..255)
# --------------------------------------------------------------------------------------------
COLOURS: dict[str, tuple[int, int, int]] = {
    "kuka_orange": (255, 98, 0),
    "kuka_black": (28, 28, 30),
    "yaskawa_blue": (0, 86, 168),
    "yaskawa_grey": (70, 74, 80),
    "steel": (170, 174, 180),
    "dark_steel": (80, 82, 86),
    "red": (210, 30, 30),
    "copper": (196, 112, 58),
    "brass": (214, 176, 70),
    "tool_black": (35, 35, 38),
    "safety_yellow": (245, 200, 0),
}


# --------------------------------------------------------------------------------------------
# Geometry primitives (millimetres, in the link frame)
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Cyl:
    """Cylinder from point ``p0`` to point ``p1`` (mm) of radius ``r`` (mm)."""

    p0: tuple[float, float, float]
    p1: tuple[float, float, float]
    r: float
    colour: str
    sections: int = 24


@dataclass(frozen=True)
class Cone:
    """Cone (or truncated cone) from ``p0`` (radius ``r0``) to ``p1`` (radius ``r1``), mm."""

    p0: tuple[float, float, float]
    p1: tuple[float, float, float]
    r0: float
    r1: float
    colour: str
    sections: int = 24


@dataclass(frozen=True)
class Box:
    """Axis-aligned box (in the link frame) between corners ``lo`` and ``hi``, mm."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    colour: str


@dataclass(frozen=True)
class Hull:
    """Convex hull of several primitives (their colours are ignored): tapered, rounded links."""

    parts: tuple[Cyl | Cone | Box, ...]
    colour: str


Primitive = Cyl | Cone | Box | Hull


def _frame_along(p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """4x4 transform whose Z axis runs from p0 to p1 and whose origin is p0 (mm)."""
    d = p1 - p0
    z = d / np.linalg.norm(d)
    # Deterministic perpendicular: the base axis least aligned with z.
    a = np.eye(3)[int(np.argmin(np.abs(z)))]
    x = np.cross(a, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, y, z])
    T[:3, 3] = p0
    return T


def _frustum(r0: float, r1: float, length: float, sections: int) -> trimesh.Trimesh:
    """Closed (truncated) cone along +Z from z=0 (radius r0) to z=length (radius r1), mm.

    A surface of revolution of the profile axis -> r0 -> r1 -> axis; a zero radius gives a
    sharp point. Watertight, outward normals.
    """
    profile = [[0.0, 0.0], [r0, 0.0]]
    if r1 > 0.0:
        profile.append([r1, length])
    profile.append([0.0, length])
    if r0 <= 0.0:
        profile = [[0.0, 0.0]] + profile[2:]
    return trimesh.creation.revolve(profile, sections=sections)


def primitive_mesh(p: Primitive) -> trimesh.Trimesh:
    """Triangle mesh of one primitive, in millimetres, in the link frame."""
    if isinstance(p, Hull):
        pts = np.vstack([primitive_mesh(q).vertices for q in p.parts])
        return trimesh.convex.convex_hull(pts)
    if isinstance(p, Box):
        lo, hi = np.asarray(p.lo, float), np.asarray(p.hi, float)
        T = np.eye(4)
        T[:3, 3] = (lo + hi) / 2.0
        return trimesh.creation.box(extents=hi - lo, transform=T)
    p0, p1 = np.asarray(p.p0, float), np.asarray(p.p1, float)
    length = float(np.linalg.norm(p1 - p0))
    if isinstance(p, Cyl):
        m = _frustum(p.r, p.r, length, p.sections)
    else:
        m = _frustum(p.r0, p.r1, length, p.sections)
    m.apply_transform(_frame_along(p0, p1))
    return m


# --------------------------------------------------------------------------------------------
# URDF model description
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Joint:
    """One URDF joint; lengths in mm, angles in degrees, velocity in deg/s."""

    name: str
    parent: str
    child: str
    xyz_mm: tuple[float, float, float]
    rpy_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)
    axis: tuple[float, float, float] | None = None  # None: fixed joint
    lower_deg: float = 0.0
    upper_deg: float = 0.0
    velocity_deg_s: float = 0.0
    source: str = ""  # where the figures come from (written as a comment)


@dataclass(frozen=True)
class Model:
    name: str
    folder: str  # sub-folder of robots/
    file: str  # URDF file name
    links: tuple[str, ...]
    joints: tuple[Joint, ...]
    visuals: dict[str, tuple[Primitive, ...]] = field(default_factory=dict)
    header: str = ""


# ---------------------------- KUKA KR 6 R900 sixx (KR 6 AGILUS) ------------------------------
# Kinematic figures (mm): KUKA KR AGILUS sixx specification (KR 6 R900 sixx dimension drawing)
# and the ROS-Industrial description kuka_experimental/kuka_kr6_support/urdf/
# kr6r900sixx_macro.xacro, which uses the same figures, axes and limits.
KR6_A2_HEIGHT = 400.0  # floor (A1 foot) to A2
KR6_A2_FORWARD = 25.0  # A1 axis to A2 axis, horizontal
KR6_UPPER_ARM = 455.0  # A2 to A3
KR6_FOREARM_OFFSET = 35.0  # A3 to A4 axis, perpendicular offset
KR6_A4_TO_WRIST = 420.0  # A3 (projected) to the wrist centre (A5), along A4
KR6_WRIST_TO_FLANGE = 80.0  # wrist centre to flange face, along A6
# Limits (deg) and top speeds (deg/s): KR AGILUS sixx specification / ROS-Industrial macro.
KR6_LIMITS = {
    "A1": (-170.0, 170.0, 360.0),
    "A2": (-190.0, 45.0, 300.0),
    "A3": (-120.0, 156.0, 360.0),
    "A4": (-185.0, 185.0, 381.0),
    "A5": (-120.0, 120.0, 388.0),
    "A6": (-350.0, 350.0, 615.0),
}
# Rotation directions as KUKA defines them (= the axes of the ROS-Industrial macro).
KR6_AXES = {
    "A1": (0.0, 0.0, -1.0),
    "A2": (0.0, 1.0, 0.0),
    "A3": (0.0, 1.0, 0.0),
    "A4": (-1.0, 0.0, 0.0),
    "A5": (0.0, 1.0, 0.0),
    "A6": (-1.0, 0.0, 0.0),
}

# Flange frame in the last link's frame: Z out of the face (= last link's +X), X up (= last
# link's +Z) in the straight-wrist pose, Y = Z x X = -Y. Matrix columns = flange X, Y, Z.
# As URDF rpy (R = Rz(yaw) Ry(pitch) Rx(roll)): roll 180, pitch -90, yaw 0 (deg).
FLANGE_RPY_DEG = (180.0, -90.0, 0.0)


def kr6_model() -> Model:
    """KUKA KR 6 R900 sixx: joints A1..A6, base_link on the floor under A1."""
    o, k = "kuka_orange", "kuka_black"
    j = []
    parents = ["base_link", "link_1", "link_2", "link_3", "link_4", "link_5"]
    xyz = [
        (0.0, 0.0, KR6_A2_HEIGHT),
        (KR6_A2_FORWARD, 0.0, 0.0),
        (KR6_UPPER_ARM, 0.0, 0.0),
        (0.0, 0.0, KR6_FOREARM_OFFSET),
        (KR6_A4_TO_WRIST, 0.0, 0.0),
        (KR6_WRIST_TO_FLANGE, 0.0, 0.0),
    ]
    for i, name in enumerate(["A1", "A2", "A3", "A4", "A5", "A6"]):
        lo, hi, v = KR6_LIMITS[name]
        j.append(
            Joint(name, parents[i], f"link_{i + 1}", xyz[i], axis=KR6_AXES[name],
                  lower_deg=lo, upper_deg=hi, velocity_deg_s=v)
        )
    j.append(Joint("flange_joint", "link_6", "flange", (0.0, 0.0, 0.0), FLANGE_RPY_DEG))
    # Link frames at zero: link_1 at A2 height on A1; link_2 at A2; link_3 at A3;
    # link_4 on the A4 axis above A3; link_5 at the wrist centre; link_6 at the flange face.
    # Upper arm and forearm lie along +X at all-zero (stretched forward).
    A2x, UA, OFF = KR6_A2_FORWARD, KR6_UPPER_ARM, KR6_FOREARM_OFFSET
    W, FL = KR6_A4_TO_WRIST, KR6_WRIST_TO_FLANGE
    vis: dict[str, tuple[Primitive, ...]] = {
        "base_link": (
            Hull(tuple(Cyl((x, y, 0.0), (x, y, 20.0), 25.0, k, 12)
                       for x in (-145.0, 115.0) for y in (-130.0, 130.0)), k),  # foot plate
            Hull((Cyl((-10.0, 0.0, 20.0), (-10.0, 0.0, 60.0), 118.0, o, 32),
                  Cyl((0.0, 0.0, 150.0), (0.0, 0.0, 185.0), 108.0, o, 32)), o),  # base body
            Box((-150.0, -60.0, 40.0), (-110.0, 60.0, 110.0), k),  # connector box at the rear
        ),
        "link_1": (  # frame at A2 height on the A1 axis
            Cyl((0.0, 0.0, -215.0), (0.0, 0.0, -185.0), 112.0, o, 32),  # turntable
            Hull((Cyl((0.0, 0.0, -185.0), (0.0, 0.0, -120.0), 100.0, o, 32),
                  Cyl((A2x, -30.0, 0.0), (A2x, 95.0, 0.0), 80.0, o, 32)), o),  # rotating column
            Cyl((-85.0, 0.0, -170.0), (-85.0, 0.0, -50.0), 40.0, k, 20),  # A1 motor (rear)
            Cyl((A2x, 95.0, 0.0), (A2x, 150.0, 0.0), 50.0, k, 24),  # A2 motor (left side)
        ),
        "link_2": (  # frame at A2; the upper arm runs along +X at A2 = 0, beside the column
            Hull((Cyl((0.0, -100.0, 0.0), (0.0, -35.0, 0.0), 78.0, o, 32),
                  Cyl((UA, -100.0, 0.0), (UA, -35.0, 0.0), 60.0, o, 32)), o),  # upper arm
            Cyl((0.0, -108.0, 0.0), (0.0, -100.0, 0.0), 55.0, k, 24),  # gear covers
            Cyl((UA, -108.0, 0.0), (UA, -100.0, 0.0), 42.0, k, 24),
        ),
        "link_3": (  # frame at A3
            Hull((Cyl((0.0, -95.0, 0.0), (0.0, 55.0, 0.0), 66.0, o, 32),
                  Cyl((-130.0, 0.0, OFF), (120.0, 0.0, OFF), 52.0, o, 24)), o),  # arm housing
            Cyl((-195.0, 0.0, OFF), (-130.0, 0.0, OFF), 40.0, k, 20),  # A4 motor (rear)
            Cyl((0.0, 55.0, 0.0), (0.0, 68.0, 0.0), 45.0, k, 24),  # A3 cover
        ),
        "link_4": (  # frame on the A4 axis above A3
            Hull((Cyl((120.0, 0.0, 0.0), (160.0, 0.0, 0.0), 48.0, o, 24),
                  Cyl((300.0, 0.0, 0.0), (330.0, 0.0, 0.0), 40.0, o, 24)), o),  # forearm
            Hull((Box((300.0, -50.0, -34.0), (330.0, -36.0, 34.0), o),
                  Cyl((W, -50.0, 0.0), (W, -36.0, 0.0), 38.0, o, 24)), o),  # wrist fork
            Hull((Box((300.0, 36.0, -34.0), (330.0, 50.0, 34.0), o),
                  Cyl((W, 36.0, 0.0), (W, 50.0, 0.0), 38.0, o, 24)), o),
        ),
        "link_5": (  # frame at the wrist centre
            Cyl((0.0, -36.0, 0.0), (0.0, 36.0, 0.0), 36.0, o, 24),  # A5 knuckle
            Cone((0.0, 0.0, 0.0), (FL - 14.0, 0.0, 0.0), 34.0, 30.0, o, 24),
        ),
        "link_6": (  # frame at the flange face
            Cyl((-14.0, 0.0, 0.0), (0.0, 0.0, 0.0), 31.5, "steel", 32),  # flange disc
            Cyl((-1.0, 0.0, 22.0), (1.0, 0.0, 22.0), 3.0, k, 8),  # dowel-pin mark (+X flange)
        ),
    }
    return Model(
        name="kuka_kr6_r900_sixx",
        folder="kr6_r900",
        file="kr6_r900.urdf",
        links=("base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6", "flange"),
        joints=tuple(j),
        visuals=vis,
        header=(
            "KUKA KR 6 R900 sixx (KR 6 AGILUS). Authored by robots/generate.py; do not edit.\n"
            "Joint zero and directions as KUKA defines them: HOME = {A1 0, A2 -90, A3 90, A4 0,\n"
            "A5 0, A6 0}. Figures: KUKA KR AGILUS sixx specification and ROS-Industrial\n"
            "kuka_experimental/kuka_kr6_support (kr6r900sixx_macro.xacro); see robots/README.md."
        ),
    )


# ---------------------------- Yaskawa Motoman GP12 class ------------------------------------
# Figures (mm): Yaskawa GP12 data sheet (1440 mm reach, 12 kg) as reproduced by the
# ROS-Industrial description motoman/motoman_gp12_support/urdf/gp12_macro.xacro.
GP12_S_HEIGHT = 450.0  # floor to the L axis
GP12_S_TO_L = 155.0  # S axis to L axis, horizontal
GP12_UPPER_ARM = 614.0  # L to U
GP12_U_TO_R_UP = 200.0  # U axis to the R (forearm) axis, vertical offset
GP12_U_TO_B = 640.0  # U axis to the B axis (wrist centre), along R
GP12_B_TO_FLANGE = 100.0  # B axis to the flange face (T)
GP12_LIMITS = {
    "S": (-170.0, 170.0, 260.0),
    "L": (-90.0, 155.0, 230.0),
    "U": (-85.0, 150.0, 260.0),
    "R": (-200.0, 200.0, 470.0),
    "B": (-150.0, 150.0, 470.0),
    "T": (-455.0, 455.0, 700.0),
}
GP12_AXES = {
    "S": (0.0, 0.0, 1.0),
    "L": (0.0, 1.0, 0.0),
    "U": (0.0, -1.0, 0.0),
    "R": (-1.0, 0.0, 0.0),
    "B": (0.0, -1.0, 0.0),
    "T": (-1.0, 0.0, 0.0),
}


def gp12_model() -> Model:
    """Yaskawa GP12-class arm: joints S, L, U, R, B, T; all zero = upper arm vertical, forearm
    and flange forward horizontal (Yaskawa's zero)."""
    b, g = "yaskawa_blue", "yaskawa_grey"
    parents = ["base_link", "link_1", "link_2", "link_3", "link_4", "link_5"]
    xyz = [
        (0.0, 0.0, GP12_S_HEIGHT),
        (GP12_S_TO_L, 0.0, 0.0),
        (0.0, 0.0, GP12_UPPER_ARM),
        (GP12_U_TO_B, 0.0, GP12_U_TO_R_UP),
        (0.0, 0.0, 0.0),
        (GP12_B_TO_FLANGE, 0.0, 0.0),
    ]
    j = []
    for i, name in enumerate(["S", "L", "U", "R", "B", "T"]):
        lo, hi, v = GP12_LIMITS[name]
        j.append(
            Joint(name, parents[i], f"link_{i + 1}", xyz[i], axis=GP12_AXES[name],
                  lower_deg=lo, upper_deg=hi, velocity_deg_s=v)
        )
    j.append(Joint("flange_joint", "link_6", "flange", (0.0, 0.0, 0.0), FLANGE_RPY_DEG))
    L, R, W, FL = GP12_UPPER_ARM, GP12_U_TO_R_UP, GP12_U_TO_B, GP12_B_TO_FLANGE
    SL = GP12_S_TO_L
    vis: dict[str, tuple[Primitive, ...]] = {
        "base_link": (
            Hull(tuple(Cyl((x, y, 0.0), (x, y, 25.0), 30.0, g, 12)
                       for x in (-160.0, 150.0) for y in (-155.0, 155.0)), g),  # base plate
            Hull((Cyl((0.0, 0.0, 25.0), (0.0, 0.0, 60.0), 140.0, b, 32),
                  Cyl((0.0, 0.0, 190.0), (0.0, 0.0, 220.0), 125.0, b, 32)), b),  # base drum
        ),
        "link_1": (  # frame at L height on the S axis
            Cyl((0.0, 0.0, -230.0), (0.0, 0.0, -190.0), 132.0, b, 32),  # turntable
            Hull((Cyl((0.0, 0.0, -190.0), (0.0, 0.0, -130.0), 125.0, b, 32),
                  Cyl((SL, -130.0, 0.0), (SL, 40.0, 0.0), 100.0, b, 32)), b),  # S head
            Cyl((-120.0, 0.0, -180.0), (-120.0, 0.0, -60.0), 50.0, g, 20),  # S motor (rear)
            Cyl((SL, -190.0, 0.0), (SL, -130.0, 0.0), 62.0, g, 24),  # L motor
        ),
        "link_2": (  # frame at L; the upper arm is vertical at L = 0
            Hull((Cyl((0.0, 45.0, 0.0), (0.0, 125.0, 0.0), 95.0, b, 32),
                  Cyl((0.0, 45.0, L), (0.0, 125.0, L), 78.0, b, 32)), b),  # upper arm
            Cyl((0.0, 125.0, 0.0), (0.0, 135.0, 0.0), 70.0, g, 24),  # covers
            Cyl((0.0, 125.0, L), (0.0, 135.0, L), 55.0, g, 24),
        ),
        "link_3": (  # frame at U
            Hull((Cyl((0.0, -85.0, 0.0), (0.0, 45.0, 0.0), 85.0, b, 32),
                  Cyl((-170.0, 0.0, R), (80.0, 0.0, R), 80.0, b, 28)), b),  # U casing
            Cyl((0.0, -140.0, 0.0), (0.0, -85.0, 0.0), 60.0, g, 24),  # U motor
            Cyl((-250.0, 0.0, R), (-170.0, 0.0, R), 60.0, g, 24),  # R, B, T motors (rear)
        ),
        "link_4": (  # frame at the B axis (wrist centre) on the R axis
            Hull((Cyl((80.0 - W, 0.0, 0.0), (140.0 - W, 0.0, 0.0), 72.0, b, 28),
                  Cyl((-150.0, 0.0, 0.0), (-110.0, 0.0, 0.0), 56.0, b, 28)), b),  # forearm
            Hull((Box((-120.0, -62.0, -45.0), (-100.0, -46.0, 45.0), b),
                  Cyl((0.0, -62.0, 0.0), (0.0, -46.0, 0.0), 48.0, b, 24)), b),  # wrist fork
            Hull((Box((-120.0, 46.0, -45.0), (-100.0, 62.0, 45.0), b),
                  Cyl((0.0, 46.0, 0.0), (0.0, 62.0, 0.0), 48.0, b, 24)), b),
        ),
        "link_5": (  # frame at the wrist centre
            Cyl((0.0, -46.0, 0.0), (0.0, 46.0, 0.0), 45.0, b, 24),  # B knuckle
            Cone((0.0, 0.0, 0.0), (FL - 14.0, 0.0, 0.0), 40.0, 36.0, b, 24),
        ),
        "link_6": (  # frame at the flange face
            Cyl((-14.0, 0.0, 0.0), (0.0, 0.0, 0.0), 31.5, "steel", 32),  # flange disc
            Cyl((-1.0, 0.0, 22.0), (1.0, 0.0, 22.0), 3.0, g, 8),  # dowel-pin mark (+X flange)
        ),
    }
    return Model(
        name="yaskawa_gp12",
        folder="gp12",
        file="gp12.urdf",
        links=("base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6", "flange"),
        joints=tuple(j),
        visuals=vis,
        header=(
            "Yaskawa Motoman GP12-class arm (12 kg, 1440 mm reach). Authored by\n"
            "robots/generate.py; do not edit. Joint zero = upper arm vertical, forearm forward.\n"
            "Figures: Yaskawa GP12 data sheet as reproduced in ROS-Industrial\n"
            "motoman/motoman_gp12_support (gp12_macro.xacro); see robots/README.md."
        ),
    )


# ---------------------------- Tools (hidden true TOOL frames) --------------------------------
# A tool's `tcp` link: origin at the tip, X = working direction. rpy (deg) is URDF's fixed-axis
# roll-pitch-yaw, R_mount_tcp = Rz(yaw) Ry(pitch) Rx(roll).
POINTER_LENGTH = 180.0  # flange face to the pointer tip, on the flange Z axis
TORCH_BODY = 220.0  # straight body along the flange axis, flange face to the bend
TORCH_NECK = 110.0  # bend to the contact tip face, along the neck
TORCH_STICKOUT = 15.0  # wire stick-out beyond the contact tip (TCP = wire end)
TORCH_BEND_DEG = 22.0  # neck bend away from the flange axis
TORCH_CLOCK_DEG = 30.0  # bend plane turned about the flange Z axis (clocking of the mount)
GRIPPER_HOUSING = 75.0  # flange face to the finger roots
GRIPPER_FINGER = 100.0  # finger length
GRIPPER_TCP = 165.0  # TCP on the flange axis, in the middle of the fingertip pads
GRIPPER_OPENING = 40.0  # gap between the finger pads


def torch_tcp() -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """TCP position (mm) and URDF rpy (deg) of the torch, in the flange (tool_mount) frame.

    Neck direction u = Rz(clock) Ry(bend) e_z; TCP = bend point + (neck + stick-out) u;
    R_mount_tcp = Rz(clock) Ry(bend - 90 deg), so tool X = u (Ry(-90 deg) turns X onto Z).
    """
    u = Rotation.from_euler("ZY", [TORCH_CLOCK_DEG, TORCH_BEND_DEG], degrees=True).apply([0, 0, 1])
    p = np.array([0.0, 0.0, TORCH_BODY]) + (TORCH_NECK + TORCH_STICKOUT) * u
    return (float(p[0]), float(p[1]), float(p[2])), (0.0, TORCH_BEND_DEG - 90.0, TORCH_CLOCK_DEG)


def _tool_model(name: str, visuals: tuple[Primitive, ...], tcp_xyz: tuple[float, float, float],
                tcp_rpy: tuple[float, float, float], header: str) -> Model:
    return Model(
        name=name,
        folder="tools",
        file=f"{name}.urdf",
        links=("tool_mount", "tcp"),
        joints=(Joint("tcp_joint", "tool_mount", "tcp", tcp_xyz, tcp_rpy),),
        visuals={"tool_mount": visuals},
        header=header,
    )


def pointer_model() -> Model:
    L = POINTER_LENGTH
    vis = (
        Cyl((0.0, 0.0, 0.0), (0.0, 0.0, 12.0), 31.5, "dark_steel", 32),  # adapter plate
        Cyl((0.0, 0.0, 12.0), (0.0, 0.0, 40.0), 16.0, "dark_steel", 24),  # clamp
        Cyl((0.0, 0.0, 40.0), (0.0, 0.0, L - 45.0), 6.0, "steel", 16),  # rod
        Cone((0.0, 0.0, L - 45.0), (0.0, 0.0, L - 12.0), 6.0, 2.5, "steel", 16),
        Cone((0.0, 0.0, L - 12.0), (0.0, 0.0, L), 2.5, 0.0, "red", 16),  # sharp red tip
    )
    return _tool_model(
        "pointer", vis, (0.0, 0.0, L), (0.0, -90.0, 0.0),
        "Straight calibration pointer: TCP on the flange Z axis, tool X along it.",
    )


def torch_model() -> Model:
    tcp_xyz, tcp_rpy = torch_tcp()
    R_clock = Rotation.from_euler("Z", TORCH_CLOCK_DEG, degrees=True)
    u = R_clock * Rotation.from_euler("Y", TORCH_BEND_DEG, degrees=True)
    bend = np.array([0.0, 0.0, TORCH_BODY])

    def on_neck(s: float) -> tuple[float, float, float]:
        p = bend + s * u.apply([0.0, 0.0, 1.0])
        return (float(p[0]), float(p[1]), float(p[2]))

    # Cable stub and bracket on the side, in the bend plane, so the clocking is visible.
    side = R_clock.apply([-1.0, 0.0, 0.0])
    stub0 = tuple(float(v) for v in (np.array([0.0, 0.0, 60.0]) + 20.0 * side))
    stub1 = tuple(float(v) for v in (np.array([0.0, 0.0, 60.0]) + 75.0 * side))
    N = TORCH_NECK
    vis = (
        Cyl((0.0, 0.0, 0.0), (0.0, 0.0, 12.0), 31.5, "dark_steel", 32),  # adapter plate
        Cyl((0.0, 0.0, 12.0), (0.0, 0.0, 55.0), 27.0, "tool_black", 24),  # collision sensor
        Cyl((0.0, 0.0, 55.0), (0.0, 0.0, TORCH_BODY), 15.0, "tool_black", 20),  # torch body
        Cyl(stub0, stub1, 9.0, "tool_black", 12),  # cable/hose stub
        Cyl(on_neck(-8.0), on_neck(N - 42.0), 11.0, "tool_black", 20),  # bent neck
        Cone(on_neck(N - 42.0), on_neck(N - 4.0), 12.0, 8.5, "copper", 20),  # gas nozzle
        Cone(on_neck(N - 4.0), on_neck(N), 5.0, 3.0, "brass", 12),  # contact tip
        Cyl(on_neck(N), on_neck(N + TORCH_STICKOUT), 1.2, "steel", 8),  # wire stick-out
    )
    return _tool_model(
        "torch", vis, tcp_xyz, tcp_rpy,
        f"MIG/MAG torch with a {TORCH_BEND_DEG:g} deg bent neck: TCP at the wire end, tool X "
        "along the wire.",
    )


def gripper_model() -> Model:
    H, F, g = GRIPPER_HOUSING, GRIPPER_FINGER, GRIPPER_OPENING / 2.0
    tip = H + F
    vis = (
        Cyl((0.0, 0.0, 0.0), (0.0, 0.0, 12.0), 31.5, "dark_steel", 32),  # adapter plate
        Box((-35.0, -60.0, 12.0), (35.0, 60.0, H), "steel"),  # gripper body
        Box((-14.0, -60.0, H - 12.0), (14.0, 60.0, H), "dark_steel"),  # jaw guide
        Box((-12.0, -g - 14.0, H), (12.0, -g - 6.0, tip), "dark_steel"),  # finger -Y
        Box((-12.0, g + 6.0, H), (12.0, g + 14.0, tip), "dark_steel"),  # finger +Y
        Box((-12.0, -g - 6.0, tip - 30.0), (12.0, -g, tip), "red"),  # pad -Y
        Box((-12.0, g, tip - 30.0), (12.0, g + 6.0, tip), "red"),  # pad +Y
    )
    return _tool_model(
        "gripper", vis, (0.0, 0.0, GRIPPER_TCP), (0.0, -90.0, 0.0),
        "Two-finger parallel gripper: TCP between the fingertip pads, tool X = approach "
        "direction (flange Z), tool Y = closing direction (flange Y).",
    )


# ---------------------------- Reference tip ---------------------------------------------------
REF_TIP_HEIGHT = 250.0  # stand_base (floor) to the spike's point


def reference_tip_model() -> Model:
    H = REF_TIP_HEIGHT
    vis = (
        Cyl((0.0, 0.0, 0.0), (0.0, 0.0, 15.0), 90.0, "dark_steel", 32),  # heavy foot
        Cyl((0.0, 0.0, 15.0), (0.0, 0.0, H - 70.0), 14.0, "safety_yellow", 20),  # column
        Cone((0.0, 0.0, H - 70.0), (0.0, 0.0, H - 45.0), 14.0, 7.0, "safety_yellow", 20),
        Cone((0.0, 0.0, H - 45.0), (0.0, 0.0, H), 7.0, 0.0, "steel", 20),  # sharp spike
    )
    return Model(
        name="reference_tip",
        folder="reference_tip",
        file="reference_tip.urdf",
        links=("stand_base", "tip"),
        joints=(Joint("tip_joint", "stand_base", "tip", (0.0, 0.0, H)),),
        visuals={"stand_base": vis},
        header="Reference tip: a sharp spike on a stand. Link `tip` is exactly at the point.",
    )


ALL_MODELS = (kr6_model, gp12_model, pointer_model, torch_model, gripper_model,
              reference_tip_model)


# --------------------------------------------------------------------------------------------
# Writers
# --------------------------------------------------------------------------------------------
def _num(x: float) -> str:
    """Shortest text that reads back as exactly the same double; -0 written as 0."""
    x = float(x) + 0.0
    return "0" if x == 0.0 else repr(x)


def _vec(v: Sequence[float]) -> str:
    return " ".join(_num(x) for x in v)


def _mesh_bytes(mesh: trimesh.Trimesh) -> bytes:
    """Binary STL (metres) with a fixed header, vertices rounded to 1 micrometre."""
    tri = np.round(mesh.vertices[mesh.faces] * MM, VERTEX_DECIMALS).astype("<f4")
    n = tri.shape[0]
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    nrm = np.cross(e1.astype(np.float64), e2.astype(np.float64))
    ln = np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm = np.where(ln > 0, nrm / np.where(ln > 0, ln, 1.0), 0.0)
    rec = np.zeros(n, dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["n"] = np.round(nrm, 6)
    rec["v"] = tri
    buf = io.BytesIO()
    buf.write(b"tcp-pendant robots/generate.py".ljust(80, b" "))
    buf.write(np.uint32(n).tobytes())
    buf.write(rec.tobytes())
    return buf.getvalue()


def build_meshes(model: Model) -> dict[str, tuple[str, str, trimesh.Trimesh]]:
    """Meshes of a model: {file name: (link, colour, mesh in mm)}; one per (link, colour)."""
    out: dict[str, tuple[str, str, trimesh.Trimesh]] = {}
    for link in model.links:
        prims = model.visuals.get(link, ())
        colours: list[str] = []
        for p in prims:
            if p.colour not in colours:
                colours.append(p.colour)
        for c in colours:
            parts = [primitive_mesh(p) for p in prims if p.colour == c]
            mesh = trimesh.util.concatenate(parts)
            fname = f"{model.name}_{link}_{c}.stl" if model.folder == "tools" else f"{link}_{c}.stl"
            out[fname] = (link, c, mesh)
    return out


def urdf_text(model: Model, meshes: dict[str, tuple[str, str, trimesh.Trimesh]]) -> str:
    """URDF text (metres, radians) with mesh paths relative to the URDF file."""
    lines = ['<?xml version="1.0"?>', "<!--"]
    lines += ["  " + h for h in model.header.splitlines()]
    lines += ["-->", f'<robot name="{model.name}">']
    used = sorted({c for (_, c, _) in meshes.values()})
    for c in used:
        r, g, b = (v / 255.0 for v in COLOURS[c])
        rgba = f"{_num(r)} {_num(g)} {_num(b)} 1"
        lines.append(f'  <material name="{c}"><color rgba="{rgba}"/></material>')
    for link in model.links:
        files = [(f, c) for f, (lk, c, _) in meshes.items() if lk == link]
        if not files:
            lines.append(f'  <link name="{link}"/>')
            continue
        lines.append(f'  <link name="{link}">')
        for f, c in files:
            lines += [
                f'    <visual name="{f[:-4]}">',
                '      <origin xyz="0 0 0" rpy="0 0 0"/>',
                f'      <geometry><mesh filename="meshes/{f}"/></geometry>',
                f'      <material name="{c}"/>',
                "    </visual>",
            ]
        lines.append("  </link>")
    for jt in model.joints:
        kind = "fixed" if jt.axis is None else "revolute"
        xyz = tuple(v / 1000.0 for v in jt.xyz_mm)  # exact decimal metres
        rpy = tuple(math.radians(v) for v in jt.rpy_deg)
        lines += [
            f'  <joint name="{jt.name}" type="{kind}">',
            f'    <parent link="{jt.parent}"/>',
            f'    <child link="{jt.child}"/>',
            f'    <origin xyz="{_vec(xyz)}" rpy="{_vec(rpy)}"/>',
        ]
        if jt.axis is not None:
            lines += [
                f'    <axis xyz="{_vec(jt.axis)}"/>',
                f'    <limit lower="{_num(math.radians(jt.lower_deg))}" '
                f'upper="{_num(math.radians(jt.upper_deg))}" effort="0" '
                f'velocity="{_num(math.radians(jt.velocity_deg_s))}"/>',
            ]
        lines.append("  </joint>")
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def render(model: Model) -> dict[str, bytes]:
    """All files of one model, keyed by their path relative to robots/."""
    meshes = build_meshes(model)
    files = {f"{model.folder}/{model.file}": urdf_text(model, meshes).encode()}
    for f, (_, _, mesh) in meshes.items():
        files[f"{model.folder}/meshes/{f}"] = _mesh_bytes(mesh)
    return files


def render_all() -> dict[str, bytes]:
    """Every generated file, keyed by its path relative to robots/."""
    files: dict[str, bytes] = {}
    for make in ALL_MODELS:
        files.update(render(make()))
    return files


def triangle_counts() -> dict[str, int]:
    """Visual triangles per model name."""
    return {
        m.name: sum(len(mesh.faces) for (_, _, mesh) in build_meshes(m).values())
        for m in (make() for make in ALL_MODELS)
    }


def write_all(out_dir: Path) -> list[Path]:
    """Write every generated file under out_dir (created if needed); returns the paths."""
    written = []
    for rel, data in render_all().items():
        p = out_dir / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(data)
        written.append(p)
    return written


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=HERE, help="output folder (default: robots/)")
    args = ap.parse_args(argv)
    paths = write_all(args.out)
    for name, n in triangle_counts().items():
        print(f"{name:24s} {n:6d} triangles")
    print(f"wrote {len(paths)} files under {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
