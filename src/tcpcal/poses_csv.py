"""Read recorded flange poses from a CSV file (the input of ``tcpcal solve``).

One flange pose ``T_world_flange`` per row; a header row names the columns. Position columns
``x, y, z`` are in millimetres (tcpcal itself is unit-agnostic, the CLI speaks mm). The
orientation is given by exactly one of these column sets (the *layout*):

===========  ==========================  ==================================================
layout       columns                     meaning
===========  ==========================  ==================================================
``kuka``     ``a, b, c``                 KUKA A, B, C in degrees: ``R = Rz(A) Ry(B) Rx(C)``
``fanuc``    ``w, p, r``                 FANUC W, P, R in degrees: ``R = Rz(R) Ry(P) Rx(W)``
``abb``      ``qw, qx, qy, qz``          unit quaternion, scalar first (ABB ``q1..q4``)
``rotvec``   ``rx, ry, rz``              rotation vector (axis times angle), radians
``matrix``   ``r11, r12, ..., r33``      rotation matrix ``R_world_flange``, row-major
===========  ==========================  ==================================================

(methods.md section 6 and docs/architecture.md "Conventions"; every conversion goes through
``scipy.spatial.transform.Rotation``.) The table is not kept here: each format module of
:mod:`tcpcal.controllers` declares its layout (``ControllerFormat.csv``: columns, units, the
conversion), and :data:`LAYOUTS` and :func:`accepted_layouts_text` read the registry.

Leniency, all documented in docs/cli.md: header names are case-insensitive and may carry
surrounding whitespace; blank lines and lines starting with ``#`` are skipped; the delimiter is
a comma, or a semicolon or tab when the header contains no comma; any other column whose name
is not one of the pose columns above (``name``, ``label``, ``time``, ...) is ignored. A header
that mixes two orientation layouts, lacks one of a layout's columns, or repeats a column is an
error.

Strictness: every pose cell must be a finite number. A quaternion whose norm differs from 1 by
more than 1e-6 and a matrix with ``max |R^T R - I| > 1e-6`` or ``det R < 0`` are errors (they
are not silently normalised: they usually mean a column mix-up or too few printed digits).

Every error is a :class:`tcpcal.errors.InvalidInputError` whose message starts with the file
name and, for an error in one row, ``line L (data row k)``: ``L`` is the 1-based line number in
the file (as an editor shows it), ``k`` the 1-based number of the pose among the data rows.
Such errors also carry ``.index`` = ``k - 1`` (the 0-based touch index of the architecture's
error convention).
"""

from __future__ import annotations

import csv
import itertools
import math
import sys
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tcpcal.controllers import csv_layouts
from tcpcal.errors import InvalidInputError
from tcpcal.validation import ORTHONORMAL_TOL

__all__ = [
    "LAYOUTS",
    "ORTHONORMAL_TOL",
    "FlangePoses",
    "accepted_layouts_text",
    "read_poses_csv",
]

# ORTHONORMAL_TOL (1e-6, dimensionless) bounds ``| |q| - 1 |`` and ``max |R^T R - I|``; it is
# the solvers' own tolerance (tcpcal.validation), so a file accepted here passes them.

POSITION_COLUMNS: tuple[str, ...] = ("x", "y", "z")


class _Layouts(Mapping[str, tuple[str, ...]]):
    """Orientation layouts: name -> column names, in the order the converter expects them.

    A live view of the ``csv`` layouts the formats of :data:`tcpcal.controllers.REGISTRY`
    declare (``ControllerFormat.csv``), in the accepted-headers order."""

    def __getitem__(self, name: str) -> tuple[str, ...]:
        return csv_layouts()[name].columns

    def __iter__(self) -> Iterator[str]:
        return iter(csv_layouts())

    def __len__(self) -> int:
        return len(csv_layouts())

    def __repr__(self) -> str:
        return repr(dict(self))


LAYOUTS: Mapping[str, tuple[str, ...]] = _Layouts()


def accepted_layouts_text() -> str:
    """One line listing the accepted header layouts (used in error messages and ``--help``)."""
    parts = [f"{','.join(POSITION_COLUMNS)},{lay.header_text or ','.join(lay.columns)} "
             f"({lay.units})" for lay in csv_layouts().values()]
    return "accepted headers: " + "; ".join(parts)


