"""Controller files (docs/formats.md): each format's file, read back by its own parser, and
files written in each vendor's documented syntax."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tcpcal.cli import main
from tcpcal.controllers import (
    CONTROLLER_FORMATS,
    ControllerFileError,
    export_tool_file,
    parse_tool_file,
)
from tcpcal.tool import Tool

DATA = Path(__file__).resolve().parents[1] / "data" / "controller_files"

#: (mm tolerance, rotation tolerance in deg) each format's fixed decimals allow
TOLERANCE = {"kuka": (5e-4, 2e-4), "abb": (5e-4, 3e-4), "fanuc": (5e-4, 2e-3),
             "ur": (5e-4, 1e-4), "yaskawa": (5e-4, 2e-4)}
#: decimals of every number a file writes (mm, angle)
DECIMALS = {"kuka": {3, 4}, "abb": {3, 6}, "fanuc": {3}, "ur": {3, 6}, "yaskawa": {3, 4}}


def angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.degrees(Rotation.from_matrix(a.T @ b).magnitude()))


def tool_from(tcp: tuple[float, float, float], quat: tuple[float, ...]) -> Tool:
    q = np.asarray(quat, dtype=float)
    rot = Rotation.from_quat(q / np.linalg.norm(q)).as_matrix()
    return Tool.from_rotation("t1", tcp, rot)


coords = st.floats(-2000.0, 2000.0, allow_nan=False)
quats = st.tuples(*[st.floats(-1.0, 1.0) for _ in range(4)]).filter(
    lambda q: sum(v * v for v in q) > 0.01)


@pytest.mark.parametrize("fmt", sorted(CONTROLLER_FORMATS))
@settings(max_examples=60, deadline=None)
@given(tcp=st.tuples(coords, coords, coords), quat=quats)
def test_round_trip_through_the_formats_own_parser(fmt: str, tcp: tuple[float, float, float],
                                                    quat: tuple[float, ...]) -> None:
    tool = tool_from(tcp, quat)
    text = export_tool_file(tool, fmt, number=2, name="tPoint")
    (entry,) = parse_tool_file(text, fmt)
    mm, deg = TOLERANCE[fmt]
    np.testing.assert_allclose(entry.tcp_mm, tool.tcp_mm, atol=mm)
    assert angle_deg(entry.rotation, tool.rotation) < deg
    assert entry.name == "tPoint"
    if fmt in ("kuka", "fanuc", "yaskawa"):
        assert entry.number == 2


@pytest.mark.parametrize("fmt", sorted(CONTROLLER_FORMATS))
@settings(max_examples=40, deadline=None)
@given(tcp=st.tuples(coords, coords, coords), quat=quats)
def test_numbers_have_fixed_decimals_and_no_float_artefacts(
        fmt: str, tcp: tuple[float, float, float], quat: tuple[float, ...]) -> None:
    text = export_tool_file(tool_from(tcp, quat), fmt, number=1, name="tPoint")
    code = "\n".join(ln for ln in text.splitlines()
                     if not ln.lstrip().startswith((";", "!", "#", "/PROG", "COMMENT")))
    assert not re.search(r"\d[eE][-+]?\d", code), text
    assert not re.search(r"-0\.0+(?![0-9])", text), text
    pose_numbers = re.findall(r"-?\d+\.(\d+)", code)
    assert pose_numbers and {len(d) for d in pose_numbers} <= DECIMALS[fmt], text


def test_a_float_artefact_is_written_as_the_pendant_shows_it() -> None:
    tool = Tool(name="tPoint", tcp_mm=(0.33589800000000003, 1e-06, -0.0), abc_deg=(0, 0, 0))
    kuka = export_tool_file(tool, "kuka")
    assert "TOOL_DATA[1]={X 0.336,Y 0.000,Z 0.000,A 0.0000,B 0.0000,C 0.0000}" in kuka
    ur = export_tool_file(tool, "ur")
    assert "p[0.000336, 0.000000, 0.000000, 0.000000, 0.000000, 0.000000]" in ur


def test_each_file_names_its_angle_convention() -> None:
    tool = Tool(name="tPoint", tcp_mm=(1, 2, 3), abc_deg=(10, 20, 30))
    assert "R = Rz(A) Ry(B) Rx(C)" in export_tool_file(tool, "kuka")
    assert "q1 the scalar part" in export_tool_file(tool, "abb")
    assert "WPR deg, fixed X Y Z" in export_tool_file(tool, "fanuc")
    assert "rotation vector (axis times angle, rad)" in export_tool_file(tool, "ur")
    for f in CONTROLLER_FORMATS.values():
        assert f.angle_convention and f.values and f.label


def test_kuka_file_matches_config_dat_syntax() -> None:
    tool = Tool(name="pointer", tcp_mm=(84.931, -11.958, 209.949), abc_deg=(0, -90, 0))
    text = export_tool_file(tool, "kuka", number=4)
    assert "TOOL_DATA[4]={X 84.931,Y -11.958,Z 209.949,A 0.0000,B -90.0000,C 0.0000}\n" in text
    assert 'TOOL_NAME[4,]="pointer"\n' in text
    assert all(ln.startswith((";", "TOOL_")) for ln in text.splitlines())


def test_abb_file_is_a_rapid_module() -> None:
    tool = Tool(name="tPointer", tcp_mm=(10, 20, 30), abc_deg=(0, -90, 0), mass_kg=1.5)
    text = export_tool_file(tool, "abb")
    lines = text.splitlines()
    assert lines[0] == "MODULE tcpcal_tPointer" and lines[-1] == "ENDMODULE"
    assert ("PERS tooldata tPointer:=[TRUE,[[10.000,20.000,30.000],"
            "[0.707107,0.000000,-0.707107,0.000000]],[1.500,[0,0,0.001],[1,0,0,0],0,0,0]];"
            ) in text


@pytest.mark.parametrize(("name", "needle"), [
    ("tool0", "'tool0' is the robot's predefined flange tool"),
    ("TOOL0", "'tool0' is the robot's predefined flange tool"),
    ("my tool", "not a RAPID identifier"),
    ("2nd", "not a RAPID identifier"),
    ("x" * 33, "not a RAPID identifier"),
    ("MODULE", "reserved or predefined RAPID name"),
    ("wobj0", "reserved or predefined RAPID name"),
])
def test_abb_refuses_names_rapid_refuses(name: str, needle: str) -> None:
    tool = Tool(name="ok", tcp_mm=(1, 2, 3), abc_deg=(0, 0, 0))
    with pytest.raises(ControllerFileError, match=re.escape(needle)):
        export_tool_file(tool, "abb", name=name)


def test_fanuc_program_sections_and_register() -> None:
    tool = Tool(name="torch", tcp_mm=(-12.5, 0.044, 395), abc_deg=(180, 45, -0.242))
    text = export_tool_file(tool, "fanuc", number=2, register=60)
    heads = [ln.split()[0] for ln in text.splitlines() if ln.startswith("/")]
    assert heads == ["/PROG", "/ATTR", "/MN", "/POS", "/END"]
    assert "PR[60]=P[1] ;" in text and "UTOOL[2]=PR[60] ;" in text
    assert "LINE_COUNT\t= 5;" in text and len(re.findall(r"^\s+\d+:", text, re.M)) == 5
    assert "X =    -12.500  mm,\tY =      0.044  mm,\tZ =    395.000  mm" in text
    assert "W =     -0.242 deg,\tP =     45.000 deg,\tR =    180.000 deg" in text


@pytest.mark.parametrize(("fmt", "kwargs", "needle"), [
    ("kuka", {"number": 17}, "tool number must be 1..16"),
    ("kuka", {"name": "n" * 25}, "at most 24 characters"),
    ("fanuc", {"number": 11}, "tool frame number must be 1..10"),
    ("fanuc", {"register": 0}, "position register must be 1..100"),
    ("yaskawa", {"name": "a" * 17}, "at most 16 ASCII characters"),
    ("yaskawa", {"number": 64}, "tool number must be 0..63"),
])
def test_out_of_range_numbers_and_names(fmt: str, kwargs: dict, needle: str) -> None:
    tool = Tool(name="ok", tcp_mm=(1, 2, 3), abc_deg=(0, 0, 0))
    with pytest.raises(ControllerFileError, match=re.escape(needle)):
        export_tool_file(tool, fmt, **kwargs)


# ------------------------------------------------------------- files in the vendors' syntax
def test_reads_a_kuka_config_dat_excerpt() -> None:
    entries = parse_tool_file((DATA / "config_excerpt.dat").read_text(), "kuka")
    assert [(e.number, e.name) for e in entries] == [(1, "GUN"), (2, "gripper"), (3, "")]
    np.testing.assert_allclose(entries[0].tcp_mm, (107.147003, 6.19999992e-05, 313.237))
    expect = Rotation.from_euler("ZYX", [90, -10, 5], degrees=True).as_matrix()
    assert angle_deg(entries[1].rotation, expect) < 1e-9


def test_reads_an_abb_module_with_several_tools() -> None:
    entries = parse_tool_file((DATA / "calib_tools.mod").read_text(), "abb")
    assert [e.name for e in entries] == ["tGripper", "tAngled"]
    np.testing.assert_allclose(entries[1].tcp_mm, (0, 6.4, 170))
    # [0.99998, 0.00625, 0, 0] (norm 1 - 1.5e-6) is about X by 2 atan2(0.00625, 0.99998)
    rv = Rotation.from_matrix(entries[1].rotation).as_rotvec()
    np.testing.assert_allclose(rv, [2 * math.atan2(0.00625, 0.99998), 0, 0], atol=1e-12)


def test_reads_a_fanuc_program_setting_utool() -> None:
    (entry,) = parse_tool_file((DATA / "set_utool.ls").read_text(), "fanuc")
    assert entry.number == 2
    np.testing.assert_allclose(entry.tcp_mm, (-12.5, 0.044, 395.0))
    expect = Rotation.from_euler("xyz", [-0.242, 45, 180], degrees=True).as_matrix()
    assert angle_deg(entry.rotation, expect) < 1e-9


def test_reads_a_yrc1000_tool_file_with_crc_lines() -> None:
    """TOOL_YRC1000.CND has the layout of a YRC1000's saved file (a ``///CRC`` line before
    ``///NAME``, CRLF lines; docs/formats.md cites the public file): every name is kept."""
    entries = parse_tool_file((DATA / "TOOL_YRC1000.CND").read_text(), "yaskawa")
    assert [(e.number, e.name) for e in entries][:4] == [
        (0, "R1 STANDARD TOOL"), (1, "TORCH"), (2, ""), (3, "SPINDLE 2")]
    assert len(entries) == 8
    # Rx, Ry, Rz about the fixed X, Y, Z: R = Rz(180) Ry(-45), by hand
    c = math.sqrt(0.5)
    expect = np.array([[-1, 0, 0], [0, -1, 0], [0, 0, 1.0]]) @ np.array(
        [[c, 0, -c], [0, 1, 0], [c, 0, c]])
    assert angle_deg(entries[1].rotation, expect) < 1e-9
    # the line after the pose is the centre of gravity, then the mass (not the inertia)
    assert entries[1].mass_kg == 3.5 and entries[1].cog_mm == (0.0, -4.5, 120.0)
    assert entries[3].mass_kg == 48.2 and entries[3].cog_mm == (-10.25, 15.0, -95.0)
    assert entries[0].mass_kg is None and entries[0].cog_mm is None  # mass 0.000: unset


