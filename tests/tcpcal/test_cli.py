"""Tests of the ``tcpcal`` command line on CSV files generated from a known true tool.

The expected TCP / rotation is the one the poses were built from (never the code's output);
the figures of the JSON output are checked against residuals recomputed here from the CSV.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from support.cli_runs import (
    R_REF,
    T_TRUE,
    assert_one_error_line,
    rot,
    run,
    run_json,
    write_csv,
    xyz4_poses,
)

PA1 = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # methods.md (PA-1)


# ---------------------------------------------------------------------------- solve xyz4
@pytest.mark.parametrize("method", ["lstsq", "sphere", "pairwise"])
@pytest.mark.parametrize("layout", ["kuka", "matrix", "abb"])
def test_xyz4_exact_recovery_json(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                  method: str, layout: str) -> None:
    rots, pos = xyz4_poses(6)
    p = write_csv(tmp_path / "poses.csv", rots, pos, layout)
    d = run_json(["solve", "xyz4", str(p), "--method", method], capsys)
    assert d["method"] == method
    np.testing.assert_allclose(d["tcp_mm"], T_TRUE, atol=1e-6)
    np.testing.assert_allclose(d["reference_mm"], R_REF, atol=1e-6)
    assert len(d["residuals_mm"]) == 6
    assert d["max_error_mm"] < 1e-6
    assert d["outliers"] == []
    assert d["input"]["layout"] == layout


def test_xyz4_noisy_json_figures_match_independent_residuals(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rots, pos = xyz4_poses(8, noise_mm=0.2, seed=3)
    p = write_csv(tmp_path / "noisy.csv", rots, pos)
    d = run_json(["solve", "xyz4", str(p)], capsys)
    t, r = np.array(d["tcp_mm"]), np.array(d["reference_mm"])
    # the true TCP is within a few sigma / sqrt(N) of the estimate
    assert np.linalg.norm(t - T_TRUE) < 1.0
    # residuals recomputed here from the poses: e_i = R_i t + f_i - r  (4P-1)
    e = np.array([R @ t + f - r for R, f in zip(rots, pos)])
    res = np.linalg.norm(e, axis=1)
    np.testing.assert_allclose(d["residuals_mm"], res, atol=1e-9)
    np.testing.assert_allclose(d["residual_vectors_mm"], e, atol=1e-9)
    assert d["mean_error_mm"] == pytest.approx(res.mean(), abs=1e-9)
    assert d["max_error_mm"] == pytest.approx(res.max(), abs=1e-9)
    assert d["rms_error_mm"] == pytest.approx(np.sqrt(np.mean(res ** 2)), abs=1e-9)
    # noise estimate of methods.md section 2: s^2 = sum |e_i|^2 / (3N - 6)
    assert d["noise_sigma_mm"] == pytest.approx(np.sqrt(np.sum(res ** 2) / (3 * 8 - 6)), rel=1e-6)
    assert d["ci95_mm"] > 0 and np.isfinite(d["ci95_mm"])
    assert np.array(d["covariance_mm2"]).shape == (3, 3)
    assert 0 < d["min_angle_deg"] <= d["max_angle_deg"] <= 180
    assert d["condition_number"] >= 1
    assert isinstance(d["warnings"], list)
    assert d["n_touches"] == 8


def test_xyz4_given_sigma_is_reported(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rots, pos = xyz4_poses(6, noise_mm=0.1, seed=1)
    p = write_csv(tmp_path / "p.csv", rots, pos)
    d = run_json(["solve", "xyz4", str(p), "--sigma", "0.5"], capsys)
    assert d["noise_sigma_mm"] == pytest.approx(0.5)


def test_xyz4_outlier_flagged_and_result_without_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rots, pos = xyz4_poses(8, noise_mm=0.05, seed=7, offset={5: np.array([3.0, -4.0, 0.0])})
    p = write_csv(tmp_path / "outlier.csv", rots, pos)
    d = run_json(["solve", "xyz4", str(p)], capsys)
    assert d["outliers"] == [5]
    sub = d["without_outliers"]
    assert sub is not None and 5 not in sub["rows"] and len(sub["rows"]) == 7
    assert np.linalg.norm(np.array(sub["tcp_mm"]) - T_TRUE) < 0.3
    code, out, _err = run(["solve", "xyz4", str(p)], capsys)
    assert code == 0
    assert re.search(r"^\s+6\s+7\s+.*<- outlier$", out, re.MULTILINE), out  # data row 6 = file line 7
    assert "Outliers: data row 6 (line 7) stands out" in out
    assert "Result without it:" in out


def test_xyz4_human_report(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rots, pos = xyz4_poses(6)
    p = write_csv(tmp_path / "poses.csv", rots, pos)
    code, out, err = run(["solve", "xyz4", str(p)], capsys)
    assert code == 0 and err == ""
    tcp_line = next(ln for ln in out.splitlines() if ln.startswith("TCP in FLANGE"))
    for v in T_TRUE:
        assert f"{v:.3f}" in tcp_line
    ref_line = next(ln for ln in out.splitlines() if ln.startswith("Reference in WORLD"))
    for v in R_REF:
        assert f"{v:.3f}" in ref_line
    for word in ("mean", "max", "RMS", "95 %", "noise", "largest angle", "condition number",
                 "Per-touch residuals", "Outliers: none", "does not prove an accurate TCP"):
        assert word in out, word
    # one residual line per touch, numbered by data row and file line
    assert len(re.findall(r"^\s+\d+\s+\d+\s+0\.000\s", out, re.MULTILINE)) == 6


# ----------------------------------------------------------------------- solve reference
def test_reference_json_and_report(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    t_known = np.array([0.0, 0.0, 150.0])
    r1, r2 = rot((10, 20, 170)), rot((-60, -30, 160))
    f1 = R_REF - r1 @ t_known   # calibrated tool touches r
    f2 = R_REF - r2 @ T_TRUE    # new tool touches the same r
    p = write_csv(tmp_path / "ref.csv", [r1, r2], [f1, f2])
    d = run_json(["solve", "reference", str(p), "--known-tcp", "0,0,150"], capsys)
    assert d["method"] == "reference"
    np.testing.assert_allclose(d["tcp_mm"], T_TRUE, atol=1e-9)
    np.testing.assert_allclose(d["reference_mm"], R_REF, atol=1e-9)
    assert d["known_tcp_mm"] == [0.0, 0.0, 150.0]
    for key in ("residuals_mm", "mean_error_mm", "max_error_mm", "rms_error_mm", "ci95_mm",
                "outliers", "warnings"):
        assert key in d
    code, out, _err = run(["solve", "reference", str(p), "--known-tcp", "0,0,150"], capsys)
    assert code == 0
    assert all(f"{v:.3f}" in out for v in T_TRUE)


# --------------------------------------------------------------------- solve three-point
TP_TCP = np.array([-20.0, 5.5, 210.0])
TP_ABC = (10.0, -20.0, 30.0)


def three_point_poses(variant: int) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Rows of methods.md section 5: touch; tip at TOOL (-50, 0, 0); tip at (0, 40, 0) (v1)
    or (15, 40, 0) (v2). f = r - R v with v the tip in FLANGE coordinates."""
    rt = rot(TP_ABC)
    r0, r1, r2 = rot((0, 0, 180)), rot((0, 0, 180)), rot((15, 10, 175))
    tip_tool = [np.zeros(3), np.array([-50.0, 0, 0]),
                np.array([0.0, 40.0, 0]) if variant == 1 else np.array([15.0, 40.0, 0])]
    rots = [r0, r1, r2]
    pos = [R_REF - r @ (TP_TCP + rt @ v) for r, v in zip(rots, tip_tool)]
    return rots, pos


