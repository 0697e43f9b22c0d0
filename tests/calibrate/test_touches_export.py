""""Export touches (CSV)": a wizard's recorded steps as the POSES.csv ``tcpcal solve`` reads. The
command line re-solves the export (a real ``python -m tcpcal solve`` process) and gets the
wizard's TCP (and frame); in an exercise the file carries only what the trainee measured."""

from __future__ import annotations

import csv
import io
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.calibrate.touches_export import touches_csv_filename, wizard_touches_csv

from support.calib_helpers import make_session, true_frame

NOISY = AutoTouchRequest(sigma_mm=0.4)
"""Touches with a simulated operator error: the result is not the truth, so a match is the file's."""


def _solve(path: Path, *extra: str) -> dict:
    out = subprocess.run([sys.executable, "-m", "tcpcal", "solve", *extra, str(path), "--json"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def _finish(s, kind: str, **options) -> None:
    s.wizard_commands.start(kind, **options)
    for _ in range(s.workflow.wizard.n_steps + 1):
        if s.workflow.result is not None:
            return
        assert s.wizard_commands.auto_touch(NOISY).ok
    assert s.workflow.result is not None


def test_the_cli_re_solves_a_4_point_export_to_the_wizards_tcp(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json", seed=7)
    _finish(s, "xyz4", n_points=6)
    run = s.workflow.run
    text = wizard_touches_csv(run.wizard, run.joints_deg)
    first, header = text.splitlines()[:2]
    assert first == "# tcpcal solve xyz4 xyz4-touches.csv" and touches_csv_filename(run.wizard) == "xyz4-touches.csv"
    assert header == "name,x,y,z,a,b,c,j1,j2,j3,j4,j5,j6"
    rows = list(csv.DictReader(io.StringIO("\n".join(text.splitlines()[1:]))))
    assert [r["name"] for r in rows] == [f"P{i}" for i in range(1, 7)]
    path = tmp_path / "xyz4-touches.csv"
    path.write_text(text)
    got = _solve(path, "xyz4")
    res = run.wizard.finished_result
    np.testing.assert_allclose(got["tcp_mm"], res.tcp_mm, atol=1e-6)
    tcp_true, _, _ = true_frame("pointer")
    assert np.linalg.norm(np.asarray(res.tcp_mm) - tcp_true) > 0.01       # noisy: the match is the file's
    assert got["mean_error_mm"] == pytest.approx(res.figures["mean_error_mm"], abs=1e-6)
    assert got["input"]["line_numbers"] == [3, 4, 5, 6, 7, 8]          # after the command line and the header


def test_the_cli_re_solves_a_tcp_zx_export_with_its_roles(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json", seed=8)
    _finish(s, "tcp-zx", n_points=4)
    run = s.workflow.run
    text = wizard_touches_csv(run.wizard, run.joints_deg)
    rows = list(csv.DictReader(io.StringIO("\n".join(text.splitlines()[1:]))))
    assert [(r["name"], r["role"]) for r in rows] == [("P1", "touch"), ("P2", "touch"), ("P3", "touch"),
                                                      ("P4", "touch"), ("Z1", "z"), ("X1", "x")]
    path = tmp_path / "tcp-zx-touches.csv"
    path.write_text(text)
    got = _solve(path, "tcp-zx")
    res = run.wizard.finished_result
    np.testing.assert_allclose(got["tcp_mm"], res.tcp_mm, atol=1e-6)
    np.testing.assert_allclose(got["rotation_matrix"], res.rotation, atol=1e-9)


def test_an_exercise_export_holds_only_what_the_trainee_measured(tmp_path: Path) -> None:
    """With the truth hidden: flange poses and joints only. Every number of the file is a pose
    or joint value of the steps (the true TCP and the touches' true distances are not there)."""
    s = make_session(tmp_path / "tools.json", seed=9)
    s.wizard_commands.set_hide_truth(True)
    assert s.workflow.hide_truth
    s.wizard_commands.start("xyz4")
    for _ in range(2):                                             # half-way: two steps recorded
        assert s.wizard_commands.auto_touch(NOISY).ok
    run = s.workflow.run
    text = wizard_touches_csv(run.wizard, run.joints_deg)
    lines = text.splitlines()
    assert lines[1] == "name,x,y,z,a,b,c,j1,j2,j3,j4,j5,j6" and len(lines) == 4
    measured = []
    for i in sorted(run.wizard.recorded_poses):
        T = run.wizard.recorded_poses[i].T_world_flange_m
        measured += [*(T[:3, 3] * 1000.0), *run.joints_deg[i]]
    numbers = [float(v) for line in lines[2:] for v in line.split(",")[1:]]
    for v in measured:                                             # the poses and joints are in it ...
        assert any(abs(v - n) < 1e-9 for n in numbers)
    tcp_true, _, _ = true_frame("pointer")
    for t in tcp_true:                                             # ... and no coordinate of the truth
        assert not any(abs(n - t) < 0.05 for n in numbers)
    assert "distance" not in text.lower() and "true" not in text.lower()


def test_a_wizard_without_a_solve_command_or_steps_is_refused_in_words(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json", seed=1)
    wiz = s.wizard_commands.start("xyz4")
    with pytest.raises(ValueError, match="No step recorded yet"):
        wizard_touches_csv(wiz)
    check = type("Check", (), {"kind": "tcp-check", "title": "TCP check", "recorded_poses": {0: None}})()
    with pytest.raises(ValueError, match="TCP check has no touches tcpcal solve reads"):
        wizard_touches_csv(check)  # type: ignore[arg-type]