@dataclass(frozen=True)
class FlangePoses:
    """Flange poses read from a CSV file.

    Attributes:
        rotations: (N, 3, 3) ``R_world_flange``, proper rotations (converted with scipy).
        positions_mm: (N, 3) ``p_world_flange`` in millimetres.
        layout: orientation layout of the file: ``"kuka"``, ``"fanuc"``, ``"abb"``, ``"rotvec"``
            or ``"matrix"``.
        line_numbers: 1-based file line number of each pose (for messages).
        path: the file that was read.
        labels: the ``name`` or ``label`` column of each row if the file has one, else ``None``.
        roles: the ``role`` column of each row (stripped, lower case; e.g. ``touch``, ``z``,
            ``x`` for ``tcpcal solve tcp-zx``) if the file has one, else ``None``. Other
            commands ignore it.
        joints_deg: the joint values ``j1, j2, ...`` of each row (deg; linear axes in mm) if
            the file has ``j1`` (then ``j1..jK``, consecutive), else ``None``; never used by a
            solve, kept for the JSON output.
    """

    rotations: np.ndarray
    positions_mm: np.ndarray
    layout: str
    line_numbers: tuple[int, ...]
    path: Path
    labels: tuple[str, ...] | None = None
    roles: tuple[str, ...] | None = None
    joints_deg: tuple[tuple[float, ...], ...] | None = None

    def __post_init__(self) -> None:
        for arr in (self.rotations, self.positions_mm):
            arr.flags.writeable = False

    def __len__(self) -> int:
        return int(self.positions_mm.shape[0])

    @property
    def n_rows(self) -> int:
        """Number of poses (data rows)."""
        return len(self)

    def where(self, index: int) -> str:
        """``"<file>, line L (data row k)"`` for the 0-based pose ``index``."""
        return f"{self.path}, line {self.line_numbers[index]} (data row {index + 1})"


def _error(msg: str, *, index: int | None = None) -> InvalidInputError:
    return InvalidInputError(msg, index=index)


def _detect_delimiter(header_line: str) -> str:
    if "," in header_line:
        return ","
    if ";" in header_line:
        return ";"
    if "\t" in header_line:
        return "\t"
    return ","


def _choose_layout(path: Path, line_no: int, names: Sequence[str]) -> str:
    """Return the single orientation layout named by the header ``names``."""
    where = f"{path}, line {line_no} (header)"
    layouts = {name: lay.columns for name, lay in csv_layouts().items()}
    pose_columns = frozenset(POSITION_COLUMNS).union(*layouts.values())
    seen: set[str] = set()
    for name in names:
        if name and name in seen and name in pose_columns:
            raise _error(f"{where}: column '{name}' appears twice")
        seen.add(name)
    missing_pos = [c for c in POSITION_COLUMNS if c not in seen]
    complete = [lay for lay, cols in layouts.items() if all(c in seen for c in cols)]
    partial = {lay: [c for c in cols if c not in seen]
               for lay, cols in layouts.items()
               if any(c in seen for c in cols) and lay not in complete}
    if missing_pos:
        raise _error(f"{where}: missing position column(s) {','.join(missing_pos)} (mm); "
                     f"{accepted_layouts_text()}")
    if len(complete) > 1:
        raise _error(f"{where}: the header mixes orientation layouts {' and '.join(complete)}; "
                     f"keep the columns of one; {accepted_layouts_text()}")
    if partial:
        lay, miss = next(iter(partial.items()))
        if complete:
            raise _error(f"{where}: the header mixes orientation layout {complete[0]} with "
                         f"column(s) of {lay}; keep the columns of one; {accepted_layouts_text()}")
        raise _error(f"{where}: orientation layout {lay} lacks column(s) {','.join(miss)}; "
                     f"{accepted_layouts_text()}")
    if not complete:
        raise _error(f"{where}: no orientation columns recognised in header "
                     f"{','.join(n for n in names)!r}; {accepted_layouts_text()}")
    return complete[0]


def _rotations_from_values(layout: str, v: np.ndarray, where: Callable[[int], str]) -> np.ndarray:
    """Convert the orientation numbers of every row (N, k) to ``R_world_flange`` (N, 3, 3)
    with the layout's own conversion (``CsvLayout.to_rotations``, scipy), in one call per file;
    the first row that is not a rotation raises the error naming it (``where(i)`` = file, line
    and data row of row i)."""
    lay = csv_layouts()[layout]
    rot = lay.to_rotations(v, where)
    n = v.shape[0]
    bad = ~np.isfinite(rot.reshape(n, 9)).all(axis=1)
    if bad.any():  # e.g. a rotation vector of length 1e308 (its norm overflows)
        i = int(np.argmax(bad))
        cols = ",".join(lay.columns)
        raise _error(f"{where(i)}: {cols} = {', '.join(f'{x:g}' for x in v[i])} give no finite "
                     f"rotation (numbers too large); check the unit ({lay.units})",
                     index=i)
    return rot


