"""The float-array fast path of ``tcpcal.report.json_dumps`` (``tcpcal
solve xyz4 --json`` on 10^6 rows).

A finite float array that is a dict value is printed by one ``%r`` format pass over its flat
values (rows of a 2-D array one a line), large ones by blocks of rows in forked processes
(``workers``). The JSON text is a contract: it must be byte for byte what the list path gives,
i.e. ``json_dumps`` of the same object with every array turned into lists by ``tolist()`` (what
``_jsonable`` did with every array before the fast path).
"""

from __future__ import annotations

import concurrent.futures
import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.poses import random_tcp, tilted_rotations, touch_positions
from scipy.spatial.transform import Rotation

from tcpcal import report
from tcpcal.cli import main
from tcpcal.poses_csv import read_poses_csv
from tcpcal.report import json_dumps, tcp_result_to_dict


def as_lists(obj: Any) -> Any:
    """``obj`` with every numpy array turned into lists (the list path's input)."""
    if isinstance(obj, dict):
        return {k: as_lists(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [as_lists(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return obj


EDGE = np.array([-0.0, 0.0, 0.1, 1 / 3, -2.5, 1e-300, 5e-324, 1.7976931348623157e308, 1e16, 1e15,
                 123456789012345680.0, -1e-5, 1e-4, 0.5, 100.0, 2.0 ** 53, -7e22, 0.000123])


def mixed() -> dict[str, Any]:
    rng = np.random.default_rng(8)
    vec = rng.normal(0.0, 0.5, (40, 3))
    return {
        "method": "lstsq", "n": 40, "flag": True, "none": None,
        "residual_vectors_mm": vec,
        "residuals_mm": np.linalg.norm(vec, axis=1),
        "edge_rows": EDGE.reshape(6, 3),
        "edge_flat": EDGE,
        "one": np.array([[2.0]]),
        "single": np.array([7.25]),
        "empty_flat": np.zeros(0),
        "empty_rows": np.zeros((0, 3)),
        "no_columns": np.zeros((3, 0)),
        "float32": vec[:5].astype(np.float32),
        "float16": EDGE[:4].astype(np.float16),
        "big_endian": vec[:4].astype(">f8"),
        "transposed": vec[:6].T,                     # not C-contiguous
        "strided": vec[::7, ::2],
        "nan_rows": np.array([[1.0, math.nan], [math.inf, 2.0]]),   # not finite: the list path
        "ints": np.arange(6).reshape(3, 2),
        "three_d": np.arange(8.0).reshape(2, 2, 2),
        "list_of_arrays": [np.arange(3.0), np.ones((2, 2))],
        "rows": list(range(40)),
        "nested": {"covariance_mm2": np.eye(3) * 0.25, "deeper": {"tcp_mm": vec[0], "v": vec[:3]}},
        "list_of_dicts": [{"a": np.ones((2, 3))}, {"b": np.arange(2.0)}],
        "warnings": ["a \"quoted\" warning, [with] brackets"],
    }


def test_fast_path_gives_the_bytes_of_the_list_path() -> None:
    obj = mixed()
    text = json_dumps(obj)
    assert text == json_dumps(as_lists(obj))
    assert json.loads(text) == json.loads(json.dumps(as_lists(obj)).replace("NaN", "null")
                                          .replace("Infinity", "null"))


def test_fast_path_layout_by_hand() -> None:
    """The exact text of a small object (a row a line, flat lists on one line)."""
    obj = {"v": np.array([[1.0, -0.0, 0.1], [1e-5, 2.5, 1e16]]), "r": np.array([0.5, 1 / 3]),
           "d": {"w": np.array([[3.0]])}}
    assert json_dumps(obj) == (
        '{\n'
        '  "v": [\n'
        '    [1.0, -0.0, 0.1],\n'
        '    [1e-05, 2.5, 1e+16]\n'
        '  ],\n'
        '  "r": [0.5, 0.3333333333333333],\n'
        '  "d": {\n'
        '    "w": [\n'
        '      [3.0]\n'
        '    ]\n'
        '  }\n'
        '}')


class NoRowLists(np.ndarray):
    """An array whose 2-D ``tolist()`` fails: the fast path must never build row lists."""

    def tolist(self) -> Any:  # type: ignore[override]
        if self.ndim > 1:
            raise AssertionError("a 2-D array was turned into Python row lists")
        return super().tolist()


def test_no_python_row_lists_are_built() -> None:
    """The gain of the fast path: 10^6 residual vectors are formatted from their flat values,
    not from 10^6 row lists (before it, ``_jsonable`` called ``tolist()`` on the 2-D array)."""
    vec = np.random.default_rng(2).normal(size=(50, 3))
    obj = {"residual_vectors_mm": vec.view(NoRowLists), "nested": {"v": vec[:2].view(NoRowLists)}}
    assert json_dumps(obj) == json_dumps(as_lists({"residual_vectors_mm": vec, "nested": {"v": vec[:2]}}))


@pytest.mark.parametrize("workers", [2, 3, 7])
def test_parallel_formatting_gives_the_same_text(monkeypatch: pytest.MonkeyPatch, workers: int) -> None:
    pools: list[Any] = []
    real = concurrent.futures.ProcessPoolExecutor

    class CountingPool(real):  # type: ignore[misc, valid-type]
        def __init__(self, *a: Any, **k: Any) -> None:
            pools.append(a)
            super().__init__(*a, **k)

    monkeypatch.setattr(concurrent.futures, "ProcessPoolExecutor", CountingPool)
    monkeypatch.setattr(report, "PARALLEL_MIN_VALUES", 6)
    obj = mixed()
    assert json_dumps(obj, workers=workers) == json_dumps(as_lists(obj))
    assert pools == [(workers - 1,)]          # one pool for the whole call, really used
    # a float array with fewer rows than workers (empty blocks must not add separators)
    few = {"wide": np.arange(12.0).reshape(2, 6), "flat": np.arange(3.0)}
    assert json_dumps(few, workers=workers) == json_dumps(as_lists(few))


def test_parallel_falls_back_to_one_process(monkeypatch: pytest.MonkeyPatch) -> None:
    """No fork (Windows) or no process to start: the text is formatted here, the same."""
    monkeypatch.setattr(report, "PARALLEL_MIN_VALUES", 6)
    obj = mixed()
    monkeypatch.setattr(report, "_fork_context", lambda: None)
    assert json_dumps(obj, workers=4) == json_dumps(as_lists(obj))

    class NoProcess(concurrent.futures.ProcessPoolExecutor):
        def submit(self, *a: Any, **k: Any) -> Any:
            raise OSError("no more processes")

    monkeypatch.undo()
    monkeypatch.setattr(report, "PARALLEL_MIN_VALUES", 6)
    monkeypatch.setattr(concurrent.futures, "ProcessPoolExecutor", NoProcess)
    assert json_dumps(obj, workers=2) == json_dumps(as_lists(obj))


class NoWalk(list):  # type: ignore[type-arg]
    """A list that must not be walked item by item (10^6 row numbers)."""

    def __iter__(self) -> Any:
        raise AssertionError("the list was walked")


def test_handing_arrays_to_the_pool_walks_dicts_only(monkeypatch: pytest.MonkeyPatch) -> None:
    """Finding the large arrays to hand to the pool looks at dict values, never at every item
    of the 10^6-item lists next to them (a walk that cost ~0.5 s on 10^6 rows)."""
    monkeypatch.setattr(report, "PARALLEL_MIN_VALUES", 6)
    fmt = report._Formatter(2)
    vec = report._FloatArray(np.ones((10, 3)))
    try:
        fmt.start({"rows": NoWalk([1, 2]), "nested": {"line_numbers": NoWalk([3]), "v": vec}})
        assert list(fmt._pending) == [id(vec)]
        assert "".join(fmt.blocks(vec, 2)) == ",\n      ".join(["[1.0, 1.0, 1.0]"] * 10)
    finally:
        fmt.close()


def test_a_dying_formatting_process_changes_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    """A child that dies (killed, out of memory) breaks the pool: this process formats the
    arrays itself, the text is the same."""
    real = report._format_block
    parent = os.getpid()

    def dying(array: np.ndarray, row: str, sep: str) -> str:
        if os.getpid() != parent:
            os._exit(3)
        return real(array, row, sep)

    dying.__module__, dying.__qualname__ = "tcpcal.report", "_format_block"   # pickled by name
    monkeypatch.setattr(report, "_format_block", dying)
    monkeypatch.setattr(report, "PARALLEL_MIN_VALUES", 6)
    obj = mixed()
    assert json_dumps(obj, workers=2) == json_dumps(as_lists(obj))


@pytest.mark.slow  # a large file through the CLI twice
def test_cli_json_of_a_large_file_equals_the_list_path(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``tcpcal solve xyz4 --json`` on 120,000 rows (360,000 residual values: the CLI's
    parallel path) prints the list path's text of the same result, with outliers (a second,
    nested result)."""
    rng = np.random.default_rng(11)
    n = 120_000
    rot = tilted_rotations(rng, n, (20.0, 50.0))
    pos = touch_positions(rot, random_tcp(rng, (100.0, 300.0)), np.array([800.0, 0.0, 300.0]), rng, 0.5)
    pos[rng.choice(n, 5, replace=False)] += [20.0, -15.0, 10.0]
    abc = Rotation.from_matrix(rot).as_euler("ZYX", degrees=True)
    path = tmp_path / "big.csv"
    with open(path, "w", encoding="utf-8") as f:
        f.write("x,y,z,a,b,c\n")
        np.savetxt(f, np.hstack([pos, abc]), fmt="%.4f", delimiter=",")
    assert main(["solve", "xyz4", "--json", str(path)]) == 0
    printed = capsys.readouterr().out
    poses = read_poses_csv(path, min_rows=4)
    from tcpcal.origin import solve_xyz4

    res = solve_xyz4(poses.rotations, poses.positions_mm)
    assert res.outliers and res.without_outliers is not None
    out = dict(tcp_result_to_dict(res))
    out["input"] = {"path": str(poses.path), "layout": poses.layout, "n_rows": len(poses),
                    "line_numbers": list(poses.line_numbers)}
    assert printed == json_dumps(as_lists(out)) + "\n"
    assert len(json.loads(printed)["without_outliers"]["residual_vectors_mm"]) == n - len(res.outliers)
