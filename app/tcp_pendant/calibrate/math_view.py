""""The math": each method's equations filled in with this run's numbers (no viser).

For the wizard on show, :func:`math_sheet` computes the equations that its method solves
(``docs/methods.md`` and the course's lecture and paper, with their labels: (4P-1) ... (4P-3),
the lecture's Eqs. (1)-(3), (7) and (8), (REF-1), (PA-1)/(PA-2) (the paper's Eqs. 4-6), the
paper's (7) ... (30), (ZX-1) ... (ZX-3), (BEAM-1)/(BEAM-2), (SC-1)/(SC-2)),
from the **same recorded poses the solver uses**: ``T_world_flange_m[:3, :3]`` and
``T_world_flange_m[:3, 3] * 1000`` (metres to mm), in step order, as each wizard's
``_compute`` hands them to ``tcpcal``. Where the method's result is a ``tcpcal`` solve, the
sheet calls the same ``tcpcal`` function (so the number shown *is* the solver's); the
intermediate quantities (differences, singular values, the paper's vectors and cosines) are
computed here with numpy, step by step as the slides do.

A wizard class names its sheet by ``Wizard.math_view`` ("xyz4", "reference", "three_point",
"abc_world", "tcp_zx", "beam", "spin_check"); :data:`MATH_VIEWS` maps the name to its builder.
No code here branches on a wizard's class. The sheet works on a wizard in progress too (the
view is live while touches are recorded): a block appears once its poses are recorded.

Units: lengths in mm (2 decimals), rotation entries and cosines 3 decimals, angles in degrees
(2 decimals), as a slide would show them. Nothing here reads the hidden true tool: in a
classroom exercise the sheet is the trainee's own data only.

Languages: the sheet's words (labels, titles, lines of words, notes, the intro) are catalog
messages in the language of ``math_sheet``'s ``tr`` (English by default); the equations stand
in them as ``{placeholders}`` and are the same in every language, as are the numbers (decimal
point) and the frame names. A line of words is held to ``MAX_LINE`` in English
(:meth:`_Block.words`); a translation may run longer and the block scrolls sideways.

Rendering (:func:`math_markdown`): monospace matrices in viser markdown, not matplotlib's
mathtext as PNG images. Why: (1) the panel is 320 px wide in presenter mode and an image is
scaled to the panel's width, so a rendered equation with two 3x3 matrices would shrink below
legibility on a projector, while text keeps its font size (``MATH_FONT_PX``) and the blocks
are laid out one matrix a line to fit 28 characters; (2) it is cheap (no figure rendered and
no PNG sent to every browser at each touch) and adds no dependency; (3) the numbers on screen
are text, which the tests read back and compare with an independent recomputation. The HTML
is our own: every line is passed through ``text_escape.escape_html`` and every note through
``text_escape.escape_markdown``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from tcpcal.errors import DegenerateTouchesError, TcpcalError
from tcpcal.orientation import R_WORLD_TOOL_PARALLEL
from tcpcal.origin import TcpResult, solve_xyz4
from tcpcal.tool import abc_deg_from_rotation

from tcp_pendant.text_escape import escape_html, escape_markdown
from tcp_pendant.translation import ENGLISH, N_, Translator

if TYPE_CHECKING:
    from tcp_pendant.wizards import (
        AbcWorldWizard,
        BeamWizard,
        ReferenceWizard,
        TcpCheckWizard,
        TcpZxWizard,
        ThreePointWizard,
        Wizard,
        Xyz4Wizard,
    )

__all__ = [
    "MATH_FONT_PX",
    "MAX_LINE",
    "MAX_WIDE_LINE",
    "MATH_VIEWS",
    "MathBlock",
    "MathSheet",
    "Shown",
    "math_markdown",
    "math_sheet",
    "rank_and_singular_values",
]

MATH_FONT_PX = 17
"""Font size of the monospace equations, pixels (28 characters fit the 320 px presenter panel)."""
MAX_LINE = 25
"""Longest monospace line, characters: 25 at ``MATH_FONT_PX`` fit the 320 px presenter panel."""
MAX_WIDE_LINE = 26
"""Longest row of the stacked matrix A (:meth:`_Block.stacked`): six entries; the block scrolls
sideways in the 320 px panel if the font makes it wider, and fits the board (``math_board``)."""
RANK_TOL = 1e-6
"""A singular value below this times the largest counts as zero (numerical rank)."""

_SUB = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")
_DECIMAL = re.compile(r"\d\.\d")


def sub(i: int | str) -> str:
    """A touch number as subscript digits (``R₁₂``)."""
    return str(i).translate(_SUB)


def fmt(x: float, decimals: int) -> str:
    """``x`` with ``decimals`` decimals, without a minus on a rounded zero."""
    if not math.isfinite(x):
        return "inf" if x > 0 else ("-inf" if x < 0 else "nan")
    s = f"{x:.{decimals}f}"
    return s[1:] if s.startswith("-") and float(s) == 0.0 else s


@dataclass(frozen=True)
class Shown:
    """One quantity a block shows.

    Attributes:
        value: the numbers (a float, a 3-vector or a 3x3 matrix), as computed.
        decimals: how many decimals the text shows.
        unit: "mm", "deg" / "°" or "" (rotation entries, cosines, unit vectors).
    """

    value: np.ndarray
    decimals: int
    unit: str = ""

    def flat(self) -> list[float]:
        return [float(v) for v in np.ravel(self.value)]


@dataclass(frozen=True)
class MathBlock:
    """One equation of the sheet, filled in.

    Attributes:
        key: short id ("touch-1", "pair", "stack", "pinv", ...): the block's ``data-key``.
        label: the equation's label as methods.md / the seeds number it ("(4P-2) · lecture Eq. (7)").
        title: what it is, in words.
        lines: the monospace lines; their decimal numbers are exactly ``values`` in order, each
            at its ``decimals``.
        values: the quantities shown, by name, in the order the lines show them.
        note: plain words under the block (no decimal numbers: it refers to the lines).
    """

    key: str
    label: str
    title: str
    lines: tuple[str, ...]
    values: Mapping[str, Shown]
    note: str = ""


@dataclass(frozen=True)
class MathSheet:
    """The equations of one wizard's run.

    Attributes:
        view: the wizard's ``math_view`` name.
        title: the method's title.
        blocks: in the order the lecture derives them.
        intro: plain words on top (what is recorded so far), in the sheet's language.
        headline: the intro's first sentence (what is recorded), the board's line under the
            title; "" for the intro's text up to its first ". ".
    """

    view: str
    title: str
    blocks: tuple[MathBlock, ...]
    intro: str = ""
    headline: str = ""

    def block(self, key: str) -> MathBlock:
        for b in self.blocks:
            if b.key == key:
                return b
        raise KeyError(f"no block {key!r} in the {self.view} sheet; it has {[b.key for b in self.blocks]}")

    def has(self, key: str) -> bool:
        return any(b.key == key for b in self.blocks)


class _Block:
    """Builds a :class:`MathBlock` line by line, recording every number it writes; its lines of
    words (:meth:`words`) in ``tr``'s language."""

    def __init__(self, key: str, label: str, title: str, tr: Translator = ENGLISH) -> None:
        self.key, self.label, self.title, self.tr = key, label, title, tr
        self.lines: list[str] = []
        self.values: dict[str, Shown] = {}
        self.notes: list[str] = []

    def _keep(self, name: str, value: npt.ArrayLike, decimals: int, unit: str) -> Shown:
        if name in self.values:
            raise ValueError(f"block {self.key}: {name!r} shown twice")
        shown = Shown(np.array(value, dtype=float), decimals, unit)
        self.values[name] = shown
        return shown

    def text(self, line: str) -> None:
        """A line of words or symbols (no decimal number: numbers go through the helpers)."""
        if _DECIMAL.search(line) or len(line) > MAX_LINE:
            raise ValueError(f"block {self.key}: a number in a text line, or a line too long: {line!r}")
        self.lines.append(line)

    def words(self, message: str, **values: object) -> None:
        """A line of words (``message``: an English msgid marked ``N_``, its ``{placeholders}``
        filled from ``values``) in the block's language. The English line is held to
        :meth:`text`'s rules (no decimal number, at most :data:`MAX_LINE`); a translation may
        run longer (the block scrolls sideways)."""
        english = message.format(**values)
        if _DECIMAL.search(english) or len(english) > MAX_LINE:
            raise ValueError(f"block {self.key}: a number in a text line, or a line too long: {english!r}")
        self.lines.append(self.tr.gettext(message).format(**values))

    def _column(self, symbol: str, rows: list[str], unit: str) -> None:
        """Three bracketed rows with ``symbol =`` on the middle one (or on a line of its own
        above them when that would pass ``MAX_LINE``), the unit after the middle row."""
        tail = f" {unit}" if unit else ""
        head = f"{symbol} = "
        if len(head) + max(len(r) for r in rows) + 2 + len(tail) > MAX_LINE:   # 2: the brackets
            self.lines.append(f"{symbol} =")
            head = "  "
        pad = " " * len(head)
        for k, (row, (lb, rb)) in enumerate(zip(rows, (("⎡", "⎤"), ("⎢", "⎥"), ("⎣", "⎦")))):
            self.lines.append((head if k == 1 else pad) + lb + row + rb + (tail if k == 1 else ""))

    def matrix(self, name: str, symbol: str, M: np.ndarray, decimals: int = 3, unit: str = "") -> None:
        """A 3x3 matrix with its symbol on the middle row: ``R₁ = ⎡ ... ⎤``."""
        shown = self._keep(name, M, decimals, unit)
        cells = [[fmt(float(v), decimals) for v in row] for row in shown.value]
        w = max(len(c) for row in cells for c in row)
        self._column(symbol, [" ".join(c.rjust(w) for c in row) for row in cells], unit)

    def vector(self, name: str, symbol: str, v: np.ndarray, decimals: int = 2, unit: str = "mm") -> None:
        """A 3-vector as a column, its symbol and unit on the middle row."""
        shown = self._keep(name, v, decimals, unit)
        cells = [fmt(float(x), decimals) for x in shown.value]
        w = max(len(c) for c in cells)
        self._column(symbol, [c.rjust(w) for c in cells], unit)

    def scalar(self, name: str, symbol: str, x: float, decimals: int = 2, unit: str = "mm") -> None:
        shown = self._keep(name, x, decimals, unit)
        u = {"deg": "°", "": ""}.get(unit, f" {unit}")
        text = f"{fmt(float(shown.value), decimals)}{u}"
        if len(symbol) + 3 + len(text) > MAX_LINE:
            self.lines += [f"{symbol} =", f"  {text}"]
        else:
            self.lines.append(f"{symbol} = {text}")

    def numbers(self, name: str, symbol: str, xs: Sequence[float] | np.ndarray, decimals: int = 3) -> None:
        """A short list on one line: ``σ = 1.234  0.567  0.000``."""
        shown = self._keep(name, np.asarray(xs, dtype=float), decimals, "")
        items = [fmt(x, decimals) for x in shown.flat()]
        one = f"{symbol} = " + "  ".join(items)
        if len(one) <= MAX_LINE:
            self.lines.append(one)
            return
        self.lines.append(f"{symbol} =")              # then as many a line as fit
        line = " "
        for item in items:
            if len(line) + 2 + len(item) > MAX_LINE:
                self.lines.append(line)
                line = " "
            line += "  " + item
        self.lines.append(line)

    def stacked(self, name: str, symbol: str, R: np.ndarray, decimals: int = 2) -> None:
        """(4P-3)'s ``A = [R_i  -I]`` stacked, one of its 3N rows a line, under ``symbol =``:
        the R_i entries at ``decimals`` (kept as ``name``, 3N x 3) and -I's entries as the whole
        numbers -1 and 0 (no decimal: constants, not kept). 2 decimals keep a row at
        :data:`MAX_WIDE_LINE` characters."""
        shown = self._keep(name, np.asarray(R, dtype=float).reshape(-1, 3), decimals, "")
        cells = [[fmt(float(v), decimals) for v in row] for row in shown.value]
        w = max(len(c) for row in cells for c in row)
        self.lines.append(f"{symbol} =")
        for k, row in enumerate(cells):
            eye = " ".join("-1" if j == k % 3 else " 0" for j in range(3))
            line = " ".join(c.rjust(w) for c in row) + " " + eye
            if len(line) > MAX_WIDE_LINE:
                raise ValueError(f"block {self.key}: a row of A too long: {line!r}")
            self.lines.append(line)

    def note(self, words: str) -> None:
        self.notes.append(words)

    def build(self) -> MathBlock:
        return MathBlock(self.key, self.label, self.title, tuple(self.lines), dict(self.values),
                         " ".join(self.notes))