MAX_ABS_MM: float = 1e6
"""Largest accepted ``|x|``, ``|y|``, ``|z|`` in POSES.csv, mm (1 km: beyond any robot cell;
documented in docs/cli.md)."""

STDIN_NAME = "<stdin>"
"""How messages and the JSON ``input.path`` name POSES.csv when it is read from stdin (``-``)."""


def _read_text(path: Path) -> tuple[str, Path]:
    """The text of ``path`` (``-``: all of stdin) and the name to use in messages."""
    if str(path) == "-":
        data = sys.stdin.buffer.read() if hasattr(sys.stdin, "buffer") else sys.stdin.read()
        shown = Path(STDIN_NAME)
        if isinstance(data, str):
            return data.removeprefix("\ufeff"), shown
    else:
        data, shown = path.read_bytes(), path
    try:
        return data.decode("utf-8-sig"), shown
    except UnicodeDecodeError as exc:
        raise _error(f"{shown}: not a UTF-8 text file ({exc.reason} at byte {exc.start}); "
                     f"save the CSV as UTF-8") from None


def _row_values_slow(path: Path, names: list[str], pose_cols: tuple[str, ...],
                     col_index: list[int], rows: list[tuple[int, list[str]]]) -> np.ndarray:
    """The pose numbers of every row, cell by cell: the first bad cell raises its error
    (file, line, data row, column). Used when the one-call conversion found a problem."""
    values = np.empty((len(rows), len(pose_cols)))
    for index, (line_no, cells) in enumerate(rows):
        where = f"{path}, line {line_no} (data row {index + 1})"
        if len(cells) > len(names) and not any(c.strip() for c in cells[len(names):]):
            cells = cells[: len(names)]  # trailing empty cells (spreadsheet export)
        if len(cells) != len(names):
            raise _error(f"{where}: {len(cells)} cells but the header has {len(names)} columns",
                         index=index)
        for k, (col, j) in enumerate(zip(pose_cols, col_index)):
            cell = cells[j].strip()
            if not cell:
                raise _error(f"{where}: column '{col}' is empty", index=index)
            try:
                val = float(cell)
            except ValueError:
                raise _error(f"{where}: column '{col}' is not a number: {cell!r}",
                             index=index) from None
            if not math.isfinite(val):
                raise _error(f"{where}: column '{col}' is {cell!r}, not a finite number",
                             index=index)
            values[index, k] = val
    return values


def _row_values(path: Path, names: list[str], pose_cols: tuple[str, ...], col_index: list[int],
                rows: list[tuple[int, list[str]]]) -> np.ndarray:
    """(N, k) pose numbers of the data rows: one numpy conversion for a clean file (10^6 rows
    in about a second), the cell-by-cell check only to name a problem."""
    width = len(names)
    if all(len(cells) == width for _, cells in rows):
        try:
            values = np.array([[cells[j] for j in col_index] for _, cells in rows],
                              dtype=np.str_).astype(float).reshape(len(rows), len(pose_cols))
        except ValueError:
            values = None
        if values is not None and np.isfinite(values).all():
            return values
    return _row_values_slow(path, names, pose_cols, col_index, rows)


