"""``tcpcal solve tcp-zx`` (ABB TCP & Z, X) and the joint columns j1..jK kept in --json."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcpcal.cli import main

T_TRUE = np.array([12.5, -30.25, 180.75])     # TCP in FLANGE, mm
R_TOOL = Rotation.from_euler("ZYX", [30.0, -20.0, 5.0], degrees=True).as_matrix()
REF = np.array([850.0, 120.0, 410.0])         # reference point in WORLD, mm
ABC = [(0, 0, 180), (30, 20, 170), (-40, -25, 160), (90, 30, -170), (120, -35, 175),
       (-100, 15, 150), (60, -10, -150), (-150, 40, 170)]


def write_zx_csv(path: Path, *, roles: list[str] | None = None, joints: bool = False,
                 z_d: float = 80.0) -> Path:
    """Rows touch x5, z, x with KUKA A, B, C columns and a role column (full precision)."""
    roles = roles or ["touch"] * 5 + ["Z", "x"]
    lines = ["name,x,y,z,a,b,c,role" + (",j1,j2,j3,j4,j5,j6" if joints else "")]
    for k, role in enumerate(roles):
        R = Rotation.from_euler("ZYX", ABC[k], degrees=True).as_matrix()
        point = T_TRUE.copy()
        if role.lower() == "z":
            point = T_TRUE + z_d * R_TOOL[:, 2]
        elif role.lower() == "x":
            point = T_TRUE + 60.0 * R_TOOL[:, 0]
        f = REF - R @ point
        cells = [f"P{k + 1}", *(repr(float(v)) for v in f), *(repr(float(v)) for v in ABC[k]), role]
        if joints:
            cells += [f"{10.0 * k + j:.3f}" for j in range(6)]
        lines.append(",".join(cells))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_json_has_the_keys_of_the_other_solves_and_the_true_frame(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write_zx_csv(tmp_path / "zx.csv")
    code, out, err = run(capsys, "solve", "tcp-zx", str(path), "--json")
    assert (code, err) == (0, "")
    d = json.loads(out)
    for key in ("method", "tcp_mm", "residuals_mm", "mean_error_mm", "max_error_mm",
                "rms_error_mm", "ci95_mm", "outliers", "warnings", "reference_mm",
                "rotation_matrix", "kuka_abc_deg", "orthogonality_defect_deg", "input"):
        assert key in d, key
    assert d["method"] == "tcp-zx"
    np.testing.assert_allclose(d["tcp_mm"], T_TRUE, atol=1e-8)
    np.testing.assert_allclose(d["reference_mm"], REF, atol=1e-8)
    np.testing.assert_allclose(d["rotation_matrix"], R_TOOL, atol=1e-10)
    np.testing.assert_allclose(d["kuka_abc_deg"], [30.0, -20.0, 5.0], atol=1e-8)
    assert d["rows"] == [0, 1, 2, 3, 4] and d["z_rows"] == [5] and d["x_rows"] == [6]
    np.testing.assert_allclose(d["z_distances_mm"], [80.0], atol=1e-8)
    np.testing.assert_allclose(d["x_distances_mm"], [60.0], atol=1e-8)
    assert "joints_deg" not in d


def test_text_report(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write_zx_csv(tmp_path / "zx.csv")
    code, out, _ = run(capsys, "solve", "tcp-zx", str(path))
    assert code == 0
    assert "ABB TCP & Z, X" in out and "5 touches, 1 z row(s), 1 x row(s)" in out
    assert "TCP in FLANGE (mm):       X    12.500  Y   -30.250  Z   180.750" in out
    assert "TOOL orientation, KUKA (deg): A    30.000  B   -20.000  C     5.000" in out
    assert "     6     7     z     80.0  P6" in out
    assert "     7     8     x     60.0  P7" in out


def test_joint_columns_are_kept_in_json_and_ignored_by_the_solve(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    plain = json.loads(run(capsys, "solve", "tcp-zx", str(write_zx_csv(tmp_path / "a.csv")),
                           "--json")[1])
    code, out, _ = run(capsys, "solve", "tcp-zx",
                       str(write_zx_csv(tmp_path / "b.csv", joints=True)), "--json")
    d = json.loads(out)
    assert code == 0
    assert d["joints_deg"][1] == [10.0, 11.0, 12.0, 13.0, 14.0, 15.0]
    assert len(d["joints_deg"]) == 7
    assert d["tcp_mm"] == plain["tcp_mm"] and d["rotation_matrix"] == plain["rotation_matrix"]


def test_xyz4_keeps_joint_columns_too(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write_zx_csv(tmp_path / "t.csv", roles=["touch"] * 6, joints=True)
    code, out, _ = run(capsys, "solve", "xyz4", str(path), "--json")
    assert code == 0
    d = json.loads(out)
    assert d["joints_deg"][0] == [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
    np.testing.assert_allclose(d["tcp_mm"], T_TRUE, atol=1e-8)


def test_a_bad_joint_value_is_an_error_naming_the_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write_zx_csv(tmp_path / "j.csv", joints=True)
    text = path.read_text().splitlines()
    text[3] = text[3].rsplit(",", 1)[0] + ",abc"
    path.write_text("\n".join(text) + "\n")
    code, out, err = run(capsys, "solve", "tcp-zx", str(path))
    assert (code, out) == (2, "")
    assert "line 4 (data row 3): joint column 'j6' is not a number: 'abc'" in err


@pytest.mark.parametrize(("roles", "needle"), [
    (["touch"] * 5 + ["z", "y"], "line 8 (data row 7): role 'y' is not one of touch, z, x"),
    (["touch"] * 5 + ["z", "z"], "at least one x row"),
    (["touch"] * 3 + ["z", "x", "z"], "too few rows: 6|at least 4 touch rows"),
])
def test_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str], roles: list[str],
                needle: str) -> None:
    path = write_zx_csv(tmp_path / "e.csv", roles=roles)
    code, out, err = run(capsys, "solve", "tcp-zx", str(path))
    assert (code, out) == (2, "")
    assert len(err.strip().splitlines()) == 1
    assert any(n in err for n in needle.split("|")), err


def test_no_role_column(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write_zx_csv(tmp_path / "r.csv")
    lines = path.read_text().splitlines()
    path.write_text("\n".join(ln.rsplit(",", 1)[0] for ln in lines) + "\n")
    code, _, err = run(capsys, "solve", "tcp-zx", str(path))
    assert code == 2 and "no 'role' column" in err


def test_a_z_row_behind_the_tcp_names_its_line(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    roles = ["touch"] * 5 + ["z", "z", "x"]
    path = tmp_path / "b.csv"
    write_zx_csv(path, roles=roles)
    lines = path.read_text().splitlines()
    # rewrite row 7 (file line 8) with the reference behind the TCP on Z
    R = Rotation.from_euler("ZYX", ABC[6], degrees=True).as_matrix()
    f = REF - R @ (T_TRUE - 30.0 * R_TOOL[:, 2])
    lines[7] = ",".join(["P7", *(repr(float(v)) for v in f), *(repr(float(v)) for v in ABC[6]), "z"])
    path.write_text("\n".join(lines) + "\n")
    code, _, err = run(capsys, "solve", "tcp-zx", str(path))
    assert code == 2
    assert "line 8 (data row 7): z row 7: the reference point lies behind the TCP" in err
