"""The pseudo-locale's check of a text: which words bypass the catalogs.

With the pseudo-locale (``translation.PSEUDO_LANGUAGE``) every message of the catalogs shows as
``⟦Ŕéçöŕð⟧``; a plain ASCII word outside those spans came from the code, not the catalogs.
"""

from __future__ import annotations

import re
from collections.abc import Iterator

import viser

__all__ = ["WORD", "english_words", "gui_texts", "untranslated_words"]

PSEUDO_SPAN = re.compile(r"⟦[^⟦⟧]*⟧")
CODE_SPAN = re.compile(r"`[^`]*`|```.*?```", re.S)
TAG = re.compile(r"<[^<>]*>")
WORD = re.compile(r"[A-Za-z][A-Za-z0-9]*")


def untranslated_words(text: str, names: set[str]) -> list[str]:
    """The ASCII words of ``text`` outside the pseudo-locale's ``⟦ ⟧`` spans and code blocks
    (the readouts' fixed tables and key names) and HTML tags (hidden markup, not shown) that
    are not ``names``."""
    rest = CODE_SPAN.sub(" ", PSEUDO_SPAN.sub(" ", TAG.sub(" ", text)))
    return [w for w in WORD.findall(rest) if w not in names]


def english_words(text: str, names: set[str]) -> list[str]:
    """The ASCII words of ``text`` inside the pseudo-locale's spans too (a placeholder's value
    left in English: ``⟦Ŕéçöŕðéð: your touches⟧``), outside code blocks and HTML tags, that are
    not ``names``: the pseudo-locale accents every letter of a translated message."""
    rest = CODE_SPAN.sub(" ", TAG.sub(" ", text)).replace("⟦", " ").replace("⟧", " ")
    return [w for w in WORD.findall(rest) if w not in names]


def gui_texts(handle: object) -> Iterator[str]:
    """The texts a GUI handle shows: its label, hint and content, a button group's or a
    dropdown's options."""
    for prop in ("label", "hint", "content"):
        value = getattr(handle, prop, None)
        if isinstance(value, str) and value:
            yield value
    if isinstance(handle, viser.GuiButtonGroupHandle | viser.GuiDropdownHandle):
        yield from (str(o) for o in handle.options)
