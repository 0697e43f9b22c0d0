r"""The trainee's name ("Your name"): what the pendant accepts and how it is normalised.

A name is what the trainer reads in the gradebook, so it must be visible text: after
:func:`validate_trainee_name` it is NFC-normalised (the same letters typed on two keyboards give
the same name), stripped, runs of spaces are one space, it has 1..40 characters and no control,
format or other invisible character.

Why not ``tcpcal.tool``'s tool-name check: that check is private (``_check_name``) and carries
a controller's rules that do not apply to people (at most 24 characters, no double quote, no
surrounding spaces instead of stripping them). The rule both share is Python's
``str.isprintable`` (no Unicode category C*, no separator but the space), used here as there;
on top of it this module refuses the braille blank, a symbol that draws nothing, and every
default-ignorable code point (below), which ``isprintable`` partly lets through.

Default-ignorable code points (Unicode's ``Default_Ignorable_Code_Point`` property,
DerivedCoreProperties.txt; The Unicode Standard, section 5.21): variation selectors, the
Mongolian free variation selectors, the Khmer inherent vowels U+17B4/U+17B5, the Hangul fillers,
the combining grapheme joiner, the tag characters and the format characters. A renderer draws
them as nothing, so "Alice" followed by VARIATION SELECTOR-16 shows as "Alice" in the trainer's
table, yet is another name. They are **refused, not stripped**: what the trainee typed is what the
gradebook keeps and what they type again after a reload, and the refusal names the code point
(U+FE0F ...) so they know what to retype; stripping would store a name they did not type. The
two exceptions are the joiners that change how a word is drawn: ZERO WIDTH NON-JOINER (U+200C)
and ZERO WIDTH JOINER (U+200D) are part of the correct spelling of many Persian, Arabic-script and
Indic names, so a name keeps one where UAX #31 (Unicode Identifiers and Syntax), section 2.3,
"Layout and Format Control Characters", allows it in an identifier: ZWNJ between a character
that joins to its left and one that joins to its right (A1: it breaks a cursive join, as in
Persian "علی‌اکبر"), ZWNJ after a virama (A2) and ZWJ after a virama not followed by a
dual-joining character (B: Indic half forms). Anywhere else a joiner draws nothing ("Al‌ice",
or ZWNJ after Persian dal, which joins no letter after it) and is refused; emoji sequences
(woman + ZWJ + laptop) are refused too, a name is letters. UTS #39 (Unicode Security
Mechanisms), section 3.1, "General Security Profile for Identifiers", restricts the same set
(Identifier_Type Default_Ignorable) and allows the two joiners.

The table: the ``regex`` package (PyPI; wheels on every platform a classroom PC runs), whose
``\p{Default_Ignorable_Code_Point}``, ``\p{Joining_Type=...}`` and
``\p{Canonical_Combining_Class=Virama}`` are generated from the Unicode Character Database of
its release (Unicode 17.0 in regex 2026.12.2); Python's ``unicodedata`` (Unicode 14.0 in 3.11)
has none of these properties. Python's older Unicode only matters for NFC and NFKC here: the
default-ignorable set is the same in Unicode 14.0 to 17.0 (4174 code points), so the two versions
agree on it.

Look-alikes (:func:`name_keys`, :func:`looks_alike`): two different names that a reader cannot
tell apart ("Alice" and "Аlice" with a Cyrillic А, "ＡＬＩＣＥ", "Aĺice") would let a second
browser pass for a trainee in the trainer's table. Names are compared by a confusable skeleton
after Unicode TR39 (UTS #39, section 4, "Confusable Detection"): NFKC, then TR39's skeleton
(NFD, every default-ignorable code point removed, every character replaced by its prototype
from Unicode's ``confusables.txt``, NFD again), once with the letters' case kept and once
case-folded. The removal covers the whole default-ignorable set, the joiners a name may keep
included ("علی‌اکبر" and "علیاکبر" look alike), and holds for every name a gradebook holds,
whichever check let it in: the comparison reads the stored names and computes their keys each
time (``Gradebook.trainees.join``), no key is stored. Two names look alike when either skeleton
is the same. On top of TR39 the diacritics of the Combining Diacritical Marks blocks are
dropped (after NFD): TR39 keeps "Aĺice" (l with acute) apart from "Alice", but at the size of a
table row the acute is a dot over the l, so here they look alike, and so do "José" and "Jose"
(a class with both asks one of them to add an initial). Marks that are vowels of their own
script (Devanagari, Thai, Hebrew and Arabic points ...) are not in those blocks and stay.

The confusable data: ``confusable-homoglyphs`` (PyPI; pure Python, a wheel on every platform a
classroom PC runs), which ships Unicode's ``confusables.txt`` as a table. Chosen over PyICU's
``SpoofChecker.getSkeleton`` (ICU's own TR39 skeleton) because PyICU has no wheels and must be
compiled against an installed ICU, which a trainer's Windows or macOS PC does not have. The
package has no skeleton function, and its table lists each mapping both ways (a source
character under its prototype and the prototype under the source), so :func:`_prototypes`
rebuilds the direction: in ``confusables.txt`` a source is one character mapped to exactly one
prototype and a prototype is never a source, so a character listed with several others, or
with a string of several characters, is a prototype; a character listed with exactly one
other that is listed with it alone is one of a pair, and the pair gets its smaller code point as
the shared prototype (the same classes: only which member names a class differs). Checked when
written against PyICU 2.17 / ICU 72: the classes of the table's 8167 characters are ICU's
skeleton classes but for one pair where the two Unicode versions differ (U+1E9A).

Names are data: the views must still show them through ``escape_markdown``.
"""

