"""Write the pseudo-locale's catalog (qps) from the template: every message wrapped and accented.

    python scripts/pseudo_locale.py app/tcp_pendant/locale/tcp_pendant.pot \
        app/tcp_pendant/locale/qps/LC_MESSAGES/tcp_pendant.po

``Record point`` becomes ``⟦Ŕéçöŕð þöîñţ⟧``: a test that finds a visible word outside ``⟦ ⟧``
has found text that bypasses the catalogs. Placeholders (``{n}``, ``%s``, ``%(name)s``,
``%.2f``), Markdown code spans (key names: `` `Shift` ``), HTML tags and entities stay as they
are, so the pseudo-locale formats like English. Plural forms as English's (two).
Run by ``scripts/i18n.sh pseudo``; needs Babel (the test extra).
"""

from __future__ import annotations

import re
import sys

from babel.messages.catalog import Catalog
from babel.messages.pofile import read_po, write_po

ACCENTED = str.maketrans(
    "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ",
    "åƀçðéƒĝĥîĵķļɱñöþǫŕšţûṽŵẋýžÅƁÇÐÉƑĜĤÎĴĶĻṀÑÖÞǪŔŠŢÛṼŴẊÝŽ")
"""Each ASCII letter to an accented look-alike (still readable, never ASCII)."""
KEEP = re.compile(r"\{[^{}]*\}|%(?:\([^)]*\))?[-+ #0]*\d*(?:\.\d+)?[sdifgeEcr%]|`[^`]*`|<[^<>]*>|&\w+;")
"""What stays as it is: format placeholders, code spans, HTML tags and entities."""
OPEN, CLOSE = "⟦", "⟧"


def pseudo(text: str) -> str:
    """``text`` wrapped in ``⟦ ⟧`` and accented outside :data:`KEEP` ("" stays "")."""
    if not text:
        return text
    out, last = [], 0
    for m in KEEP.finditer(text):
        out.append(text[last:m.start()].translate(ACCENTED))
        out.append(m.group(0))
        last = m.end()
    out.append(text[last:].translate(ACCENTED))
    return OPEN + "".join(out) + CLOSE


def pseudo_catalog(template: Catalog) -> Catalog:
    """The qps catalog of ``template`` (English plural rule)."""
    catalog = Catalog(locale="en", domain=template.domain, project=template.project,
                      version=template.version, fuzzy=False)
    for message in template:
        if not message.id:
            continue
        if isinstance(message.id, tuple | list):
            string: str | tuple[str, ...] = (pseudo(message.id[0]), pseudo(message.id[1]))
        else:
            string = pseudo(message.id)
        catalog.add(message.id, string, locations=message.locations, flags=message.flags - {"fuzzy"},
                    context=message.context)
    return catalog


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print("usage: pseudo_locale.py TEMPLATE.pot OUT.po", file=sys.stderr)
        return 2
    with open(argv[0], "rb") as f:
        template = read_po(f)
    with open(argv[1], "wb") as f:
        write_po(f, pseudo_catalog(template), width=100, omit_header=False)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
