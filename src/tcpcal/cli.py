"""The ``tcpcal`` command line: solve calibrations from recorded poses, convert tool data,
manage the tool library.

Units: millimetres and degrees (KUKA A, B, C unless a format says otherwise). Exit status 0 on
success, 2 on bad input or usage (one line on stderr that names the file, the row and what is
wrong), 1 on an internal error (a bug: one line, the traceback only with ``TCPCAL_DEBUG=1``).
Documentation with examples and the JSON keys: docs/cli.md.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import traceback
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from tcpcal.controllers import formats as registered_formats
from tcpcal.errors import DegenerateTouchesError, TcpcalError
from tcpcal.poses_csv import MAX_ABS_MM, FlangePoses, accepted_layouts_text, read_poses_csv
from tcpcal.report import (
    format_orientation_report,
    format_tcp_report,
    format_tcp_zx_report,
    format_tool,
    format_tool_table,
    json_dumps,
    orientation_result_to_dict,
    tcp_result_to_dict,
    tcp_zx_result_to_dict,
    tool_to_dict,
)
from tcpcal.tool import rotation_from_abc_deg

__all__ = ["CliInputError", "build_parser", "main"]

# The formats, their choices, value counts and help come from tcpcal.controllers.REGISTRY,
# read when the parser is built (docs/architecture.md "Controller formats").


class CliInputError(Exception):
    """Bad command-line input found after argparse (exit 2, message printed as is)."""


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose usage errors are one line on stderr (exit 2).

    Also treats every token that starts with ``-`` followed by a digit or ``.`` as a value, so
    ``--tcp -10,20,30`` and ``convert --from kuka -10,20,30,0,0,0`` work (no option of tcpcal
    starts with a digit).
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def _floats(text: str, n: int, what: str) -> tuple[float, ...]:
    parts = [p for p in re.split(r"[,\s]+", text.strip()) if p]
    if len(parts) != n:
        raise argparse.ArgumentTypeError(
            f"{what} needs {n} comma-separated numbers, got {text!r}")
    try:
        vals = tuple(float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what} must be numbers, got {text!r}") from None
    if not all(np.isfinite(vals)):
        raise argparse.ArgumentTypeError(f"{what} must be finite numbers, got {text!r}")
    return vals


def _xyz_arg(text: str) -> tuple[float, float, float]:
    return _floats(text, 3, "X,Y,Z")  # type: ignore[return-value]


def _abc_arg(text: str) -> tuple[float, float, float]:
    return _floats(text, 3, "A,B,C")  # type: ignore[return-value]


def _positive_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not (np.isfinite(v) and v > 0):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text!r}")
    return v


#: ``solve --sigma`` range, mm (docs/cli.md "Number ranges").
SIGMA_RANGE_MM = (1e-9, 1e6)


def _sigma_mm(text: str) -> float:
    v = _positive_float(text)
    lo, hi = SIGMA_RANGE_MM
    if not lo <= v <= hi:
        raise argparse.ArgumentTypeError(f"touch noise must be within {lo:g}..{hi:g} mm, got {text!r}")
    return v


def _xyz_mm(text: str) -> tuple[float, float, float]:
    """X,Y,Z of a TCP for ``solve`` (mm), each within +-``MAX_ABS_MM`` like POSES.csv."""
    vals = _xyz_arg(text)
    if max(abs(v) for v in vals) > MAX_ABS_MM:
        raise argparse.ArgumentTypeError(f"X,Y,Z must be within +-{MAX_ABS_MM:g} mm, got {text!r}")
    return vals


def _beam_dir(text: str) -> tuple[float, float, float]:
    """U,V,W of ``solve beam --beam-dir``: 3 finite numbers, not all zero (any length)."""
    vals = _floats(text, 3, "U,V,W")
    if not any(vals):
        raise argparse.ArgumentTypeError(f"the beam direction must not be zero, got {text!r}")
    if max(abs(v) for v in vals) > MAX_ABS_MM:
        raise argparse.ArgumentTypeError(f"U,V,W must be within +-{MAX_ABS_MM:g}, got {text!r}")
    return vals  # type: ignore[return-value]


# ----------------------------------------------------------------------------------- parser
def build_parser() -> argparse.ArgumentParser:
    """The argparse tree of ``tcpcal`` (see docs/cli.md)."""
    p = _Parser(prog="tcpcal", description="TCP and TOOL-frame calibration from recorded "
                "flange poses; controller tool-data conversion; the tool library. "
                "Lengths in mm, angles in deg. See docs/cli.md.")
    sub = p.add_subparsers(dest="command", required=True,
                           metavar="{solve,convert,tools,poses}")

    # solve ---------------------------------------------------------------------------------
    solve = sub.add_parser("solve", help="calibrate from a CSV of flange poses",
                           description="Calibrate from a CSV of flange poses (one pose per "
                           "row, header row naming the columns). " + accepted_layouts_text())
    ssub = solve.add_subparsers(dest="method_cmd", required=True,
                                metavar="{xyz4,reference,three-point,abc-world,tcp-zx,beam}")

    def add_common(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("poses", metavar="POSES.csv", type=Path,
                        help="flange poses, x,y,z in mm + one orientation layout ('-': read "
                        "the CSV from stdin)")
        sp.add_argument("--json", action="store_true", help="print one JSON object")

    xyz4 = ssub.add_parser("xyz4", help="TCP from N >= 4 touches of one reference point",
                           description="XYZ 4-point: the tool tip touches one fixed point from "
                           "N >= 4 different orientations; one touch per row.")
    add_common(xyz4)
    xyz4.add_argument("--method", choices=("lstsq", "sphere", "pairwise"), default="lstsq",
                      help="estimator (default lstsq: joint least squares, the best)")
    xyz4.add_argument("--sigma", type=_sigma_mm, metavar="MM", default=None,
                      help="assumed touch noise per axis in mm (default: estimated from the "
                      "residuals)")
    xyz4.add_argument("--no-outliers", dest="detect_outliers", action="store_false",
                      help="do not flag outliers")

    ref = ssub.add_parser("reference", help="TCP of a new tool from one touch each",
                          description="XYZ reference: row 1 = the calibrated tool's touch, "
                          "row 2 = the new tool's touch of the same point.")
    add_common(ref)
    ref.add_argument("--known-tcp", type=_xyz_mm, required=True, metavar="X,Y,Z",
                     help="TCP of the calibrated tool in FLANGE, mm")
    ref.add_argument("--sigma", type=_sigma_mm, metavar="MM", default=None,
                     help="assumed touch noise per axis in mm")

    tp = ssub.add_parser("three-point", help="TOOL orientation from three poses",
                         description="Three-point orientation: row 1 = TCP on the reference, "
                         "row 2 = reference tip on the tool's -X axis, row 3 = tip on the +Y "
                         "axis (variant 1) or in the +Y half of the XY plane (variant 2).")
    add_common(tp)
    tp.add_argument("--tcp", type=_xyz_mm, required=True, metavar="X,Y,Z",
                    help="calibrated TCP in FLANGE, mm")
    tp.add_argument("--variant", type=int, choices=(1, 2), required=True)

    abc = ssub.add_parser("abc-world", help="TOOL orientation from the aligned flange pose",
                          description="ABC world (parallel axes): one row, the flange pose "
                          "while tool X points down (WORLD -Z), tool Y along WORLD +Y "
                          "(6d) - or only tool X down (5d).")
    add_common(abc)
    abc.add_argument("--variant", choices=("6d", "5d"), default="6d")
    abc.add_argument("--current-abc", type=_abc_arg, metavar="A,B,C", default=None,
                     help="5d only: the tool's present KUKA A,B,C (deg) whose rotation about "
                     "tool X is kept")

    zx = ssub.add_parser("tcp-zx", help="TCP and TOOL frame in one run (ABB TCP & Z, X)",
                         description="ABB TCP & Z, X: a 'role' column says what each row is: "
                         "touch (>= 4: the TCP on the reference point), z (the reference on "
                         "the tool's +Z axis ahead of the TCP: back off along the tool's Z), x "
                         "(the reference on the tool's +X axis). Several z and x rows are "
                         "averaged; Z is kept, X orthogonalised against it.")
    add_common(zx)
    zx.add_argument("--sigma", type=_sigma_mm, metavar="MM", default=None,
                    help="assumed touch noise per axis in mm (default: estimated)")
    zx.add_argument("--no-outliers", dest="detect_outliers", action="store_false",
                    help="do not flag outlying touches")

    beam = ssub.add_parser("beam", help="TCP from beam-sensor tip events (BullsEye / TRACC)",
                           description="Beam sensor: each row is the flange pose at which the "
                           "tool tip was on the light beam's centre line (a tip event); the "
                           "beam is the line through --beam-point along --beam-dir in WORLD. "
                           "At least 2 events whose tool orientations differ other than by a "
                           "turn about the beam (methods.md section 9).")
    add_common(beam)
    beam.add_argument("--beam-point", type=_xyz_mm, required=True, metavar="X,Y,Z",
                      help="a point of the beam line in WORLD, mm")
    beam.add_argument("--beam-dir", type=_beam_dir, required=True, metavar="U,V,W",
                      help="the beam's direction in WORLD (any length, not zero)")
    beam.add_argument("--sigma", type=_sigma_mm, metavar="MM", default=None,
                      help="assumed event noise per axis across the beam in mm (default: "
                      "estimated from the residuals)")

    # convert -------------------------------------------------------------------------------
    text_fmts = registered_formats(lambda f: f.has_text)
    text_names = tuple(f.name for f in text_fmts)
    file_only = tuple(f.name for f in registered_formats(lambda f: f.has_file and not f.has_text))
    pose_names = tuple(f.name for f in registered_formats(lambda f: f.parse_poses is not None))
    numbers = "; ".join(f"{f.name}: {f.numbers}" for f in text_fmts)
    conv = sub.add_parser(
        "convert", help="convert tool data between controller formats",
        description="Convert one tool frame between controller formats. VALUES is either the "
        f"numbers ({numbers}), or the controller text as the controller writes "
        "it (quote it), or '-' to read that text from stdin.")
    conv.add_argument("--from", dest="from_fmt", choices=text_names, required=True)
    conv.add_argument("--to", dest="to_fmt", choices=text_names, required=True)
    conv.add_argument("--name", default="tool", help="tool name used in the output text")
    conv.add_argument("--slot", type=int, default=1, help="tool number in the output text")
    conv.add_argument("--json", action="store_true", help="print one JSON object")
    conv.add_argument("values", nargs="+", metavar="VALUES")

    # tools ---------------------------------------------------------------------------------
    lib_help = "tool library file (default: the user data directory's tools.json)"
    tools = sub.add_parser("tools", help="the tool library (slots 1..16, one active)")
    tools.add_argument("--library", type=Path, default=None, metavar="PATH", help=lib_help)
    lib_parent = _Parser(add_help=False)
    lib_parent.add_argument("--library", type=Path, default=argparse.SUPPRESS, metavar="PATH",
                            help=lib_help)
    tsub = tools.add_subparsers(dest="tools_cmd", required=True,
                                metavar="{list,show,add,remove,activate,export,import}")
    tl = tsub.add_parser("list", parents=[lib_parent], help="the tool table")
    tl.add_argument("--json", action="store_true")
    ts = tsub.add_parser("show", parents=[lib_parent], help="one tool in detail")
    ts.add_argument("slot", metavar="SLOT", help="slot number or tool name")
    ts.add_argument("--json", action="store_true")
    ta = tsub.add_parser("add", parents=[lib_parent], help="store a tool in a slot")
    ta.add_argument("slot", metavar="SLOT", type=int)
    ta.add_argument("name", metavar="NAME")
    ta.add_argument("--xyz", type=_xyz_arg, required=True, metavar="X,Y,Z",
                    help="TCP in FLANGE, mm")
    ta.add_argument("--abc", type=_abc_arg, default=(0.0, 0.0, 0.0), metavar="A,B,C",
                    help="TOOL orientation, KUKA A,B,C in deg (default 0,0,0)")
    ta.add_argument("--mass", type=_positive_float, default=None, metavar="KG")
    ta.add_argument("--notes", default="")
    ta.add_argument("--activate", action="store_true", help="make it the active tool")
    ta.add_argument("--replace", action="store_true", help="overwrite an occupied slot")
    tr = tsub.add_parser("remove", parents=[lib_parent], help="empty a slot")
    tr.add_argument("slot", metavar="SLOT", help="slot number or tool name")
    tact = tsub.add_parser("activate", parents=[lib_parent], help="make a tool the active one")
    tact.add_argument("slot", metavar="SLOT", help="slot number, tool name, or 'none'")
    te = tsub.add_parser("export", parents=[lib_parent], help="print a tool as controller text")
    te.add_argument("slot", metavar="SLOT", help="slot number or tool name")
    te.add_argument("--format", dest="fmt", choices=(*text_names, *file_only), required=True,
                    help=f"{'|'.join(text_names)} print the tool data text; with --file or "
                    "--output, the whole file the controller loads"
                    + "".join(f" ({n}: always the file)" for n in file_only) + ". docs/formats.md")
    te.add_argument("--file", dest="whole_file", action="store_true",
                    help="print the whole controller file ("
                    + ", ".join(f.controller for f in registered_formats(lambda f: f.has_file))
                    + ")")
    te.add_argument("--output", type=Path, default=None, metavar="FILE",
                    help="write the controller file to FILE (implies --file; an existing FILE "
                    "is refused)")
    te.add_argument("--name", dest="file_name", default=None, metavar="NAME",
                    help="the tool's name in the file (default: its library name; ABB needs a "
                    "RAPID identifier)")
    te.add_argument("--register", type=int, default=None, metavar="M",
                    help=f"{'|'.join(_option_formats('register'))} file: the position register "
                    "the program overwrites (default 100)")

    tool_readers = tuple(f.name for f in registered_formats(lambda f: f.parse_file is not None))
    timp = tsub.add_parser("import", parents=[lib_parent],
                           help="read a controller file's tool table into the library",
                           description="Read the tool table of a controller file (KUKA "
                           "$config.dat, ABB RAPID module, FANUC UTOOL program, URScript "
                           "set_tcp, Yaskawa TOOL.CND: docs/formats.md) into the library. "
                           "Slots are the controller's tool numbers (a file without numbers: "
                           "the free slots in file order); names are kept (an entry without a "
                           "name becomes tool<n>); unused entries (no name, all zero) are "
                           "skipped. An occupied slot is never overwritten without --replace.")
    timp.add_argument("file", metavar="FILE", type=Path)
    timp.add_argument("--format", dest="fmt", default="auto", choices=("auto", *tool_readers),
                      help="the controller (default auto: from the extension, else the content)")
    timp.add_argument("--replace", action="store_true",
                      help="overwrite the occupied slots the file's tools go into")

    # poses ---------------------------------------------------------------------------------
    poses_p = sub.add_parser("poses", help="touch poses from controller program files")
    psub = poses_p.add_subparsers(dest="poses_cmd", required=True, metavar="{import}")
    pim = psub.add_parser("import", help="print POSES.csv from a controller program file",
                          description="Read the recorded positions of a controller program "
                          f"file ({', '.join(pose_names)}: docs/formats.md) and "
                          "print them as POSES.csv for 'tcpcal solve'. Record the touches with "
                          "no tool and no base active (the flange in WORLD). Points in joint "
                          "representation are skipped (tcpcal has no robot model): 'tcp-pendant "
                          "poses import FILE --robot ...' converts them.")
    pim.add_argument("file", metavar="FILE", type=Path)
    pim.add_argument("--format", dest="fmt", default="auto",
                     choices=("auto", *pose_names),
                     help="the controller (default auto: from the extension, else the content)")
    pim.add_argument("--output", type=Path, default=None, metavar="POSES.csv",
                     help="write the CSV to this file instead of stdout (an existing file is "
                     "refused)")
    return p


# ------------------------------------------------------------------------------ solve paths
def _solver_error(exc: TcpcalError, poses: FlangePoses, rows: Sequence[int] | None = None) -> str:
    """One line for a solver error: file, row (when the error names one) and the message."""
    msg = " ".join(str(exc).split())
    index = getattr(exc, "index", None)
    if isinstance(index, (int, np.integer)) and index >= 0:
        row = int(rows[int(index)]) if rows is not None and index < len(rows) else int(index)
        where = poses.where(row) if row < len(poses) else str(poses.path)
    else:
        where = f"{poses.path}, data rows 1-{len(poses)}" if len(poses) > 1 else str(poses.path)
    if isinstance(exc, DegenerateTouchesError):
        axis = getattr(exc, "unobservable_axis", None)
        if axis is not None:
            u = np.asarray(axis, dtype=float)
            k = int(np.argmax(np.abs(u)))
            if abs(u[k]) > 0.9:
                msg += f" [unobservable direction ~ flange {'XYZ'[k]} axis]"
            else:
                comps = ", ".join("0.000" if c == "-0.000" else c for c in (f"{v:.3f}" for v in u))
                msg += f" [unobservable direction in FLANGE: ({comps})]"
    return f"{where}: {msg}"


def _emit(text: str) -> None:
    sys.stdout.write(text)
    if not text.endswith("\n"):          # not text + "\n": a copy of 100 MB of --json
        sys.stdout.write("\n")


def _run_solve(args: argparse.Namespace) -> int:
    cmd = args.method_cmd
    if cmd == "xyz4":
        poses = read_poses_csv(args.poses, min_rows=4, purpose="xyz4")
        from tcpcal.origin import solve_xyz4

        try:
            res = solve_xyz4(poses.rotations, poses.positions_mm, method=args.method,
                             sigma=args.sigma, detect_outliers=args.detect_outliers)
        except TcpcalError as exc:
            raise CliInputError(_solver_error(exc, poses)) from None
        out = tcp_result_to_dict(res)
        _emit(_with_source(out, poses) if args.json
              else format_tcp_report(res, poses, command="solve xyz4"))
        return 0
    if cmd == "reference":
        poses = read_poses_csv(args.poses, min_rows=2, max_rows=2, purpose="reference "
                               "(row 1: calibrated tool, row 2: new tool)")
        from tcpcal.origin import solve_reference

        try:
            res = solve_reference(np.array(args.known_tcp), poses.rotations[0],
                                  poses.positions_mm[0], poses.rotations[1],
                                  poses.positions_mm[1], sigma=args.sigma)
        except TcpcalError as exc:
            raise CliInputError(_solver_error(exc, poses)) from None
        out = tcp_result_to_dict(res)
        out["known_tcp_mm"] = list(args.known_tcp)
        _emit(_with_source(out, poses) if args.json
              else format_tcp_report(res, poses, command="solve reference"))
        return 0
    if cmd == "three-point":
        from tcpcal.orientation import solve_three_point

        poses = read_poses_csv(args.poses, min_rows=3, max_rows=3, purpose="three-point "
                               "(row 1: touch, row 2: tip on -X, row 3: tip on +Y)")
        try:
            ores = solve_three_point(poses.rotations, poses.positions_mm, np.array(args.tcp),
                                     variant=args.variant)
        except TcpcalError as exc:
            raise CliInputError(_solver_error(exc, poses)) from None
        out = orientation_result_to_dict(ores, tcp_mm=args.tcp)
        _emit(_with_source(out, poses) if args.json else format_orientation_report(
            ores, poses, command=f"solve three-point --variant {args.variant}", tcp_mm=args.tcp))
        return 0
    if cmd == "abc-world":
        from tcpcal.orientation import solve_abc_world

        poses = read_poses_csv(args.poses, min_rows=1, max_rows=1, purpose="abc-world (the "
                               "flange pose at alignment)")
        if args.current_abc is not None and args.variant != "5d":
            raise CliInputError("--current-abc applies only to --variant 5d")
        current = (None if args.current_abc is None
                   else rotation_from_abc_deg(args.current_abc))
        try:
            ores = solve_abc_world(poses.rotations[0], variant=args.variant,
                                   current_rotation=current)
        except TcpcalError as exc:
            raise CliInputError(_solver_error(exc, poses)) from None
        out = orientation_result_to_dict(ores)
        _emit(_with_source(out, poses) if args.json else format_orientation_report(
            ores, poses, command=f"solve abc-world --variant {args.variant}"))
        return 0
    if cmd == "tcp-zx":
        return _run_tcp_zx(args)
    if cmd == "beam":
        return _run_beam(args)
    raise AssertionError(cmd)  # pragma: no cover - argparse restricts the choices


def _run_tcp_zx(args: argparse.Namespace) -> int:
    """``solve tcp-zx``: ABB TCP & Z, X from a CSV with a ``role`` column."""
    from tcpcal.tcp_zx import parse_role, solve_tcp_zx

    poses = read_poses_csv(args.poses, min_rows=6, purpose="tcp-zx (at least 4 touch rows, "
                           "1 z row and 1 x row)")
    if poses.roles is None:
        raise CliInputError(f"{poses.path} (header): no 'role' column; tcp-zx needs one "
                            f"saying touch, z or x for each row")
    roles = []
    for i, text in enumerate(poses.roles):
        try:
            roles.append(parse_role(text))
        except TcpcalError as exc:
            raise CliInputError(f"{poses.where(i)}: {' '.join(str(exc).split())}") from None
    try:
        res = solve_tcp_zx(poses.rotations, poses.positions_mm, roles, sigma=args.sigma,
                           detect_outliers=args.detect_outliers)
    except TcpcalError as exc:
        raise CliInputError(_solver_error(exc, poses)) from None
    _emit(_with_source(tcp_zx_result_to_dict(res), poses) if args.json
          else format_tcp_zx_report(res, poses))
    return 0


def _run_beam(args: argparse.Namespace) -> int:
    """``solve beam``: the TCP from beam-sensor tip events (methods.md section 9)."""
    from tcpcal.beam import MIN_EVENTS, solve_beam
    from tcpcal.report import beam_result_to_dict, format_beam_report

    poses = read_poses_csv(args.poses, min_rows=MIN_EVENTS, purpose="beam (one tip event per "
                           "row)")
    try:
        res = solve_beam(poses.rotations, poses.positions_mm, np.array(args.beam_point),
                         np.array(args.beam_dir), sigma=args.sigma)
    except TcpcalError as exc:
        raise CliInputError(_solver_error(exc, poses)) from None
    if args.json:
        _emit(_with_source(beam_result_to_dict(res, beam_point_mm=args.beam_point,
                                               beam_dir=args.beam_dir), poses))
    else:
        _emit(format_beam_report(res, poses, beam_point_mm=args.beam_point,
                                 beam_dir=args.beam_dir))
    return 0


def _with_source(out: dict[str, Any], poses: FlangePoses) -> str:
    out = dict(out)
    out["input"] = {"path": str(poses.path), "layout": poses.layout, "n_rows": len(poses),
                    "line_numbers": list(poses.line_numbers)}
    if poses.joints_deg is not None:  # j1..jK columns: kept, never solved
        out["joints_deg"] = [list(j) for j in poses.joints_deg]
    return json_dumps(out, workers=_json_workers())


def _json_workers() -> int:
    """Processes that format a large --json output (``json_dumps``): the CPUs this process may
    use, at most 4 (10^6 residual vectors: ~1.7 s of float formatting in one process)."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # not on every platform
        cpus = os.cpu_count() or 1
    return max(1, min(4, cpus))