from __future__ import annotations

import re
import unicodedata
from functools import lru_cache

import regex
from confusable_homoglyphs import confusables

from tcp_pendant.translation import ENGLISH, N_, Translator

__all__ = ["MAX_TRAINEE_NAME_LENGTH", "TraineeNameError", "looks_alike", "name_keys", "skeleton",
           "validate_trainee_name"]

MAX_TRAINEE_NAME_LENGTH: int = 40
"""Longest trainee name, in characters (after normalisation)."""

#: Printable by ``str.isprintable``, not default-ignorable, but drawn as nothing: BRAILLE PATTERN BLANK.
_BLANK_SYMBOLS = frozenset("\u2800")
#: Unicode's Default_Ignorable_Code_Point (module docstring): one such code point.
_DEFAULT_IGNORABLE = regex.compile(r"\p{Default_Ignorable_Code_Point}")
#: The joiners where UAX #31, section 2.3, lets an identifier keep them (A1, A2, B); matched at
#: the joiner's index of the whole name, so the look-behinds see the letters before it.
_KEPT_JOINER = regex.compile(
    r"(?<=[\p{Joining_Type=Dual_Joining}\p{Joining_Type=Left_Joining}]\p{Joining_Type=Transparent}*)"
    r"\u200c(?=\p{Joining_Type=Transparent}*[\p{Joining_Type=Dual_Joining}\p{Joining_Type=Right_Joining}])"
    r"|(?<=\p{L}\p{Mn}*\p{Canonical_Combining_Class=Virama}[\p{Mn}&&\P{Canonical_Combining_Class=0}]*)"
    r"(?:\u200c|\u200d(?!\p{Joining_Type=Dual_Joining}))",
    regex.V1)
_SPACES = re.compile(" {2,}")


class TraineeNameError(ValueError):
    """A name the pendant does not accept; the message says why and what to type instead.

    Args:
        message: the English msgid (``N_``) with named placeholders; ``str(error)`` is it filled
            in English.
        values: the placeholders' values (plain text: names, numbers).
    """

    def __init__(self, message: str, **values: object) -> None:
        self.message = message
        self.values = {key: str(value) for key, value in values.items()}
        super().__init__(message.format(**self.values))

    def words(self, tr: Translator = ENGLISH) -> str:
        """The message in ``tr``'s language (plain text)."""
        return tr.gettext(self.message).format(**self.values)


