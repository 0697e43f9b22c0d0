"""Human-readable reports and JSON objects for the ``tcpcal`` command line.

Lengths are millimetres and angles degrees (the CLI's units); the keys of the JSON objects are
a documented contract (docs/cli.md, "JSON output"): change them only together with that page.
Figures that are not defined (e.g. an infinite confidence radius) become JSON ``null``.
"""

from __future__ import annotations

import itertools
import json
import math
import textwrap
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # imported for type hints only; the CLI imports the modules themselves
    from tcpcal.beam import BeamResult
    from tcpcal.orientation import OrientationResult
    from tcpcal.origin import TcpResult
    from tcpcal.poses_csv import FlangePoses
    from tcpcal.tcp_zx import TcpZxResult
    from tcpcal.tool import Tool

__all__ = [
    "CAVEAT",
    "METHOD_TITLES",
    "beam_result_to_dict",
    "format_beam_report",
    "format_orientation_report",
    "format_tcp_report",
    "format_tcp_zx_report",
    "format_tool",
    "format_tool_table",
    "json_dumps",
    "orientation_result_to_dict",
    "tcp_result_to_dict",
    "tcp_zx_result_to_dict",
    "tool_to_dict",
]

#: The standing caveat printed under every TCP report.
CAVEAT = ("Note: a small residual does not prove an accurate TCP. Systematic errors (robot "
          "calibration, a bent or loose tool, the same misjudgement at every touch) hide in it. "
          "Check the TCP by rotating the tool about it: the tip must stay on the reference.")

METHOD_TITLES: dict[str, str] = {
    "lstsq": "XYZ 4-point, joint least squares (4P-3)",
    "sphere": "XYZ 4-point, sphere fit (4P-1a)",
    "pairwise": "XYZ 4-point, pairwise differences (4P-2)",
    "reference": "XYZ reference (REF-1)",
}


