"""``tcp-pendant poses import``: POSES.csv from a controller program file, joint points included.

Usage::

    tcp-pendant poses import FILE --robot kr6|gp12|PATH.urdf|PATH.xacro
                             [--format auto|kuka|abb|fanuc|ur|yaskawa] [--flange-link LINK]
                             [--package-path DIR]... [--pulses-per-degree S,L,U,R,B,T]
                             [--output POSES.csv]

The same POSES.csv as ``tcpcal poses import`` (docs/cli.md), and the same warnings, but the
positions a program records in joint representation (FANUC ``J1 = ..`` points, ABB
``jointtarget``, KUKA ``E6AXIS``/``AXIS``; :class:`tcpcal.controllers.JointPoint`) are not
skipped: each becomes the flange pose ``T_world_flange(q)`` of the robot's forward kinematics
(:class:`tcp_pendant.controller.RobotKinematics`, pinocchio), WORLD being the URDF's root link
and FLANGE the ``--flange-link`` (default as ``tcp-pendant --robot``; ``--package-path`` finds
a ROS description's packages, as the server's option does). Rows keep the file order.

Positions in encoder counts (a Yaskawa job's PULSE positions,
:class:`tcpcal.controllers.PulsePoint`, of a format with ``parse_pulse_points``) become joint
points with ``--pulses-per-degree``: axis value (deg) = pulses / pulses per degree
of that axis, one number per robot axis in the job's order (S, L, U, R, B, T[, E]), from the
controller's parameters (the pulses of one axis revolution divided by 360; a negative number
turns an axis whose positive direction is the URDF's opposite), or the path of a text file
holding those numbers (commas, spaces or one per line; ``#`` starts a comment: tcp-pendant's
own format; a controller's parameter file such as ``ALL.PRM`` is refused with what to write).
Without it they are refused with this way out.

Units: the file's axis values are degrees for revolute joints and millimetres for prismatic
ones (as the controllers write them), in the URDF's joint order; the CSV is mm and the format's
orientation columns, like every POSES.csv. The values are taken in the URDF's joint convention
(zero and sign): right for a URDF whose joints match the controller's, as the built-in robots'
do; a point outside the URDF's joint limits is named in a warning.

Exit codes: 0 written; 2 bad options, an unreadable file or robot, a point whose axis count
differs from the robot's (one line on stderr).
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tcpcal.controllers import (
    POSE_FORMATS,
    PULSE_SKIPPED,
    REGISTRY,
    ControllerFileError,
    JointPoint,
    PoseImport,
    PulsePoint,
    RecordedPose,
    import_poses,
    detect_pose_format,
    poses_csv_text,
)
from tcpcal.errors import TcpcalError

if TYPE_CHECKING:
    from tcp_pendant.controller import RobotKinematics

__all__ = ["build_parser", "flange_poses_of_joint_points", "joint_points_of_pulses", "main"]


def build_parser() -> argparse.ArgumentParser:
    """The parser of ``tcp-pendant poses import``."""
    p = argparse.ArgumentParser(
        prog="tcp-pendant poses import",
        description="Print POSES.csv (as 'tcpcal poses import') from a controller program file; "
                    "positions in joint representation become flange poses by the robot's "
                    "forward kinematics.")
    p.add_argument("file", metavar="FILE", type=Path)
    p.add_argument("--robot", required=True,
                   help="kr6, gp12 or PATH.urdf: the robot that recorded the positions")
    p.add_argument("--flange-link", default=None,
                   help="link used as FLANGE (default: 'flange', else the last link of the longest "
                        "chain)")
    p.add_argument("--format", dest="fmt", default="auto", choices=("auto", *POSE_FORMATS),
                   help="the controller (default auto: from the extension, else the content)")
    p.add_argument("--package-path", action="append", default=[], type=Path, metavar="DIR",
                   help="a folder holding ROS packages (or a package itself), searched for "
                        "xacro's $(find pkg) before ROS_PACKAGE_PATH (repeatable)")
    p.add_argument("--pulses-per-degree", type=_pulses_per_degree, default=None,
                   metavar="S,L,U,R,B,T|FILE",
                   help="Yaskawa PULSE positions: the encoder pulses per degree of each axis "
                        "(controller parameters), or a text file holding them; the counts "
                        "become axis values in degrees")
    p.add_argument("--output", type=Path, default=None, metavar="POSES.csv",
                   help="write the CSV to this file instead of stdout (an existing file is refused)")
    return p


_CONTROLLER_PARAMETERS = re.compile(r"\A\s*/+[A-Z0-9]+ YAS\b")
"""The first line of a Yaskawa parameter file (``ALL.PRM``: ``/ALL YAS``, ``RC.PRM``: ``//RC
YAS``): blocks of comma-separated integers under ``///`` headers, which name no axis nor
unit."""


def _pulses_per_degree(text: str) -> tuple[float, ...]:
    """``--pulses-per-degree``: comma-separated non-zero finite numbers, or the path of a text
    file holding them (separated by commas, spaces or lines; ``#`` starts a comment). A
    controller's parameter file (``ALL.PRM``, ``RC.PRM``...) is refused with what to write."""
    path = Path(text).expanduser()
    source = repr(text)
    if not re.fullmatch(r"[-+0-9.,eE\s]*", text) and path.is_file():
        try:
            body = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise argparse.ArgumentTypeError(f"{text}: cannot read the file: {exc}") from None
        if _CONTROLLER_PARAMETERS.match(body):
            raise argparse.ArgumentTypeError(
                f"{text}: a Yaskawa parameter file ({body.split(chr(10), 1)[0].strip()}); "
                "tcp-pendant does not read pulses per degree from it. Write the robot's pulses "
                "per degree, one number per axis S L U R B T, in a plain text file "
                "(docs/pendant-cli.md) or give them as S,L,U,R,B,T")
        source = text
        text = ",".join(re.sub(r"#[^\n]*", "", body).replace(",", " ").split())
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{source}: give one number per axis, e.g. "
                                         "1300.5,1300.5,1100,800,800,500") from None
    if not values or any(not np.isfinite(v) or v == 0 for v in values):
        raise argparse.ArgumentTypeError(f"{source}: every axis needs a non-zero finite number")
    return values