# ------------------------------------------------------------------ shared pieces
def _poses_mm(wizard: Wizard, indices: Sequence[int] | None = None) -> tuple[list[int], np.ndarray, np.ndarray]:
    """(step indices, R (N,3,3), f (N,3) mm) of the recorded poses, in step order, exactly as
    the wizards hand them to tcpcal (rotation block; translation times 1000)."""
    poses = wizard.recorded_poses
    idx = sorted(poses) if indices is None else [i for i in indices if i in poses]
    T = np.array([poses[i].T_world_flange_m for i in idx], dtype=float).reshape(-1, 4, 4)
    return idx, T[:, :3, :3].copy(), T[:, :3, 3] * 1000.0


def rank_and_singular_values(A: np.ndarray) -> tuple[int, np.ndarray, np.ndarray]:
    """Numerical rank (singular values above ``RANK_TOL`` times the largest), the singular
    values (descending) and the right singular vector of the smallest one."""
    _, s, vt = np.linalg.svd(A)
    rank = int(np.sum(s > RANK_TOL * s[0])) if s.size and s[0] > 0 else 0
    return rank, s, vt[-1]


def _unit_sign(u: np.ndarray) -> np.ndarray:
    """A direction's sign made definite (largest component positive), for a stable display."""
    return u if u[int(np.argmax(np.abs(u)))] >= 0 else -u


