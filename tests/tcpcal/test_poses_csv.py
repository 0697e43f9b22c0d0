"""Tests of tcpcal.poses_csv: layouts against hand-built rotations, leniency, every error."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tcpcal.errors import InvalidInputError, TcpcalError
from tcpcal.poses_csv import LAYOUTS, read_poses_csv


def rx(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def write(tmp_path: Path, text: str, name: str = "poses.csv") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


# --------------------------------------------------------------- layouts, hand-computed values
def test_kuka_abc_is_rz_ry_rx(tmp_path: Path) -> None:
    p = write(tmp_path, "x,y,z,a,b,c\n1,2,3,30,20,10\n4,5,6,90,0,0\n")
    poses = read_poses_csv(p)
    assert poses.layout == "kuka"
    np.testing.assert_allclose(poses.rotations[0], rz(30) @ ry(20) @ rx(10), atol=1e-14)
    np.testing.assert_allclose(poses.rotations[1], [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    np.testing.assert_array_equal(poses.positions_mm, [[1, 2, 3], [4, 5, 6]])


def test_fanuc_wpr_is_fixed_xyz(tmp_path: Path) -> None:
    poses = read_poses_csv(write(tmp_path, "x,y,z,w,p,r\n0,0,0,10,20,30\n"))
    assert poses.layout == "fanuc"
    np.testing.assert_allclose(poses.rotations[0], rz(30) @ ry(20) @ rx(10), atol=1e-14)


def test_quaternion_scalar_first(tmp_path: Path) -> None:
    h = float(np.sqrt(0.5))
    poses = read_poses_csv(write(tmp_path, f"x,y,z,qw,qx,qy,qz\n0,0,0,{h!r},0,0,{h!r}\n"))
    assert poses.layout == "abb"
    np.testing.assert_allclose(poses.rotations[0], rz(90), atol=1e-15)


def test_rotation_vector_radians(tmp_path: Path) -> None:
    poses = read_poses_csv(write(tmp_path, f"x,y,z,rx,ry,rz\n0,0,0,{np.pi / 2!r},0,0\n"))
    assert poses.layout == "rotvec"
    np.testing.assert_allclose(poses.rotations[0], rx(90), atol=1e-15)


def test_matrix_row_major(tmp_path: Path) -> None:
    m = rz(30) @ ry(-40) @ rx(15)
    cols = ",".join(LAYOUTS["matrix"])
    vals = ",".join(repr(float(v)) for v in m.reshape(-1))
    poses = read_poses_csv(write(tmp_path, f"x,y,z,{cols}\n7,8,9,{vals}\n"))
    assert poses.layout == "matrix"
    np.testing.assert_allclose(poses.rotations[0], m, atol=1e-15)
    assert cols.startswith("r11,r12,r13,r21")


# ------------------------------------------------------------------------------- leniency
def test_header_case_whitespace_blank_comment_lines_extra_columns(tmp_path: Path) -> None:
    text = ("# recorded on the cell 3 robot\n"
            "\n"
            " Name , X ,Y, z , A,B ,C , time\n"
            "p1, 1, 2, 3, 0, 0, 0, 12:00\n"
            "\n"
            "# a comment between rows\n"
            "p2,4,5,6,90,0,0,12:01,\n")  # trailing empty cell from a spreadsheet
    poses = read_poses_csv(write(tmp_path, text))
    assert poses.line_numbers == (4, 7)
    assert poses.labels == ("p1", "p2")
    np.testing.assert_array_equal(poses.positions_mm[1], [4, 5, 6])
    np.testing.assert_allclose(poses.rotations[1], rz(90), atol=1e-15)


def test_semicolon_delimiter_and_bom(tmp_path: Path) -> None:
    p = tmp_path / "semi.csv"
    p.write_bytes("\ufeffx;y;z;a;b;c\n1;2;3;0;90;0\n".encode())
    poses = read_poses_csv(p)
    np.testing.assert_allclose(poses.rotations[0], ry(90), atol=1e-15)


def test_result_arrays_are_read_only(tmp_path: Path) -> None:
    poses = read_poses_csv(write(tmp_path, "x,y,z,a,b,c\n1,2,3,0,0,0\n"))
    with pytest.raises(ValueError):
        poses.positions_mm[0, 0] = 5.0


# --------------------------------------------------------------------------------- errors
def _err(tmp_path: Path, text: str, **kw: object) -> InvalidInputError:
    p = write(tmp_path, text)
    with pytest.raises(InvalidInputError) as info:
        read_poses_csv(p, **kw)  # type: ignore[arg-type]
    msg = str(info.value)
    assert str(p) in msg, msg
    assert "\n" not in msg
    assert isinstance(info.value, TcpcalError)
    return info.value


@pytest.mark.parametrize("cell", ["nan", "NaN", "inf", "-inf"])
def test_non_finite_cell_names_line_row_and_column(tmp_path: Path, cell: str) -> None:
    e = _err(tmp_path, f"x,y,z,a,b,c\n1,2,3,0,0,0\n\n1,2,3,0,{cell},0\n")
    assert "line 4 (data row 2)" in str(e)
    assert "'b'" in str(e) and "finite" in str(e)
    assert e.index == 1


def test_not_a_number(tmp_path: Path) -> None:
    e = _err(tmp_path, "x,y,z,a,b,c\n1,2,3,0,0,0\n1,2,3,0,0,zero\n")
    assert "line 3 (data row 2)" in str(e) and "'c'" in str(e) and "'zero'" in str(e)


def test_empty_cell_and_short_row(tmp_path: Path) -> None:
    e = _err(tmp_path, "x,y,z,a,b,c\n1,,3,0,0,0\n")
    assert "line 2 (data row 1)" in str(e) and "'y' is empty" in str(e)
    e = _err(tmp_path, "x,y,z,a,b,c\n1,2,3,0,0\n")
    assert "line 2 (data row 1)" in str(e) and "5 cells" in str(e)


def test_too_few_and_too_many_rows(tmp_path: Path) -> None:
    body = "x,y,z,a,b,c\n" + "1,2,3,0,0,0\n" * 3
    e = _err(tmp_path, body, min_rows=4, purpose="xyz4")
    assert "too few rows" in str(e) and "3 data row" in str(e) and "at least 4" in str(e)
    e = _err(tmp_path, body, min_rows=2, max_rows=2)
    assert "too many rows" in str(e) and "exactly 2" in str(e)
    e = _err(tmp_path, "x,y,z,a,b,c\n")
    assert "too few rows" in str(e)
    e = _err(tmp_path, "\n# only a comment\n")
    assert "empty" in str(e)


def test_non_orthonormal_matrix(tmp_path: Path) -> None:
    m = rz(20).reshape(-1).copy()
    m[0] += 2e-6  # beyond the 1e-6 tolerance
    cols = ",".join(LAYOUTS["matrix"])
    good = ",".join(repr(float(v)) for v in rz(20).reshape(-1))
    bad = ",".join(repr(float(v)) for v in m)
    e = _err(tmp_path, f"x,y,z,{cols}\n0,0,0,{good}\n0,0,0,{bad}\n")
    assert "line 3 (data row 2)" in str(e) and "not orthonormal within 1e-06" in str(e)
    # just inside the tolerance is accepted
    m2 = rz(20).reshape(-1).copy()
    m2[0] += 2e-7
    ok = ",".join(repr(float(v)) for v in m2)
    poses = read_poses_csv(write(tmp_path, f"x,y,z,{cols}\n0,0,0,{ok}\n", "ok.csv"))
    np.testing.assert_allclose(poses.rotations[0], rz(20), atol=1e-6)


def test_reflection_matrix(tmp_path: Path) -> None:
    cols = ",".join(LAYOUTS["matrix"])
    e = _err(tmp_path, f"x,y,z,{cols}\n0,0,0,1,0,0,0,1,0,0,0,-1\n")
    assert "reflection" in str(e)


def test_quaternion_not_unit(tmp_path: Path) -> None:
    e = _err(tmp_path, "x,y,z,qw,qx,qy,qz\n0,0,0,0.7071,0,0,0.7071\n")
    assert "line 2 (data row 1)" in str(e) and "norm" in str(e) and "not 1" in str(e)


@pytest.mark.parametrize("header, words", [
    ("x,y,z,alpha,beta,gamma", ["no orientation columns", "x,y,z,a,b,c", "qw,qx,qy,qz",
                                "r11", "rx,ry,rz", "w,p,r"]),
    ("x,y,a,b,c", ["missing position column(s) z"]),
    ("x,y,z,a,b", ["kuka lacks column(s) c"]),
    ("x,y,z,a,b,c,qw,qx,qy,qz", ["mixes orientation layouts kuka and abb"]),
    ("x,y,z,a,b,c,w", ["mixes orientation layout kuka with column(s) of fanuc"]),
    ("x,y,z,a,b,c,A", ["column 'a' appears twice"]),
])
def test_unknown_or_ambiguous_layout_lists_the_accepted_ones(
        tmp_path: Path, header: str, words: list[str]) -> None:
    e = _err(tmp_path, f"{header}\n" + ",".join(["0"] * len(header.split(","))) + "\n")
    assert "line 1 (header)" in str(e)
    for w in words:
        assert w in str(e), (w, str(e))


def test_missing_file_is_oserror(tmp_path: Path) -> None:
    with pytest.raises(OSError):
        read_poses_csv(tmp_path / "nope.csv")


def test_not_utf8(tmp_path: Path) -> None:
    p = tmp_path / "bin.csv"
    p.write_bytes(b"x,y,z,a,b,c\n\xff\xfe,1\n")
    with pytest.raises(InvalidInputError, match="UTF-8"):
        read_poses_csv(p)