def joint_points_of_pulses(points: Sequence[PulsePoint], pulses_per_degree: Sequence[float]
                           ) -> list[JointPoint]:
    """Each PULSE position as a joint point: ``deg = pulses / pulses_per_degree`` per axis.

    Raises:
        ValueError: a position whose axis count is not the number of factors given.
    """
    out = []
    for p in points:
        if len(p.pulses) != len(pulses_per_degree):
            raise ValueError(f"line {p.line}: {p.name} has {len(p.pulses)} axes but "
                             f"--pulses-per-degree gives {len(pulses_per_degree)} numbers")
        out.append(JointPoint(p.name, tuple(c / f for c, f in zip(p.pulses, pulses_per_degree)),
                              p.line, tool=p.tool, kind="PULSE"))
    return out


def _with_pulses(text: str, fmt: str, filename: str,
                 pulses_per_degree: Sequence[float]) -> PoseImport:
    """``import_poses`` of a program with its positions in encoder counts as joint points.

    Raises:
        ControllerFileError: the format has no such positions, or the file is unreadable.
        ValueError: a position whose axis count is not the number of factors.
    """
    parse = REGISTRY[fmt].parse_pulse_points
    if parse is None:
        raise ControllerFileError(f"--pulses-per-degree: {REGISTRY[fmt].label} files hold no "
                                  "positions in encoder counts; leave it out")
    pulses = parse(text)
    try:
        imported = import_poses(text, fmt, filename=filename)
    except ControllerFileError:
        if not pulses:
            raise
        imported = PoseImport(fmt, (), ())
    warnings = tuple(w for w in imported.warnings if PULSE_SKIPPED not in w)
    joints = joint_points_of_pulses(pulses, pulses_per_degree)
    return replace(imported, warnings=warnings, joint_points=(*imported.joint_points, *joints))