def read_poses_csv(path: str | Path, *, min_rows: int = 1, max_rows: int | None = None,
                   purpose: str = "") -> FlangePoses:
    """Read flange poses ``T_world_flange`` (positions in mm) from a CSV file.

    Args:
        path: the CSV file (header row + one pose per row; see the module docstring), or
            ``-`` for stdin (named ``<stdin>`` in messages and in ``FlangePoses.path``).
        min_rows: fewer data rows than this is an error.
        max_rows: more data rows than this is an error (``None``: no limit).
        purpose: what the rows are for, quoted in the row-count message (e.g. ``"xyz4"``).

    Returns:
        The poses, their layout and the line number of each row.

    Raises:
        InvalidInputError: unknown or ambiguous header, a cell that is not a finite number, a
            row with the wrong number of cells, a quaternion or matrix that is not orthonormal
            within 1e-6, a position beyond +-``MAX_ABS_MM`` (1e6 mm), orientation numbers that
            give no finite rotation, or too few / too many rows. The message names the file and the line.
        OSError: the file cannot be opened or read. ``UnicodeDecodeError`` (a ``ValueError``)
            is turned into an ``InvalidInputError``.
    """
    text, path = _read_text(Path(path))
    body = _parse_body(text, path)
    del text
    layout, values, line_numbers = body.layout, body.values, body.line_numbers

    def where(i: int) -> str:
        return f"{path}, line {line_numbers[i]} (data row {i + 1})"

    big = np.abs(values[:, :3]) > MAX_ABS_MM
    if big.any():
        i, k = divmod(int(np.argmax(big.ravel())), 3)
        raise _error(f"{where(i)}: column '{POSITION_COLUMNS[k]}' is {values[i, k]:g} mm, beyond "
                     f"+-{MAX_ABS_MM:g} mm (coordinates beyond +-{MAX_ABS_MM:g} mm are not a robot "
                     "cell); check the unit (mm) and the column order", index=i)

    rotations = (_rotations_from_values(layout, values[:, 3:], where) if len(values)
                 else np.zeros((0, 3, 3)))
    positions = values[:, :3]

    n = len(positions)
    what = f" for {purpose}" if purpose else ""
    if n < min_rows:
        need = f"exactly {min_rows}" if max_rows == min_rows else f"at least {min_rows}"
        raise _error(f"{path}: too few rows: {n} data row(s), {need} needed{what} "
                     f"(one flange pose per row after the header)")
    if max_rows is not None and n > max_rows:
        need = f"exactly {max_rows}" if max_rows == min_rows else f"at most {max_rows}"
        raise _error(f"{path}: too many rows: {n} data rows, {need} expected{what}")

    return FlangePoses(
        rotations=np.ascontiguousarray(rotations, dtype=float).reshape(n, 3, 3),
        positions_mm=np.ascontiguousarray(positions, dtype=float).reshape(n, 3),
        layout=layout,
        line_numbers=tuple(line_numbers),
        path=path,
        labels=body.labels,
        roles=body.roles,
        joints_deg=body.joints,
    )


@dataclass(frozen=True)
class _Body:
    """What the data rows of a file hold (internal; see :class:`FlangePoses`)."""

    layout: str
    values: np.ndarray  # (N, 3 + k) x, y, z (mm) then the layout's orientation columns
    line_numbers: Sequence[int]
    labels: tuple[str, ...] | None
    roles: tuple[str, ...] | None
    joints: tuple[tuple[float, ...], ...] | None


def _content_lines(text: str, lines: list[str]) -> tuple[list[str], Sequence[int]]:
    """The lines that are neither blank nor ``#`` comments, and their 1-based line numbers."""
    if "#" not in text and "" not in lines and not any(map(str.isspace, lines)):
        return lines, range(1, len(lines) + 1)  # the usual file: every line is content
    keep = [i for i, ln in enumerate(lines) if (s := ln.strip()) and s[0] != "#"]
    return [lines[i] for i in keep], [i + 1 for i in keep]


def _parse_body(text: str, path: Path) -> _Body:
    """Header, layout and every data row of the file's ``text`` (errors name file and line).

    A file without quotes or NUL characters is split at its delimiter and converted a block of
    rows at a time (:func:`_fast_rows`; 10^6 rows in about a second); any other file, or a row
    that fast path does not take, goes through :mod:`csv` and the cell-by-cell checks, which
    raise the error naming the first problem.
    """
    lines = text.splitlines()
    content, line_nos = _content_lines(text, lines)
    del lines
    if not content:
        raise _error(f"{path}: the file is empty (no header row); {accepted_layouts_text()}")
    header_no = line_nos[0]
    delim = _detect_delimiter(content[0])
    if '"' not in text and "\0" not in text:
        # no quoting: csv.reader splits each line at every delimiter, nothing else, and cannot
        # fail; so the header splits alike and its errors come first, as they do below
        names = [h.strip().lower() for h in content[0].split(delim)]
        layout = _choose_layout(path, header_no, names)
        fast = _fast_rows(content, delim, names, layout)
        if fast is not None:
            values, labels, roles, joints = fast
            return _Body(layout, values, line_nos[1:], labels, roles, joints)
    return _csv_body(path, content, line_nos, delim)


_FAST_CHUNK = 65_536  # rows converted per block by _fast_rows (bounds the transient memory)


