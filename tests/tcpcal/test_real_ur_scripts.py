"""URScript programs PolyScope exported (tests/data/controller_files/real/README.md cites them):
the waypoints a program records are rows (mm and the rotation vector in rad, as POSES.csv has
them), relative offsets of ``pose_trans`` are not and are named in a warning, and nothing inside
PolyScope's ``$ n "..."`` line labels or string literals is read."""

from __future__ import annotations

from pathlib import Path

import pytest

from tcpcal.cli import main as tcpcal_main
from tcpcal.controllers import detect_pose_format, import_poses, parse_tool_file, poses_csv_text

REAL = Path(__file__).resolve().parents[1] / "data" / "controller_files" / "real"
TIMING = REAL / "ur_timing_debug.script"  # UniversalRobots/URScript_Examples, whole
LAB = REAL / "ur_dan_to_out18_excerpt.script"  # pharmbio/robotlab, an excerpt


def read(path: Path) -> str:
    return path.read_text(encoding="utf-8")


TIMING_OFFSETS = (
    "4 poses used as relative offsets of the current pose: p[0.01,0,0,0,0,0] (line 125, "
    "pose_trans), p[0.02,0,0,0,0,0] (line 127, pose_trans), p[0.03,0,0,0,0,0] (line 129, "
    "pose_trans), p[0.04,0,0,0,0,0] (line 131, pose_trans): not recorded positions, skipped")


def test_polyscope_waypoints_are_the_rows_and_pose_trans_offsets_a_warning() -> None:
    """timing_debug.script (PolyScope 5.22): 2 waypoints; ``get_inverse_kin(pose_trans(
    get_target_tcp_pose(), p[0.01, 0, 0, 0, 0, 0]), ...)`` four times, each quoted again in the
    ``$ 43 "..."`` label above it: 4 offsets on the code lines, none from the labels."""
    text = read(TIMING)
    assert detect_pose_format(text, "timing_debug.script") == "ur"
    assert detect_pose_format(text) == "ur"
    assert text.count("pose_trans(get_target_tcp_pose(), p[0.0") == 8  # 4 code + 4 labels
    imported = import_poses(text, filename="timing_debug.script")
    assert [(p.name, p.line) for p in imported.poses] == [("Waypoint_1_p", 47),
                                                          ("Waypoint_2_p", 49)]
    assert poses_csv_text(imported).splitlines() == [
        "name,x,y,z,rx,ry,rz",
        "Waypoint_1_p,-120.0000,-430.0000,140.0000,0.000000000,3.110000000,0.040000000",
        "Waypoint_2_p,-120.0000,-430.0000,203.3923,0.000000000,3.110000000,0.040000000"]
    assert imported.warnings == (TIMING_OFFSETS,)  # set_tcp(p[0.0,...]) is the flange: no word


def test_polyscope_line_labels_are_never_read() -> None:
    text = read(TIMING)
    lines = text.splitlines(keepends=True)
    # the 4 code lines gone, their 4 labels kept: no offset left, still the 2 waypoints
    code_gone = "".join(ln for k, ln in enumerate(lines, 1) if k not in (125, 127, 129, 131))
    assert code_gone.count("get_target_tcp_pose(), p[0.0") == 4  # the labels
    imported = import_poses(code_gone, filename="timing_debug.script")
    assert [p.name for p in imported.poses] == ["Waypoint_1_p", "Waypoint_2_p"]
    assert imported.warnings == ()
    # a TCP written in a label is not set; the same call as code is
    labelled = text.replace('$ 2 "BeforeStart"', '$ 2 "set_tcp(p[0, 0, .15, 0, 0, 0])"')
    assert import_poses(labelled, filename="t.script").warnings == (TIMING_OFFSETS,)
    coded = text.replace('$ 2 "BeforeStart"', "set_tcp(p[0, 0, .15, 0, 0, 0])")
    assert import_poses(coded, filename="t.script").warnings[0].startswith(
        "the script sets a TCP: poses recorded with a TCP active are TCP poses")
    assert [e.tcp_mm for e in parse_tool_file(text, "ur")] == [(0.0, 0.0, 0.0)]


LAB_ROWS = [
    "name,x,y,z,rx,ry,rz",
    "h21_neu_p,209.0864,-427.0020,817.9741,1.640594661,-0.010872806,0.011591693",
    "h21_pick_neu_p,209.0811,-580.0653,817.9934,1.640550250,-0.010881361,0.011545342",
    "h21_pick_p,209.0794,-580.0510,801.3472,1.640538155,-0.010860971,0.011577037",
    "out_neu_p,394.4602,251.6000,817.9472,0.742736230,1.853498674,1.738067165",
    "o18_drop_neu_p,514.0494,375.6898,817.9639,0.742761857,1.853460244,1.738007067",
    "o18_drop_p,514.0072,376.7406,802.3011,0.737487010,1.857895253,1.742110324",
]


def test_polyscope_program_with_a_gripper_urcap_reads_its_six_waypoints() -> None:
    """dan_to_out18.script: 6 ``global name_p=p[...]`` waypoints moved to by ``movel(name_p)``;
    their ``name_q`` joint lists, the Robotiq URCap's code and its ``popup("...")`` strings are
    not positions."""
    text = read(LAB)
    imported = import_poses(text, filename="dan_to_out18.script")
    assert poses_csv_text(imported).splitlines() == LAB_ROWS
    assert [p.line for p in imported.poses] == [18, 20, 22, 24, 26, 28]
    assert imported.warnings == ()
    # a pose written inside one of its strings or labels is still text
    quoted = text.replace("Gripper 1 must be connected to run this program.",
                          "p[0.5, 0.1, 0.2, 0, 3.14, 0]").replace(
        '$ 4 "h21_neu"', '$ 4 "movel(p[0.5, 0.1, 0.2, 0, 3.14, 0])"')
    assert quoted.count("p[0.5, 0.1, 0.2, 0, 3.14, 0]") == 4  # 3 popup strings, 1 label
    assert poses_csv_text(import_poses(quoted, filename="x.script")).splitlines() == LAB_ROWS


def test_tcpcal_poses_import_writes_the_waypoints_and_names_the_offsets(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "POSES.csv"
    assert tcpcal_main(["poses", "import", str(TIMING), "--output", str(out)]) == 0
    assert out.read_text(encoding="utf-8").splitlines()[1:] == [
        "Waypoint_1_p,-120.0000,-430.0000,140.0000,0.000000000,3.110000000,0.040000000",
        "Waypoint_2_p,-120.0000,-430.0000,203.3923,0.000000000,3.110000000,0.040000000"]
    assert "p[0.04,0,0,0,0,0] (line 131, pose_trans)" in capsys.readouterr().err
