"""The catalogs and the translator (``tcp_pendant.translation``): negotiation of a browser's
``Accept-Language``, plural forms from the catalogs, the committed ``.mo`` files compiled from
their ``.po`` sources, the template holding every message of the code, the German catalog
complete with the same placeholders, and the pseudo-locale generated from the template."""

from __future__ import annotations

import io
import re
import runpy
from pathlib import Path

import pytest
from babel.messages.extract import extract_from_dir
from babel.messages.mofile import write_mo
from babel.messages.pofile import read_po

from tcp_pendant.pendant.formatting import dropped_presses_text
from tcp_pendant.translation import (
    LANGUAGE_NAMES,
    LOCALE_DIR,
    PSEUDO_LANGUAGE,
    languages,
    negotiate,
    translator,
)

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

ROOT = Path(__file__).resolve().parents[2]
KEYWORDS = {"_": None, "gettext": None, "N_": None, "ngettext": (1, 2), "pgettext": ((1, "c"), 2)}
"""What scripts/i18n.sh extracts (its -k options plus Babel's defaults that the code uses)."""
PO_FILES = sorted(LOCALE_DIR.glob("*/LC_MESSAGES/tcp_pendant.po"))


@pytest.mark.parametrize(("header", "language"), [
    ("de-DE,de;q=0.9,en-US;q=0.8,en;q=0.7", "de"),           # Chrome in Germany
    ("fr-FR,fr;q=0.9", "en"),                               # nothing offered: the default
    ("fr-FR, ja;q=0.5, de;q=0.4", "ja"),                    # the best offered by quality
    ("es;q=0.5, ru;q=0.5", "es"),                           # a tie: the header's order
    ("en;q=0.1, ru", "ru"),                                 # q=1 by default
    ("de;q=0, es", "es"),                                   # q=0 refuses
    ("zh-CN,zh;q=0.9", "zh_Hans"),
    ("zh-TW", "en"),                                        # Traditional Chinese: no catalog yet
    ("hi-IN", "hi"),
    ("qps-ploc", "en"),                                     # the pseudo-locale is never negotiated
    ("de;q=abc, *", "en"),                                  # unreadable quality, a wildcard
    ("", "en"),
    (None, "en"),
])
def test_negotiate_picks_the_best_offered_language_of_the_header(header: str | None, language: str) -> None:
    assert negotiate(header) == language


def test_negotiate_falls_back_to_the_given_default_and_reads_a_bounded_header() -> None:
    assert negotiate("fr", default="de") == "de"
    assert negotiate("x" * 5000 + ",de") == "en"             # past the first 1000 characters: not read


def test_languages_are_the_seven_of_the_issue_and_unknown_codes_are_refused() -> None:
    assert set(languages()) == {"en", "de", "ru", "hi", "zh_Hans", "es", "ja"} == set(LANGUAGE_NAMES)
    assert languages(include_pseudo=True)[-1] == PSEUDO_LANGUAGE
    with pytest.raises(ValueError, match="Unknown language 'fr'; use one of en, de"):
        translator("fr")


def test_german_plural_forms_come_from_the_catalog() -> None:
    de = translator("de")
    assert dropped_presses_text(1, de) == "1 Verfahrbefehl verworfen: der Server war ausgelastet"
    assert dropped_presses_text(2, de) == "2 Verfahrbefehle verworfen: der Server war ausgelastet"
    assert dropped_presses_text(0, de) == "0 Verfahrbefehle verworfen: der Server war ausgelastet"
    assert dropped_presses_text(1) == "1 jog press dropped: the server was busy"
    assert dropped_presses_text(5) == "5 jog presses dropped: the server was busy"


def test_plural_rules_are_the_languages_own() -> None:
    """Russian has three forms (1, 21: one; 2-4: few; 5-20: many), Hindi two (0 and 1 the
    singular), Japanese and Chinese one: the .po headers say so, and the forms come out by them."""
    for code, n in (("ru", 3), ("ja", 1), ("zh_Hans", 1), ("de", 2), ("hi", 2), ("es", 3)):
        with (LOCALE_DIR / code / "LC_MESSAGES" / "tcp_pendant.po").open("rb") as f:
            assert read_po(f).num_plurals == n, code
    ru = translator("ru")
    assert dropped_presses_text(1, ru) == "1 команда перемещения отброшена: сервер был занят"
    assert dropped_presses_text(3, ru) == "3 команды перемещения отброшены: сервер был занят"
    assert dropped_presses_text(5, ru) == "5 команд перемещения отброшено: сервер был занят"
    assert dropped_presses_text(21, ru) == "21 команда перемещения отброшена: сервер был занят"
    hi = translator("hi")
    assert dropped_presses_text(1, hi) == "1 जॉग प्रेस छूटा: सर्वर व्यस्त था"
    assert dropped_presses_text(3, hi) == "3 जॉग प्रेस छूटे: सर्वर व्यस्त था"
    ja = translator("ja")
    assert dropped_presses_text(1, ja) == "ジョグ操作 1 回を取りこぼしました：サーバがビジーでした"
    assert dropped_presses_text(3, ja) == "ジョグ操作 3 回を取りこぼしました：サーバがビジーでした"