@pytest.mark.parametrize("variant", [1, 2])
def test_three_point(tmp_path: Path, capsys: pytest.CaptureFixture[str], variant: int) -> None:
    rots, pos = three_point_poses(variant)
    p = write_csv(tmp_path / "tp.csv", rots, pos)
    # negative first component given as its own token: must not be taken for an option
    argv = ["solve", "three-point", str(p), "--tcp", "-20,5.5,210", "--variant", str(variant)]
    d = run_json(argv, capsys)
    np.testing.assert_allclose(d["rotation_matrix"], rot(TP_ABC), atol=1e-9)
    np.testing.assert_allclose(d["kuka_abc_deg"], TP_ABC, atol=1e-7)
    assert d["orthogonality_defect_deg"] == pytest.approx(0.0, abs=1e-6)
    assert d["displacements_mm"][0] == pytest.approx(50.0, abs=1e-9)
    assert d["tcp_mm"] == [-20.0, 5.5, 210.0]
    assert d["method"] == f"three-point-{variant}"
    code, out, _err = run(argv, capsys)
    assert code == 0
    abc_line = next(ln for ln in out.splitlines() if "KUKA" in ln)
    assert all(f"{v:.3f}" in abc_line for v in TP_ABC)


# ----------------------------------------------------------------------- solve abc-world
def test_abc_world_6d_and_5d(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rt = rot(TP_ABC)
    r_world_flange = PA1 @ rt.T     # aligned: R_world_flange R_flange_tool = (PA-1)
    p = write_csv(tmp_path / "abc.csv", [r_world_flange], [np.array([600.0, 0, 300])])
    d = run_json(["solve", "abc-world", str(p)], capsys)
    np.testing.assert_allclose(d["rotation_matrix"], rt, atol=1e-9)
    np.testing.assert_allclose(d["kuka_abc_deg"], TP_ABC, atol=1e-7)
    assert d["method"] == "abc-world-6d"
    # 5d: only tool X is determined; tool X must equal the true one
    d5 = run_json(["solve", "abc-world", str(p), "--variant", "5d"], capsys)
    np.testing.assert_allclose(np.array(d5["rotation_matrix"])[:, 0], rt[:, 0], atol=1e-9)
    assert d5["warnings"]
    # 5d keeping the present tool Y: the true rotation comes back
    d5c = run_json(["solve", "abc-world", str(p), "--variant", "5d", "--current-abc",
                    ",".join(str(v) for v in TP_ABC)], capsys)
    np.testing.assert_allclose(d5c["rotation_matrix"], rt, atol=1e-9)
    code, out, _err = run(["solve", "abc-world", str(p)], capsys)
    assert code == 0 and "R_flange_tool" in out
    assert all(f"{v:.3f}" in out for v in TP_ABC)


def test_abc_world_needs_exactly_one_row(tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    rots, pos = xyz4_poses(2)
    p = write_csv(tmp_path / "two.csv", rots, pos)
    assert_one_error_line(*run(["solve", "abc-world", str(p)], capsys),
                          "two.csv", "too many rows", "exactly 1")


# ---------------------------------------------------------------------------- error paths
def test_nan_row(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rots, pos = xyz4_poses(5)
    p = write_csv(tmp_path / "nan.csv", rots, pos)
    lines = p.read_text().splitlines()
    cells = lines[3].split(",")
    cells[4] = "nan"
    lines[3] = ",".join(cells)
    p.write_text("\n".join(lines) + "\n")
    assert_one_error_line(*run(["solve", "xyz4", str(p)], capsys),
                          "nan.csv", r"line 4 \(data row 3\)", "'b'", "finite")


def test_too_few_rows(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rots, pos = xyz4_poses(3)
    p = write_csv(tmp_path / "three.csv", rots, pos)
    assert_one_error_line(*run(["solve", "xyz4", str(p), "--json"], capsys),
                          "three.csv", "too few rows", "3 data row", "at least 4")


def test_non_orthonormal_matrix(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rots, pos = xyz4_poses(5)
    rots[1] = rots[1] * (1 + 1e-5)
    p = write_csv(tmp_path / "mat.csv", rots, pos, layout="matrix")
    assert_one_error_line(*run(["solve", "xyz4", str(p)], capsys),
                          "mat.csv", r"line 3 \(data row 2\)", "not orthonormal within 1e-06")


def test_unknown_layout(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    p = tmp_path / "odd.csv"
    p.write_text("x,y,z,roll,pitch,yaw\n1,2,3,0,0,0\n")
    assert_one_error_line(*run(["solve", "xyz4", str(p)], capsys),
                          "odd.csv", r"line 1 \(header\)", "accepted headers",
                          "a,b,c", "w,p,r", "qw,qx,qy,qz", "rx,ry,rz", "r11")


def test_degenerate_touches_name_the_axis(tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    # every flange rotation about the same WORLD axis through tool-down: R_i = Rz(A_i) R0,
    # so R_a - R_b kills R0^T z = the flange axis u with R0 u = z: here R0 = Rx(180), u = -Z.
    r0 = rot((0, 0, 180))
    rots = [rot((a, 0, 0)) @ r0 for a in (0, 40, 95, 170, 250)]
    pos = [R_REF - r @ T_TRUE for r in rots]
    p = write_csv(tmp_path / "flat.csv", rots, pos)
    code, out, err = run(["solve", "xyz4", str(p)], capsys)
    assert_one_error_line(code, out, err, "flat.csv", "data rows 1-5", r"flange Z axis")


def test_missing_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / "nope.csv"
    assert_one_error_line(*run(["solve", "xyz4", str(missing)], capsys),
                          "nope.csv", "No such file")


def test_reference_wrong_row_count(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rots, pos = xyz4_poses(3)
    p = write_csv(tmp_path / "r3.csv", rots, pos)
    assert_one_error_line(*run(["solve", "reference", str(p), "--known-tcp", "0,0,1"], capsys),
                          "r3.csv", "too many rows", "exactly 2")


@pytest.mark.parametrize("argv, word", [
    (["solve", "reference", "x.csv"], "--known-tcp"),
    (["solve", "reference", "x.csv", "--known-tcp", "1,2"], "X,Y,Z needs 3"),
    (["solve", "three-point", "x.csv", "--tcp", "1,2,3"], "--variant"),
    (["solve", "xyz4", "x.csv", "--method", "ransac"], "invalid choice"),
    (["solve", "xyz4", "x.csv", "--sigma", "-1"], "positive"),
    (["frobnicate"], "invalid choice"),
    ([], "required"),
])
def test_usage_errors_exit_2_with_one_line(argv: list[str], word: str,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    assert_one_error_line(*run(argv, capsys), re.escape(word))


def test_help_exits_0(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(["solve", "xyz4", "--help"], capsys)
    assert code == 0 and "--method" in out


# -------------------------------------------------------------- a real console-script run
def _console_script() -> Path:
    exe = Path(sys.executable).parent / ("tcpcal.exe" if os.name == "nt" else "tcpcal")
    assert exe.exists(), f"console script not installed next to {sys.executable}"
    return exe


def test_console_script_subprocess(tmp_path: Path) -> None:
    rots, pos = xyz4_poses(6)
    p = write_csv(tmp_path / "poses.csv", rots, pos)
    exe = _console_script()
    proc = subprocess.run([str(exe), "solve", "xyz4", str(p), "--json"],
                          capture_output=True, text=True, timeout=60, check=False)
    assert proc.returncode == 0, proc.stderr
    np.testing.assert_allclose(json.loads(proc.stdout)["tcp_mm"], T_TRUE, atol=1e-6)
    # an error through the real entry point: exit 2, one line, no traceback
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y,z,a,b,c\n1,2,3,0,0,0\n1,2,3,0,oops,0\n")
    proc = subprocess.run([str(exe), "solve", "xyz4", str(bad)],
                          capture_output=True, text=True, timeout=60, check=False)
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert "bad.csv, line 3 (data row 2)" in proc.stderr


def test_python_dash_m(tmp_path: Path) -> None:
    proc = subprocess.run([sys.executable, "-m", "tcpcal", "--help"],
                          capture_output=True, text=True, timeout=60, check=False)
    assert proc.returncode == 0 and "solve" in proc.stdout


def test_three_point_error_names_the_row(tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    # row 2 repeats row 1: the tip was never moved onto the tool's -X axis
    rots, pos = three_point_poses(1)
    p = write_csv(tmp_path / "tp_bad.csv", [rots[0], rots[0], rots[2]],
                  [pos[0], pos[0], pos[2]])
    assert_one_error_line(*run(["solve", "three-point", str(p), "--tcp", "-20,5.5,210",
                                "--variant", "1"], capsys),
                          "tp_bad.csv", r"line 3 \(data row 2\)", "-X axis")


def test_reference_with_sigma_gives_a_radius(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    r1, r2 = rot((10, 20, 170)), rot((-60, -30, 160))
    p = write_csv(tmp_path / "ref.csv", [r1, r2],
                  [R_REF - r1 @ np.array([0.0, 0, 150]), R_REF - r2 @ T_TRUE])
    d = run_json(["solve", "reference", str(p), "--known-tcp", "0,0,150", "--sigma", "0.3"],
                 capsys)
    assert d["noise_sigma_mm"] == pytest.approx(0.3)
    assert d["ci95_mm"] is not None and d["ci95_mm"] > 0.3


def test_docs_example_output_is_real(capsys: pytest.CaptureFixture[str],
                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """docs/cli.md pastes the output of its example: it must be what tcpcal prints today, and
    the example's known tool (85, -12, 210) mm must lie within the reported 95 % radius."""
    root = Path(__file__).resolve().parents[2]
    doc = (root / "docs" / "cli.md").read_text(encoding="utf-8")
    monkeypatch.chdir(root)
    cmd = "$ tcpcal solve xyz4 docs/examples/xyz4_poses.csv\n"
    pasted = doc[doc.index(cmd) + len(cmd):].split("\n```", 1)[0]
    code, out, _err = run(["solve", "xyz4", "docs/examples/xyz4_poses.csv"], capsys)
    assert code == 0 and out.rstrip("\n") == pasted
    d = run_json(["solve", "xyz4", "docs/examples/xyz4_poses.csv"], capsys)
    assert np.linalg.norm(np.array(d["tcp_mm"]) - [85.0, -12.0, 210.0]) < d["ci95_mm"]


def test_every_solve_json_has_the_contract_keys(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    """Every ``--json`` object has at least method, tcp_mm, residuals_mm,
    mean/max/rms_error_mm, ci95_mm, outliers (0-based rows) and warnings; reference_mm for
    xyz4 and reference; rotation_matrix (3x3 rows) and kuka_abc_deg for the orientation
    methods (docs/cli.md: null / empty where a figure is not defined)."""
    rots, pos = xyz4_poses(8, noise_mm=0.05, seed=7, offset={5: np.array([3.0, -4.0, 0.0])})
    xyz4 = write_csv(tmp_path / "xyz4.csv", rots, pos)
    r1, r2 = rot((10, 20, 170)), rot((-60, -30, 160))
    ref = write_csv(tmp_path / "ref.csv", [r1, r2],
                    [R_REF - r1 @ np.array([0.0, 0, 150]), R_REF - r2 @ T_TRUE])
    tp = write_csv(tmp_path / "tp.csv", *three_point_poses(2))
    abc = write_csv(tmp_path / "abc.csv", [PA1 @ rot(TP_ABC).T], [np.array([600.0, 0, 300])])
    outputs = {
        "xyz4": run_json(["solve", "xyz4", str(xyz4)], capsys),
        "reference": run_json(["solve", "reference", str(ref), "--known-tcp", "0,0,150"], capsys),
        "three-point": run_json(["solve", "three-point", str(tp), "--tcp", "-20,5.5,210",
                                 "--variant", "2"], capsys),
        "abc-world": run_json(["solve", "abc-world", str(abc)], capsys),
    }
    for cmd, d in outputs.items():
        assert isinstance(d["method"], str)
        assert d["tcp_mm"] is None or (len(d["tcp_mm"]) == 3
                                       and all(isinstance(v, float) for v in d["tcp_mm"])), cmd
        assert isinstance(d["residuals_mm"], list)
        for key in ("mean_error_mm", "max_error_mm", "rms_error_mm", "ci95_mm"):
            assert key in d and (d[key] is None or isinstance(d[key], float)), (cmd, key)
        assert isinstance(d["outliers"], list) and all(isinstance(i, int) for i in d["outliers"])
        assert isinstance(d["warnings"], list) and all(isinstance(w, str) for w in d["warnings"])
    for cmd in ("xyz4", "reference"):
        d = outputs[cmd]
        assert len(d["reference_mm"]) == 3 and len(d["residuals_mm"]) == d["n_touches"]
        assert all(isinstance(d[k], float) for k in ("mean_error_mm", "max_error_mm",
                                                     "rms_error_mm"))
    assert outputs["xyz4"]["outliers"] == [5] and isinstance(outputs["xyz4"]["ci95_mm"], float)
    for cmd in ("three-point", "abc-world"):
        d = outputs[cmd]
        assert np.array(d["rotation_matrix"]).shape == (3, 3) and len(d["kuka_abc_deg"]) == 3
        np.testing.assert_allclose(d["kuka_abc_deg"], TP_ABC, atol=1e-7)
        assert d["residuals_mm"] == [] and d["outliers"] == [] and d["ci95_mm"] is None
    assert outputs["three-point"]["tcp_mm"] == [-20.0, 5.5, 210.0]
    assert outputs["abc-world"]["tcp_mm"] is None


def test_duplicated_pose_error_names_file_line_and_row(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Five rows but only three orientations (rows 4 and 5 repeat rows 2 and 1): exit 2, one
    line naming the file, the file line and data row of the first repeat, and what to do."""
    rots, pos = xyz4_poses(3)
    p = write_csv(tmp_path / "dup.csv", [rots[0], rots[1], rots[2], rots[1], rots[0]],
                  [pos[0], pos[1], pos[2], pos[1], pos[0]])
    assert_one_error_line(*run(["solve", "xyz4", str(p)], capsys),
                          "dup.csv", r"line 5 \(data row 4\)", "same orientation",
                          "at least 4", "re-record")