def _label(tag: str, words: str = "") -> str:
    """A block's label: the equation's tag (``(4P-2)``), then where it comes from in words."""
    return f"{tag} · {words}" if words else tag


def _touch_blocks(steps: Sequence[int], R: np.ndarray, f: np.ndarray, label: str,
                  tr: Translator = ENGLISH) -> list[MathBlock]:
    out = []
    for i, Ri, fi in zip(steps, R, f):
        n = i + 1
        b = _Block(f"touch-{n}", label, tr.gettext("touch {n}: {equation}").format(
            n=n, equation=f"T_f{n} = [R{sub(n)} f{sub(n)}; 0 1]"), tr)
        b.matrix(f"R_{n}", f"R{sub(n)}", Ri)
        b.vector(f"f_{n}", f"f{sub(n)}", fi)
        out.append(b.build())
    return out


def _pair_block(a: int, b_: int, Ra: np.ndarray, Rb: np.ndarray, fa: np.ndarray, fb: np.ndarray,
                tr: Translator = ENGLISH) -> MathBlock:
    """Lecture Eq. (7) / (4P-2) for one pair, with its rank and unobservable direction."""
    _ = tr.gettext
    A, B = a + 1, b_ + 1
    D = Ra - Rb
    y = -(fa - fb)
    rank, s, u = rank_and_singular_values(D)
    blk = _Block("pair", _label("(4P-2)", _("lecture Eq. {eq}").format(eq="(7)")),
                 _("one pair, touches {a} and {b}").format(a=A, b=B), tr)
    blk.text(f"(R{sub(A)}−R{sub(B)}) t = −(f{sub(A)}−f{sub(B)})")
    blk.matrix("R_a-R_b", f"R{sub(A)}−R{sub(B)}", D)
    blk.vector("-(f_a-f_b)", f"−(f{sub(A)}−f{sub(B)})", y)
    blk.numbers("sigma", "σ", s)
    blk.words(N_("rank {rank} of {full}"), rank=rank, full=3)
    # (R_a - R_b) u = 0 for u the axis of R_b^T R_a: the tool turned about u between a and b.
    blk.vector("u", "u", _unit_sign(u), decimals=3, unit="")
    blk.note(_("[{ra} − {rb}] is normally a singular matrix and results in no solution "
               "(lecture, Eq. 7): its rank is {rank}, never 3. Between touch {a} and {b} the tool turned about "
               "the flange direction u, and ({ra} − {rb}) u = 0, so the TCP along u "
               "cannot be determined from this pair. Brush the reference from four quite distinct "
               "directions: they give six linear equations.").format(
                   ra=f"R{sub(A)}", rb=f"R{sub(B)}", rank=rank, a=A, b=B))
    return blk.build()