def _finite_or_none(x: float | np.floating) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def _jsonable(obj: Any) -> Any:
    """Convert numpy values and non-finite floats (-> ``None``) for strict JSON."""
    if isinstance(obj, Mapping):
        return {str(k): _FloatArray(v) if _FloatArray.takes(v) else _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "biu" or (obj.dtype.kind == "f" and bool(np.isfinite(obj).all())):
            return obj.tolist()  # plain Python numbers already (one call for 1e6 residuals)
        return _jsonable(obj.tolist())
    if isinstance(obj, (list, tuple)):
        plain = _plain_list(obj)
        return plain if plain is not None else [_jsonable(v) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return _finite_or_none(obj)
    return obj


_PLAIN_TYPES = frozenset((int, float, str))


def _plain_list(obj: list[Any] | tuple[Any, ...]) -> list[Any] | None:
    """``obj`` as a list when :func:`_jsonable` would keep every item as it is (only ``int``,
    ``str`` and finite ``float``, or lists/tuples of ``int`` and finite ``float``), else
    ``None``. One pass in C per list: 10^6 line numbers or residual rows in milliseconds."""
    types = set(map(type, obj))
    rows = False
    items: Sequence[Any] = obj
    if not types <= _PLAIN_TYPES:
        if not (types and types <= {list, tuple}):
            return None
        rows = True
        items = list(itertools.chain.from_iterable(obj))
        types = set(map(type, items))
        if not types <= {int, float}:
            return None
    if float in types:
        floats = items if str not in types else [v for v in items if type(v) is float]
        try:
            if not all(map(math.isfinite, floats)):
                return None
        except OverflowError:  # an int beyond the float range: _jsonable keeps it as it is
            return None
    return [list(v) for v in obj] if rows else list(obj)


PARALLEL_MIN_VALUES = 300_000
"""A float array of at least this many values is formatted by :func:`json_dumps` in ``workers``
processes (below it, handing it to another process costs more than it saves)."""


def _format_block(array: np.ndarray, row: str, sep: str) -> str:
    """The rows of a 2-D float array, each ``row % values`` (``row``: ``%r`` per column), joined
    by ``sep``: one ``%`` pass over the flat values. ``%r`` is ``repr``, which is what
    ``json.dumps`` writes for a finite float."""
    return sep.join([row] * array.shape[0]) % tuple(array.ravel().tolist())


class _Formatter:
    """Formats the float arrays of one :func:`json_dumps` call: alone, or with ``workers - 1``
    forked processes. :meth:`start` hands every large array's blocks of rows but the last to
    the pool at once (one pool for the call), so the pool formats while this process writes the
    rest of the text and the last block of each array; :meth:`blocks` collects them in order."""

    def __init__(self, workers: int) -> None:
        self.workers = max(1, int(workers))
        self._pool: Any = None
        self._pending: dict[int, tuple[list[Any], np.ndarray]] = {}  # id(_FloatArray) -> futures, last block

    def start(self, tree: dict[str, Any], level: int = 0) -> None:
        """Submit the large float arrays of the dict ``tree`` (from :func:`_jsonable`) printed at
        ``level`` and of the dicts in it (not of dicts inside lists: those are formatted here)."""
        if self.workers == 1:
            return
        for v in tree.values():
            if isinstance(v, dict):
                self.start(v, level + 1)
            if not isinstance(v, _FloatArray):
                continue
            array, row, sep, _, _ = v.layout(level + 1)
            if array.size < PARALLEL_MIN_VALUES:
                continue
            blocks = [b for b in np.array_split(array, self.workers) if len(b)]
            futures = self._submit(blocks[:-1], row, sep)
            if futures is None:
                return
            self._pending[id(v)] = (futures, blocks[-1])

    def _submit(self, blocks: list[np.ndarray], row: str, sep: str) -> list[Any] | None:
        import warnings
        from concurrent.futures import ProcessPoolExecutor

        try:
            with warnings.catch_warnings():   # Python >= 3.12 warns of fork() next to threads:
                warnings.simplefilter("ignore", DeprecationWarning)  # the children only format
                if self._pool is None:
                    ctx = _fork_context()
                    if ctx is None:
                        self.workers = 1
                        return None
                    self._pool = ProcessPoolExecutor(self.workers - 1, mp_context=ctx)
                return [self._pool.submit(_format_block, b, row, sep) for b in blocks]
        except OSError:                          # no process: this one formats alone
            self.workers = 1
            return None

    def blocks(self, value: _FloatArray, level: int) -> list[str]:
        """The rows of ``value`` at ``level`` as pieces to concatenate (blocks of rows and the
        separator between them): the pool's blocks and the last one formatted here, or all
        formatted here (a small array, or the pool failed)."""
        from concurrent.futures.process import BrokenProcessPool

        array, row, sep, _, _ = value.layout(level)
        pending = self._pending.pop(id(value), None)
        if pending is not None:
            futures, last = pending
            last_text = _format_block(last, row, sep)
            try:
                texts = [f.result() for f in futures] + [last_text]
            except (OSError, BrokenProcessPool):
                pass                           # a child died: this one formats the array
            else:
                return [piece for text in texts for piece in (sep, text)][1:]
        return [_format_block(array, row, sep)]

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)
            self._pool = None


def _fork_context() -> Any:
    """The ``fork`` multiprocessing context, or None where there is none (Windows)."""
    import multiprocessing

    return (multiprocessing.get_context("fork") if "fork" in multiprocessing.get_all_start_methods()
            else None)


class _FloatArray:
    """A dict value that is a finite float array, 1-D or of n >= 1 rows (10^6 residuals and
    residual vectors): :func:`_dump` prints it in one ``%`` format pass over the flat values
    (a row a line for 2-D), without the Python lists ``tolist()`` builds and one JSON encoding
    pass of them; large ones in several processes (:class:`_Formatter`).

    Same bytes as the list path: ``json.dumps`` writes a finite float as its ``repr`` (as ``%r``
    does), a list as ``[a, b, c]``; tests/tcpcal/test_json_fast_path.py compares both.
    """

    __slots__ = ("array",)

    def __init__(self, array: np.ndarray) -> None:
        self.array = array

    @staticmethod
    def takes(obj: Any) -> bool:
        """``obj`` is a float array this class prints (else :func:`_jsonable` converts it)."""
        return (isinstance(obj, np.ndarray) and obj.dtype.kind == "f"
                and (obj.ndim == 1 or (obj.ndim == 2 and obj.shape[0] > 0))
                and bool(np.isfinite(obj).all()))

    def layout(self, level: int) -> tuple[np.ndarray, str, str, str, str]:
        """(the values as rows, a row's ``%`` format, the separator of rows, the text before
        them, the text after them) of the array printed at ``level``; 1-D: one value a row."""
        a = self.array
        if a.ndim == 1:
            return a.reshape(-1, 1), "%r", ", ", "[", "]"
        pad = "  " * (level + 1)
        row = "[" + ", ".join(["%r"] * a.shape[1]) + "]"
        return a, row, ",\n" + pad, "[\n" + pad, "\n" + "  " * level + "]"

    def parts(self, level: int, fmt: _Formatter) -> list[str]:
        """The array's JSON text as pieces to concatenate."""
        _, _, _, head, tail = self.layout(level)
        return [head, *fmt.blocks(self, level), tail]


def _dump_parts(obj: Any, level: int, fmt: _Formatter, parts: list[str]) -> None:
    """Append the JSON text of ``obj`` to ``parts`` in pieces (a dict's values and large float
    arrays are not copied into one string per level: :func:`json_dumps` joins once)."""
    if isinstance(obj, _FloatArray):
        parts += obj.parts(level, fmt)
    elif isinstance(obj, dict) and obj:
        pad = "  " * (level + 1)
        sep = "{\n"
        for k, v in obj.items():
            parts.append(f"{sep}{pad}{json.dumps(k)}: ")
            sep = ",\n"
            _dump_parts(v, level + 1, fmt, parts)
        parts.append("\n" + "  " * level + "}")
    else:
        parts.append(_dump(obj, level, fmt))


def _dump(obj: Any, level: int, fmt: _Formatter) -> str:
    if isinstance(obj, _FloatArray) or (isinstance(obj, dict) and obj):
        parts: list[str] = []
        _dump_parts(obj, level, fmt, parts)
        return "".join(parts)
    if isinstance(obj, list) and obj:
        types = set(map(type, obj))
        if any(issubclass(t, (dict, list)) for t in types):
            pad = "  " * (level + 1)
            if types == {list}:  # rows of numbers, one per line (10^6 residual vectors)
                flat = json.dumps(obj, allow_nan=False)
                if flat.count("[") == len(obj) + 1 and '"' not in flat and "{" not in flat:
                    # no string, dict or deeper list inside: "], [" only separates the rows
                    return ("[\n" + pad + flat[1:-1].replace("], [", "],\n" + pad + "[")
                            + "\n" + "  " * level + "]")
            return ("[\n" + ",\n".join(pad + _dump(v, level + 1, fmt) for v in obj) + "\n"
                    + "  " * level + "]")
    return json.dumps(obj, allow_nan=False)


def json_dumps(obj: Any, *, workers: int = 1) -> str:
    """Strict JSON (no NaN/Infinity tokens): one key per line, number lists on one line.

    Args:
        obj: dicts, lists, numbers, strings, None and numpy arrays/numbers.
        workers: processes that format a large float array (a dict value of at least
            ``PARALLEL_MIN_VALUES`` values, e.g. 10^6 residual vectors) together, this one and
            ``workers - 1`` forked; 1 (default): no process is started. Same text either way.
            For a command-line process only (not a server with threads of its own).
    """
    fmt = _Formatter(workers)
    try:
        tree = _jsonable(obj)
        if isinstance(tree, dict):
            fmt.start(tree)
        parts: list[str] = []
        _dump_parts(tree, 0, fmt, parts)
        return "".join(parts)
    finally:
        fmt.close()


def tcp_result_to_dict(result: TcpResult, *, rows: Sequence[int] | None = None) -> dict[str, Any]:
    """The JSON object of a TCP origin result (``solve xyz4`` and ``solve reference``).

    Args:
        result: the solver result; lengths in mm because the CLI feeds mm.
        rows: 0-based input row index of each touch of ``result`` (identity when ``None``);
            used for the result recomputed without outliers, whose touches are a subset.
    """
    n = int(result.n_touches)
    rows = list(range(n)) if rows is None else list(rows)
    out: dict[str, Any] = {
        "method": result.method,
        "n_touches": n,
        "rows": rows,
        "tcp_mm": np.asarray(result.tcp, dtype=float),
        "reference_mm": np.asarray(result.reference, dtype=float),
        "residuals_mm": np.asarray(result.residuals, dtype=float),
        "residual_vectors_mm": np.asarray(result.residual_vectors, dtype=float),
        "mean_error_mm": result.mean_error,
        "max_error_mm": result.max_error,
        "rms_error_mm": result.rms_error,
        "noise_sigma_mm": result.noise_sigma,
        "ci95_mm": result.ci95_radius,
        "covariance_mm2": np.asarray(result.covariance, dtype=float),
        "max_angle_deg": result.max_angle_deg,
        "max_angle_exact": bool(getattr(result, "max_angle_exact", True)),
        "max_angle_upper_deg": getattr(result, "max_angle_upper_deg", result.max_angle_deg),
        "min_angle_deg": result.min_angle_deg,
        "min_angle_exact": bool(getattr(result, "min_angle_exact", True)),
        "condition_number": result.condition_number,
        "outliers": [rows[i] for i in result.outliers],
        "warnings": list(result.warnings),
    }
    sub = result.without_outliers
    if sub is not None:
        dropped = set(result.outliers)
        kept = [r for i, r in enumerate(rows) if i not in dropped]
        out["without_outliers"] = tcp_result_to_dict(sub, rows=kept)
    else:
        out["without_outliers"] = None
    return out


def orientation_result_to_dict(result: OrientationResult, *,
                               tcp_mm: Sequence[float] | None = None) -> dict[str, Any]:
    """The JSON object of a TOOL-orientation result (``solve three-point`` / ``abc-world``).

    It carries the keys every ``solve`` object has (``tcp_mm``, ``residuals_mm``, the
    error figures, ``ci95_mm``, ``outliers``), so that scripts read all four commands alike:
    ``tcp_mm`` is the TCP the method was given (``None`` for abc-world, which needs none);
    these methods have no touch residuals, so ``residuals_mm`` and ``outliers`` are empty and
    the figures ``None`` (JSON ``null``: not defined).
    """
    return {
        "method": result.method,
        "tcp_mm": None if tcp_mm is None else [float(v) for v in tcp_mm],
        "rotation_matrix": np.asarray(result.rotation, dtype=float),
        "kuka_abc_deg": np.asarray(result.kuka_abc_deg, dtype=float),
        "orthogonality_defect_deg": result.orthogonality_defect_deg,
        "displacements_mm": list(result.displacements),
        "residuals_mm": [],
        "mean_error_mm": None,
        "max_error_mm": None,
        "rms_error_mm": None,
        "ci95_mm": None,
        "outliers": [],
        "warnings": list(result.warnings),
    }


def _xyz(v: Sequence[float] | np.ndarray, fmt: str = "9.3f") -> str:
    x, y, z = (float(c) for c in v)
    return f"X {x:{fmt}}  Y {y:{fmt}}  Z {z:{fmt}}"


def _abc(v: Sequence[float] | np.ndarray, fmt: str = "9.3f") -> str:
    a, b, c = (float(c) for c in v)
    return f"A {a:{fmt}}  B {b:{fmt}}  C {c:{fmt}}"


def _fig(x: float, unit: str = " mm", fmt: str = ".3f") -> str:
    x = float(x)
    return f"{x:{fmt}}{unit}" if math.isfinite(x) else "undefined"


def _warning_lines(warnings: Sequence[str]) -> list[str]:
    """``Warnings:`` and one bullet per warning, or ``Warnings: none`` (every report ends so)."""
    return ["Warnings:", *_bullets(warnings)] if warnings else ["Warnings: none"]


def _bullets(items: Sequence[str]) -> list[str]:
    out: list[str] = []
    for w in items:
        out += textwrap.wrap(str(w), width=92, initial_indent="  - ", subsequent_indent="    ")
    return out


def _largest_angle(result: TcpResult) -> str:
    """``174.4 deg``, or for an estimate (above 512 touches, ``max_angle_exact`` False)
    ``>= 179.9 deg (estimate, at most 180.0)``."""
    if getattr(result, "max_angle_exact", True):
        return _fig(result.max_angle_deg, " deg", ".1f")
    return (f">= {_fig(result.max_angle_deg, ' deg', '.1f')} (estimate, at most "
            f"{_fig(result.max_angle_upper_deg, '', '.1f')})")


def _smallest_angle(result: TcpResult) -> str:
    """``12.3 deg``, or for an estimate (above 512 touches, ``min_angle_exact`` False)
    ``<= 0.4 deg (estimate)``."""
    if getattr(result, "min_angle_exact", True):
        return _fig(result.min_angle_deg, " deg", ".1f")
    return f"<= {_fig(result.min_angle_deg, ' deg', '.1f')} (estimate)"


def _tcp_block(result: TcpResult) -> list[str]:
    return [
        f"TCP in FLANGE (mm):       {_xyz(result.tcp)}",
        f"Reference in WORLD (mm):  {_xyz(result.reference)}",
        (f"Error (mm):               mean {_fig(result.mean_error, '')}   "
         f"max {_fig(result.max_error, '')}   RMS {_fig(result.rms_error, '')}"),
        (f"95 % radius of the TCP:   {_fig(result.ci95_radius)}   "
         f"(estimated touch noise {_fig(result.noise_sigma)} per axis)"),
        (f"Touch orientations:       largest angle {_largest_angle(result)}, "
         f"smallest {_smallest_angle(result)}; "
         f"condition number {_fig(result.condition_number, '', '.1f')}"),
    ]


def _residual_lines(result: TcpResult, poses: FlangePoses | None,
                    outliers: set[int]) -> list[str]:
    """The per-touch rows of :func:`format_tcp_report`: ``row line |e| ex ey ez`` (mm), then
    the row's label and the outlier mark. One ``%`` format per row mapped in C over columns
    built with numpy (10^6 rows in about a second); ``%4d``, ``%4s`` and ``%7.3f`` give the
    same text as the f-string specs ``4d``, ``>4`` and ``7.3f`` (tests/tcpcal/
    test_cli_large_outputs.py compares them with the row-by-row formatting byte for byte)."""
    n = int(result.n_touches)
    e = np.asarray(result.residual_vectors, dtype=float).reshape(n, 3)
    m = min(n, len(poses)) if poses is not None else 0
    line_nos: Sequence[Any] = poses.line_numbers[:m] if poses is not None else ()
    if m < n:
        line_nos = [*line_nos, *[""] * (n - m)]
    suffixes: Sequence[str] | None = None
    if poses is not None and poses.labels is not None:
        k = min(n, len(poses.labels))
        suffixes = [f"  {lab}" if lab else "" for lab in poses.labels[:k]] + [""] * (n - k)
    if outliers:
        suffixes = list(suffixes) if suffixes is not None else [""] * n
        for i in outliers:
            if 0 <= i < n:
                suffixes[i] += "  <- outlier"
    fmt = "  %4d  %4s  %7.3f  %7.3f  %7.3f  %7.3f%s"
    return list(map(fmt.__mod__, zip(
        range(1, n + 1), line_nos, np.asarray(result.residuals, dtype=float).reshape(n).tolist(),
        e[:, 0].tolist(), e[:, 1].tolist(), e[:, 2].tolist(),
        suffixes if suffixes is not None else itertools.repeat("", n))))


def format_tcp_report(result: TcpResult, poses: FlangePoses | None = None, *,
                      command: str = "solve xyz4") -> str:
    """A short plain-text report of a TCP origin result (lengths in mm, angles in deg).

    Lists the TCP (FLANGE) and reference point (WORLD), mean / max / RMS error, 95 % confidence
    radius, estimated noise, tilt angles, condition number, per-touch residuals ``|e_i|`` with
    their components, the outliers and the result without them, warnings and :data:`CAVEAT`.
    """
    n = int(result.n_touches)
    title = METHOD_TITLES.get(result.method, result.method)
    src = f" from {poses.path} (layout {poses.layout})" if poses is not None else ""
    lines = [f"tcpcal {command}: {title}, {n} touch{'es' if n != 1 else ''}{src}", ""]
    lines += _tcp_block(result)
    lines += ["", "Per-touch residuals e_i = R_i t + f_i - r (mm):",
              "   row  line      |e|       ex       ey       ez"]
    outliers = set(result.outliers)
    lines += _residual_lines(result, poses, outliers)
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
    lines += _warning_lines(result.warnings)
    lines += ["", *textwrap.wrap(CAVEAT, width=92)]
    return "\n".join(lines)


def format_orientation_report(result: OrientationResult, poses: FlangePoses | None = None, *,
                              command: str, tcp_mm: Sequence[float] | None = None) -> str:
    """A short plain-text report of a TOOL-orientation result (mm, deg)."""
    src = f" from {poses.path} (layout {poses.layout})" if poses is not None else ""
    r = np.asarray(result.rotation, dtype=float)
    lines = [f"tcpcal {command}: method {result.method}{src}", ""]
    if tcp_mm is not None:
        lines.append(f"TCP in FLANGE (mm, given):     {_xyz(tcp_mm)}")
    lines += [
        f"TOOL orientation, KUKA (deg): {_abc(result.kuka_abc_deg)}",
        "R_flange_tool (columns: tool X, Y, Z in FLANGE):",
        *[f"  [{row[0]:10.6f} {row[1]:10.6f} {row[2]:10.6f}]" for row in r],
        f"Orthogonality defect:         {_fig(result.orthogonality_defect_deg, ' deg', '.3f')}",
    ]
    if len(result.displacements):
        lines.append("Displacements used:           "
                     + ", ".join(f"{float(d):.1f} mm" for d in result.displacements)
                     + "  (longer gives a smaller angular error)")
    lines += _warning_lines(result.warnings)
    return "\n".join(lines)


def tool_to_dict(tool: Tool, *, slot: int | None = None, active: bool = False) -> dict[str, Any]:
    """JSON object of a stored tool (``tcpcal tools list/show --json``)."""
    d: dict[str, Any] = {"slot": slot, "active": active}
    d.update(tool.to_dict())
    d["rotation_matrix"] = np.asarray(tool.rotation, dtype=float)
    return d


def format_tool(tool: Tool, *, slot: int | None = None, active: bool = False) -> str:
    """Several lines describing one tool (``tcpcal tools show``)."""
    head = f"Slot {slot}: " if slot is not None else ""
    lines = [f"{head}{tool.name}{'  (active)' if active else ''}",
             f"  TCP in FLANGE (mm):     {_xyz(tool.tcp_mm)}",
             f"  Orientation KUKA (deg): {_abc(tool.abc_deg)}"]
    if tool.mass_kg is not None:
        lines.append(f"  Mass: {tool.mass_kg:g} kg")
    if tool.cog_mm is not None:
        lines.append(f"  Centre of gravity in FLANGE (mm): {_xyz(tool.cog_mm)}")
    if tool.load_abc_deg is not None:
        lines.append(f"  Load inertia axes KUKA (deg): {_abc(tool.load_abc_deg)}")
    if tool.inertia_kgm2 is not None:
        lines.append("  Moments of inertia (kg m^2): "
                     + ", ".join(f"{v:g}" for v in tool.inertia_kgm2))
    if tool.notes:
        lines.append(f"  Notes: {tool.notes}")
    cal = tool.calibration
    if cal is not None:
        lines.append(f"  Calibrated: {cal.method} at {cal.calibrated_at}")
        for k, v in cal.figures.items():
            lines.append(f"    {k}: {v:g}" if isinstance(v, (int, float)) else f"    {k}: {v}")
    else:
        lines.append("  Calibrated: no record")
    return "\n".join(lines)


def format_tool_table(tools: Mapping[int, Tool], active_slot: int | None) -> str:
    """The tool table (``tcpcal tools list``): one line per used slot, ``*`` marks the active."""
    if not tools:
        return "No tools stored."
    lines = [("  slot  name                        X mm       Y mm       Z mm      A deg     "
              "B deg     C deg  calibration")]
    for slot in sorted(tools):
        t = tools[slot]
        mark = "*" if slot == active_slot else " "
        cal = t.calibration.method if t.calibration is not None else "-"
        x, y, z = t.tcp_mm
        a, b, c = t.abc_deg
        lines.append(f"{mark} {slot:4d}  {t.name[:24]:24s} {x:10.3f} {y:10.3f} {z:10.3f} "
                     f"{a:9.3f} {b:9.3f} {c:9.3f}  {cal}")
    if active_slot is None:
        lines.append("No active tool (TCP = flange).")
    return "\n".join(lines)


def tcp_zx_result_to_dict(result: TcpZxResult) -> dict[str, Any]:
    """The JSON object of ``solve tcp-zx`` (ABB TCP & Z, X; mm, deg).

    The keys of ``solve xyz4`` for the touch rows (their ``rows``, ``outliers`` and
    ``without_outliers`` are 0-based input rows), ``method`` = ``"tcp-zx"``, plus the keys of
    the orientation methods (``rotation_matrix`` = ``R_flange_tool``, ``kuka_abc_deg``,
    ``orthogonality_defect_deg``, ``displacements_mm`` = the z then the x distances) and
    ``z_rows``, ``x_rows``, ``z_distances_mm``, ``x_distances_mm``.
    """
    out = tcp_result_to_dict(result.origin, rows=result.touch_rows)
    out["method"] = "tcp-zx"
    out["rotation_matrix"] = np.asarray(result.rotation, dtype=float)
    out["kuka_abc_deg"] = np.asarray(result.kuka_abc_deg, dtype=float)
    out["orthogonality_defect_deg"] = result.orthogonality_defect_deg
    out["displacements_mm"] = [*result.z_distances, *result.x_distances]
    out["z_rows"] = list(result.z_rows)
    out["x_rows"] = list(result.x_rows)
    out["z_distances_mm"] = list(result.z_distances)
    out["x_distances_mm"] = list(result.x_distances)
    out["warnings"] = list(result.warnings)
    return out


def format_tcp_zx_report(result: TcpZxResult, poses: FlangePoses | None = None, *,
                         command: str = "solve tcp-zx") -> str:
    """Plain-text report of ABB TCP & Z, X: the 4-point block of the touch rows, the TOOL frame
    (KUKA A, B, C and ``R_flange_tool``), the axis distances, residuals, warnings (mm, deg)."""
    o = result.origin
    n = int(o.n_touches)
    src = f" from {poses.path} (layout {poses.layout})" if poses is not None else ""
    r = np.asarray(result.rotation, dtype=float)

    def line_of(row: int) -> str:
        return str(poses.line_numbers[row]) if poses is not None and row < len(poses) else ""

    def label_of(row: int) -> str:
        if poses is not None and poses.labels is not None and row < len(poses.labels):
            return f"  {poses.labels[row]}" if poses.labels[row] else ""
        return ""

    lines = [f"tcpcal {command}: ABB TCP & Z, X (methods.md section 8), {n} touches, "
             f"{len(result.z_rows)} z row(s), {len(result.x_rows)} x row(s){src}", ""]
    lines += _tcp_block(o)
    lines += [
        f"TOOL orientation, KUKA (deg): {_abc(result.kuka_abc_deg)}",
        "R_flange_tool (columns: tool X, Y, Z in FLANGE):",
        *[f"  [{row[0]:10.6f} {row[1]:10.6f} {row[2]:10.6f}]" for row in r],
        f"Orthogonality defect:         {_fig(result.orthogonality_defect_deg, ' deg', '.3f')}"
        "  (X corrected, Z kept)",
        "", "Axis rows (the reference ahead of the TCP on the tool axis):",
        "   row  line  axis    d mm",
    ]
    for axis, rows, ds in (("z", result.z_rows, result.z_distances),
                           ("x", result.x_rows, result.x_distances)):
        for row, d in zip(rows, ds):
            lines.append(f"  {row + 1:4d}  {line_of(row):>4}  {axis:>4}  {d:7.1f}{label_of(row)}")
    lines += ["", "Per-touch residuals e_i = R_i t + f_i - r (mm):",
              "   row  line      |e|       ex       ey       ez"]
    outliers = set(o.outliers)
    for i, row in enumerate(result.touch_rows):
        e = np.asarray(o.residual_vectors[i], dtype=float)
        mark = "  <- outlier" if i in outliers else ""
        lines.append(f"  {row + 1:4d}  {line_of(row):>4}  {float(o.residuals[i]):7.3f}  "
                     f"{e[0]:7.3f}  {e[1]:7.3f}  {e[2]:7.3f}{label_of(row)}{mark}")
    lines.append("")
    if outliers:
        rows_txt = ", ".join(str(result.touch_rows[i] + 1) for i in sorted(outliers))
        lines.append(f"Outliers: data row {rows_txt} stand(s) out; the TCP above uses every "
                     "touch (--json: without_outliers).")
    else:
        lines.append("Outliers: none")
    lines += _warning_lines(result.warnings)
    lines += ["", *textwrap.wrap(CAVEAT, width=92)]
    return "\n".join(lines)


def _unit3(v: Sequence[float]) -> list[float]:
    a = np.asarray(v, dtype=float)
    unit: list[float] = (a / float(np.linalg.norm(a))).tolist()
    return unit


def beam_result_to_dict(result: BeamResult, *, beam_point_mm: Sequence[float],
                        beam_dir: Sequence[float]) -> dict[str, Any]:
    """The JSON object of ``solve beam`` (beam-sensor tip events, methods.md section 9; mm).

    The keys of ``solve xyz4`` that apply (``method`` = ``"beam"``, ``n_touches`` = the number
    of events, ``rows``, ``tcp_mm``, ``residuals_mm`` = each computed tip's distance from the
    beam line, ``residual_vectors_mm``, the error figures, ``noise_sigma_mm``, ``ci95_mm``,
    ``covariance_mm2``, ``condition_number``, ``outliers`` (always empty: no outlier test),
    ``warnings``), plus ``n_events``, ``beam_point_mm``, ``beam_dir`` (unit, WORLD),
    ``beam_positions_mm`` (where along the beam each tip crossed it, from ``beam_point_mm``)
    and ``weakest_axis`` (FLANGE direction of the largest TCP uncertainty).
    """
    n = int(result.n_events)
    return {
        "method": "beam",
        "n_touches": n,
        "n_events": n,
        "rows": list(range(n)),
        "tcp_mm": np.asarray(result.tcp, dtype=float),
        "beam_point_mm": [float(v) for v in beam_point_mm],
        "beam_dir": _unit3(beam_dir),
        "residuals_mm": np.asarray(result.residuals, dtype=float),
        "residual_vectors_mm": np.asarray(result.residual_vectors, dtype=float),
        "beam_positions_mm": np.asarray(result.beam_positions, dtype=float),
        "mean_error_mm": result.mean_error,
        "max_error_mm": result.max_error,
        "rms_error_mm": result.rms_error,
        "noise_sigma_mm": result.noise_sigma,
        "ci95_mm": result.ci95_radius,
        "covariance_mm2": np.asarray(result.covariance, dtype=float),
        "condition_number": result.condition_number,
        "weakest_axis": np.asarray(result.weakest_axis, dtype=float),
        "outliers": [],
        "warnings": list(result.warnings),
    }


def format_beam_report(result: BeamResult, poses: FlangePoses | None = None, *,
                       beam_point_mm: Sequence[float], beam_dir: Sequence[float],
                       command: str = "solve beam") -> str:
    """Plain-text report of ``solve beam``: the beam, the TCP, error figures, the 95 % radius,
    each event's distance from the beam line, warnings and :data:`CAVEAT` (mm)."""
    n = int(result.n_events)
    src = f" from {poses.path} (layout {poses.layout})" if poses is not None else ""
    u = _unit3(beam_dir)
    lines = [f"tcpcal {command}: beam sensor (methods.md section 9), {n} tip events{src}", "",
             f"Beam in WORLD (mm):       point {_xyz(beam_point_mm)}",
             f"                          direction {_xyz(u, '8.5f')}",
             f"TCP in FLANGE (mm):       {_xyz(result.tcp)}",
             (f"Tip to beam line (mm):    mean {_fig(result.mean_error, '')}   "
              f"max {_fig(result.max_error, '')}   RMS {_fig(result.rms_error, '')}"),
             (f"95 % radius of the TCP:   {_fig(result.ci95_radius)}   (event noise "
              f"{_fig(result.noise_sigma)} per axis across the beam)"),
             (f"Weakest flange direction: {_xyz(result.weakest_axis, '7.3f')}; condition number "
              f"{_fig(result.condition_number, '', '.1f')}"),
             "", "Per-event distance of the tip from the beam line e_i = P (R_i t + f_i - b) (mm):",
             "   row  line      |e|       ex       ey       ez   along beam"]
    for i in range(n):
        line_no = poses.line_numbers[i] if poses is not None and i < len(poses) else ""
        e = np.asarray(result.residual_vectors[i], dtype=float)
        label = ""
        if poses is not None and poses.labels is not None and i < len(poses.labels):
            label = f"  {poses.labels[i]}" if poses.labels[i] else ""
        lines.append(f"  {i + 1:4d}  {line_no:>4}  {float(result.residuals[i]):7.3f}  "
                     f"{e[0]:7.3f}  {e[1]:7.3f}  {e[2]:7.3f}  "
                     f"{float(result.beam_positions[i]):11.3f}{label}")
    lines += ["", "Outliers: not tested for beam events"]
    lines += _warning_lines(result.warnings)
    lines += ["", *textwrap.wrap(CAVEAT, width=92)]
    return "\n".join(lines)