def test_reads_a_dx100_tool_file() -> None:
    entries = parse_tool_file((DATA / "TOOL_DX100.CND").read_text(), "yaskawa")
    assert [(e.number, e.name, e.mass_kg) for e in entries] == [(0, "FLANGE", None),
                                                               (1, "TORCH", 3.5)]
    np.testing.assert_allclose(entries[1].tcp_mm, (12.345, 0, 350))


def test_yaskawa_entry_writes_the_public_layout_with_the_tools_load() -> None:
    """After the pose: Xg,Yg,Zg; W; Ix,Iy,Iz; the 3-field line, as the public files."""
    tool = Tool(name="TORCH", tcp_mm=(12.345, 0, 350), abc_deg=(180, -45, 0), mass_kg=1.5,
                cog_mm=(0, -4.5, 120))
    lines = export_tool_file(tool, "yaskawa", number=1).splitlines()
    assert lines == ["//TOOL 1", "///NAME TORCH", "12.345,0.000,350.000,0.0000,-45.0000,180.0000",
                     "0.000,-4.500,120.000", "1.500", "0.000,0.000,0.000", "0.000,0,1"]
    (entry,) = parse_tool_file("\n".join(lines), "yaskawa")
    assert entry.mass_kg == 1.5 and entry.cog_mm == (0.0, -4.5, 120.0)
    # the public file's layout, line by line: same count and field counts as our fixture
    public = (DATA / "TOOL_DX100.CND").read_text().splitlines()[7:14]
    assert [len(ln.split(",")) for ln in lines[1:]] == [len(ln.split(",")) for ln in public[1:]]


