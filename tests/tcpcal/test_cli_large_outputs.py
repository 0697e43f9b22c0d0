"""`tcpcal solve xyz4` on large files: same bytes, same errors, no per-row
Python work.

The fast CSV reader (``tcpcal.poses_csv._fast_rows``), the column-wise residual table
(``tcpcal.report._residual_lines``) and the list fast paths of ``tcpcal.report.json_dumps``
must give exactly what the row-by-row code gave. The row-by-row formatting of the commit before
them is kept here, verbatim, as the reference (``_old_*``); the reader's reference is its own
csv / cell-by-cell path (``_csv_body``), which names every error.
"""

from __future__ import annotations

import cProfile
import dataclasses
import json
import math
import pstats
import textwrap
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.poses import random_tcp, tilted_rotations, touch_positions
from scipy.spatial.transform import Rotation

from tcpcal import poses_csv, report
from tcpcal.cli import _with_source, main
from tcpcal.errors import InvalidInputError
from tcpcal.origin import solve_xyz4
from tcpcal.poses_csv import read_poses_csv
from tcpcal.report import (CAVEAT, METHOD_TITLES, _bullets, _tcp_block, format_tcp_report,
                           json_dumps, tcp_result_to_dict)


# ------------------------------------------------------------ reference: the row-by-row code
def _old_format_tcp_report(result: Any, poses: Any = None, *, command: str = "solve xyz4") -> str:
    """``tcpcal.report.format_tcp_report`` as it was before the column-wise table (verbatim)."""
    n = int(result.n_touches)
    title = METHOD_TITLES.get(result.method, result.method)
    src = f" from {poses.path} (layout {poses.layout})" if poses is not None else ""
    lines = [f"tcpcal {command}: {title}, {n} touch{'es' if n != 1 else ''}{src}", ""]
    lines += _tcp_block(result)
    lines += ["", "Per-touch residuals e_i = R_i t + f_i - r (mm):",
              "   row  line      |e|       ex       ey       ez"]
    outliers = set(result.outliers)
    for i in range(n):
        line_no = poses.line_numbers[i] if poses is not None and i < len(poses) else None
        e = np.asarray(result.residual_vectors[i], dtype=float)
        mark = "  <- outlier" if i in outliers else ""
        label = ""
        if poses is not None and poses.labels is not None and i < len(poses.labels):
            label = f"  {poses.labels[i]}" if poses.labels[i] else ""
        lines.append(f"  {i + 1:4d}  {'' if line_no is None else line_no:>4}  "
                     f"{float(result.residuals[i]):7.3f}  {e[0]:7.3f}  {e[1]:7.3f}  {e[2]:7.3f}"
                     f"{label}{mark}")
    lines.append("")
    if outliers:
        rows = ", ".join(f"{i + 1}" + (f" (line {poses.line_numbers[i]})" if poses is not None
                                        and i < len(poses) else "") for i in sorted(outliers))
        lines.append(f"Outliers: data row {rows} stand{'s' if len(outliers) == 1 else ''} out "
                     f"from the others; re-record {'it' if len(outliers) == 1 else 'them'} "
                     f"or use the result without {'it' if len(outliers) == 1 else 'them'}.")
        sub = result.without_outliers
        if sub is not None:
            lines.append(f"Result without {'it' if len(outliers) == 1 else 'them'}:")
            lines += ["  " + s for s in _tcp_block(sub)]
    else:
        lines.append("Outliers: none")
    if result.warnings:
        lines.append("Warnings:")
        lines += _bullets(result.warnings)
    else:
        lines.append("Warnings: none")
    lines += ["", *textwrap.wrap(CAVEAT, width=92)]
    return "\n".join(lines)


