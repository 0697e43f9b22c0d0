"""``tcpcal poses import``: touch poses from controller program files (docs/formats.md), and
the whole road from a robot's program file to the TCP."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np
import pytest
from poses import tilted_rotations, touch_positions
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
