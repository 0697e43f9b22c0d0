"""The ``tcpcal`` command line's tests' shared parts: flange poses in CSV files built from a
known true tool (never from the code under test), and ``main`` run with pytest's ``capsys``."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcpcal.cli import main

T_TRUE = np.array([12.5, -30.25, 180.75])         # TCP in FLANGE, mm
R_REF = np.array([850.0, 120.0, 410.0])          # reference tip in WORLD, mm
# Diverse flange orientations (KUKA A, B, C deg): tool pointing roughly down, tilted 15-40 deg
# about different axes.
ABC_TOUCHES = [(0, 0, 180), (30, 20, 170), (-40, -25, 160), (90, 30, -170),
               (120, -35, 175), (-100, 15, 150), (60, -10, -150), (-150, 40, 170)]


def rot(abc: tuple[float, float, float]) -> np.ndarray:
    """KUKA A, B, C (deg) -> R = Rz(A) Ry(B) Rx(C), built by hand (not by the code under test)."""
    a, b, c = np.radians(abc)
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    rx = np.array([[1, 0, 0], [0, np.cos(c), -np.sin(c)], [0, np.sin(c), np.cos(c)]])
    return rz @ ry @ rx


def write_csv(path: Path, rotations: list[np.ndarray], positions: list[np.ndarray],
              layout: str = "kuka") -> Path:
    """One flange pose per row, full float precision."""
    if layout == "kuka":
        head = "x,y,z,a,b,c"
        ori = [Rotation.from_matrix(r).as_euler("ZYX", degrees=True) for r in rotations]
    elif layout == "matrix":
        head = "x,y,z," + ",".join(f"r{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3))
        ori = [r.reshape(-1) for r in rotations]
    elif layout == "abb":
        head = "x,y,z,qw,qx,qy,qz"
        ori = [np.roll(Rotation.from_matrix(r).as_quat(), 1) for r in rotations]   # (w, x, y, z), any scipy
    else:
        raise ValueError(layout)
    rows = [",".join(repr(float(v)) for v in (*p, *o)) for p, o in zip(positions, ori)]
    path.write_text(head + "\n" + "\n".join(rows) + "\n", encoding="utf-8")
    return path


def xyz4_poses(n: int = 6, noise_mm: float = 0.0, seed: int = 0,
               offset: dict[int, np.ndarray] | None = None
               ) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Touches of R_REF by the true tool: f_i = r - R_i t (+ noise), methods.md (4P-1)."""
    rng = np.random.default_rng(seed)
    rots = [rot(abc) for abc in ABC_TOUCHES[:n]]
    pos = [R_REF - r @ T_TRUE + noise_mm * rng.standard_normal(3) for r in rots]
    for i, d in (offset or {}).items():
        pos[i] = pos[i] + d
    return rots, pos


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def run_json(argv: list[str], capsys: pytest.CaptureFixture[str]) -> dict:
    code, out, err = run([*argv, "--json"], capsys)
    assert code == 0, err
    assert err == ""
    return json.loads(out)


def assert_one_error_line(code: int, out: str, err: str, *words: str) -> None:
    assert code == 2
    assert out == ""
    assert err.endswith("\n") and err.count("\n") == 1, err
    assert "Traceback" not in err
    for w in words:
        assert re.search(w, err), (w, err)