def _old_jsonable(obj: Any) -> Any:
    """``tcpcal.report._jsonable`` before the list fast path (verbatim)."""
    if isinstance(obj, Mapping):
        return {str(k): _old_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "biu" or (obj.dtype.kind == "f" and bool(np.isfinite(obj).all())):
            return obj.tolist()
        return _old_jsonable(obj.tolist())
    if isinstance(obj, (list, tuple)):
        return [_old_jsonable(v) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        return x if math.isfinite(x) else None
    return obj


def _old_dump(obj: Any, level: int) -> str:
    """``tcpcal.report._dump`` before the rows fast path (verbatim)."""
    if isinstance(obj, dict) and obj:
        pad = "  " * (level + 1)
        items = [f"{pad}{json.dumps(k)}: {_old_dump(v, level + 1)}" for k, v in obj.items()]
        return "{\n" + ",\n".join(items) + "\n" + "  " * level + "}"
    if isinstance(obj, list) and obj and any(isinstance(v, (dict, list)) for v in obj):
        pad = "  " * (level + 1)
        return ("[\n" + ",\n".join(pad + _old_dump(v, level + 1) for v in obj) + "\n"
                + "  " * level + "]")
    return json.dumps(obj, allow_nan=False)


def _old_json_dumps(obj: Any) -> str:
    return _old_dump(_old_jsonable(obj), 0)


# ------------------------------------------------------------------------------ test files
def _write_touches(path: Path, n: int, seed: int, *, labels: bool = False,
                   joints: bool = False, outliers: int = 0, delim: str = ",") -> np.ndarray:
    """A kuka-layout touch file of ``n`` rows (0.5 mm noise; ``outliers`` rows 20 mm off);
    returns the true TCP (mm)."""
    rng = np.random.default_rng(seed)
    rot = tilted_rotations(rng, n, (20.0, 50.0))
    tcp = random_tcp(rng, (100.0, 300.0))
    pos = touch_positions(rot, tcp, np.array([800.0, 0.0, 300.0]), rng, 0.5)
    if outliers:
        pos[rng.choice(n, outliers, replace=False)] += [20.0, -15.0, 10.0]
    abc = Rotation.from_matrix(rot).as_euler("ZYX", degrees=True)
    cols = [f"{v:.4f}" for v in np.hstack([pos, abc]).ravel()]
    names = ["x", "y", "z", "a", "b", "c"]
    rows = [cols[6 * i:6 * i + 6] for i in range(n)]
    if labels:  # some empty, one with characters that mean something to '%' formatting
        names.insert(0, "Name")
        for i, r in enumerate(rows):
            r.insert(0, "" if i % 3 == 1 else (f"p{i} %s %d" if i % 7 == 0 else f"p{i}"))
    if joints:
        names += ["j1", "j2"]
        for i, r in enumerate(rows):
            r += [f"{i % 90}.5", f"-{i % 17}"]
    path.write_text(delim.join(names) + "\n" + "\n".join(delim.join(r) for r in rows) + "\n",
                    encoding="utf-8")
    return tcp


def _json_out(res: Any, poses: Any) -> dict[str, Any]:
    """The object ``tcpcal solve xyz4 --json`` prints (``tcpcal.cli._with_source``)."""
    out = dict(tcp_result_to_dict(res))
    out["input"] = {"path": str(poses.path), "layout": poses.layout, "n_rows": len(poses),
                    "line_numbers": list(poses.line_numbers)}
    if poses.joints_deg is not None:
        out["joints_deg"] = [list(j) for j in poses.joints_deg]
    return out


# ------------------------------------------------------------------ byte-identical outputs
@pytest.mark.parametrize(("n", "labels", "joints", "outliers"), [
    (10, True, True, 1), (1000, True, False, 3), (1000, False, True, 0),
    pytest.param(100_000, False, False, 0, marks=pytest.mark.slow)])
def test_text_and_json_are_byte_identical_to_the_row_by_row_code(
        tmp_path: Path, n: int, labels: bool, joints: bool, outliers: int) -> None:
    path = tmp_path / "touches.csv"
    _write_touches(path, n, seed=n + outliers, labels=labels, joints=joints, outliers=outliers)
    poses = read_poses_csv(path, min_rows=4)
    res = solve_xyz4(poses.rotations, poses.positions_mm)
    if outliers:
        assert res.outliers  # the outlier marks and the result without them are compared too
    text = format_tcp_report(res, poses)
    assert text == _old_format_tcp_report(res, poses)
    assert text.count("\n") > n
    assert format_tcp_report(res) == _old_format_tcp_report(res)  # no poses: no line numbers
    out = _json_out(res, poses)
    assert _with_source(tcp_result_to_dict(res), poses) == json_dumps(out)
    new = json_dumps(out)
    assert new == _old_json_dumps(out)
    assert len(json.loads(new)["residuals_mm"]) == n


def test_residual_table_edge_values_match_the_row_by_row_code(tmp_path: Path) -> None:
    """Signed zeros, rounding ties, fields wider than 7 characters, NaN/inf, more touches than
    poses and more poses than labels: the ``%`` formats give the f-string specs' text."""
    path = tmp_path / "touches.csv"
    _write_touches(path, 12, seed=5, labels=True)
    poses = read_poses_csv(path)
    res = solve_xyz4(poses.rotations, poses.positions_mm)
    vals = np.array([-0.0, 0.0, -0.0004, 0.0005, 0.0625, -0.0625, 999.9996, -99.9996, 1e7,
                     -1234.5675, 2.5e-4, 1.0005, math.nan, math.inf, -math.inf, 5e-324,
                     -123456.0001, 0.1235])
    vectors = np.resize(vals, (12, 3))
    vectors[:, 1] = vals[::-1][:12]
    fake = dataclasses.replace(res, residual_vectors=vectors,
                               residuals=np.resize(vals[3:], 12), outliers=(0, 5, 11))
    assert format_tcp_report(fake, poses) == _old_format_tcp_report(fake, poses)
    # a pose set shorter than the result (rows without a line number or label)
    short = dataclasses.replace(poses, rotations=poses.rotations[:7].copy(),
                                positions_mm=poses.positions_mm[:7].copy(),
                                line_numbers=poses.line_numbers[:7], labels=poses.labels[:5])
    assert format_tcp_report(fake, short) == _old_format_tcp_report(fake, short)


@pytest.mark.parametrize("obj", [
    {"a": [1, 2.5, -0.0, "x"], "b": [], "c": [[]], "d": [[], [1]], "e": [[1, 2], [3.5, 4]]},
    {"nan": [1.0, math.nan, 2.0], "inf": [[1.0, math.inf]], "big": [10**400, 1.5],
     "bigrows": [[10**400, 1.5]]},
    {"bools": [True, 1, 2.0], "np": [np.float64(1.5), np.int64(3)], "tup": (1, (2, 3.0))},
    {"strings": [["], [", 1], ["{x}", 2]], "mixed": [[1, 2], 3, {"k": [4]}],
     "deep": [[[1, 2]], [[3]]], "dicts": [{"a": 1}, {"b": [2]}], "none": [[None, 1], [2, None]]},
    {"arr": np.arange(6.0).reshape(2, 3), "nanarr": np.array([[1.0, np.nan]]),
     "ints": np.arange(4), "empty": np.zeros((0, 3)), "rows": [np.arange(3.0), np.arange(2.0)]},
])
def test_json_dumps_fast_paths_match_the_old_dump(obj: dict[str, Any]) -> None:
    assert json_dumps(obj) == _old_json_dumps(obj)


# -------------------------------------------------------------------- the reader's fast path
def _slow_body(path: Path) -> Any:
    text, shown = poses_csv._read_text(path)
    lines = text.splitlines()
    content, line_nos = poses_csv._content_lines(text, lines)
    return poses_csv._csv_body(shown, content, line_nos,
                               poses_csv._detect_delimiter(content[0]))


@pytest.mark.parametrize("variant", ["plain", "labels_joints", "semicolon", "tab", "comments"])
def test_fast_reader_equals_the_csv_path(tmp_path: Path, variant: str,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "t.csv"
    delim = {"semicolon": ";", "tab": "\t"}.get(variant, ",")
    _write_touches(path, 70_000, seed=3, labels=variant != "plain", joints=variant != "plain",
                   delim=delim)
    if variant == "comments":  # blank and comment lines shift the line numbers
        lines = path.read_text().splitlines()
        lines[40_000:40_000] = ["", "# pause", "   "]
        path.write_text("# tracker log\n\n" + "\n".join(lines) + "\n")
    slow = _slow_body(path)
    with monkeypatch.context() as m:  # the fast path alone reads these files
        m.setattr(poses_csv, "_csv_body", None)
        fast = poses_csv._parse_body(*poses_csv._read_text(path))
    assert fast.layout == slow.layout
    np.testing.assert_array_equal(fast.values, slow.values)
    assert list(fast.line_numbers) == list(slow.line_numbers)
    assert (fast.labels, fast.roles, fast.joints) == (slow.labels, slow.roles, slow.joints)
    poses = read_poses_csv(path)
    assert len(poses) == 70_000 and isinstance(poses.line_numbers, tuple)
    if variant == "comments":
        assert poses.where(40_000) == f"{path}, line 40007 (data row 40001)"


def _file_with_row(tmp_path: Path, row: str, *, at: int = 70_000, n: int = 80_000,
                   header: str = "x,y,z,a,b,c,j1") -> Path:
    """A clean file of ``n`` rows whose data row ``at + 1`` is ``row`` (past the first block
    of rows the fast reader converts)."""
    good = "800.5,0.25,300,10,20,30,1.5"
    lines = [header] + [good] * n
    lines[at + 1] = row
    path = tmp_path / "big.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize(("row", "message"), [
    ("800,0,300,10,,30,1", "column 'b' is empty"),
    ("800,0,300,10,x,30,1", "column 'b' is not a number: 'x'"),
    ("800,0,300,10,nan,30,1", "column 'b' is 'nan', not a finite number"),
    ("800,0,300,10,20,30", "6 cells but the header has 7 columns"),
    ("800,0,300,10,20,30,1,2", "8 cells but the header has 7 columns"),
    ("800,0,300,10,0x10,30,1", "column 'b' is not a number: '0x10'"),
    ("800,0,300,10,20,30,inf", "joint column 'j1' is 'inf', not a finite number"),
    ("800,0,300,10,20,30,a", "joint column 'j1' is not a number: 'a' (joint values are "
                             "optional: leave the j columns out or fill every row)"),
    ("800,0,2e6,10,20,30,1", "column 'z' is 2e+06 mm, beyond +-1e+06 mm"),
])
def test_errors_in_large_files_name_the_same_line(tmp_path: Path, row: str,
                                                  message: str) -> None:
    path = _file_with_row(tmp_path, row)
    with pytest.raises(InvalidInputError) as info:
        read_poses_csv(path)
    assert str(info.value).startswith(f"{path}, line 70002 (data row 70001): {message}")
    assert info.value.index == 70_000


@pytest.mark.parametrize(("row", "value"), [
    ("1_000,0,300,10,20,30,1", 1000.0),      # Python's float takes underscores
    (" 20.5 ,0,300,10,20,30,1", 20.5),       # spaces around a value
    ("\u0661\u0662,0,300,10,20,30,1", 12.0),  # Arabic-Indic digits: float() takes them
    ("800,0,300,10,20,30,1,,", 800.0),       # trailing empty cells (spreadsheet export)
])
def test_cells_the_cell_by_cell_reader_takes_are_still_taken(tmp_path: Path, row: str,
                                                             value: float) -> None:
    poses = read_poses_csv(_file_with_row(tmp_path, row))
    assert poses.positions_mm[70_000, 0] == value
    assert poses.positions_mm[70_001, 0] == 800.5
    assert poses.line_numbers[70_000] == 70_002


def test_quoted_cells_go_through_csv(tmp_path: Path) -> None:
    path = tmp_path / "q.csv"
    path.write_text('name,x,y,z,a,b,c\n"p, 1",1,2,3,0,0,0\n"p2",4,5,6,0,0,0\n')
    poses = read_poses_csv(path)
    assert poses.labels == ("p, 1", "p2")
    path.write_text('name,x,y,z,a,b,c\n"p1,1,2,3,0,0,0\n')
    with pytest.raises(InvalidInputError, match="CSV syntax error"):
        read_poses_csv(path)


# ------------------------------------------------------ no per-row Python work, end to end
def _profiled_calls(fn: Any) -> int:
    prof = cProfile.Profile()
    prof.runcall(fn)
    return sum(s[1] for s in pstats.Stats(prof).stats.values())  # type: ignore[attr-defined]


@pytest.mark.slow
def test_reading_and_formatting_make_no_python_call_per_row(tmp_path: Path) -> None:
    """10^5 rows cost O(1) Python-level calls (blocks of rows, columns), not O(N): the row
    loops of the csv reader, the report table and the JSON conversion were 10^5 - 10^6 calls
    (and 30 s for 10^6 rows end to end)."""
    path = tmp_path / "touches.csv"
    _write_touches(path, 100_000, seed=1, labels=True, joints=True)
    assert _profiled_calls(lambda: read_poses_csv(path)) < 5_000
    poses = read_poses_csv(path)
    res = solve_xyz4(poses.rotations, poses.positions_mm)
    assert _profiled_calls(lambda: format_tcp_report(res, poses)) < 5_000
    assert _profiled_calls(lambda: json_dumps(_json_out(res, poses))) < 5_000


@pytest.mark.slow
def test_cli_solves_1e5_rows_in_process(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "tracker.csv"
    tcp = _write_touches(path, 100_000, seed=7)
    assert main(["solve", "xyz4", str(path)]) == 0
    text = capsys.readouterr().out
    assert "100000 touches" in text
    table = [ln for ln in text.splitlines() if ln.startswith("  ") and ln.split()[0].isdigit()]
    assert len(table) == 100_000 and table[-1].split()[:2] == ["100000", "100001"]
    assert main(["solve", "xyz4", "--json", str(path)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["residuals_mm"]) == len(out["residual_vectors_mm"]) == 100_000
    assert out["input"]["line_numbers"][-1] == 100_001
    # 0.5 mm noise on 10^5 touches: the TCP within a few hundredths of a millimetre
    assert np.linalg.norm(np.array(out["tcp_mm"]) - tcp) < 0.05
    assert out["rms_error_mm"] == pytest.approx(0.5 * math.sqrt(3), rel=0.05)


def test_bench_cli_table_runs_the_command(capsys: pytest.CaptureFixture[str]) -> None:
    """Table 6 of tests/bench/bench_solver.py (a small file here): both outputs exit 0 and get a
    time, a CPU time, a peak RSS and an output size."""
    import importlib.util

    bench = Path(__file__).resolve().parents[1] / "bench" / "bench_solver.py"
    spec = importlib.util.spec_from_file_location("bench_solver_cli_table", bench)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.print_cli_table((2_000,))
    rows = [ln.split() for ln in capsys.readouterr().out.splitlines()
            if ln.split()[:2] in (["text", "2,000"], ["--json", "2,000"])]
    assert [r[0] for r in rows] == ["text", "--json"], rows
    for r in rows:
        wall, cpu, rss, size = map(float, r[2:6])
        assert wall > 0 and cpu > 0 and 10 < rss < 2048 and size > 0.05
        assert "EXIT" not in r