def _stack(R: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The N-1 consecutive pairs (a, a+1) of (4P-2) stacked: (3(N-1), 3) and (3(N-1),), as
    ``tcpcal``'s pairwise estimator stacks them."""
    D = (R[:-1] - R[1:]).reshape(-1, 3)
    y = (-(f[:-1] - f[1:])).reshape(-1)
    return D, y


def _stack_block(steps: Sequence[int], R: np.ndarray, f: np.ndarray,
                 tr: Translator = ENGLISH) -> tuple[MathBlock, np.ndarray | None]:
    """The stacked pair system's rank and singular values; the pseudo-inverse solution
    (lecture Eq. (8)) when it has rank 3, else None."""
    _ = tr.gettext
    n = len(steps)
    D, y = _stack(R, f)
    rank, s, u = rank_and_singular_values(D)
    pairs = ", ".join(f"({steps[k] + 1},{steps[k + 1] + 1})" for k in range(n - 1))
    blk = _Block("stack", _label(_("{tag} stacked").format(tag="(4P-2)"), _("lecture Eqs. {eqs}").format(eqs="(7)-(8)")),
                 tr.ngettext("{n} consecutive pair {pairs}: {rows} equations, 3 unknowns",
                             "{n} consecutive pairs {pairs}: {rows} equations, 3 unknowns",
                             n - 1).format(n=n - 1, pairs=pairs, rows=3 * (n - 1)), tr)
    blk.numbers("sigma", "σ", s)
    blk.words(N_("rank {rank} of {full}"), rank=rank, full=3)
    t_pinv = None
    if rank < 3:
        blk.vector("u", "u", _unit_sign(u), decimals=3, unit="")
        if n == 2:
            blk.note(_("One pair is rank ≤ 2: the matrix is normally singular and results in no "
                       "solution (lecture, Eq. 7); the TCP along u cannot be determined. Touch again "
                       "from a quite distinct direction."))
        else:
            blk.note(_("All touches rotate about nearly the same axis u, so the TCP along u cannot "
                       "be determined; tilt the tool about a second axis."))
    else:
        t_pinv = np.linalg.pinv(D) @ y          # t = -[R_a - R_b]^+ [f_a - f_b]   (Eq. 8)
        blk.text("t = −[R_a−R_b]†[f_a−f_b]")
        blk.vector("t_pinv", "t", t_pinv)
        blk.note(_("Eq. (8): the pseudo-inverse of the stacked differences (tcpcal's pairwise "
                   "estimator uses these same consecutive pairs)."))
    return blk.build(), t_pinv


def _refusal_note(exc: TcpcalError, steps: Sequence[int], tr: Translator) -> str:
    """Why the solver refused the touches, in ``tr``'s language (tcpcal's own message is English:
    it has no user interface), from what its error names: the axis all touches turn about, the
    two touches (step numbers of ``steps``) of the same orientation, or the orientations alike."""
    _ = tr.gettext
    if isinstance(exc, DegenerateTouchesError):
        if exc.unobservable_axis is not None:
            return _("All touches rotate about nearly the same axis, so the TCP along it cannot be "
                     "determined; tilt the tool about a second axis.")
        if len(exc.indices) == 2 and all(0 <= i < len(steps) for i in exc.indices):
            a, b = (steps[i] + 1 for i in exc.indices)
            return _("Touches {a} and {b} have the same orientation: record touch {b} again from a "
                     "different orientation.").format(a=a, b=b)
        return _("The touches have nearly the same orientation, so the TCP cannot be determined; tilt "
                 "the tool 30 to 60 degrees between touches, about two different axes.")
    return _("The solver refuses these touches: {error}").format(error=exc)


def _lstsq_block(R: np.ndarray, f: np.ndarray, t_pinv: np.ndarray | None,
                 tr: Translator = ENGLISH, steps: Sequence[int] = ()) -> tuple[MathBlock, TcpResult | None]:
    """(4P-3) by tcpcal's solve_xyz4 (the solver), set beside the pseudo-inverse; its refusal
    in words (:func:`_refusal_note`)."""
    _ = tr.gettext
    blk = _Block("lstsq", "(4P-3)", _("joint least squares, {equation}").format(
        equation="x = (t, r): [R_i  −I] x = −f_i"), tr)
    try:
        res = solve_xyz4(R, f, method="lstsq", detect_outliers=False)   # t, r: the same; cheaper
    except TcpcalError as exc:
        blk.words(N_("no solution yet"))
        blk.note(_refusal_note(exc, steps, tr))
        return blk.build(), None
    t = np.asarray(res.tcp, dtype=float)
    if t_pinv is not None:                       # side by side: Eq. (8), then (4P-3)
        blk.vector("t_pinv", _("t (Eq. 8)"), t_pinv)
    blk.vector("t_lstsq", "t (4P-3)", t)
    blk.vector("r_lstsq", "r", np.asarray(res.reference, dtype=float))
    blk.scalar("ci95", _("{percent} radius").format(percent="95 %"), float(res.ci95_radius))
    if t_pinv is not None:
        diff = float(np.linalg.norm(t - t_pinv))
        blk.scalar("diff", "|t − t_pinv|", diff)
        blk.note(_("The pseudo-inverse of Eq. (8) solves only the differences of consecutive "
                   "touches: it drops the reference point r and weights every difference equally, "
                   "although neighbouring differences share a touch and its error, so it discards "
                   "information. The joint least squares (4P-3) fits t and r to every touch at once: "
                   "for an isotropic touch error it is the maximum-likelihood estimate, the one "
                   "tcpcal reports. With exact touches both give the same t; the difference is the "
                   "touch noise, seen through two different weightings (compare it with the {percent} radius)."
                   ).format(percent="95 %"))
    return blk.build(), res


def _sphere_block(R: np.ndarray, f: np.ndarray, tr: Translator = ENGLISH) -> MathBlock:
    """(4P-1a): ``|f_i|^2 = 2 f_i . r + k`` by least squares (centred as tcpcal does),
    radius ``sqrt(k + |r|^2)``, then ``t = mean R_i^T (r - f_i)``."""
    _ = tr.gettext
    blk = _Block("sphere", _label("(4P-1a)", _("lecture: best-fit sphere")),
                 _("the flange origins f_i lie on a sphere about r of radius |t|"), tr)
    fbar = f.mean(axis=0)
    d = f - fbar
    H = np.column_stack([2.0 * d, np.ones(len(f))])
    sv = np.linalg.svd(d, compute_uv=False)
    if len(f) < 4 or sv[0] <= 0 or sv[-1] / sv[0] < 1e-6:
        blk.words(N_("no sphere yet"))
        blk.note(_("The sphere needs four flange origins that are not in one plane."))
        return blk.build()
    z, *_rest = np.linalg.lstsq(H, np.einsum("ni,ni->n", d, d), rcond=None)
    r = fbar + z[:3]
    radius = math.sqrt(max(float(z[3] + z[:3] @ z[:3]), 0.0))
    t = np.einsum("nki,nk->i", R, r - f) / len(f)
    blk.text("|f_i − r|² = |t|²")
    blk.vector("centre", "r", r)
    blk.scalar("radius", _("radius"), radius)
    blk.words(N_("t = mean R_iᵀ (r − f_i)"))
    blk.vector("t_sphere", "t", t)
    return blk.build()


def _design_block(steps: Sequence[int], R: np.ndarray, tr: Translator = ENGLISH) -> MathBlock:
    """(4P-3)'s design matrix ``A = [R_i  -I]`` stacked (3N x 6, unknowns ``x = (t, r)``, right
    side ``b = -f_i``), its singular values and numerical rank (of 6), as the touches arrive."""
    n = len(steps)
    A = np.vstack([np.hstack([Ri, -np.eye(3)]) for Ri in R])
    rank, s, _v = rank_and_singular_values(A)
    _ = tr.gettext
    blk = _Block("A", "(4P-3) · A x = b", _("{matrix} stacked: {size}, {unknowns}").format(
        matrix="A = [R_i  −I]", size=f"{3 * n}×6", unknowns="x = (t, r), b = −f_i"), tr)
    blk.stacked("A_R", "A", R)
    blk.numbers("sigma", "σ(A)", s)
    blk.words(N_("rank {rank} of {full}"), rank=rank, full=6)
    if rank < 6:
        blk.note(_("Rank below 6: t and r cannot both be determined yet. Each touch adds three rows; "
                   "two touches leave the TCP along the axis the tool turned about free (a zero "
                   "singular value). Touches about two different axes give rank 6."))
    else:
        blk.note(_("Rank 6: t and r are determined; the smallest singular value says how well "
                   "(a small one: the touches are nearly about one axis)."))
    return blk.build()


def _touches_recorded(n: int, tr: Translator) -> str:
    """``"2 touches recorded."``, ``"1 touch recorded."`` in ``tr``'s language."""
    return tr.ngettext("{n} touch recorded.", "{n} touches recorded.", n).format(n=n)


def _poses_recorded(n: int, tr: Translator) -> str:
    """``"3 poses recorded."``, ``"1 pose recorded."`` in ``tr``'s language."""
    return tr.ngettext("{n} pose recorded.", "{n} poses recorded.", n).format(n=n)


def _sheet(view: str, title: str, blocks: Sequence[MathBlock], headline: str = "", more: str = "") -> MathSheet:
    """A sheet whose intro is ``headline`` (what is recorded) then ``more`` (sentences apart:
    each its own message)."""
    return MathSheet(view, title, tuple(blocks), " ".join(x for x in (headline, more) if x), headline)


# ------------------------------------------------------------------ the sheets
def xyz4_sheet(wizard: Xyz4Wizard, pair: tuple[int, int] | None = None, *, tr: Translator = ENGLISH) -> MathSheet:
    """XYZ 4-point: (4P-1) per touch, a pair's Eq. (7), the stack's rank and Eq. (8), (4P-3)
    beside it, the sphere (4P-1a). Touches the trainee dropped are left out, as the solver does.

    Args:
        wizard: the 4-point wizard (``recorded_poses``, ``excluded``).
        pair: 0-based step indices (a, b) of the pair to show; default the last two recorded.
        tr: the language of the words.
    """
    excluded = set(getattr(wizard, "excluded", ()))
    steps, R, f = _poses_mm(wizard, [i for i in sorted(wizard.recorded_poses) if i not in excluded])
    return _origin_sheet("xyz4", tr.gettext(wizard.title), steps, R, f, pair, tr=tr)


def _origin_sheet(view: str, title: str, steps: list[int], R: np.ndarray, f: np.ndarray,
                  pair: tuple[int, int] | None, extra: Sequence[MathBlock] = (), *,
                  tr: Translator = ENGLISH) -> MathSheet:
    _ = tr.gettext
    blocks = _touch_blocks(steps, R, f, _label("(4P-1)", _("lecture Eqs. {eqs}").format(eqs="(1)-(3)")), tr)
    n = len(steps)
    if n >= 1:
        blocks.append(_design_block(steps, R, tr))
    if n >= 2:
        if pair is None or pair[0] not in steps or pair[1] not in steps or pair[0] == pair[1]:
            pair = (steps[-2], steps[-1])
        ia, ib = steps.index(pair[0]), steps.index(pair[1])
        blocks.append(_pair_block(pair[0], pair[1], R[ia], R[ib], f[ia], f[ib], tr))
        stack, t_pinv = _stack_block(steps, R, f, tr)
        blocks.append(stack)
        if n >= 4:
            lst, _res = _lstsq_block(R, f, t_pinv, tr, steps)
            blocks.append(lst)
            blocks.append(_sphere_block(R, f, tr))
    more = _("Each touch gives R_i t + f_i = r (4P-1): three equations, but t and r are six unknowns.") if n < 2 else ""
    return _sheet(view, title, (*blocks, *extra), _touches_recorded(n, tr), more)


def reference_sheet(wizard: ReferenceWizard, *, tr: Translator = ENGLISH) -> MathSheet:
    """XYZ reference: ``r = f_1 + R_1 t_1`` (lecture ``r ≡ f_1 + t_1``), then (REF-1):
    ``t_2 = r - f_2`` in WORLD and ``R_2^T (r - f_2)`` in FLANGE."""
    _ = tr.gettext
    steps, R, f = _poses_mm(wizard)
    got = dict(zip(steps, range(len(steps))))
    t1 = np.asarray(wizard.reference_tool.tcp_mm, dtype=float)
    blocks = []
    if 0 in got:
        k = got[0]
        r = R[k] @ t1 + f[k]
        b = _Block("reference-point", _label("(REF-1)", _("lecture: {equation}").format(equation="r ≡ f₁ + t₁")),
                   _("the calibrated tool touches the reference point"), tr)
        b.vector("t_1", "t₁", t1)
        b.matrix("R_1", "R₁", R[k])
        b.vector("f_1", "f₁", f[k])
        b.text("r = f₁ + R₁ t₁")
        b.vector("r", "r", r)
        b.note(_("t₁ is the TCP of the reference tool data '{name}' (FLANGE); "
                 "R₁ t₁ is the same vector in WORLD.").format(name=wizard.reference_tool.name))
        blocks.append(b.build())
        if 1 in got:
            j = got[1]
            b = _Block("new-tcp", _label("(REF-1)", _("lecture: {equation}").format(
                equation="t₂ = r − f₂, ᶠt₂ = [⁰Q₂]⁻¹ t₂")), _("the new tool touches the same point"), tr)
            b.matrix("R_2", "R₂", R[j])
            b.vector("f_2", "f₂", f[j])
            b.text("t₂ = r − f₂  WORLD")
            b.vector("t_2_world", "t₂", r - f[j])
            b.text("ᶠt₂ = R₂ᵀ(r − f₂) FLANGE")
            b.vector("t_2", "ᶠt₂", R[j].T @ (r - f[j]))
            b.note(_("One touch per tool: the new TCP carries the errors of both touches and of t₁."))
            blocks.append(b.build())
    return _sheet("reference", _(wizard.title), blocks, _touches_recorded(len(steps), tr))


def three_point_sheet(wizard: ThreePointWizard, *, tr: Translator = ENGLISH) -> MathSheet:
    """Three-point, variants 1 and 2 (paper eqs. 7-30): V(1), c11 c21 c31, Δ1; V(2) (variant
    1, with c2 straightened orthogonal to c1) or V(3) (variant 2), the second column and its
    orthogonality; c3 (30) and the defect."""
    steps, R, f = _poses_mm(wizard)
    got = dict(zip(steps, range(len(steps))))
    t = np.asarray(wizard.tool.tcp_mm, dtype=float)
    blocks: list[MathBlock] = []
    if 0 in got:
        block, r = _tp_reference(t, R[got[0]], f[got[0]], tr)
        blocks.append(block)
        c1 = None
        if 1 in got:
            block, c1 = _tp_first_axis(t, r, R[got[1]], f[got[1]], tr)
            blocks.append(block)
        if c1 is not None and 2 in got:
            k = got[2]
            second = _tp_variant1 if int(wizard.variant) == 1 else _tp_variant2
            block, c2 = second(t, r, c1, R[k], f[k], tr)
            blocks.append(block)
            if c2 is not None:
                res = wizard.result
                blocks.append(_tp_frame(c1, c2, None if res is None else res.orthogonality_defect_deg, tr))
    return _sheet("three_point", tr.gettext(wizard.title), blocks, _poses_recorded(len(steps), tr))


def _paper(tr: Translator, eqs: str) -> str:
    """``paper Eq. (7)`` / ``paper Eqs. (8)-(17)`` in ``tr``'s language."""
    if "-" in eqs:
        return tr.gettext("paper Eqs. {eqs}").format(eqs=eqs)
    return tr.gettext("paper Eq. {eq}").format(eq=eqs)


def _tp_reference(t: np.ndarray, R1: np.ndarray, f1: np.ndarray,
                  tr: Translator = ENGLISH) -> tuple[MathBlock, np.ndarray]:
    """Paper Eq. (7): the TCP ``t`` (mm, FLANGE) touches the reference, ``r = R⁽¹⁾ t + f⁽¹⁾``."""
    r = R1 @ t + f1
    b = _Block("eq7", _paper(tr, "(7)"), tr.gettext("the TCP touches the reference: {equation}").format(
        equation="r = T⁽¹⁾ [t; 1]"), tr)
    b.vector("t", "t", t)
    b.matrix("R_1", "R⁽¹⁾", R1)
    b.vector("f_1", "f⁽¹⁾", f1)
    b.vector("r", "r", r)
    return b.build(), r


def _tp_first_axis(t: np.ndarray, r: np.ndarray, R2: np.ndarray, f2: np.ndarray,
                   tr: Translator = ENGLISH) -> tuple[MathBlock, np.ndarray | None]:
    """Paper Eqs. (8)-(17): ``V(1) = R⁽²⁾ᵀ (r − f⁽²⁾) = t + Δ1 c1``, ``Δ1 = −|V(1) − t|``; c1
    (None when the tip was not moved off the TCP)."""
    v1 = R2.T @ (r - f2)
    d1 = v1 - t
    delta1 = -float(np.linalg.norm(d1))
    b = _Block("eq8-17", _paper(tr, "(8)-(17)"), tr.gettext("the tip on the tool's −X axis: {equation}").format(
        equation="V(1) = (T⁽²⁾)⁻¹ r = t + Δ1 c1"), tr)
    b.matrix("R_2", "R⁽²⁾", R2)
    b.vector("f_2", "f⁽²⁾", f2)
    b.vector("V1", "V(1)", v1)
    b.scalar("delta1", "Δ1", delta1)
    c1 = None
    if delta1 < 0:
        c1 = d1 / delta1
        b.text("c1 = (c11, c21, c31)")
        b.text("   = (V(1) − t) / Δ1")
        b.vector("c1", "c1", c1, decimals=3, unit="")
    else:
        b.note(tr.gettext("The tip was not moved off the TCP: Δ1 = 0, tool X is undefined."))
    return b.build(), c1


def _tp_variant1(t: np.ndarray, r: np.ndarray, c1: np.ndarray, R3: np.ndarray, f3: np.ndarray,
                 tr: Translator = ENGLISH) -> tuple[MathBlock, np.ndarray | None]:
    """Paper Eqs. (18)-(24), variant 1: ``V(2) = t + Δ2 c2``; c2 as measured, ``c1 · c2``, the
    orthogonality defect, and c2 straightened (Gram-Schmidt keeping c1, as tcpcal does): the
    middle column of ``R_n,n*``. Returns the straightened c2 (None: Δ2 = 0)."""
    v = R3.T @ (r - f3)
    w = v - t
    b = _Block("eq18-24", _paper(tr, "(18)-(24)"), tr.gettext("variant 1, the tip on the tool's +Y axis: {equation}").format(
        equation="V(2) = t + Δ2 c2"), tr)
    b.matrix("R_3", "R⁽³⁾", R3)
    b.vector("f_3", "f⁽³⁾", f3)
    b.vector("V2", "V(2)", v)
    delta2 = float(np.linalg.norm(w))
    b.scalar("delta2", "Δ2", delta2)
    if delta2 <= 0:
        return b.build(), None
    c2_raw = w / delta2
    b.text("c2 = (c12, c22, c32)")
    b.text("   = (V(2) − t) / Δ2")
    b.vector("c2", "c2", c2_raw, decimals=3, unit="")
    cos = float(c1 @ c2_raw)
    b.scalar("c1.c2", "c1 · c2", cos, decimals=3, unit="")
    defect = abs(90.0 - math.degrees(math.atan2(float(np.linalg.norm(np.cross(c1, c2_raw))), cos)))
    b.scalar("defect", "|90° − ∠(c1, c2)|", defect, unit="deg")
    c2 = c2_raw - cos * c1
    c2 = c2 / np.linalg.norm(c2)
    b.text("c2' ∝ c2 − (c1·c2) c1")
    b.text("|c2'| = 1, c1 · c2' = 0")
    b.vector("c2_straight", "c2'", c2, decimals=3, unit="")
    b.note(tr.gettext("c1 and c2 should be orthogonal (c1 · c2 = 0); the touch error leaves them not quite "
                      "so. tcpcal keeps c1 and makes c2 orthogonal to it (Gram-Schmidt): the straightened c2' "
                      "is the middle column of R_n,n* below, and the angle is the orthogonality defect."))
    return b.build(), c2


def _tp_variant2(t: np.ndarray, r: np.ndarray, c1: np.ndarray, R3: np.ndarray, f3: np.ndarray,
                 tr: Translator = ENGLISH) -> tuple[MathBlock, np.ndarray | None]:
    """Paper Eqs. (25)-(29), variant 2: ``V(3) = t + Δ3 c1 + Δ4 c2`` with ``Δ3 = c1 · (V(3) − t)``;
    c2 orthogonal to c1 by construction (None: Δ4 = 0)."""
    v = R3.T @ (r - f3)
    w = v - t
    b = _Block("eq25-29", _paper(tr, "(25)-(29)"), tr.gettext("variant 2, the tip in the +Y half-plane: {equation}").format(
        equation="V(3) = t + Δ3 c1 + Δ4 c2"), tr)
    b.matrix("R_3", "R⁽³⁾", R3)
    b.vector("f_3", "f⁽³⁾", f3)
    b.vector("V3", "V(3)", v)
    delta3 = float(c1 @ w)
    p = w - delta3 * c1
    delta4 = float(np.linalg.norm(p))
    b.scalar("delta3", "Δ3 = c1 · (V(3) − t)", delta3)
    b.scalar("delta4", "Δ4", delta4)
    if delta4 <= 0:
        return b.build(), None
    c2 = p / delta4
    b.text("c2 = (c12, c22, c32)")
    b.text("   = (V(3)−t−Δ3 c1)/Δ4")
    b.vector("c2", "c2", c2, decimals=3, unit="")
    b.scalar("c1.c2", "c1 · c2", float(c1 @ c2), decimals=3, unit="")
    b.scalar("defect", tr.gettext("defect"), 0.0, unit="deg")
    b.note(tr.gettext("Eq. (29) with the orthogonality condition: c2 is orthogonal to c1 by "
                      "construction, so variant 2 has no orthogonality defect."))
    return b.build(), c2


def _tp_frame(c1: np.ndarray, c2: np.ndarray, defect_tcpcal_deg: float | None,
              tr: Translator = ENGLISH) -> MathBlock:
    """Paper Eq. (30): ``c3 = c1 × c2`` and ``R_n,n* = [c1 c2 c3]`` with its A, B, C (degrees);
    tcpcal's orthogonality defect when the result is there."""
    c3 = np.cross(c1, c2)
    c3 = c3 / np.linalg.norm(c3)
    Rt = np.column_stack([c1, c2, c3])
    b = _Block("eq30", _paper(tr, "(30)"), "c3 = c1 × c2, R_n,n* = [c1 c2 c3]", tr)
    b.vector("c3", "c3", c3, decimals=3, unit="")
    b.matrix("R_n,n*", "R_n,n*", Rt)
    b.vector("abc", "A,B,C", np.asarray(abc_deg_from_rotation(Rt), dtype=float), unit="°")
    if defect_tcpcal_deg is not None:
        b.scalar("defect_tcpcal", tr.gettext("tcpcal's defect"), float(defect_tcpcal_deg), unit="deg")
    return b.build()


def abc_world_sheet(wizard: AbcWorldWizard, *, tr: Translator = ENGLISH) -> MathSheet:
    """ABC world: (PA-1) the prescribed R_0,n*, (PA-2) ``R_n,n* = R_0,n^T R_0,n*``."""
    steps, R, _ = _poses_mm(wizard)
    blocks = []
    if steps:
        R0n = R[0]
        b = _Block("pa", _label("(PA-1), (PA-2)", _paper(tr, "(4)-(6)")),
                   "R_0,n* = R_0,n R_n,n*  ⇒  R_n,n* = R_0,nᵀ R_0,n*", tr)
        b.matrix("R_0,n", "R_0,n", R0n)
        b.matrix("R_0,n*", "R_0,n*", R_WORLD_TOOL_PARALLEL)
        Rnn = R0n.T @ R_WORLD_TOOL_PARALLEL
        b.matrix("R_n,n*", "R_n,n*", Rnn)
        b.vector("abc", "A,B,C", np.asarray(abc_deg_from_rotation(Rnn), dtype=float), unit="°")
        b.note(tr.gettext("R_0,n is the flange rotation read at the aligned pose; R_0,n* is the orientation "
                          "(PA-1) prescribes (tool X down, Y along WORLD Y, Z along WORLD X)."))
        if getattr(wizard, "variant", "6d") == "5d":
            b.note(tr.gettext("5D: only the first column (tool X) is kept; the turn about X comes from the "
                              "tool's current data."))
            res = wizard.result
            if res is not None and res.rotation is not None:
                b.matrix("R_5d", "R (5D)", np.asarray(res.rotation, dtype=float))
        blocks.append(b.build())
    return _sheet("abc_world", tr.gettext(wizard.title), blocks, _poses_recorded(len(steps), tr))


def tcp_zx_sheet(wizard: TcpZxWizard, pair: tuple[int, int] | None = None, *,
                 tr: Translator = ENGLISH) -> MathSheet:
    """TCP & Z, X (methods.md section 8): the touches as the 4-point's, then
    ``u_k = unit(R_k^T (r - f_k) - t)`` for the z and x poses, Gram-Schmidt keeping z."""
    roles = [s.role for s in wizard.steps]
    touch_steps = [i for i in sorted(wizard.recorded_poses) if roles[i] == "touch"]
    steps, R, f = _poses_mm(wizard, touch_steps)
    axis_blocks: list[MathBlock] = []
    if len(steps) >= 4:
        try:
            origin = solve_xyz4(R, f)
        except TcpcalError:
            origin = None
        if origin is not None:
            t, r = np.asarray(origin.tcp, dtype=float), np.asarray(origin.reference, dtype=float)
            dirs: dict[str, np.ndarray] = {}
            for role in ("z", "x"):
                rows = [i for i in sorted(wizard.recorded_poses) if roles[i] == role]
                if not rows:
                    continue
                _, Rk, fk = _poses_mm(wizard, rows[:1])
                v = Rk[0].T @ (r - fk[0]) - t
                d = float(np.linalg.norm(v))
                b = _Block(f"axis-{role}", "(ZX-1) · (ZX-3)" if role == "z" else "(ZX-2) · (ZX-3)",
                           tr.gettext("the reference on the tool's +{axis} axis: {equation}").format(
                               axis=role.upper(), equation=f"R_kᵀ (r − f_k) − t = d_k {role}"), tr)
                b.matrix("R_k", "R_k", Rk[0])
                b.vector("f_k", "f_k", fk[0])
                b.vector("v", "v", v)
                b.scalar("d", f"d_{role}", d)
                if d > 0:
                    dirs[role] = v / d
                    b.vector("u", role, v / d, decimals=3, unit="")
                axis_blocks.append(b.build())
            if "z" in dirs and "x" in dirs:
                z, xm = dirs["z"], dirs["x"]
                angle = math.degrees(math.atan2(float(np.linalg.norm(np.cross(xm, z))), float(xm @ z)))
                x = xm - (xm @ z) * z
                x = x / np.linalg.norm(x)
                y = np.cross(z, x)
                b = _Block("frame", tr.gettext("methods.md §{section} step {step}").format(section=8, step=5),
                           tr.gettext("z defines, x only completes: x orthogonalised "
                                      "(Gram-Schmidt keeping z), y = z × x"), tr)
                b.scalar("defect", "|90° − ∠(x, z)|", abs(90.0 - angle), unit="deg")
                Rt = np.column_stack([x, y, z])
                b.matrix("R_flange_tool", "[x y z]", Rt)
                b.vector("abc", "A,B,C", np.asarray(abc_deg_from_rotation(Rt), dtype=float), unit="°")
                axis_blocks.append(b.build())
    sheet = _origin_sheet("tcp_zx", tr.gettext(wizard.title), steps, R, f, pair, axis_blocks, tr=tr)
    return sheet


def beam_sheet(wizard: BeamWizard, *, tr: Translator = ENGLISH) -> MathSheet:
    """Beam (BEAM-1): per tip event ``(I - u u^T)(R_i t + f_i - b) = 0``, stacked
    ``(P R_i) t = -P (f_i - b)``: its rank and singular values, and tcpcal's t."""
    _ = tr.gettext
    scan = wizard.scan
    if scan is None:
        return _sheet("beam", _(wizard.title), (), _("No scan yet: press Finish and the controller runs it."))
    tips = [e for e in scan.events if e.kind == "tip"]
    blocks = []
    rows, rhs = [], []
    for k, e in enumerate(tips, start=1):
        Ri, fi = e.T_world_flange[:3, :3], e.T_world_flange[:3, 3] * 1000.0
        bp, u = np.asarray(e.beam_point, dtype=float) * 1000.0, np.asarray(e.beam_dir, dtype=float)
        P = np.eye(3) - np.outer(u, u)
        rows.append(P @ Ri)
        rhs.append(-P @ (fi - bp))
        if k <= 2:                               # the first two in full; the rest are alike
            b = _Block(f"event-{k}", "(BEAM-1)", _("tip event {k}: {equation}").format(
                k=k, equation="(I − u uᵀ)(R_i t + f_i − b) = 0"), tr)
            b.vector("b", "b", bp)
            b.vector("u", "u", u, decimals=3, unit="")
            b.matrix("R_i", "R_i", Ri)
            b.vector("f_i", "f_i", fi)
            blocks.append(b.build())
    if tips:
        A = np.vstack(rows)
        rank, s, _v = rank_and_singular_values(A)
        b = _Block("stack", _label(_("{tag} stacked").format(tag="(BEAM-1)"), "(BEAM-2)"),
                   tr.ngettext("{n} tip event: {equation}", "{n} tip events: {equation}", len(tips)).format(
                       n=len(tips), equation="(P R_i) t = −P (f_i − b)"), tr)
        b.numbers("sigma", "σ", s)
        b.words(N_("rank {rank} of {full}"), rank=rank, full=3)
        res = wizard.result
        if res is not None:
            b.vector("t", "t", np.asarray(res.tcp_mm, dtype=float))
        b.note(_("Each event gives two equations (across the beam); t is observable once the stack "
                 "has rank 3, i.e. events at several tool orientations."))
        blocks.append(b.build())
    return _sheet("beam", _(wizard.title), blocks,
                  tr.ngettext("{n} tip event.", "{n} tip events.", len(tips)).format(n=len(tips)))


def spin_check_sheet(wizard: TcpCheckWizard, *, tr: Translator = ENGLISH) -> MathSheet:
    """TCP check (methods.md section 10): a spin by θ moves the tip by at most
    ``2 sin(θ/2) |t - t_s|``."""
    _ = tr.gettext
    check = getattr(wizard, "check", None)
    if check is None:
        return _sheet("spin_check", _(wizard.title), (), _("No check run yet."))
    b = _Block("spin", "(SC-1), (SC-2)", _("drift {equation}").format(
        equation="|d_i| = 2 |sin(θ/2)| |e_⊥| ≤ 2 sin(θ/2) |e|, e = t − t_s"), tr)
    b.scalar("theta", "θ", float(check.angle_deg), unit="deg")
    devs = [float(r.deviation_mm) for r in check.rows if r.reached]
    b.numbers("drifts", _("drifts (mm)"), devs, decimals=2)
    if check.implied_tcp_error_mm is not None:
        e = float(check.implied_tcp_error_mm)
        b.scalar("error", "|e| (SC-2)", e)
        b.scalar("bound", "2 sin(θ/2) |e|", 2.0 * math.sin(math.radians(float(check.angle_deg)) / 2.0) * e)
    return _sheet("spin_check", _(wizard.title), (b.build(),))


MATH_VIEWS: dict[str, Callable[..., MathSheet]] = {
    "xyz4": xyz4_sheet,
    "reference": reference_sheet,
    "three_point": three_point_sheet,
    "abc_world": abc_world_sheet,
    "tcp_zx": tcp_zx_sheet,
    "beam": beam_sheet,
    "spin_check": spin_check_sheet,
}
"""``Wizard.math_view`` name -> the function building its sheet from the wizard."""

PAIR_VIEWS = frozenset({"xyz4", "tcp_zx"})
"""The sheets that take a chosen pair of touches (``pair=``)."""


def math_sheet(wizard: Wizard, *, pair: tuple[int, int] | None = None,
               tr: Translator = ENGLISH) -> MathSheet | None:
    """The sheet of ``wizard`` by its class's ``math_view`` (None: it declares none), its
    words in ``tr``'s language (the equations' symbols and numbers are the same in every one)."""
    name = getattr(type(wizard), "math_view", None)
    if name is None:
        return None
    build = MATH_VIEWS.get(name)
    if build is None:
        raise ValueError(f"The {wizard.title} wizard declares math view {name!r}; known: {sorted(MATH_VIEWS)}.")
    return build(wizard, pair=pair, tr=tr) if name in PAIR_VIEWS else build(wizard, tr=tr)


# ------------------------------------------------------------------ markdown
def block_html(block: MathBlock, *, font_px: int = MATH_FONT_PX) -> str:
    """The block's lines as one monospace ``<div>`` (raw HTML of our own lines, escaped). A block
    with a line over :data:`MAX_LINE` (the stacked A's rows, :data:`MAX_WIDE_LINE`) is set
    half a pixel tighter per character, so it fits the 320 px presenter panel as well."""
    body = "<br>".join(escape_html(line).replace(" ", "&nbsp;") for line in block.lines)
    tight = " letter-spacing:-0.5px;" if any(len(line) > MAX_LINE for line in block.lines) else ""
    return (f'<div class="math-block" data-key="{escape_html(block.key)}" style="font-family:monospace; '
            f'font-size:{int(font_px)}px; line-height:1.25; white-space:nowrap; overflow-x:auto;{tight}">'
            f"{body}</div>")


def math_markdown(sheet: MathSheet | None, *, font_px: int = MATH_FONT_PX, tr: Translator = ENGLISH) -> str:
    """The whole sheet as viser markdown: per block its label (bold), words, lines and note
    (the sheet's words are in its language already; ``tr``: the words without a sheet)."""
    if sheet is None:
        return tr.gettext("*This method has no worked equations.*")
    parts = [escape_markdown(sheet.intro)] if sheet.intro else []
    for b in sheet.blocks:
        parts.append(f"**{escape_markdown(b.label)}** {escape_markdown(b.title)}")
        parts.append(block_html(b, font_px=font_px))
        if b.note:
            parts.append(escape_markdown(b.note))
    return "\n\n".join(parts)
