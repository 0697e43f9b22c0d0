"""The pseudo-locale's word check for "The math": the equations' symbols exempt.

"The math" (``calibrate.math_view``) writes its equations as monospace lines of symbols and
numbers, not LaTeX (its module docstring says why), and they are the same in every language:
they never go through the catalogs, while every word around them does. So the check of
``support.pseudo_text.untranslated_words`` would flag the symbols; :func:`untranslated_outside_math`
leaves them out first.
"""

from __future__ import annotations

import re

from support.pseudo_text import untranslated_words

__all__ = ["MATH_FUNCTIONS", "untranslated_outside_math"]

EQUATION_TAG = re.compile(r"\\?\((?:4P|REF|PA|ZX|BEAM|SC)\\?-\d+[a-z]?\\?\)")
"""An equation's tag as methods.md numbers it: ``(4P-2)``, ``(4P-1a)``, ``(REF-1)``, ``(BEAM-2)``
(in markdown perhaps escaped: ``\\(PA\\-1\\)``)."""
ENTITY = re.compile(r"&#?\w+;")
SYMBOL = re.compile(r"[A-Za-z][0-9]*")
"""A symbol: one letter, perhaps with digits (``t``, ``R``, ``c1``, ``c11``, ``V``; the subscripts
₁₂ and primes are not ASCII); the words' check takes ``R_i`` apart into ``R`` and ``i``."""
MATH_FUNCTIONS = frozenset({"sin", "pinv"})
"""Functions written as words inside the equations: ``2 sin(θ/2) |e|``, ``t_pinv``."""


def untranslated_outside_math(text: str, names: set[str]) -> list[str]:
    """The ASCII words of ``text`` that bypass the catalogs, the math left out.

    Why it leaves out what it does: the equations are symbols, identical in every language and
    written by the code, never translated; they are (1) the symbols (one letter with optional
    digits: :data:`SYMBOL`), (2) the functions written as words (:data:`MATH_FUNCTIONS`), (3)
    the equations' tags of methods.md (:data:`EQUATION_TAG`) and (4) the HTML entities of the
    monospace lines (``&nbsp;``: markup, not shown as a word). There is no LaTeX and no ``$...$``
    math to strip: the sheets have none. What stays must be a pseudo-locale span, a name of
    ``names`` (frames, units, tool names) or a number. The price: a single-letter English word
    ("a") outside a span would pass; every sentence the sheets write has longer words too.
    """
    rest = ENTITY.sub(" ", EQUATION_TAG.sub(" ", text))
    return [w for w in untranslated_words(rest, names) if not SYMBOL.fullmatch(w) and w not in MATH_FUNCTIONS]
