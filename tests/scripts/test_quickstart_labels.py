"""The translated quick starts (docs/quickstart/<language>.md) quote the pendant's labels as
that language's catalog shows them.

The labels are the ones the English quick start (docs/quickstart/index.md) quotes in bold:
each is looked up in the catalogs the pendant reads (``tcp_pendant.translation``, with the
message's context where the code has one), and each translated quick start must quote that
translation in bold, and must not quote the English label beside it where the pendant shows
a translation (the English parentheses of the time before the catalogs were complete).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest

from tcp_pendant.translation import LANGUAGE_NAMES, SOURCE_LANGUAGE, Translator, translator
from tcp_pendant.views.language_selector import selector_label

ROOT = Path(__file__).resolve().parents[2]
QUICKSTART = ROOT / "docs" / "quickstart"
TRANSLATED = tuple(code for code in LANGUAGE_NAMES if code != SOURCE_LANGUAGE)

TOUCHING_MESSAGE = "✔ **TOUCHING** the reference tip ({distance} mm ≤ {tolerance} mm)"
"""The distance line within 0.5 mm (``pendant.formatting``)."""


def _message(msgid: str, context: str | None = None) -> Callable[[Translator], str]:
    if context is None:
        return lambda tr: tr.gettext(msgid)
    return lambda tr: tr.pgettext(context, msgid)


def _bold_word(tr: Translator) -> str:
    """The bold word of the TOUCHING line (``BERÜHRT``, ``स्पर्श में``)."""
    found = re.search(r"\*\*(.+?)\*\*", tr.gettext(TOUCHING_MESSAGE))
    assert found, f"{tr.language}: the TOUCHING line has no bold word"
    return found.group(1)


LABELS: dict[str, Callable[[Translator], str]] = {
    "Join the class": _message("Join the class"),                 # views/identity.py JOIN_LABEL
    "Language": selector_label,                                   # "Sprache (Language)"
    "Jog": _message("Jog", "tab"),                                # views/tab_titles.py
    "View": _message("View"),                                     # the Jog tab's folder
    "Mode": _message("Mode"),
    "Jog frame": _message("Jog frame"),
    "Increment": _message("Increment"),
    "Cont.": _message("Cont.", "increment"),
    "Override %": _message("Override %"),
    "TOUCHING": _bold_word,
    "Calibrate": _message("Calibrate", "tab"),
    "XYZ 4-point": _message("XYZ 4-point"),                       # wizards/xyz4.py title
    "Start": _message("Start"),
    "Record": _message("Record"),
    "Next": _message("Next"),
    "Finish": _message("Finish"),
    "Save to tool library": _message("Save to tool library"),
    "TCP check": _message("TCP check"),                           # the Tool tab's folder
}
"""Each label the English quick start quotes in bold → its text in a language."""

OPTIONS = ("Cartesian", "Joint")
"""The Mode's buttons, quoted in plain text ("Cartesian or Joint")."""


def _text(code: str) -> str:
    name = "index.md" if code == SOURCE_LANGUAGE else f"{code}.md"
    return (QUICKSTART / name).read_text(encoding="utf-8")


def _bold_spans(text: str) -> list[str]:
    return re.findall(r"\*\*(.+?)\*\*", text)


def _quoted_labels(text: str) -> set[str]:
    """The labels the English quick start quotes: its bold spans except each step's heading
    (the first bold span of a numbered item, ending with a full stop), a span with arrows
    (``Calibrate → XYZ 4-point → Start.``) read as its labels."""
    headings = set(re.findall(r"^\d+\. \*\*(.+?\.)\*\*", text, flags=re.MULTILINE))
    labels = set()
    for span in _bold_spans(text):
        if span in headings:
            continue
        if "→" in span:
            labels |= {part.strip() for part in span.removesuffix(".").split("→")}
        else:
            labels.add(span)
    return labels


def _without(text: str, phrases: list[str]) -> str:
    for phrase in sorted(phrases, key=len, reverse=True):
        text = text.replace(phrase, " ")
    return text


def test_the_table_holds_exactly_the_labels_the_english_quick_start_quotes() -> None:
    assert _quoted_labels(_text(SOURCE_LANGUAGE)) == set(LABELS)


def test_the_english_labels_are_the_pendants_own() -> None:
    english = translator(SOURCE_LANGUAGE)
    for label, look_up in LABELS.items():
        assert look_up(english) == label
    text = _text(SOURCE_LANGUAGE)
    assert "**TOUCHING** the reference tip" in text
    assert all(option in text for option in OPTIONS)


@pytest.mark.parametrize("code", TRANSLATED)
def test_a_translated_quick_start_quotes_each_label_as_its_catalog_shows_it(code: str) -> None:
    tr = translator(code)
    bold = set(_bold_spans(_text(code)))
    missing = {label: look_up(tr) for label, look_up in LABELS.items() if look_up(tr) not in bold}
    assert missing == {}, f"docs/quickstart/{code}.md lacks in bold (English label: catalog's text)"


@pytest.mark.parametrize("code", TRANSLATED)
def test_a_translated_quick_start_quotes_the_touching_line_and_the_modes_as_shown(code: str) -> None:
    tr = translator(code)
    line = tr.gettext(TOUCHING_MESSAGE).removeprefix("✔ ")
    shown = re.split(r"\s*[(（]\{distance\}", line)[0]        # without "(0.3 mm ≤ 0.5 mm)"
    text = _text(code)
    assert shown != TOUCHING_MESSAGE and shown in text
    assert [tr.gettext(option) for option in OPTIONS if tr.gettext(option) not in text] == []


@pytest.mark.parametrize("code", TRANSLATED)
def test_a_translated_quick_start_keeps_no_english_label_the_pendant_translates(code: str) -> None:
    """The English word stays only where the pendant shows it too (``Sprache (Language)``, or
    a label the catalog keeps as it is, such as German ``Start``)."""
    tr = translator(code)
    translations = [look_up(tr) for look_up in LABELS.values()] + [tr.gettext(o) for o in OPTIONS]
    rest = _without(_text(code), translations)
    left = [label for label in (*LABELS, *OPTIONS)
            if re.search(rf"(?<!\w){re.escape(label)}(?!\w)", rest, flags=re.IGNORECASE)]
    assert left == []


def test_the_german_quick_start_names_the_selector_with_its_english_word_and_nothing_else_english() -> None:
    text = _text("de")
    assert "**Sprache (Language)**" in text
    assert "**Verfahren**" in text and "(Jog)" not in text
    assert "**Vermessen**" in text and "Calibrate" not in text
    assert "**BERÜHRT**" in text and "touching" not in text.lower()
