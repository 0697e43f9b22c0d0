"""What each language's catalog will show in the browser, for the font and layout tests: the
characters of its translations and its longest translations, read from the ``.po`` sources with
Babel (the compiled ``.mo`` files are compiled from them: ``tests/app/test_translation.py``).

While a catalog is still empty (its translators have not started), a fixed sample of its script
stands in (:data:`SCRIPT_SAMPLES`): the language's name and a few domain words as the glossary
(docs/languages.md) or the vendors' HMIs write them. Once a catalog has translations, the
characters come from them (and the sample's only from the language's own name, which the
language selector always shows).
"""

from __future__ import annotations

from pathlib import Path

from babel.messages.catalog import Catalog
from babel.messages.pofile import read_po
from tcp_pendant.translation import DOMAIN, LANGUAGE_NAMES, LOCALE_DIR

__all__ = ["SCRIPT_SAMPLES", "catalog", "catalog_chars", "translations"]

SCRIPT_SAMPLES: dict[str, str] = {
    "de": "Werkzeug vermessen: XYZ 4-Punkt, Berührung, Flanschkoordinatensystem, Größe ÄÖÜäöüß „Ä“",
    "es": "Calibración de la herramienta: ¿Tocar la punta de referencia? ¡Guardar! áéíóúñÁÉÍÓÚÑü",
    "ru": "Калибровка инструмента: фланец, опорное острие, касание, ёЁ щЩ ъЪ ыЫ эЭ юЮ яЯ «Готово»",
    "hi": "उपकरण अंशांकन: फ़्लैंज, संदर्भ नोक, स्पर्श दर्ज करें। टूल फ़्रेम ०१२३४५६७८९",
    "zh_Hans": "工具标定：法兰、参考尖端、触碰、记录点，工具坐标系。「完成」",
    "ja": "ツール座標設定：フランジ、基準ピン、タッチアップ、点を記録。ツール座標系「完了」",
    "qps": "⟦Ŕéçöŕð Îñçŕéɱéñţ⟧",
}
"""Per language, text of its script that stands in while its catalog has no translation (the
pseudo-locale's catalog is generated whole: its sample is only a fallback)."""


def po_path(language: str) -> Path:
    return LOCALE_DIR / language / "LC_MESSAGES" / f"{DOMAIN}.po"


def catalog(language: str) -> Catalog:
    """The language's ``.po`` catalog, read with Babel."""
    with po_path(language).open("rb") as f:
        return read_po(f, locale=None if language == "qps" else language)


def translations(language: str) -> list[str]:
    """Every non-empty translation of the language's catalog (each plural form one entry), the
    header left out."""
    out: list[str] = []
    for message in catalog(language):
        if not message.id:
            continue                                       # the header
        forms = message.string if isinstance(message.string, tuple | list) else (message.string,)
        out.extend(f for f in forms if f)
    return out


def catalog_chars(language: str) -> tuple[str, bool]:
    """(the distinct characters the browser will draw for ``language``, sorted; whether they
    come from the catalog). From the catalog's translations plus the language's own name when
    it has any, else from :data:`SCRIPT_SAMPLES`."""
    texts = translations(language)
    from_catalog = bool(texts)
    if not from_catalog:
        texts = [SCRIPT_SAMPLES[language]]
    texts.append(LANGUAGE_NAMES.get(language, ""))
    chars = {c for t in texts for c in t if not c.isspace()}
    return "".join(sorted(chars)), from_catalog