def test_yaskawa_entry_of_a_tool_without_load_writes_the_unset_load() -> None:
    tool = Tool(name="P", tcp_mm=(1, 2, 3))
    lines = export_tool_file(tool, "yaskawa", number=2).splitlines()
    assert lines[3:] == ["0.000,0.000,0.000", "0.000", "0.000,0.000,0.000", "0.000,0,1"]


def test_the_ur_tcp_is_read_in_metres() -> None:
    (entry,) = parse_tool_file("# comment p[1, 2]\nset_tcp(p[0.0125, 0, 0.18, 0, -1.5707963, 0])\n",
                               "ur")
    np.testing.assert_allclose(entry.tcp_mm, (12.5, 0, 180))


@pytest.mark.parametrize(("fmt", "text", "needle"), [
    ("kuka", "nothing", "no TOOL_DATA"),
    ("kuka", "TOOL_DATA[1]={X 1,Y 2,Z 3,A 0,B 0}", "lacks C"),
    ("abb", "PERS tooldata t:=[TRUE,[[1,2,3],[0.5,0,0,0]],[1,[0,0,1],[1,0,0,0],0,0,0]];",
     "quaternion norm 0.5"),
    ("abb", "PERS tooldata t:=[FALSE,[[1,2,3],[1,0,0,0]],[1,[0,0,1],[1,0,0,0],0,0,0]];",
     "stationary tool"),
    ("fanuc", "/MN\n 1: UTOOL[1]=PR[5] ;\n/POS\n/END\n", "does not set PR[5]"),
    ("ur", "set_tcp(p[0, 0, 0.1])", "needs 6 numbers"),
    ("yaskawa", "//TOOL 1\n///NAME A\n1,2,3\n", "needs 6 numbers"),
])
def test_unreadable_files_say_what_is_wrong(fmt: str, text: str, needle: str) -> None:
    with pytest.raises(ControllerFileError, match=re.escape(needle)):
        parse_tool_file(text, fmt)


