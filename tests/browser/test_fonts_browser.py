"""No boxes instead of letters (tofu), in chromium, for every language of the pendant.

For each language (German, Spanish, Russian, Hindi, Simplified Chinese, Japanese, and the
pseudo-locale) every distinct character of its catalog's translations (while a catalog is empty:
a sample of its script, ``support.catalog_text``) is drawn on a canvas in the page, once with the
panel's font stack (the computed ``font-family`` of the panel's buttons) and once with viser's
3D-label font stack (``LABEL_FONT_STACK``, read from viser's own ``client/src/label/GlyphAtlas.ts``:
the labels are drawn on a canvas with it), and compared with the drawing of U+10FFFD, a
private-use code point no font has: the browser draws the missing-glyph box for both, so identical
pixels mean tofu. Without the fonts ``scripts/run-tests.sh`` installs (Devanagari, CJK) this test
fails, listing the characters per language and font stack.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import viser

from support.catalog_text import catalog_chars

pytestmark = pytest.mark.browser

LANGUAGES = ("de", "es", "ru", "hi", "zh_Hans", "ja", "qps")
NO_FONT_CODEPOINT = "\U0010FFFD"

GLYPH_ATLAS = Path(viser.__file__).resolve().parent / "client" / "src" / "label" / "GlyphAtlas.ts"


def label_font_stack() -> str:
    """viser's ``LABEL_FONT_STACK``, as its label renderer declares it."""
    m = re.search(r"LABEL_FONT_STACK\s*=\s*'([^']+)'", GLYPH_ATLAS.read_text(encoding="utf-8"))
    assert m, f"no LABEL_FONT_STACK in {GLYPH_ATLAS}"
    return m.group(1)


# chars: one string per character; returns the ones drawn exactly like the missing-glyph box,
# and whether that box draws anything at all (else the comparison would be blind)
TOFU_JS = """([chars, font, noFont]) => {
  const c = document.createElement('canvas');
  c.width = 96; c.height = 64;
  const ctx = c.getContext('2d', {willReadFrequently: true});
  const draw = (ch) => {
    ctx.clearRect(0, 0, c.width, c.height);
    ctx.font = `40px ${font}`;
    ctx.fillStyle = '#000';
    ctx.textBaseline = 'alphabetic';
    ctx.fillText(ch, 8, 48);
    return ctx.getImageData(0, 0, c.width, c.height).data;
  };
  const box = draw(noFont);
  const inked = box.some((v, i) => i % 4 === 3 && v > 0);
  const same = (a) => a.length === box.length && a.every((v, i) => v === box[i]);
  return {inked, tofu: chars.filter((ch) => same(draw(ch)))};
}"""


def test_no_character_of_any_catalog_draws_as_a_box(app_factory, new_page: Callable[..., Any]) -> None:
    app = app_factory()
    page = new_page(app.url)
    panel_font = str(page.get_by_role("button", name="Record point").first.evaluate(
        "e => getComputedStyle(e).fontFamily"))
    stacks = {"panel": panel_font, "3D labels": label_font_stack()}
    problems: list[str] = []
    sources: dict[str, str] = {}
    for language in LANGUAGES:
        chars, from_catalog = catalog_chars(language)
        sources[language] = f"{len(chars)} characters from the {'catalog' if from_catalog else 'sample'}"
        for where, font in stacks.items():
            out = page.evaluate(TOFU_JS, [list(chars), font, NO_FONT_CODEPOINT])
            assert out["inked"], f"the missing-glyph box draws nothing in {font!r}: the check would be blind"
            if out["tofu"]:
                problems.append(f"{language} ({where}: {font}): {''.join(out['tofu'])!r} "
                                f"({', '.join(f'U+{ord(c):04X}' for c in out['tofu'][:12])})")
    print("font stacks:", stacks, "| characters:", sources)
    assert not problems, ("characters drawn as boxes (tofu): install the fonts (docs/languages.md, Fonts):\n"
                          + "\n".join(problems))