# ---------------------------------------------------------------------------- convert path
def _run_convert(args: argparse.Namespace) -> int:
    from tcpcal.formats import export_tool, import_tool, text_format

    if args.values == ["-"]:
        raw = sys.stdin.read()
    else:
        raw = " ".join(args.values)
    tokens = [t for t in re.split(r"[,\s]+", raw.strip()) if t]
    try:
        numbers: list[float] | None = [float(t) for t in tokens] if tokens else None
    except ValueError:
        numbers = None
    if numbers is not None:
        source = text_format(args.from_fmt)
        counts = source.value_counts
        if len(numbers) not in counts:
            raise CliInputError(f"convert --from {args.from_fmt}: {len(numbers)} numbers given, "
                                f"{' or '.join(map(str, counts))} expected "
                                f"(see 'tcpcal convert --help')")
        if not all(np.isfinite(numbers)):
            raise CliInputError(f"convert --from {args.from_fmt}: the values must be finite "
                                f"numbers")
        raw = source.values_to_text(numbers)  # type: ignore[misc]  # its own syntax
    try:
        tool = import_tool(raw, args.from_fmt, name=args.name)
    except TcpcalError as exc:
        raise CliInputError(f"convert: {' '.join(str(exc).split())}") from None
    text = export_tool(tool, args.to_fmt, slot=args.slot)
    if args.json:
        _emit(json_dumps({"from": args.from_fmt, "to": args.to_fmt, "text": text,
                          "tcp_mm": list(tool.tcp_mm), "kuka_abc_deg": list(tool.abc_deg),
                          "rotation_matrix": np.asarray(tool.rotation)}))
    else:
        _emit(text)
    return 0


