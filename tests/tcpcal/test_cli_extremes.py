"""The CLI keeps its contract on extreme numbers and on stdin.

Each case was an internal error (exit 1: OverflowError, ZeroDivisionError) or a NaN TCP with
exit 0 before: now exit 2 with one line naming the problem (docs/cli.md "Number ranges").
"""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from tcpcal.errors import InvalidInputError
from tcpcal.origin import solve_xyz4

from support.cli_runs import R_REF, T_TRUE, assert_one_error_line, run, write_csv, xyz4_poses


def _csv(tmp_path: Path, scale: float = 1.0, row: int | None = None, value: float | None = None) -> Path:
    rots, pos = xyz4_poses(6, noise_mm=0.1)
    pos = [p * scale for p in pos]
    if row is not None:
        pos[row] = pos[row].copy()
        pos[row][0] = value
    return write_csv(tmp_path / "p.csv", rots, pos)


def test_one_coordinate_1e308_is_exit_2_naming_the_row(tmp_path: Path,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(["solve", "xyz4", str(_csv(tmp_path, row=2, value=1e308))], capsys)
    assert_one_error_line(code, out, err, r"line 4 \(data row 3\)", "column 'x'", r"beyond \+-1e\+06 mm")


@pytest.mark.parametrize("scale", [1e200, 1e308 / 2000.0])
def test_positions_scaled_to_overflow_are_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                  scale: float) -> None:
    code, out, err = run(["solve", "xyz4", str(_csv(tmp_path, scale=scale)), "--json"], capsys)
    assert_one_error_line(code, out, err, r"data row 1\)", r"beyond \+-1e\+06 mm")


def test_all_positions_1e308_is_exit_2_not_a_nan_tcp(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    rots, _ = xyz4_poses(6)
    path = write_csv(tmp_path / "p.csv", rots, [np.full(3, 1e308)] * 6)
    code, out, err = run(["solve", "xyz4", str(path)], capsys)
    assert_one_error_line(code, out, err, "beyond")


@pytest.mark.parametrize("sigma", ["1e308", "1e-320", "1e7", "1e-10"])
@pytest.mark.parametrize("cmd", ["xyz4", "reference"])
def test_sigma_out_of_range_is_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                      sigma: str, cmd: str) -> None:
    extra = ["--known-tcp", "1,2,3"] if cmd == "reference" else []
    rots, pos = xyz4_poses(6 if cmd == "xyz4" else 2)
    path = write_csv(tmp_path / "p.csv", rots, pos)
    code, out, err = run(["solve", cmd, str(path), *extra, "--sigma", sigma], capsys)
    assert_one_error_line(code, out, err, "--sigma", r"1e-09\.\.1e\+06 mm")


@pytest.mark.parametrize("sigma", ["1e-9", "1e6"])
def test_sigma_at_the_bounds_is_accepted(tmp_path: Path, capsys: pytest.CaptureFixture[str], sigma: str) -> None:
    code, out, err = run(["solve", "xyz4", str(_csv(tmp_path)), "--sigma", sigma, "--json"], capsys)
    assert code == 0, err
    res = json.loads(out)
    assert res["noise_sigma_mm"] == float(sigma)
    assert np.allclose(res["tcp_mm"], T_TRUE, atol=0.5)


def test_known_tcp_beyond_range_is_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rots, pos = xyz4_poses(2)
    path = write_csv(tmp_path / "p.csv", rots, pos)
    code, out, err = run(["solve", "reference", str(path), "--known-tcp", "1e308,0,0"], capsys)
    assert_one_error_line(code, out, err, "--known-tcp", r"\+-1e\+06 mm")


def test_rotation_vector_that_overflows_is_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "r.csv"
    rows = ["x,y,z,rx,ry,rz"] + [f"{i},0,0,{0.1 * i},0.2,0.3" for i in range(5)]
    rows[3] = "2,0,0,1e308,1e308,1e308"
    path.write_text("\n".join(rows) + "\n")
    code, out, err = run(["solve", "xyz4", str(path)], capsys)
    assert_one_error_line(code, out, err, r"line 4 \(data row 3\)", "no finite rotation")


def test_solve_reads_stdin_for_dash(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    text = _csv(tmp_path).read_bytes()
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(text), encoding="utf-8"))
    code, out, err = run(["solve", "xyz4", "-", "--json"], capsys)
    assert code == 0, err
    res = json.loads(out)
    assert res["input"]["path"] == "<stdin>" and res["input"]["n_rows"] == 6
    assert np.allclose(res["tcp_mm"], T_TRUE, atol=0.5)
    assert np.allclose(res["reference_mm"], R_REF, atol=0.5)


def test_stdin_error_names_stdin(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(b"x,y,z,a,b,c\n1,2,3,0,0,nan\n")))
    code, out, err = run(["solve", "abc-world", "-"], capsys)
    assert_one_error_line(code, out, err, r"<stdin>, line 2 \(data row 1\)", "column 'c'")


# ------------------------------------------------------------- the same bounds from Python
def test_solver_refuses_overflowing_positions_and_sigma() -> None:
    rots, pos = xyz4_poses(6, noise_mm=0.1)
    with pytest.raises(InvalidInputError, match=r"positions\[0\].*beyond"):
        solve_xyz4(np.array(rots), np.array(pos) * 1e200)
    for sigma in (1e-320, 1e308):
        with pytest.raises(InvalidInputError, match="sigma"):
            solve_xyz4(np.array(rots), np.array(pos), sigma=sigma)
    rots, pos = xyz4_poses(6)  # exact touches
    res = solve_xyz4(np.array(rots), np.array(pos) * 1e6)  # up to 1e9 units accepted, finite
    assert np.allclose(res.tcp, T_TRUE * 1e6, rtol=1e-9)
