"""What a controller format declares about itself (docs/architecture.md "Controller formats").

A format module of :mod:`tcpcal.controllers` (``kuka.py``, ``abb.py``, ...) ends with
``FORMAT = ControllerFormat(...)``; :mod:`tcpcal.controllers` collects every such module into
:data:`tcpcal.controllers.REGISTRY`, and everything that lists or dispatches on formats reads
that registry: ``tcpcal.formats.export_tool/import_tool``, the CLI's ``--format``/``--from``/
``--to`` choices and value counts, the POSES.csv layouts of :mod:`tcpcal.poses_csv`, whole
controller files, pose import and the app's export menu. Adding a format touches one module
(and its tests).

Also here: the number and text helpers the tool-text parsers share (``repr`` numbers,
:class:`tcpcal.errors.InvalidInputError` messages that name the format).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from tcpcal.errors import InvalidInputError, TcpcalError
from tcpcal.tool import Tool, abc_deg_from_rotation

__all__ = ["ControllerFormat", "CsvLayout", "TEXT_NUM", "TEXT_NUM_RE", "check_slot",
           "make_tool", "text_float", "text_number", "tool_from_rotation"]


@dataclass(frozen=True)
class CsvLayout:
    """The orientation columns of POSES.csv a format's poses are read and written in.

    Attributes:
        name: the layout's name (``FlangePoses.layout``, JSON ``input.layout``).
        columns: the orientation columns after ``x, y, z``, in the order ``to_rotations`` takes
            them (lower case).
        units: the columns' meaning and unit, in words (error messages, ``solve --help``).
        to_rotations: ``(values (N, k), where) -> R_world_flange (N, 3, 3)``; raises
            :class:`~tcpcal.errors.InvalidInputError` (``index=`` the row) naming ``where(i)``
            for a row that is no rotation. A row that gives a non-finite rotation is reported
            by :mod:`tcpcal.poses_csv` itself.
        decimals: decimals of the orientation numbers ``tcpcal poses import`` writes.
        rank: place of the layout in the accepted-headers list (lower first).
        header_text: how the accepted-headers list writes the columns (default: joined by
            commas).
        row_values: ``RecordedPose -> numbers`` of a row ``poses import`` writes (default: the
            numbers as the program file wrote them, ``RecordedPose.values``).
    """

    name: str
    columns: tuple[str, ...]
    units: str
    to_rotations: Callable[[np.ndarray, Callable[[int], str]], np.ndarray]
    decimals: int = 6
    rank: int = 100
    header_text: str = ""
    row_values: Callable[[Any], Sequence[float]] | None = None


@dataclass(frozen=True)
class ControllerFormat:
    """Everything tcpcal knows about one controller format.

    Lengths are mm and angles deg unless ``numbers`` says otherwise (UR: m, rad).

    Attributes:
        name: the value of ``--format``/``--from``/``--to`` and of ``fmt=``.
        label: the format in menus (the app's export list), e.g. ``"KUKA"``.
        rank: place in menus and CLI choices (lower first).
        angle_convention: the rotation convention in words and as a formula.
        rotation_from_angles: the format's orientation numbers -> (3, 3) ``R_flange_tool``.
        angles_from_rotation: (3, 3) rotation -> the format's orientation numbers.
        numbers: the bare values of ``tcpcal convert`` with units, e.g. ``"X,Y,Z,A,B,C mm/deg"``.
        value_counts: how many bare values ``tcpcal convert --from`` takes.
        values_to_text: bare values -> text that ``parse_text`` reads (one place for the
            conventions).
        render_text: ``(tool, slot) -> str``: the tool data text (``tcpcal.formats.export_tool``).
        parse_text: ``(text, name or None) -> Tool`` (``tcpcal.formats.import_tool``).
        tool_numbers: the controller's tool numbers (slots), or ``None`` if it has none.
        name_rule: what the controller accepts as a tool name, in words.
        controller: the controller and its file, in words (``""``: no controller file).
        filename: default file name of an exported tool (``{n}`` = tool number).
        values: the value layout of the tool frame in the controller file, with units.
        render_file: ``(tool, number, name=None, **options) -> str``: the whole file.
        parse_file: ``text -> [ToolEntry]``: the tool frames of such a file.
        file_options: keyword options ``render_file`` takes (``tools export --register``).
        parse_poses: ``text -> [RecordedPose]`` of a program file (``None``: no pose import).
        render_poses: poses -> a program file declaring them (tests, examples).
        pose_extensions: program file extensions (lower case) that ``poses import`` knows.
        detect: a pattern found in the program files of this controller (``poses import
            --format auto`` tries the formats in ``rank`` order).
        detect_text: what ``detect`` looks for, in words (the message when nothing matches).
        pose_warnings: ``text -> [warning]``: what else the technician should know about a
            program file's poses (e.g. a UR script that sets a TCP).
        csv: the POSES.csv layout of its poses (``None``: none).
        parse_joint_points: ``text -> [JointPoint]``: the positions the program file records
            in joint representation (``None``: the format has none); ``poses import`` skips
            them (tcpcal has no robot model) and the app converts them.
        claim: content that only this controller's files have (FANUC's ``A05B-`` order
            numbers of ``ORDERFIL.DAT``): it wins over the file extension in ``--format auto``.
        tool_file_extensions: extensions (lower case) of the files ``tools import`` reads.
        tool_file_detect: content found in this controller's tool files (``tools import
            --format auto`` tries the formats in ``rank`` order).
        parse_pulse_points: ``text -> [PulsePoint]``: the positions a program holds in encoder
            counts (Yaskawa PULSE; ``None``: the format has none); ``poses import`` refuses or
            skips them, the app converts them with ``--pulses-per-degree``.
        pose_layout: the name of another format whose POSES.csv layout this format's poses
            are written in, when it has none of its own (Yaskawa: ``fanuc``, the same
            convention).
    """

    name: str
    label: str
    rank: int
    angle_convention: str
    rotation_from_angles: Callable[[Sequence[float]], np.ndarray]
    angles_from_rotation: Callable[[np.ndarray], tuple[float, ...]]
    numbers: str = ""
    value_counts: tuple[int, ...] = ()
    values_to_text: Callable[[Sequence[float]], str] | None = None
    render_text: Callable[[Tool, int], str] | None = None
    parse_text: Callable[[str, str | None], Tool] | None = None
    tool_numbers: range | None = None
    name_rule: str = ""
    controller: str = ""
    filename: str = ""
    values: str = ""
    render_file: Callable[..., str] | None = None
    parse_file: Callable[[str], list[Any]] | None = None
    file_options: tuple[str, ...] = ()
    parse_poses: Callable[[str], list[Any]] | None = None
    render_poses: Callable[..., str] | None = None
    pose_extensions: tuple[str, ...] = ()
    detect: re.Pattern[str] | None = None
    detect_text: str = ""
    pose_warnings: Callable[[str], list[str]] | None = None
    csv: CsvLayout | None = None
    parse_joint_points: Callable[[str], list[Any]] | None = None
    claim: re.Pattern[str] | None = None
    tool_file_extensions: tuple[str, ...] = ()
    tool_file_detect: re.Pattern[str] | None = None
    parse_pulse_points: Callable[[str], list[Any]] | None = None
    pose_layout: str = ""

    # The names the file functions had before the registries were one (tests, callers).
    @property
    def render_tool(self) -> Callable[..., str] | None:
        """Alias of :attr:`render_file`."""
        return self.render_file

    @property
    def parse_tool(self) -> Callable[[str], list[Any]] | None:
        """Alias of :attr:`parse_file`."""
        return self.parse_file

    @property
    def has_text(self) -> bool:
        """The format has a tool data text (``export_tool``/``import_tool``, ``convert``)."""
        return self.render_text is not None and self.parse_text is not None

    @property
    def has_file(self) -> bool:
        """The format has a whole controller file (``tools export --file``)."""
        return self.render_file is not None

    def slot_for(self, slot: int) -> int | None:
        """``slot`` if it is one of the controller's tool numbers, else ``None`` (the text is
        then written for the format's default number)."""
        return slot if self.tool_numbers is not None and slot in self.tool_numbers else None