# ------------------------------------------------------------------------------ tools path
def _resolve_slot(lib: Any, key: str) -> int:
    """A slot number from ``SLOT`` (a number 1..16 or a stored tool's name)."""
    key = key.strip()
    if re.fullmatch(r"\d+", key):
        slot = int(key)
        if not 1 <= slot <= lib.N_SLOTS:
            raise CliInputError(f"slot {slot} is out of range 1..{lib.N_SLOTS}")
        return slot
    found = lib.find(key)
    if found is None:
        raise CliInputError(f"{lib.path}: no tool named {key!r}; 'tcpcal tools list' shows "
                            f"the table")
    return int(found[0])


def _run_tools(args: argparse.Namespace) -> int:
    from tcpcal.library import ToolLibrary

    lib = ToolLibrary(args.library)
    try:
        with warnings.catch_warnings():  # reported below as one line, not a Python warning
            warnings.simplefilter("ignore")
            code = _tools_command(lib, args)
    except (CliInputError, TcpcalError) as exc:  # still one line: the error, then the note
        if not lib.recoveries:
            raise
        raise CliInputError(f"{exc} (note: {_recovery_line(lib)})") from None
    if lib.recoveries:
        print(f"tcpcal: warning: {_recovery_line(lib)}", file=sys.stderr)
    return code