def test_context_separates_the_continuous_increment() -> None:
    assert translator("de").pgettext("increment", "Cont.") == "Kont."
    assert translator("de").gettext("Cont.") == "Cont."        # without the context: not that message


def test_each_committed_mo_is_its_po_compiled() -> None:
    """``scripts/i18n.sh compile`` was run after the last change of a .po (a stale .mo would
    ship other words than the repository's sources)."""
    assert {p.parent.parent.name for p in PO_FILES} == set(languages(include_pseudo=True)) - {"en"}
    for po in PO_FILES:
        with po.open("rb") as f:
            catalog = read_po(f)
        buf = io.BytesIO()
        write_mo(buf, catalog)
        assert po.with_suffix(".mo").read_bytes() == buf.getvalue(), f"{po}: run scripts/i18n.sh compile"


def _template_ids(catalog_path: Path) -> set[tuple[str | None, str]]:
    with catalog_path.open("rb") as f:
        return {(m.context, m.id if isinstance(m.id, str) else m.id[0]) for m in read_po(f) if m.id}


def test_the_template_holds_every_message_of_the_code() -> None:
    """``scripts/i18n.sh extract`` was run after the last wrapped string changed; every
    language's catalog was updated from it (``update``)."""
    in_code = set()
    for _file, _line, message, _comments, context in extract_from_dir(ROOT / "app" / "tcp_pendant", keywords=KEYWORDS):
        in_code.add((context, message if isinstance(message, str) else message[0]))
    template = _template_ids(LOCALE_DIR / "tcp_pendant.pot")
    assert in_code == template, "run scripts/i18n.sh extract update pseudo compile"
    for po in PO_FILES:
        assert _template_ids(po) == template, f"{po}: run scripts/i18n.sh update"


def _fields(text: str) -> list[str]:
    return sorted(re.findall(r"\{[^{}]*\}", text))


@pytest.mark.parametrize("language", [code for code in LANGUAGE_NAMES if code != "en"])
def test_each_language_is_complete_with_the_same_placeholders_and_no_fuzzy_entry(language: str) -> None:
    """Every message of every offered language is translated (every plural form its rule
    asks for), keeps the English message's ``{placeholders}``, code spans and bold marks, and
    none is marked fuzzy (a guess of ``update``'s that nobody checked)."""
    with (LOCALE_DIR / language / "LC_MESSAGES" / "tcp_pendant.po").open("rb") as f:
        catalog = read_po(f)
    missing = []
    for m in catalog:
        if not m.id:
            continue
        assert "fuzzy" not in m.flags, m.id
        ids = (m.id,) if isinstance(m.id, str) else tuple(m.id)
        strings = (m.string,) if isinstance(m.string, str) else tuple(m.string)
        if not all(strings) or len(strings) != (1 if isinstance(m.id, str) else catalog.num_plurals):
            missing.append(ids[0])
            continue
        for s in strings:
            assert _fields(s) == _fields(ids[-1]) or _fields(s) == _fields(ids[0]), (m.id, s)
            assert s.count("`") == ids[0].count("`") and s.count("**") == ids[0].count("**"), (m.id, s)
    assert missing == [], f"{language}: {len(missing)} untranslated, e.g. {missing[:3]}"


def test_the_pseudo_locale_is_generated_from_the_template() -> None:
    module = runpy.run_path(str(ROOT / "scripts" / "pseudo_locale.py"))
    pseudo = module["pseudo"]
    assert pseudo("Record point") == "⟦Ŕéçöŕð þöîñţ⟧"
    assert pseudo("{n} jog at %(x)s, `Shift` <b>&amp;") == "⟦{n} ĵöĝ åţ %(x)s, `Shift` <b>&amp;⟧"
    with (LOCALE_DIR / "tcp_pendant.pot").open("rb") as f:
        generated = module["pseudo_catalog"](read_po(f))
    with (LOCALE_DIR / PSEUDO_LANGUAGE / "LC_MESSAGES" / "tcp_pendant.po").open("rb") as f:
        committed = read_po(f)
    assert {(m.context, str(m.id)): m.string for m in generated if m.id} == \
        {(m.context, str(m.id)): m.string for m in committed if m.id}, "run scripts/i18n.sh pseudo compile"
    qps = translator(PSEUDO_LANGUAGE)
    assert qps.ngettext("{n} jog press dropped: the server was busy",
                        "{n} jog presses dropped: the server was busy", 2).startswith("⟦{n} ĵöĝ þŕéššéš")