# ----------------------------------------------------------------- tool text helpers
TEXT_NUM = r"[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?|[-+]?(?:nan|inf(?:inity)?)"
"""A number in pasted tool data text (also ``nan``/``inf``, refused by :func:`text_float`)."""
TEXT_NUM_RE = re.compile(TEXT_NUM, re.IGNORECASE)
_ZERO_BELOW = 1e-13


def text_number(x: float, upper_e: bool = False) -> str:
    """``x`` in Python's shortest round-trip form (``repr``); ``|x| < 1e-13`` (rotation noise)
    as 0; ``upper_e``: an exponent as ``E`` (KUKA, ABB)."""
    x = float(x)
    if abs(x) < _ZERO_BELOW:
        x = 0.0
    s = repr(x)
    return s.upper() if upper_e and "e" in s else s


def text_float(token: str, fmt: str, what: str) -> float:
    """A finite float from a tool text token, or an ``InvalidInputError`` naming ``fmt``."""
    try:
        value = float(token)
    except ValueError:
        raise InvalidInputError(f"{fmt}: {what} {token!r} is not a number.") from None
    if not math.isfinite(value):
        raise InvalidInputError(f"{fmt}: {what} is {token!r}; it must be a finite number.")
    return value


def check_slot(slot: Any, numbers: range, fmt: str) -> int:
    """``slot`` if it is one of ``numbers``, else an ``InvalidInputError``."""
    if isinstance(slot, bool) or not isinstance(slot, int) or slot not in numbers:
        raise InvalidInputError(
            f"{fmt}: tool number must be {numbers.start}..{numbers.stop - 1}, got {slot!r}.")
    return slot


def make_tool(fmt: str, name: str, name_given: bool, **kw: Any) -> Tool:
    """A :class:`Tool`, or an ``InvalidInputError`` naming ``fmt`` (and ``name=`` if the name
    came from the text)."""
    try:
        return Tool(name=name, **kw)
    except TcpcalError as exc:
        hint = "" if name_given else " (pass name=... to import it under another name)"
        raise InvalidInputError(f"{fmt}: the imported tool is invalid: {exc}{hint}") from None


def tool_from_rotation(fmt: str, name: str, name_given: bool, tcp_mm: Any, R: np.ndarray,
                       **kw: Any) -> Tool:
    """A :class:`Tool` from a TCP (mm) and ``R_flange_tool`` (stored as KUKA A, B, C)."""
    abc = abc_deg_from_rotation(R)
    return make_tool(fmt, name, name_given, tcp_mm=tuple(float(v) for v in tcp_mm),
                     abc_deg=tuple(float(v) for v in abc), **kw)