def _recovery_line(lib: Any) -> str:
    """What the library set aside while this command ran, and where the backup is."""
    text = " ".join(_one_line(r.summary()) for r in lib.recoveries)
    return text[:1].lower() + text[1:]


def _tools_command(lib: Any, args: argparse.Namespace) -> int:
    cmd = args.tools_cmd
    if cmd == "list":
        tools = lib.tools()
        active = lib.active_slot()
        if args.json:
            _emit(json_dumps({"library": str(lib.path), "active_slot": active,
                              "tools": [tool_to_dict(t, slot=s, active=s == active)
                                        for s, t in sorted(tools.items())]}))
        else:
            _emit(f"Tool library {lib.path}\n{format_tool_table(tools, active)}")
        return 0
    if cmd == "add":
        from tcpcal.tool import Tool

        if not 1 <= args.slot <= lib.N_SLOTS:
            raise CliInputError(f"slot {args.slot} is out of range 1..{lib.N_SLOTS}")
        old = lib.get(args.slot)
        if old is not None and not args.replace:
            raise CliInputError(f"{lib.path}: slot {args.slot} holds {old.name!r}; add "
                                f"--replace to overwrite it or choose a free slot "
                                f"(first free: {lib.first_free_slot()})")
        tool = Tool(name=args.name, tcp_mm=tuple(args.xyz), abc_deg=tuple(args.abc),
                    mass_kg=args.mass, notes=args.notes)
        lib.save(args.slot, tool, activate=args.activate)
        _emit(f"Stored {args.name!r} in slot {args.slot}"
              f"{' (active)' if args.activate else ''} of {lib.path}")
        return 0
    if cmd == "import":
        from tcpcal.tools_import import import_tool_file

        report = import_tool_file(lib, read_controller_text(args.file), args.fmt,
                                  filename=args.file.name, replace=args.replace,
                                  where=str(args.file))
        for w in report.warnings:
            print(f"tcpcal: warning: {args.file}: {w}", file=sys.stderr)
        _emit(report.summary(lib.path))
        return 0
    if cmd == "activate" and args.slot.strip().lower() in ("none", "0"):
        lib.activate(None)
        _emit("No active tool (TCP = flange).")
        return 0
    slot = _resolve_slot(lib, args.slot)
    tool = lib.get(slot)
    if tool is None:
        raise CliInputError(f"{lib.path}: slot {slot} is empty; 'tcpcal tools list' shows the "
                            f"table")
    if cmd == "show":
        active = lib.active_slot() == slot
        _emit(json_dumps(tool_to_dict(tool, slot=slot, active=active)) if args.json
              else format_tool(tool, slot=slot, active=active))
    elif cmd == "remove":
        lib.remove(slot)
        _emit(f"Removed {tool.name!r} from slot {slot}")
    elif cmd == "activate":
        lib.activate(slot)
        _emit(f"Active tool: slot {slot} {tool.name!r}")
    elif cmd == "export":
        _run_export(tool, slot, args)
    else:  # pragma: no cover - argparse restricts the choices
        raise AssertionError(cmd)
    return 0


