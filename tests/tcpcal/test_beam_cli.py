"""``tcpcal solve beam``: the beam-sensor TCP from a CSV of tip events (docs/cli.md)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcpcal.cli import main

T_TRUE = np.array([12.5, -30.25, 180.75])  # TCP in FLANGE, mm
B = np.array([900.0, 150.0, 400.0])  # beam point, WORLD mm
U = np.array([0.0, 1.0, 0.0])  # beam along WORLD Y
ABC = [(0, 0, 180), (90, 0, 180), (180, 20, 180), (270, -20, 170), (45, 10, -170),
       (-60, 25, 175)]


def write_beam_csv(path: Path, abc=ABC, noise: float = 0.0) -> Path:
    """One tip event per row (KUKA A, B, C columns, full precision): the tip on the beam."""
    rng = np.random.default_rng(4)
    lines = ["name,x,y,z,a,b,c"]
    for k, angles in enumerate(abc):
        R = Rotation.from_euler("ZYX", angles, degrees=True).as_matrix()
        f = B + (k - 2) * 3.0 * U - R @ T_TRUE + rng.normal(0.0, noise, 3)
        lines.append(",".join([f"E{k + 1}", *(repr(float(v)) for v in f),
                               *(repr(float(v)) for v in angles)]))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


BEAM_ARGS = ("--beam-point", "900,150,400", "--beam-dir", "0,2,0")


def test_json_has_the_keys_of_the_other_solves_and_the_true_tcp(tmp_path, capsys):
    path = write_beam_csv(tmp_path / "beam.csv")
    code, out, err = run(capsys, "solve", "beam", str(path), *BEAM_ARGS, "--json")
    assert (code, err) == (0, "")
    d = json.loads(out)
    for key in ("method", "tcp_mm", "residuals_mm", "mean_error_mm", "max_error_mm",
                "rms_error_mm", "ci95_mm", "outliers", "warnings", "beam_point_mm", "beam_dir",
                "n_events", "noise_sigma_mm", "covariance_mm2", "condition_number", "input"):
        assert key in d, key
    assert d["method"] == "beam" and d["n_events"] == 6 and d["outliers"] == []
    np.testing.assert_allclose(d["tcp_mm"], T_TRUE, atol=1e-8)
    assert d["beam_point_mm"] == [900.0, 150.0, 400.0]
    assert d["beam_dir"] == [0.0, 1.0, 0.0]  # normalised
    assert max(d["residuals_mm"]) < 1e-8 and d["ci95_mm"] < 1e-7
    np.testing.assert_allclose(d["beam_positions_mm"], [-6.0, -3.0, 0.0, 3.0, 6.0, 9.0],
                               atol=1e-8)
    assert d["input"]["n_rows"] == 6


def test_sigma_and_the_text_report(tmp_path, capsys):
    path = write_beam_csv(tmp_path / "beam.csv", noise=0.02)
    code, out, err = run(capsys, "solve", "beam", str(path), *BEAM_ARGS, "--sigma", "0.02")
    assert (code, err) == (0, "")
    assert "beam sensor (methods.md section 9), 6 tip events" in out
    assert "TCP in FLANGE (mm):" in out and "95 % radius of the TCP:" in out
    assert "(event noise 0.020 mm per axis across the beam)" in out
    assert out.count("\n  ") >= 6  # one row per event


@pytest.mark.parametrize("beam_dir, why", [
    ("0,0,0", "must not be zero"),
    ("1,0", "needs 3 comma-separated numbers"),
    ("1,a,0", "must be numbers"),
    ("1,nan,0", "finite"),
])
def test_bad_beam_direction_exits_2_with_one_line(tmp_path, capsys, beam_dir, why):
    path = write_beam_csv(tmp_path / "beam.csv")
    code, out, err = run(capsys, "solve", "beam", str(path), "--beam-point", "900,150,400",
                         f"--beam-dir={beam_dir}")
    assert code == 2 and out == ""
    assert why in err and err.count("\n") == 1


def test_bad_beam_point_and_missing_options_exit_2(tmp_path, capsys):
    path = write_beam_csv(tmp_path / "beam.csv")
    code, _, err = run(capsys, "solve", "beam", str(path), "--beam-point", "900,150",
                       "--beam-dir", "0,1,0")
    assert code == 2 and "X,Y,Z needs 3" in err
    code, _, err = run(capsys, "solve", "beam", str(path), "--beam-dir", "0,1,0")
    assert code == 2 and "--beam-point" in err


def test_too_few_rows_exit_2(tmp_path, capsys):
    path = write_beam_csv(tmp_path / "beam.csv", abc=ABC[:1])
    code, out, err = run(capsys, "solve", "beam", str(path), *BEAM_ARGS)
    assert code == 2 and out == ""
    assert "beam" in err and "1" in err and err.count("\n") == 1


def test_events_turned_only_about_the_beam_exit_2_naming_the_axis(tmp_path, capsys):
    # tool down, turned about WORLD Y (the beam) only: every event sees the beam along flange Y
    rows = [Rotation.from_euler("y", a, degrees=True) * Rotation.from_euler("y", 180, degrees=True)
            for a in (0.0, 20.0, -30.0)]
    abc = [tuple(r.as_euler("ZYX", degrees=True)) for r in rows]
    path = write_beam_csv(tmp_path / "beam.csv", abc=abc)
    code, out, err = run(capsys, "solve", "beam", str(path), *BEAM_ARGS)
    assert code == 2 and out == ""
    assert "same flange direction" in err and "[unobservable direction ~ flange Y axis]" in err