def validate_trainee_name(text: object) -> str:
    """Check and normalise a trainee's name.

    Args:
        text: what the browser sent (anything; only a str can pass).

    Returns:
        The name as stored and shown: NFC, stripped, single spaces, 1..40 characters.

    Raises:
        TraineeNameError: not a string, empty, longer than 40 characters, or holding a control
            or invisible character (the message names it by its code point and Unicode name):
            a default-ignorable code point but for a joiner in a UAX #31 context (module docstring).
    """
    if not isinstance(text, str):
        raise TraineeNameError(N_("a name must be text, got {kind}; type your name."), kind=type(text).__name__)
    name = _SPACES.sub(" ", unicodedata.normalize("NFC", text).strip())
    for i, ch in enumerate(name):
        if ch in "\u200c\u200d" and _KEPT_JOINER.match(name, i):
            continue
        if not ch.isprintable() or ch in _BLANK_SYMBOLS or _DEFAULT_IGNORABLE.match(ch):
            what = unicodedata.name(ch, unicodedata.category(ch))
            raise TraineeNameError(
                N_("your name contains an invisible or control character, {code} ({what}); "
                   "type it again with visible letters only."), code=f"U+{ord(ch):04X}", what=what)
    if not name:
        raise TraineeNameError(N_("your name is empty; type the name your trainer should see "
                                  "(1 to {most} characters)."), most=MAX_TRAINEE_NAME_LENGTH)
    if len(name) > MAX_TRAINEE_NAME_LENGTH:
        raise TraineeNameError(N_("your name has {n} characters; shorten it to at most {most}."),
                               n=len(name), most=MAX_TRAINEE_NAME_LENGTH)
    return name


# --------------------------------------------------------------------------- look-alikes

#: The Combining Diacritical Marks blocks (and Extended, Supplement, for Symbols, Half Marks):
#: accents on Latin, Greek and Cyrillic letters, dropped when names are compared.
_DIACRITIC_BLOCKS = ((0x0300, 0x036F), (0x1AB0, 0x1AFF), (0x1DC0, 0x1DFF), (0x20D0, 0x20FF), (0xFE20, 0xFE2F))
_BIDI_MARKS = dict.fromkeys(map(ord, "\u200e\u200f"))    # the table wraps right-to-left text in them


@lru_cache(maxsize=1)
def _prototypes() -> dict[str, str]:
    """Source character -> its prototype string (the direction rebuilt: module docstring)."""
    table = {key.translate(_BIDI_MARKS): [e["c"].translate(_BIDI_MARKS) for e in entries]
             for key, entries in confusables.confusables_data.items()}
    out: dict[str, str] = {}
    for key, others in table.items():
        if len(key) > 1 or len(others) > 1:          # a prototype: each other is one of its sources
            for other in others:
                if len(other) == 1:
                    out.setdefault(other, key)
        else:
            other = others[0]
            if len(other) > 1 or len(table.get(other, ())) > 1:
                out.setdefault(key, other)            # a source of the prototype ``other``
            else:                                     # a pair: the smaller code point names it
                small, large = sorted((key, other))
                out.setdefault(large, small)
    return out


def _is_diacritic(ch: str) -> bool:
    o = ord(ch)
    return any(lo <= o <= hi for lo, hi in _DIACRITIC_BLOCKS)


def skeleton(text: str) -> str:
    """TR39's skeleton of ``text`` (UTS #39, section 4): NFD, default-ignorable code points
    removed, each character replaced by its confusable prototype, NFD again (the prototypes as
    :func:`_prototypes` names them)."""
    table = _prototypes()
    visible = _DEFAULT_IGNORABLE.sub("", unicodedata.normalize("NFD", text))
    return unicodedata.normalize("NFD", "".join(table.get(ch, ch) for ch in visible))


@lru_cache(maxsize=4096)
def name_keys(name: str) -> tuple[str, str]:
    """The two comparison keys of a name: its skeleton with the case kept ("Ivan" and "lvan"
    look alike: capital I and small l) and case-folded ("ALICE" and "Alice"), each of NFKC
    text and with the diacritics dropped (module docstring)."""
    text = unicodedata.normalize("NFKC", name)
    cased = skeleton(text)
    folded = skeleton(skeleton(text.casefold()).casefold())   # a prototype may be a capital letter

    def bare(s: str) -> str:
        return "".join(ch for ch in s if not _is_diacritic(ch))

    return bare(cased), bare(folded)


def looks_alike(a: str, b: str) -> bool:
    """Whether two names cannot be told apart by eye (either of :func:`name_keys` is equal)."""
    ka, kb = name_keys(a), name_keys(b)
    return ka[0] == kb[0] or ka[1] == kb[1]