def _write_new(path: Path, text: str) -> None:
    """Write ``text`` to a new file ``path`` (an existing file is never overwritten)."""
    try:
        with open(path, "x", encoding="utf-8", newline="\n") as fh:
            fh.write(text)
    except FileExistsError:
        raise CliInputError(f"{path}: the file exists; choose another name or remove it "
                            f"first (tcpcal never overwrites a file)") from None


def _run_export(tool: Any, slot: int, args: argparse.Namespace) -> None:
    """``tools export``: the tool data text (unchanged contract) or a whole controller file."""
    from tcpcal.controllers import REGISTRY, export_tool_file

    fmt = REGISTRY[args.fmt]
    whole = args.whole_file or args.output is not None or not fmt.has_text
    if not whole:
        if args.file_name is not None or args.register is not None:
            raise CliInputError("--name and --register apply to controller files: add --file "
                                "or --output FILE")
        from tcpcal.formats import export_tool

        _emit(export_tool(tool, args.fmt, slot=slot))
        return
    if not fmt.has_file:
        files = [f.name for f in registered_formats(lambda f: f.has_file)]
        raise CliInputError(f"--format {fmt.name} has no controller file; use "
                            f"{', '.join(files[:-1])} or {files[-1]} with --file/--output")
    if args.register is not None and "register" not in fmt.file_options:
        raise CliInputError(f"--register applies only to --format "
                            f"{' or '.join(_option_formats('register'))}")
    options = {} if args.register is None else {"register": args.register}
    text = export_tool_file(tool, args.fmt, number=slot, name=args.file_name, **options)
    if args.output is None:
        _emit(text)
    else:
        _write_new(args.output, text)
        _emit(f"Wrote {args.fmt} file for slot {slot} {tool.name!r} to {args.output}")


