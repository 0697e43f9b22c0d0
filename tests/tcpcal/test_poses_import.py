"""``tcpcal poses import``: touch poses from controller program files (docs/formats.md), and
the whole road from a robot's program file to the TCP."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np
import pytest
from support.poses import tilted_rotations, touch_positions
from scipy.spatial.transform import Rotation

from tcpcal.cli import main
from tcpcal.controllers import (
    CONTROLLER_FORMATS,
    POSE_FORMATS,
    ControllerFileError,
    RecordedPose,
    import_poses,
)

DATA = Path(__file__).resolve().parents[1] / "data" / "controller_files"
EXAMPLE = Path(__file__).resolve().parents[2] / "docs" / "examples" / "xyz4_poses.csv"
FILES = {"kuka": "touches.dat", "abb": "touches.mod", "fanuc": "touches.ls",
         "ur": "touches.script"}
NAMES = {"kuka": [f"XP{k}" for k in range(1, 7)], "abb": [f"p{k}0" for k in range(1, 7)],
         "fanuc": [f"touch {k}" for k in range(1, 7)],
         "ur": ["p1", "p2", "p3", "touch_4", "touch_5", "touch_6"]}


def example_rows() -> list[dict[str, str]]:
    return list(csv.DictReader(EXAMPLE.open()))


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("fmt", sorted(FILES))
def test_each_vendor_file_gives_the_documented_touches(fmt: str) -> None:
    """The fixtures hold docs/examples/xyz4_poses.csv written the way each controller does."""
    path = DATA / FILES[fmt]
    imported = import_poses(path.read_text(), filename=path.name)
    assert imported.format == fmt
    assert imported.warnings == ()
    assert [p.name for p in imported.poses] == NAMES[fmt]
    for pose, row in zip(imported.poses, example_rows(), strict=True):
        np.testing.assert_allclose(pose.position_mm, [float(row[k]) for k in "xyz"], atol=5e-4)
        expect = Rotation.from_euler("ZYX", [float(row[k]) for k in "abc"], degrees=True)
        err = (expect.inv() * Rotation.from_matrix(pose.rotation)).magnitude()
        assert np.degrees(err) < 1e-4


@pytest.mark.parametrize("fmt", sorted(FILES))
def test_detection_from_the_content(fmt: str) -> None:
    assert import_poses((DATA / FILES[fmt]).read_text()).format == fmt


@pytest.mark.parametrize("fmt", sorted(FILES))
def test_cli_prints_the_csv_the_solver_reads_and_the_tcp_follows(
        fmt: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "poses", "import", str(DATA / FILES[fmt]))
    assert (code, err) == (0, "")
    header = out.splitlines()[0]
    assert header == {"kuka": "name,x,y,z,a,b,c", "abb": "name,x,y,z,qw,qx,qy,qz",
                      "fanuc": "name,x,y,z,w,p,r", "ur": "name,x,y,z,rx,ry,rz"}[fmt]
    assert "e-" not in out and "e+" not in out
    csv_path = tmp_path / "poses.csv"
    csv_path.write_text(out)
    code, out, _ = run(capsys, "solve", "xyz4", str(csv_path), "--json")
    assert code == 0
    # the documented result of docs/examples/xyz4_poses.csv (docs/cli.md)
    np.testing.assert_allclose(json.loads(out)["tcp_mm"], [84.931, -11.958, 209.949], atol=2e-3)


def test_output_option_writes_a_new_file(tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "poses.csv"
    code, out, err = run(capsys, "poses", "import", str(DATA / "touches.mod"), "--output",
                         str(target))
    assert (code, out) == (0, "") and "Wrote 6 abb poses" in err
    assert target.read_text().startswith("name,x,y,z,qw,qx,qy,qz\np10,815.1030,")
    code, _, err = run(capsys, "poses", "import", str(DATA / "touches.mod"), "--output",
                       str(target))
    assert code == 2 and "the file exists" in err


def test_a_touch_recorded_with_a_tool_or_base_warns(tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    text = (DATA / "touches.dat").read_text().replace(
        "FP2={TOOL_NO 0,BASE_NO 0", "FP2={TOOL_NO 3,BASE_NO 0").replace(
        "FP5={TOOL_NO 0,BASE_NO 0", "FP5={TOOL_NO 0,BASE_NO 1")
    path = tmp_path / "t.dat"
    path.write_text(text)
    code, out, err = run(capsys, "poses", "import", str(path))
    assert code == 0 and len(out.splitlines()) == 7
    assert "XP2 recorded with a tool active (not 0)" in err
    assert "XP5 recorded in a base / user frame (not 0)" in err
    ls = (DATA / "touches.ls").read_text().replace("UF : 0, UT : 0", "UF : 0, UT : 1", 1)
    assert "touch 1 recorded with a tool active" in import_poses(ls, "fanuc").warnings[0]


def test_a_ur_script_with_a_tcp_set_warns() -> None:
    text = (DATA / "touches.script").read_text().replace(
        "set_tcp(p[0.0, 0.0, 0.0,", "set_tcp(p[0.0, 0.0, 0.2,")
    (warning,) = import_poses(text, "ur").warnings
    assert "sets a TCP" in warning


@pytest.mark.parametrize(("fmt", "text", "needle"), [
    ("auto", "hello", "cannot tell which controller wrote this file"),
    ("kuka", "DEFDAT X\nENDDAT\n", "no recorded position found"),
    ("kuka", "DECL E6POS XP1={X 1,Y 2,Z 3,A 0,B 0}", "line 1: E6POS XP1 lacks C"),
    ("abb", "CONST robtarget p1:=[[1,2,3],[0.9,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];",
     "quaternion norm 0.9"),
    ("ur", "movel(p[0.1, 0.2, 0.3, 0, 0])", "needs 6 numbers"),
])
def test_errors(fmt: str, text: str, needle: str) -> None:
    with pytest.raises(ControllerFileError, match=needle):
        import_poses(text, fmt)


def test_cli_error_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "bad.ls"
    path.write_text("/POS\nP[1]{\n   GP1:\n\tX = 1 mm, Y = 2 mm\n};\n/END\n")
    code, out, err = run(capsys, "poses", "import", str(path))
    assert (code, out) == (2, "")
    assert err.strip().splitlines() == [f"tcpcal: error: {path}: fanuc: line 2: P[1] lacks Z, "
                                        "W, P, R"]


@pytest.mark.parametrize("fmt", POSE_FORMATS)
def test_end_to_end_program_file_to_tcp(fmt: str, tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    """A synthetic calibration: touches of a known tool written to the vendor's program file,
    imported, solved: the TCP comes back within its 95 % radius (plus the file's rounding)."""
    rng = np.random.default_rng(42)
    t_true = np.array([-40.0, 25.0, 260.0])
    r_true = np.array([1100.0, 300.0, 420.0])
    rots = tilted_rotations(rng, 8, tilt_deg=(25.0, 55.0))
    pos = touch_positions(rots, t_true, r_true, rng, sigma=0.05)
    recorded = [RecordedPose(f"T{k}", tuple(p), R, ()) for k, (p, R) in enumerate(zip(pos, rots))]
    program = tmp_path / f"touches{CONTROLLER_FORMATS[fmt].pose_extensions[0]}"
    program.write_text(CONTROLLER_FORMATS[fmt].render_poses(recorded))
    code, out, err = run(capsys, "poses", "import", str(program))
    assert (code, err) == (0, "")
    rows = list(csv.DictReader(io.StringIO(out)))
    assert len(rows) == 8
    csv_path = tmp_path / "poses.csv"
    csv_path.write_text(out)
    code, out, _ = run(capsys, "solve", "xyz4", str(csv_path), "--json")
    assert code == 0
    d = json.loads(out)
    err_mm = float(np.linalg.norm(np.array(d["tcp_mm"]) - t_true))
    assert err_mm < d["ci95_mm"] + 0.01, (err_mm, d["ci95_mm"])


# ------------------------------------------------ real-program layouts: groups, tools, arrays
#: program files in the layouts the public programs have (docs/formats.md cites them), holding
#: the touches of docs/examples/xyz4_poses.csv among the things a real program also has
REAL = {"fanuc": ("touches_multigroup.ls", NAMES["fanuc"]),
        "ur": ("touches_indexing.script", NAMES["ur"]),
        "abb": ("touches_tool_wobj.mod", NAMES["abb"]),
        "kuka": ("touches_extra.dat", ["XP1", "XP2", "XP3", "XF4", "XAPP[1]", "XAPP[2]"])}


def assert_documented_touches(poses: tuple[RecordedPose, ...]) -> None:
    assert len(poses) == 6
    for pose, row in zip(poses, example_rows(), strict=True):
        np.testing.assert_allclose(pose.position_mm, [float(row[k]) for k in "xyz"], atol=5e-4)
        expect = Rotation.from_euler("ZYX", [float(row[k]) for k in "abc"], degrees=True)
        assert np.degrees((expect.inv() * Rotation.from_matrix(pose.rotation)).magnitude()) < 1e-4


@pytest.mark.parametrize("fmt", sorted(REAL))
def test_real_program_layouts_give_the_documented_touches(fmt: str) -> None:
    path = DATA / REAL[fmt][0]
    imported = import_poses(path.read_text(), filename=path.name)
    assert imported.format == fmt
    assert [p.name for p in imported.poses] == REAL[fmt][1]
    assert_documented_touches(imported.poses)


def test_fanuc_multi_group_program_reads_group_1_and_notes_the_others() -> None:
    imported = import_poses((DATA / "touches_multigroup.ls").read_text(), "fanuc")
    (warning,) = imported.warnings
    assert warning.startswith("7 points (touch 1, touch 2, touch 3, touch 4, touch 5, touch 6, "
                              "home) also hold motion group GP2")
    assert "only group 1 (GP1, the robot) was read" in warning
    (home,) = imported.joint_points
    assert (home.name, home.kind, home.tool, home.base) == ("home", "FANUC J", 0, 0)
    assert home.joints_deg == (0.0, -30.0, 15.0, 0.0, -75.0, 90.0)


def test_ur_indexing_and_default_arguments_are_not_poses() -> None:
    imported = import_poses((DATA / "touches_indexing.script").read_text(), "ur")
    assert imported.warnings == (
        "1 pose on line 11 computed from variables (not numbers): not recorded positions, "
        "skipped",
        "2 poses in function default arguments (def f(x=p[...])) skipped: a default is not "
        "a touch")
    # clamp[fixture] and Kp[0] are indexing: no "pose needs 6 numbers" error
    assert "clamp[fixture] = True" in (DATA / "touches_indexing.script").read_text()


def test_abb_moves_with_a_tool_or_a_work_object_warn_naming_the_points() -> None:
    imported = import_poses((DATA / "touches_tool_wobj.mod").read_text(), "abb")
    assert imported.warnings == (
        "p30, p40 reached by moves with tool HeatGun (not tool0): those are TCP poses, not the "
        "flange; record the touches with tool0",
        "p30, p50 reached by moves in work object wTable: those positions are in the work "
        "object, not WORLD; record the touches with wobj0")
    (home,) = imported.joint_points
    assert (home.name, home.kind, home.joints_deg) == ("jHome", "jointtarget",
                                                       (0, -30, 15, 0, 75, 90))


def test_kuka_external_axes_frame_data_and_axis_points_are_said() -> None:
    imported = import_poses((DATA / "touches_extra.dat").read_text(), "kuka")
    assert imported.warnings == (
        "XP2 (E1 88.24): external-axis values are not part of the pose; tcpcal ignores them, "
        "so the poses are right only if no external axis (a linear track, a turntable) moves "
        "the robot or the reference between touches",
        "XF4 read from FRAME data (X, Y, Z, A, B, C, no status and turn): check that they are "
        "recorded flange positions, not a base or tool frame")
    (home,) = imported.joint_points
    assert (home.name, home.kind, home.joints_deg) == ("XHOME", "E6AXIS",
                                                       (0, -90, 90, 0, 30, 0))


@pytest.mark.parametrize("fmt", sorted(REAL))
def test_cli_on_real_layouts_solves_and_reports_skipped_joint_points(
        fmt: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "poses", "import", str(DATA / REAL[fmt][0]))
    assert code == 0, err
    joint_name = {"fanuc": "home", "abb": "jHome", "kuka": "XHOME"}.get(fmt)
    if joint_name:
        assert (f"skipped 1 point in joint representation ({joint_name}): tcpcal has no robot "
                "model") in err
        assert "tcp-pendant poses import FILE --robot kr6|gp12|PATH.urdf" in err
    else:
        assert "joint representation" not in err
    csv_path = tmp_path / "poses.csv"
    csv_path.write_text(out)
    code, out, _ = run(capsys, "solve", "xyz4", str(csv_path), "--json")
    assert code == 0
    np.testing.assert_allclose(json.loads(out)["tcp_mm"], [84.931, -11.958, 209.949], atol=2e-3)


def test_a_program_of_joint_points_only_is_an_error_with_the_hint(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "joints.ls"
    path.write_text("/PROG J\n/POS\nP[1]{\n   GP1:\n\tUF : 0, UT : 0,\n\tJ1= 0.0 deg, J2 = 1 deg,"
                    "J3 = 2 deg, J4 = 3 deg, J5 = 4 deg, J6 = 5 deg\n};\n/END\n")
    imported = import_poses(path.read_text(), "fanuc")
    assert imported.poses == () and imported.joint_points[0].joints_deg == (0, 1, 2, 3, 4, 5)
    code, out, err = run(capsys, "poses", "import", str(path))
    assert code == 2 and err.count("\n") == 1
    assert "all 1 position of the file is in joint representation" in err
    assert "--robot kr6|gp12|PATH.urdf" in err


def test_fanuc_orderfil_dat_is_recognised_as_fanuc(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """ORDERFIL.DAT (the software options list of a FANUC backup, layout of
    JuniorNatalin/VASC BVTU/Backups/07.10.24/KJBVTU211150R01/ORDERFIL.DAT) is FANUC's, not a
    KUKA .dat."""
    path = tmp_path / "ORDERFIL.DAT"
    path.write_text("! Generated for F00000\n!   Min. F-ROM :  16 MB\n1A05B-2500-H521 ! English "
                    "Dictionary\n1A05B-2500-H552 ! HandlingTool\n1A05B-2500-J601 ! Multi-Group "
                    "Motion\n1A05B-2500-R796 ! Ascii Program Loader\nZ\n")
    from tcpcal.controllers import detect_pose_format

    assert detect_pose_format(path.read_text(), path.name) == "fanuc"
    code, _, err = run(capsys, "poses", "import", str(path))
    assert code == 2 and "fanuc: this is ORDERFIL.DAT" in err and "kuka" not in err


def test_an_excerpt_of_a_public_multi_group_program() -> None:
    """Two points of layers_splitter/output_data/layer_2.ls of Creearc/welding_project, as
    published (a space before the brace, CONFIG: without a space, GP2 in joints)."""
    text = """/PROG layer_2
/ATTR
DEFAULT_GROUP   = 1,1,*,*,*;
/MN
1: L P[1] 240cm/min CNT100 COORD ;
2: L P[2] WELD_SPEED CNT100 COORD PTH ;
/POS
P[1] {
    GP1:
        UF : 6, UT : 5,     CONFIG: 'N U T, 0, 0, 0',
       X = 45.4 mm, Y = -124.0 mm, Z = 56.6 mm,
       W = 0.0 deg, P = 0.0 deg, R = 0.0 deg
    GP2:
        UF : 1, UT : 2,
       J1 = 0.0 deg, J2 = 0.0 deg 
 };
P[2] {
    GP1:
        UF : 6, UT : 5,     CONFIG: 'N U T, 0, 0, 0',
       X = -48.8 mm, Y = -124.0 mm, Z = 56.6 mm,
       W = 0.0 deg, P = 0.0 deg, R = 0.0 deg
    GP2:
        UF : 1, UT : 2,
       J1 = 0.0 deg, J2 = 0.0 deg 
 };
/END
"""
    imported = import_poses(text, filename="layer_2.ls")
    assert [(p.name, p.position_mm, p.tool, p.base) for p in imported.poses] == [
        ("P[1]", (45.4, -124.0, 56.6), 5, 6), ("P[2]", (-48.8, -124.0, 56.6), 5, 6)]
    assert imported.joint_points == ()
    assert [w.split(" (")[0] for w in imported.warnings] == [
        "P[1], P[2] recorded with a tool active", "P[1], P[2] recorded in a base / user frame",
        "2 points"]
    assert "also hold motion group GP2" in imported.warnings[2]


def test_fanuc_integrated_extended_axis_values_are_said() -> None:
    ls = (DATA / "touches.ls").read_text().replace(
        "R =     30.000 deg\n};", "R =     30.000 deg,\n\tE1 =  1500.000  mm\n};", 1)
    imported = import_poses(ls, "fanuc")
    assert len(imported.poses) == 6
    assert imported.warnings == (
        "touch 2 (E1 1500): extended-axis values are not part of the pose; tcpcal ignores them, "
        "so the poses are right only if no extended axis moves the robot or the reference "
        "between touches",)


def test_a_tool_cnd_in_another_layout_is_a_clear_error() -> None:
    from tcpcal.controllers import parse_tool_file

    text = ("//TOOL 1\n///NAME T\n1.000,2.000,3.000,0.0000,0.0000,0.0000\n0.000,0.000,0.000\n"
            "0.000,0.000,0.000\n0.000\n0,0\n")
    with pytest.raises(ControllerFileError, match=r"line 5: //TOOL 1: the line after the centre "
                       r"of gravity is the mass W \(1 number\), got '0.000,0.000,0.000'"):
        parse_tool_file(text, "yaskawa")


def test_kuka_frame_data_without_a_whole_pose_is_skipped_and_said() -> None:
    text = (DATA / "touches_extra.dat").read_text().replace(
        "ENDDAT", "DECL FRAME XOFFSET={X 0.0,Y 0.0,Z 50.0}\nENDDAT")
    imported = import_poses(text, "kuka")
    assert [p.name for p in imported.poses] == REAL["kuka"][1]
    assert imported.warnings[-1] == ("XOFFSET: FRAME data without all of X, Y, Z, A, B, C "
                                     "skipped (not a pose)")