def flange_poses_of_joint_points(points: Sequence[JointPoint], kinematics: RobotKinematics,
                                 fmt: str) -> tuple[list[RecordedPose], list[str]]:
    """Each joint point as the flange pose of the robot ``kinematics``, with the
    orientation numbers of format ``fmt``; and the warnings (points outside the joint limits).

    Args:
        points: the file's joint points (deg for revolute joints, mm for prismatic ones).
        kinematics: the robot (``T_world_flange(q_rad)`` in m; ``revolute`` says which axis
            values are degrees, the others mm).
        fmt: the format whose orientation numbers the poses carry (``RecordedPose.values``).

    Raises:
        ValueError: a point whose number of axis values is not the robot's.
    """
    kin = kinematics
    n = kin.n_joints
    revolute = np.asarray(kin.revolute)
    angles = REGISTRY[fmt].angles_from_rotation
    poses: list[RecordedPose] = []
    outside: list[str] = []
    for p in points:
        if len(p.joints_deg) != n:
            raise ValueError(
                f"line {p.line}: {p.name} has {len(p.joints_deg)} axis values but the robot has "
                f"{n} joints ({', '.join(kin.joint_names)}); give the robot that recorded "
                "the file with --robot")
        v = np.asarray(p.joints_deg, dtype=float)
        q = np.where(revolute, np.radians(v), v / 1000.0)
        if kin.limit_violation(q) is not None:
            outside.append(p.name)
        T = np.asarray(kin.T_world_flange(q))
        R = T[:3, :3]
        xyz = tuple(float(c) * 1000.0 for c in T[:3, 3])
        poses.append(RecordedPose(p.name, xyz, R, tuple(float(a) for a in angles(R)),  # type: ignore[arg-type]
                                  tool=None, base=None, line=p.line))
    warnings = ([f"{', '.join(outside)} outside the joint limits of the robot model: check that "
                 "--robot is the robot that recorded the file"] if outside else [])
    return poses, warnings


def _error(message: str) -> int:
    print(f"tcp-pendant poses import: error: {' '.join(message.split())}", file=sys.stderr)
    return 2


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``tcp-pendant poses import``; return the exit status (0, or 2 with one line)."""
    args = build_parser().parse_args(list(sys.argv[1:] if argv is None else argv))
    from tcpcal.cli import read_controller_text
    from tcp_pendant.controller import ControllerError, RobotKinematics
    from tcp_pendant.serve.server import resolve_robot

    try:
        urdf = resolve_robot(args.robot)
    except ControllerError as exc:
        return _error(str(exc))
    try:
        text = read_controller_text(args.file)
        fmt = detect_pose_format(text, args.file.name) if args.fmt == "auto" else args.fmt
        if args.pulses_per_degree is not None:
            imported = _with_pulses(text, fmt, args.file.name, args.pulses_per_degree)
        else:
            imported = import_poses(text, fmt, filename=args.file.name)
    except OSError as exc:
        return _error(f"{args.file}: cannot read the file: {exc.strerror or exc}")
    except (TcpcalError, ValueError) as exc:
        return _error(f"{args.file}: {exc}")
    warnings = list(imported.warnings)
    poses = list(imported.poses)
    if imported.joint_points:
        try:
            kin = RobotKinematics.from_urdf(urdf, flange_link=args.flange_link,
                                            package_paths=tuple(args.package_path))
            converted, more = flange_poses_of_joint_points(imported.joint_points, kin,
                                                           imported.format)
        except (ControllerError, ValueError) as exc:
            return _error(f"{args.file}: {exc}")
        poses = sorted(poses + converted, key=lambda p: p.line)
        warnings += more
        n = len(converted)
        print(f"tcp-pendant: {args.file}: {n} point{'s' if n != 1 else ''} in joint "
              f"representation converted to flange poses of {kin.urdf_path.name} "
              f"(flange {kin.flange_link})", file=sys.stderr)
    for w in warnings:
        print(f"tcp-pendant: warning: {args.file}: {w}", file=sys.stderr)
    csv_text = poses_csv_text(PoseImport(imported.format, tuple(poses), tuple(warnings)))
    if args.output is None:
        sys.stdout.write(csv_text)
        return 0
    try:
        with open(args.output, "x", encoding="utf-8", newline="\n") as fh:
            fh.write(csv_text)
    except FileExistsError:
        return _error(f"{args.output}: the file exists; choose another name or remove it first")
    except OSError as exc:
        return _error(f"{args.output}: cannot write: {exc.strerror or exc}")
    print(f"Wrote {len(poses)} {imported.format} poses to {args.output}", file=sys.stderr)
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