def _option_formats(option: str) -> list[str]:
    """The formats whose controller file takes ``option`` (``ControllerFormat.file_options``)."""
    return [f.name for f in registered_formats(lambda f: option in f.file_options)]


def read_controller_text(path: Path) -> str:
    """A controller file's text: UTF-8 (a BOM dropped), else Latin-1 (controllers often write
    it)."""
    try:
        return path.read_text(encoding="utf-8-sig", errors="strict")
    except UnicodeDecodeError:
        return path.read_text(encoding="latin-1")


def _run_poses(args: argparse.Namespace) -> int:
    """``poses import FILE``: POSES.csv from a controller program file."""
    from tcpcal.controllers import (
        ROBOT_HINT,
        import_poses,
        poses_csv_text,
        skipped_joints_warning,
    )

    text = read_controller_text(args.file)
    try:
        imported = import_poses(text, args.fmt, filename=args.file.name)
    except TcpcalError as exc:
        raise CliInputError(f"{args.file}: {_one_line(str(exc))}") from None
    if not imported.poses:
        n = len(imported.joint_points)
        raise CliInputError(f"{args.file}: all {n} position{'s' if n != 1 else ''} of the file "
                            f"{'are' if n != 1 else 'is'} in joint representation and tcpcal "
                            f"has no robot model; {ROBOT_HINT}")
    skipped = skipped_joints_warning(imported)
    for w in (*imported.warnings, *([skipped] if skipped else [])):
        print(f"tcpcal: warning: {args.file}: {w}", file=sys.stderr)
    csv_text = poses_csv_text(imported)
    if args.output is None:
        sys.stdout.write(csv_text)
    else:
        _write_new(args.output, csv_text)
        print(f"Wrote {len(imported.poses)} {imported.format} poses to {args.output}",
              file=sys.stderr)
    return 0