def _fast_rows(content: list[str], delim: str, names: list[str], layout: str) -> tuple[
        np.ndarray, tuple[str, ...] | None, tuple[str, ...] | None,
        tuple[tuple[float, ...], ...] | None] | None:
    """Values, labels, roles and joints of the data rows ``content[1:]`` when every row has the
    header's number of cells and every pose and joint cell is a finite number; ``None``
    otherwise (the slow path then names the problem).

    The numbers are converted a block of rows at a time by :func:`numpy.loadtxt` (its C
    parser; Python's own ``float`` parsing without underscores, so a cell it takes is a cell
    :func:`_row_values_slow` and :func:`_joint_values` take, with the same value; a cell it
    refuses, e.g. ``1_000``, sends the file to the slow path, which decides)."""
    width = len(names)
    data = content[1:]
    n = len(data)
    pose_cols = POSITION_COLUMNS + csv_layouts()[layout].columns
    num_index = [names.index(c) for c in pose_cols] + [j for _, j in _joint_columns(names)]
    label_col = next((names.index(c) for c in ("name", "label") if c in names), None)
    role_col = names.index("role") if "role" in names else None
    numbers = np.empty((n, len(num_index)))
    labels: list[str] = []
    roles: list[str] = []
    for start in range(0, n, _FAST_CHUNK):
        block = data[start:start + _FAST_CHUNK]
        m = len(block)
        if set(map(str.count, block, itertools.repeat(delim, m))) != {width - 1}:
            return None  # a row with another number of cells (or trailing empty cells)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                numbers[start:start + m] = np.loadtxt(
                    block, dtype=float, delimiter=delim, comments=None, usecols=num_index,
                    ndmin=2, encoding=None)
        except (ValueError, Warning):
            return None
        if label_col is not None or role_col is not None:
            cells = delim.join(block).split(delim)  # m * width cells, row by row
            if label_col is not None:
                labels += map(str.strip, cells[label_col::width])
            if role_col is not None:
                roles += map(str.lower, map(str.strip, cells[role_col::width]))
    if not np.isfinite(numbers).all():
        return None
    k = len(pose_cols)
    return (numbers[:, :k],
            tuple(labels) if label_col is not None else None,
            tuple(roles) if role_col is not None else None,
            tuple(map(tuple, numbers[:, k:].tolist())) if len(num_index) > k else None)


def _csv_body(path: Path, content: list[str], line_nos: Sequence[int], delim: str) -> _Body:
    """The rows through :mod:`csv` (quoted cells) and the cell-by-cell checks."""
    try:
        parsed = list(csv.reader(content, delimiter=delim, strict=True))
    except csv.Error as exc:
        raise _error(f"{path}: CSV syntax error: {exc}") from None
    names = [h.strip().lower() for h in parsed[0]]
    layout = _choose_layout(path, line_nos[0], names)
    pose_cols = POSITION_COLUMNS + csv_layouts()[layout].columns
    col_index = [names.index(c) for c in pose_cols]
    label_col = next((names.index(c) for c in ("name", "label") if c in names), None)
    role_col = names.index("role") if "role" in names else None
    joint_cols = _joint_columns(names)

    rows = list(zip(line_nos[1:], parsed[1:]))
    del parsed
    values = _row_values(path, names, pose_cols, col_index, rows)

    def where(i: int) -> str:
        return f"{path}, line {rows[i][0]} (data row {i + 1})"

    labels = (tuple(cells[label_col].strip() for _, cells in rows) if label_col is not None
              else None)
    roles = (tuple(cells[role_col].strip().lower() for _, cells in rows)
             if role_col is not None else None)
    joints = (tuple(_joint_values(cells, joint_cols, where(i), i)
                    for i, (_, cells) in enumerate(rows)) if joint_cols else None)
    return _Body(layout, values, [line_no for line_no, _ in rows], labels, roles, joints)


def _joint_columns(names: Sequence[str]) -> list[tuple[str, int]]:
    """``(name, index)`` of the joint columns ``j1, j2, ...`` (consecutive from ``j1``)."""
    cols: list[tuple[str, int]] = []
    while f"j{len(cols) + 1}" in names:
        name = f"j{len(cols) + 1}"
        cols.append((name, names.index(name)))
    return cols


def _joint_values(cells: Sequence[str], cols: Sequence[tuple[str, int]], where: str,
                  index: int) -> tuple[float, ...]:
    """The finite numbers of one row's joint columns (an error names the column)."""
    out: list[float] = []
    for name, j in cols:
        cell = cells[j].strip()
        try:
            val = float(cell)
        except ValueError:
            raise _error(f"{where}: joint column '{name}' is not a number: {cell!r} (joint "
                         f"values are optional: leave the j columns out or fill every row)",
                         index=index) from None
        if not math.isfinite(val):
            raise _error(f"{where}: joint column '{name}' is {cell!r}, not a finite number",
                         index=index)
        out.append(val)
    return tuple(out)