# ----------------------------------------------------------------------------- the CLI
@pytest.fixture()
def library(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> Path:
    lib = tmp_path / "tools.json"
    assert main(["tools", "--library", str(lib), "add", "3", "pointer", "--xyz",
                 "84.931,-11.958,209.949", "--abc", "10,-35.5,0.335898"]) == 0
    capsys.readouterr()
    return lib


def test_tools_export_keeps_its_text_and_adds_files(library: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["tools", "--library", str(library), "export", "3", "--format", "kuka"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("TOOL_DATA[3]={X 84.931,Y -11.958,Z 209.949,A 10.0,B -35.5,C 0.335898}")
    assert main(["tools", "--library", str(library), "export", "3", "--format", "kuka",
                 "--file"]) == 0
    out = capsys.readouterr().out
    assert "TOOL_DATA[3]={X 84.931,Y -11.958,Z 209.949,A 10.0000,B -35.5000,C 0.3359}" in out
    assert main(["tools", "--library", str(library), "export", "pointer", "--format",
                 "yaskawa"]) == 0
    assert capsys.readouterr().out.startswith("//TOOL 3\n///NAME pointer\n")


def test_tools_export_output_writes_a_new_file(library: Path, tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "tPointer.mod"
    assert main(["tools", "--library", str(library), "export", "3", "--format", "abb",
                 "--name", "tPointer", "--output", str(target)]) == 0
    (entry,) = parse_tool_file(target.read_text(), "abb")
    np.testing.assert_allclose(entry.tcp_mm, (84.931, -11.958, 209.949))
    capsys.readouterr()
    assert main(["tools", "--library", str(library), "export", "3", "--format", "abb",
                 "--name", "tPointer", "--output", str(target)]) == 2
    assert "the file exists" in capsys.readouterr().err


@pytest.mark.parametrize(("argv", "needle"), [
    (["--format", "abb", "--file"], "'pointer' is not a RAPID identifier"),
    (["--format", "abb", "--file", "--name", "tool0"], "'tool0' is the robot's predefined"),
    (["--format", "matrix", "--file"], "matrix has no controller file"),
    (["--format", "kuka", "--name", "x"], "apply to controller files"),
    (["--format", "kuka", "--file", "--register", "5"], "only to --format fanuc"),
])
def test_tools_export_errors(library: Path, capsys: pytest.CaptureFixture[str], argv: list[str],
                             needle: str) -> None:
    # 'pointer' is a fine RAPID identifier; the library tool is renamed to one that is not
    if needle.startswith("'pointer'"):
        argv = [*argv, "--name", "my pointer"]
        needle = "'my pointer' is not a RAPID identifier"
    assert main(["tools", "--library", str(library), "export", "3", *argv]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and needle in err, err
