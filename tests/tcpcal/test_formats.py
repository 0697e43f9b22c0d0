"""Controller tool-data formats (methods.md section 6): round trips and hand-computed values."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tcpcal.errors import InvalidInputError
from tcpcal.formats import FORMATS, export_tool, import_tool
from tcpcal.tool import Tool

NUM = r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"
S = math.sqrt(0.5)


def numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(NUM, text)]


quats = st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
    lambda q: np.linalg.norm(q) > 0.1)
coords = st.floats(-500.0, 500.0)


@settings(max_examples=60, deadline=None)
@given(quats, coords, coords, coords, st.sampled_from(FORMATS),
       st.one_of(st.none(), st.floats(0.01, 50.0)))
def test_round_trip_of_random_tools_through_every_format(q, x, y, z, fmt, mass):
    R = Rotation.from_quat(np.array(q) / np.linalg.norm(q)).as_matrix()
    tool = Tool.from_rotation("rt_tool", (x, y, z), R, mass_kg=mass)
    back = import_tool(export_tool(tool, fmt), fmt, name="rt_tool")
    np.testing.assert_allclose(back.T_flange_tool_mm, tool.T_flange_tool_mm, rtol=0, atol=1e-9)
    if fmt == "abb":
        assert back.mass_kg == mass  # ABB stores the mass; None travels as tool0's 0.001 kg


@pytest.mark.parametrize("fmt", FORMATS)
def test_round_trip_at_gimbal_lock_and_identity(fmt):
    for abc in [(0.0, 0.0, 0.0), (30.0, 90.0, 10.0), (-120.0, -90.0, 45.0), (180.0, 0.0, 180.0)]:
        tool = Tool("g", (1e-3, -250.125, 333.333), abc)
        back = import_tool(export_tool(tool, fmt), fmt)
        np.testing.assert_allclose(back.T_flange_tool_mm, tool.T_flange_tool_mm, atol=1e-9)


@pytest.mark.parametrize("fmt", FORMATS)
def test_round_trip_next_to_gimbal_lock(fmt):
    rng = np.random.default_rng(8)
    for offset in (1e-11, 1e-9, 1e-8, 1e-7):
        for _ in range(10):
            A, C = rng.uniform(-180.0, 180.0, size=2)
            R = Rotation.from_euler("ZYX", [A, 90.0 - math.degrees(offset), C],
                                    degrees=True).as_matrix()
            # B = +-90 is also FANUC's lock (P = +-90): Rz(R) Ry(P) Rx(W) has the same form
            tool = Tool.from_rotation("g", (10.0, 20.0, 30.0), R)
            np.testing.assert_allclose(tool.rotation, R, rtol=0, atol=1e-11)
            back = import_tool(export_tool(tool, fmt), fmt)
            np.testing.assert_allclose(back.T_flange_tool_mm, tool.T_flange_tool_mm,
                                       rtol=0, atol=1e-9)


# --------------------------------------------------------------------------- KUKA
def test_kuka_known_text_and_values():
    tool = Tool("gripper", (12.5, 0.0, 180.25), (0.0, -90.0, 0.0))
    assert export_tool(tool, "kuka", slot=3) == (
        'TOOL_DATA[3]={X 12.5,Y 0.0,Z 180.25,A 0.0,B -90.0,C 0.0}\n'
        'TOOL_NAME[3,]="gripper"\n'
    )
    # a line as in $config.dat: B = -90 is Ry(-90), computed by hand
    t = import_tool("TOOL_DATA[1]={X 12.5,Y 0.0,Z 180.25,A 0.0,B -90.0,C 0.0}", "kuka")
    np.testing.assert_allclose(t.rotation, [[0, 0, -1], [0, 1, 0], [1, 0, 0]], atol=1e-15)
    assert t.tcp_mm == (12.5, 0.0, 180.25) and t.name == "tool1"
    # A = 90: Rz(90)
    t = import_tool("TOOL_DATA[2]={X 0,Y 0,Z 0,A 90,B 0,C 0}", "kuka")
    np.testing.assert_allclose(t.rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)


def test_kuka_import_is_tolerant():
    text = """
    ; from $config.dat
    DECL FRAME tool_data[4] = {  x 1.5 , y -2 ,z 3E1, a 10.0,b 20.0 , c 30.0 }   ; torch
    TOOL_NAME[4,]="MIG torch"
    TOOL_TYPE[4]=#NONE
    LOAD_DATA[4]={M 3.2,CM {X 0.0,Y 0.0,Z 80.0,A 0.0,B 0.0,C 0.0},J {X 0.0,Y 0.0,Z 0.0}}
    """
    t = import_tool(text, "kuka")
    assert t.name == "MIG torch"
    assert t.tcp_mm == (1.5, -2.0, 30.0)
    assert t.abc_deg == (10.0, 20.0, 30.0)
    assert t.mass_kg == 3.2
    assert import_tool(text, "kuka", name="other").name == "other"
    # KUKA's "no load data" marker M -1 means unknown mass
    assert import_tool("TOOL_DATA[1]={X 0,Y 0,Z 1,A 0,B 0,C 0}\nLOAD_DATA[1]={M -1,CM {}}",
                       "kuka").mass_kg is None


@pytest.mark.parametrize(
    "text, match",
    [
        ("nothing here", "no TOOL_DATA"),
        ("TOOL_DATA[1]={X 1,Y 2,Z 3,A 0,B 0}", "lacks C"),
        ("TOOL_DATA[1]={X 1,Y 2,Z 3,A 0,B 0,C zero}", "could not parse 'C zero'"),
        ("TOOL_DATA[1]={X 1,X 2,Z 3,A 0,B 0,C 0}", "X appears twice"),
        ("TOOL_DATA[1]={X 1,Y 2,Z 3,A 0,B 0,C 0}\nTOOL_DATA[2]={X 1,Y 2,Z 3,A 0,B 0,C 0}",
         r"found 2 tools \(TOOL_DATA\[1\], TOOL_DATA\[2\]\)"),
        ('TOOL_DATA[1]={X 1,Y 2,Z 3,A 0,B 0,C 0}\nTOOL_NAME[1,]="' + "n" * 30 + '"',
         "at most 24.*name="),
    ],
)
def test_kuka_import_errors(text, match):
    with pytest.raises(InvalidInputError, match=match):
        import_tool(text, "kuka")


def test_kuka_slot_range():
    with pytest.raises(InvalidInputError, match="1..16"):
        export_tool(Tool("t", (0, 0, 0)), "kuka", slot=17)


# --------------------------------------------------------------------------- ABB
def test_abb_known_quaternion_and_text():
    tool = Tool("gun", (10.0, 0.0, 250.0), (90.0, 0.0, 0.0), mass_kg=4.0)  # Rz(90)
    text = export_tool(tool, "abb")
    assert text.startswith("PERS tooldata gun:=[TRUE,[[10.0,0.0,250.0],[")
    assert text.rstrip().endswith("],[4.0,[0.0,0.0,0.001],[1,0,0,0],0,0,0]];")
    nums = numbers(text)
    # q = [cos 45, 0, 0, sin 45] (scalar first) for a 90 deg turn about Z
    np.testing.assert_allclose(nums[3:7], [S, 0.0, 0.0, S], atol=1e-15)


def test_abb_default_mass_and_identifier():
    text = export_tool(Tool("2nd gripper-L", (0, 0, 100)), "abb")
    assert text.startswith("PERS tooldata t2nd_gripper_L:=[TRUE,")
    nums = numbers(text.split(":=")[1])
    assert nums[7] == 0.001  # tool0's mass: ABB needs a positive mass
    assert import_tool(text, "abb").mass_kg is None
    assert import_tool(text, "abb").name == "t2nd_gripper_L"


def test_abb_import_is_tolerant():
    text = """MODULE Tools
      TASK PERS tooldata tWeld := [ TRUE , [ [ 97.4, 0, 223.1 ] ,
          [ 0.924, 0, 0.383, 0 ] ],
          [ 5, [ 23, 0, 75 ], [ 1, 0, 0, 0 ], 0, 0, 0 ] ] ;
    ENDMODULE"""
    t = import_tool(text, "abb")
    assert t.name == "tWeld" and t.mass_kg == 5.0 and t.tcp_mm == (97.4, 0.0, 223.1)
    # 3-decimal quaternion as printed by a pendant: rotation about Y by ~45 deg
    q = np.array([0.924, 0, 0.383, 0]) / np.linalg.norm([0.924, 0, 0.383, 0])
    angle = 2 * math.degrees(math.atan2(q[2], q[0]))
    expected = np.array([[math.cos(math.radians(angle)), 0, math.sin(math.radians(angle))],
                         [0, 1, 0],
                         [-math.sin(math.radians(angle)), 0, math.cos(math.radians(angle))]])
    np.testing.assert_allclose(t.rotation, expected, atol=1e-12)
    bare = import_tool("[TRUE,[[1,2,3],[1,0,0,0]],[1,[0,0,1],[1,0,0,0],0,0,0]]", "abb", name="b")
    assert bare.tcp_mm == (1.0, 2.0, 3.0) and bare.name == "b"


@pytest.mark.parametrize(
    "text, match",
    [
        ("PERS tooldata t:=[TRUE,[[1,2],[1,0,0,0]],[1,[0,0,0],[1,0,0,0],0,0,0]];",
         r"tframe.trans must be \[3 numbers\]"),
        ("PERS tooldata t:=[TRUE,[[1,2,3],[0.5,0,0,0]],[1,[0,0,0],[1,0,0,0],0,0,0]];", "norm"),
        ("PERS tooldata t:=[FALSE,[[1,2,3],[1,0,0,0]],[1,[0,0,0],[1,0,0,0],0,0,0]];",
         "stationary"),
        ("PERS tooldata t:=[TRUE,[[1,2,3],[1,0,0,0]],[0,[0,0,0],[1,0,0,0],0,0,0]];", "positive"),
        ("PERS tooldata t:=[TRUE,[[1,2,3],[1,0,0,0]],[1,[0,0,0],[1,0,0,0],0,0,0]", "end of text"),
        ("PERS tooldata t:=[TRUE,[[1,2,x],[1,0,0,0]],[1,[0,0,0],[1,0,0,0],0,0,0]];", "near 'x"),
        ("no data", "no tooldata found"),
        ("PERS tooldata a:=[TRUE];\nPERS tooldata b:=[TRUE];", "2 tooldata declarations"),
    ],
)
def test_abb_import_errors(text, match):
    with pytest.raises(InvalidInputError, match=match):
        import_tool(text, "abb")


# --------------------------------------------------------------------------- FANUC
def test_fanuc_known_wpr_of_a_hand_built_matrix():
    # tool X = flange Y, tool Y = flange Z, tool Z = flange X: R = Rz(90) Rx(90) -> W=90,P=0,R=90
    R = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    tool = Tool.from_rotation("spot", (0.0, 120.0, 35.5), R)
    text = export_tool(tool, "fanuc", slot=2)
    lines = text.splitlines()
    assert lines[0] == "UTOOL[2] Direct Entry"
    assert lines[1] == "Comment: spot"
    values = {ln.split(":")[0]: float(ln.split(":")[1]) for ln in lines[2:]}
    assert list(values) == ["X", "Y", "Z", "W", "P", "R"]
    assert [values[k] for k in "XYZ"] == [0.0, 120.0, 35.5]
    np.testing.assert_allclose([values[k] for k in "WPR"], [90.0, 0.0, 90.0], atol=1e-12)


def test_fanuc_import_is_tolerant():
    screen = """SETUP Frames
    Tool Frame     Direct Entry    1/7
     Frame Number:  3
       1 Comment:          Torch 3
       2 X:       12.500
       3 Y:        0.000
       4 Z:      180.250
       5 W:      180.000
       6 P:      -90.000
       7 R:        0.000
       Configuration: N D B, 0, 0, 0
    """
    t = import_tool(screen, "fanuc")
    assert t.name == "Torch 3" and t.tcp_mm == (12.5, 0.0, 180.25)
    expected = Rotation.from_euler("xyz", [180.0, -90.0, 0.0], degrees=True).as_matrix()
    np.testing.assert_allclose(t.rotation, expected, atol=1e-12)
    one_line = import_tool("X: 1 Y: 2 Z: 3 W: 0 P: 0 R: 90", "fanuc")
    assert one_line.name == "utool"
    np.testing.assert_allclose(one_line.rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12)
    assert import_tool("UTOOL[5]\nx=1\ny=2\nz=3\nw=0\np=0\nr=0", "fanuc").name == "utool5"


@pytest.mark.parametrize(
    "text, match",
    [("X: 1 Y: 2", "could not find Z, W, P, R"),
     ("X: 1 X: 2 Y 0 Z 0 W 0 P 0 R 0", "X appears twice")],
)
def test_fanuc_import_errors(text, match):
    with pytest.raises(InvalidInputError, match=match):
        import_tool(text, "fanuc")


# --------------------------------------------------------------------------- UR
def test_ur_known_rotation_vector_and_metres():
    tool = Tool("pen", (12.5, 0.0, 180.25), (90.0, 0.0, 0.0))
    text = export_tool(tool, "ur")
    assert text.startswith("set_tcp(p[") and text.rstrip().endswith("])")
    nums = numbers(text)
    np.testing.assert_allclose(nums[:3], [0.0125, 0.0, 0.18025], atol=1e-15)
    np.testing.assert_allclose(nums[3:], [0.0, 0.0, math.pi / 2], atol=1e-15)


def test_ur_import_is_tolerant():
    for text in ["p[0.0, 0.0, 0.2, 0.0, 3.14159265358979, 0.0]",
                 "  global Tool_tcp =p[ 0 ,0,0.2 , 0,3.14159265358979,0 ]  ",
                 "set_tcp(p[0,0,0.2,0,3.14159265358979,0])",
                 "[0, 0, 0.2, 0, 3.14159265358979, 0]"]:
        t = import_tool(text, "ur")
        assert t.tcp_mm == pytest.approx((0.0, 0.0, 200.0), abs=1e-12)
        np.testing.assert_allclose(t.rotation, np.diag([-1.0, 1.0, -1.0]), atol=1e-13)


@pytest.mark.parametrize(
    "text, match",
    [("p[1,2,3]", "has 3 values"), ("p[1,2,3,nan,0,0]", "rx is 'nan'"),
     ("p[1,2,3,a,0,0]", "rx 'a' is not a number"), ("set_tcp()", "found 0"),
     ("p[1,2,3,0,0,0] p[1,2,3,0,0,0]", "found 2")],
)
def test_ur_import_errors(text, match):
    with pytest.raises(InvalidInputError, match=match):
        import_tool(text, "ur")


# --------------------------------------------------------------------------- matrix
def test_matrix_known_values():
    tool = Tool("m", (1.0, 2.0, 3.0), (90.0, 0.0, 0.0))
    rows = [numbers(line) for line in export_tool(tool, "matrix").splitlines()]
    np.testing.assert_allclose(
        rows, [[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]], atol=1e-15
    )


def test_matrix_import_is_tolerant_and_strict_on_content():
    t = import_tool("# T_flange_tool\n[[0,-1,0,1],[1,0,0,2],\n [0,0,1,3], [0,0,0,1]]", "matrix")
    assert t.abc_deg == pytest.approx((90.0, 0.0, 0.0)) and t.tcp_mm == (1.0, 2.0, 3.0)
    t12 = import_tool("1 0 0 5\n0 1 0 6\n0 0 1 7", "matrix")
    assert t12.tcp_mm == (5.0, 6.0, 7.0)
    with pytest.raises(InvalidInputError, match="found 15 numbers"):
        import_tool("1 0 0 0 0 1 0 0 0 0 1 0 0 0 0", "matrix")
    with pytest.raises(InvalidInputError, match="last row"):
        import_tool("1 0 0 0 0 1 0 0 0 0 1 0 1 0 0 1", "matrix")
    with pytest.raises(InvalidInputError, match="orthonormal"):
        import_tool("2 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1", "matrix")
    with pytest.raises(InvalidInputError, match="could not parse 'foo'"):
        import_tool("1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 foo", "matrix")


# --------------------------------------------------------------------------- common
def test_unknown_format_lists_the_known_ones():
    with pytest.raises(InvalidInputError, match="kuka, abb, fanuc, ur, matrix"):
        export_tool(Tool("t", (0, 0, 0)), "staubli")
    with pytest.raises(InvalidInputError, match="kuka, abb"):
        import_tool("x", "yaskawa")
    with pytest.raises(InvalidInputError, match="Tool"):
        export_tool({"name": "t"}, "kuka")  # type: ignore[arg-type]


def test_tiny_conversion_noise_is_written_as_zero():
    text = export_tool(Tool("t", (0, 0, 100), (90.0, 0.0, 0.0)), "abb")
    assert "e-1" not in text.lower()  # no 6.1e-17 quaternion components