# ----------------------------------------------------------------------------------- main
def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _os_error_line(exc: OSError) -> str:
    name = exc.filename if exc.filename is not None else ""
    why = exc.strerror or exc.__class__.__name__
    return f"{name}: cannot open the file: {why}" if name else f"{why}: {exc}"


def main(argv: list[str] | None = None) -> int:
    """Run ``tcpcal`` with ``argv`` (default ``sys.argv[1:]``); return the exit status.

    0: success. 2: bad input or usage; exactly one line on stderr. 1: internal error (a bug).
    """
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help (0) or a usage error (2): argparse already printed
        return int(exc.code) if isinstance(exc.code, int) else 2
    try:
        if args.command == "solve":
            return _run_solve(args)
        if args.command == "convert":
            return _run_convert(args)
        if args.command == "tools":
            return _run_tools(args)
        if args.command == "poses":
            return _run_poses(args)
        raise AssertionError(args.command)  # pragma: no cover
    except CliInputError as exc:
        print(f"tcpcal: error: {_one_line(str(exc))}", file=sys.stderr)
    except TcpcalError as exc:
        print(f"tcpcal: error: {_one_line(str(exc))}", file=sys.stderr)
    except OSError as exc:
        print(f"tcpcal: error: {_one_line(_os_error_line(exc))}", file=sys.stderr)
    except KeyboardInterrupt:
        print("tcpcal: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001 - no traceback reaches the user
        if os.environ.get("TCPCAL_DEBUG"):
            traceback.print_exc()
        print(f"tcpcal: internal error: {exc.__class__.__name__}: {_one_line(str(exc))} "
              f"(a bug; rerun with TCPCAL_DEBUG=1 for the traceback)", file=sys.stderr)
        return 1
    return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
