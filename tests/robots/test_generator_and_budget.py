"""robots/generate.py reproduces the committed files; visuals stay within the triangle budget
and carry the makers' colours."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yourdfpy

ROBOTS = Path(__file__).resolve().parents[2] / "robots"
NOT_GENERATED = {"generate.py", "README.md"}
BUDGET = 20_000  # triangles per robot, tools and reference tip included


def _committed_files() -> dict[str, bytes]:
    out = {}
    for p in sorted(ROBOTS.rglob("*")):
        rel = p.relative_to(ROBOTS).as_posix()
        if p.is_file() and rel not in NOT_GENERATED and "__pycache__" not in rel:
            out[rel] = p.read_bytes()
    return out


def test_generator_reproduces_committed_files(tmp_path: Path) -> None:
    subprocess.run([sys.executable, str(ROBOTS / "generate.py"), "--out", str(tmp_path)],
                   check=True, capture_output=True, cwd=tmp_path)
    fresh = {p.relative_to(tmp_path).as_posix(): p.read_bytes()
             for p in sorted(tmp_path.rglob("*")) if p.is_file()}
    committed = _committed_files()
    assert sorted(fresh) == sorted(committed), "files added or missing: run robots/generate.py"
    differing = [k for k in fresh if fresh[k] != committed[k]]
    assert not differing, f"regenerated files differ: {differing}"


def _triangles(path: Path) -> int:
    urdf = yourdfpy.URDF.load(str(path))
    return sum(len(g.faces) for g in urdf.scene.geometry.values())


@pytest.mark.parametrize("robot", ["kr6_r900/kr6_r900.urdf", "gp12/gp12.urdf"])
def test_triangle_budget(robot: str) -> None:
    extras = [*sorted((ROBOTS / "tools").glob("*.urdf")),
              ROBOTS / "reference_tip" / "reference_tip.urdf"]
    total = _triangles(ROBOTS / robot) + sum(_triangles(p) for p in extras)
    assert 0 < total < BUDGET


def _colour_fractions(path: Path) -> dict[str, float]:
    """Fraction of the visual triangles per colour class, from the colours yourdfpy applies
    (the ones ViserUrdf hands to the browser)."""
    urdf = yourdfpy.URDF.load(str(path))
    counts = {"orange": 0, "blue": 0, "dark": 0}
    n = 0
    for g in urdf.scene.geometry.values():
        rgb = np.asarray(g.visual.face_colors)[:, :3].astype(int)
        n += len(rgb)
        r, gg, b = rgb[:, 0], rgb[:, 1], rgb[:, 2]
        counts["orange"] += int(np.sum((r >= 230) & (gg >= 60) & (gg <= 140) & (b <= 40)))
        counts["blue"] += int(np.sum((b >= 140) & (r <= 60) & (gg <= 120)))
        counts["dark"] += int(np.sum((r <= 90) & (gg <= 90) & (b <= 90)))
    return {k: v / n for k, v in counts.items()}


def test_kr6_is_kuka_orange_and_black() -> None:
    f = _colour_fractions(ROBOTS / "kr6_r900" / "kr6_r900.urdf")
    assert f["orange"] > 0.6 and f["dark"] > 0.05 and f["blue"] == 0.0


def test_gp12_is_yaskawa_blue() -> None:
    f = _colour_fractions(ROBOTS / "gp12" / "gp12.urdf")
    assert f["blue"] > 0.6 and f["orange"] == 0.0
