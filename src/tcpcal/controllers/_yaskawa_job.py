"""Yaskawa Motoman INFORM jobs (``.JBI``): the positions of a job's ``//POS`` section.

A job, as DX100/YRC1000 controllers save it::

    /JOB
    //NAME R1_TABLE
    //POS
    ///NPOS 0,0,0,4,0,0
    ///TOOL 3                     (the tool the next positions were taught with)
    ///POSTYPE PULSE              (PULSE: encoder counts per axis; ROBOT, BASE, USER: Cartesian)
    ///PULSE
    P00001=164994,-57222,-52993,1,5655,0
    ///POSTYPE BASE
    ///RECTAN                     (Cartesian: X, Y, Z mm, Rx, Ry, Rz deg)
    ///RCONF 0,0,0,0,0,0,0,0
    P00006=-863.111,979.613,426.219,178.9297,-0.1487,123.0482
    //INST
    ...
    SUB P006 P004                 (P004 is an offset here, not a position)

``C#####`` are the job's own positions, ``P#####`` the position variables it uses; ``BC``/``EC``
(base and station axes) are not the robot's and are not read. A RECTAN position is
``R = Rz(Rz) Ry(Ry) Rx(Rx)`` (about the fixed X, then Y, then Z: the convention of
``TOOL.CND``, and FANUC's W, P, R), in the ROBOT or BASE frame (``///POSTYPE USER`` with
``///USER n``: user frame n, reported as the base). A PULSE position is encoder counts: the
axis angle is ``pulses / pulses_per_degree`` with the robot's own pulses per degree (its
controller parameters), which tcpcal does not know; ``tcp-pendant poses import --robot ...
--pulses-per-degree ...`` converts them (:func:`pulse_refusal` names the way).
docs/formats.md cites the public jobs this layout is taken from.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from scipy.spatial.transform import Rotation

from tcpcal.controllers._common import (
    PULSE_SKIPPED,
    ControllerFileError,
    PulsePoint,
    RecordedPose,
    fixed,
    to_float,
)
from tcpcal.tool import abc_deg_from_rotation

__all__ = ["job_warnings", "parse_job_poses", "parse_pulse_points", "pulse_refusal",
           "render_job"]

_POSITION = re.compile(r"^(C|P)(\d+)\s*=\s*(.*)$")
_OFFSET_USE = re.compile(r"^\s*(?:ADD|SUB)\s+P(\d+)\s+P(\d+)\b|^\s*SFTON\s+P(\d+)\b", re.M)
_CARTESIAN = ("ROBOT", "BASE", "USER")
@dataclass
class _Job:
    rectan: list[RecordedPose]
    pulses: list[PulsePoint]
    other: list[str]


def _offsets(text: str) -> dict[int, str]:
    """The position variables a job's ``//INST`` uses as offsets (``ADD/SUB Pa Pb``: Pb;
    ``SFTON Pn``), by number, with the instruction."""
    inst = text[text.find("//INST"):] if "//INST" in text else ""
    out: dict[int, str] = {}
    for m in _OFFSET_USE.finditer(inst):
        number = int(m.group(2) or m.group(3))
        out.setdefault(number, " ".join(m.group(0).split()))
    return out


def _read(text: str) -> _Job:
    """Every robot position of the ``//POS`` section, in file order."""
    job = _Job([], [], [])
    tool: int | None = None
    user: int | None = None
    postype = ""
    mode = ""
    in_pos = False
    for i, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if line.startswith("//") and not line.startswith("///"):
            in_pos = line == "//POS"
            continue
        if not in_pos:
            continue
        if line.startswith("///"):
            key, _, value = line[3:].partition(" ")
            if key == "TOOL":
                tool = int(value) if value.strip().isdigit() else None
            elif key == "USER":
                user = int(value) if value.strip().isdigit() else None
            elif key == "POSTYPE":
                postype = value.strip().upper()
            elif key in ("PULSE", "RECTAN"):
                mode = key
            continue
        m = _POSITION.match(line)
        if not m:
            continue
        name = f"{m.group(1)}{m.group(2)}"
        values = [v for v in m.group(3).split(",") if v.strip()]
        if mode == "PULSE":
            counts = tuple(int(to_float(v, "yaskawa", f"line {i}: {name}")) for v in values)
            job.pulses.append(PulsePoint(name, counts, i, tool))
        elif mode == "RECTAN" and postype in _CARTESIAN:
            if len(values) < 6:
                raise ControllerFileError(f"yaskawa: line {i}: {name} needs X,Y,Z,Rx,Ry,Rz, got "
                                          f"{len(values)} numbers")
            v = [to_float(t, "yaskawa", f"line {i}: {name}") for t in values[:6]]
            base = (user if user is not None else 1) if postype == "USER" else None
            rot = Rotation.from_euler("xyz", v[3:], degrees=True).as_matrix()
            job.rectan.append(RecordedPose(name, (v[0], v[1], v[2]), rot, tuple(v[3:]),
                                           tool=tool, base=base, line=i))
        else:
            job.other.append(f"{name} ({postype or 'no POSTYPE'})")
    return job


def _offset_number(name: str) -> int | None:
    return int(name[1:]) if name.startswith("P") else None


def parse_job_poses(text: str) -> list[RecordedPose]:
    """The RECTAN positions (ROBOT/BASE/USER frame) of a job, in file order, without the
    position variables its instructions use as offsets (:func:`job_warnings` names them).

    Raises:
        ControllerFileError: a RECTAN position that cannot be read; a job whose robot
            positions are all PULSE (:func:`pulse_refusal`).
    """
    job = _read(text)
    offsets = _offsets(text)
    poses = [p for p in job.rectan if _offset_number(p.name) not in offsets]
    if not job.rectan and job.pulses:
        raise ControllerFileError(pulse_refusal(len(job.pulses)))
    return poses


def parse_pulse_points(text: str) -> list[PulsePoint]:
    """The PULSE positions of a job (encoder counts), in file order."""
    return _read(text).pulses


def pulse_refusal(count: int) -> str:
    """Why a job's PULSE positions are not imported, and the ways out."""
    return (f"yaskawa: the job holds {count} position{'s' if count != 1 else ''} "
            f"{PULSE_SKIPPED}, not Cartesian poses: an axis angle is the count divided by the "
            "robot's pulses per degree, which only the controller's parameters give; convert "
            "them with 'tcp-pendant poses import FILE --robot PATH.urdf --pulses-per-degree "
            "S,L,U,R,B,T', or save the job with RECTAN positions on the pendant (position "
            "type ROBOT or BASE)")


def job_warnings(text: str) -> list[str]:
    """What the technician should know about a job's positions: offsets skipped, PULSE
    positions skipped next to Cartesian ones, positions of a type tcpcal does not read."""
    job = _read(text)
    out: list[str] = []
    offsets = _offsets(text)
    used = [(p.name, offsets[n]) for p in job.rectan
            if (n := _offset_number(p.name)) is not None and n in offsets]
    if used:
        out.append("; ".join(f"{name} is an offset ({how})" for name, how in used)
                   + ": not a recorded position, skipped")
    if job.rectan and job.pulses:
        names = ", ".join(p.name for p in job.pulses[:8]) + (", ..." if len(job.pulses) > 8 else "")
        out.append(f"skipped {len(job.pulses)} position{'s' if len(job.pulses) != 1 else ''} "
                   f"{PULSE_SKIPPED} ({names}): convert them with 'tcp-pendant poses import "
                   "FILE --robot PATH.urdf --pulses-per-degree S,L,U,R,B,T', or save them as "
                   "RECTAN on the pendant")
    if job.other:
        out.append(f"skipped {', '.join(job.other)}: tcpcal reads RECTAN positions in the "
                   "ROBOT, BASE or USER frame")
    return out


def render_job(poses: Sequence[RecordedPose], name: str = "TOUCHES") -> str:
    """A job declaring each pose as ``P0000k`` RECTAN in the ROBOT frame with tool 0 (the
    flange), mm 3 decimals and deg 4, as the public jobs write them (tests, examples)."""
    lines = ["/JOB", f"//NAME {name}", "//POS", f"///NPOS 0,0,0,{len(poses)},0,0", "///TOOL 0",
             "///POSTYPE ROBOT", "///RECTAN", "///RCONF 0,0,0,0,0,0,0,0"]
    for k, p in enumerate(poses, 1):
        rz, ry, rx = abc_deg_from_rotation(p.rotation)
        values = [fixed(v, 3) for v in p.position_mm] + [fixed(v, 4) for v in (rx, ry, rz)]
        lines.append(f"P{k:05d}={','.join(values)}")
    lines += ["//INST", "///ATTR SC,RW", "///GROUP1 RB1", "NOP", "END"]
    return "\n".join(lines) + "\n"
