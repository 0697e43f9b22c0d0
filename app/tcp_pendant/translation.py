"""The pendant's words in the trainee's language: gettext catalogs, one translator per session.

The catalogs are the standard library's ``gettext`` ``.mo`` files shipped in the package
(``tcp_pendant/locale/<language>/LC_MESSAGES/tcp_pendant.mo``), compiled from the ``.po``
sources beside them by ``scripts/i18n.sh compile`` (extraction and updates with Babel:
docs/languages.md). English is the source language (no catalog); a message a catalog lacks
falls back to English. Plural forms come from the catalog's ``Plural-Forms`` header
(:meth:`Translator.ngettext`), never from appending "s".

:data:`PSEUDO_LANGUAGE` (``qps``) is the pseudo-locale: every message wrapped and accented
(``⟦Ŕéçöŕð⟧``), generated from the template by ``scripts/i18n.sh pseudo``; tests select it to
find text that bypasses the catalogs. It is not offered to trainees (:func:`languages`).

This module imports nothing of the app (the utilities layer).
"""

from __future__ import annotations

import functools
import gettext
from dataclasses import dataclass, field
from pathlib import Path

__all__ = [
    "DOMAIN",
    "ENGLISH",
    "LANGUAGE_NAMES",
    "LOCALE_DIR",
    "N_",
    "PSEUDO_LANGUAGE",
    "SOURCE_LANGUAGE",
    "Translator",
    "languages",
    "negotiate",
    "translator",
]

DOMAIN = "tcp_pendant"
"""The gettext domain: the catalogs' file name (``tcp_pendant.mo``)."""
LOCALE_DIR = Path(__file__).resolve().parent / "locale"
"""Where the catalogs are: ``LOCALE_DIR / <language> / "LC_MESSAGES" / "tcp_pendant.mo"``."""
SOURCE_LANGUAGE = "en"
"""The language of the messages in the code."""
PSEUDO_LANGUAGE = "qps"
"""The pseudo-locale of the tests (module docstring)."""

LANGUAGE_NAMES: dict[str, str] = {
    "en": "English",
    "de": "Deutsch",
    "es": "Español",
    "ru": "Русский",
    "hi": "हिन्दी",
    "zh_Hans": "中文（简体）",
    "ja": "日本語",
}
"""The languages offered, by catalog code, each named in itself (the selector's entries)."""

# Accept-Language tags whose primary subtag alone does not name our catalog (BCP 47, lower case)
_TAG_ALIASES = {"zh": "zh_Hans", "zh-hans": "zh_Hans", "zh-cn": "zh_Hans", "zh-sg": "zh_Hans",
                "zh-hans-cn": "zh_Hans", "zh-hans-sg": "zh_Hans"}
_NOT_SIMPLIFIED = ("zh-hant", "zh-tw", "zh-hk", "zh-mo")
_MAX_HEADER = 1000          # characters of an Accept-Language header read (a browser sends < 200)


def N_(message: str) -> str:
    """Marks ``message`` for extraction where it is defined (a module constant) and returns it
    unchanged; it is translated where it is shown (``tr.gettext(CONSTANT)``)."""
    return message


@dataclass(frozen=True)
class Translator:
    """The messages of one language (a session holds one; switching language swaps it).

    Attributes:
        language: the catalog code (``"de"``), ``"en"`` for the source language.
    """

    language: str
    catalog: gettext.NullTranslations = field(repr=False, compare=False)

    def gettext(self, message: str) -> str:
        """``message`` in this language (itself when the catalog lacks it)."""
        return self.catalog.gettext(message)

    def ngettext(self, singular: str, plural: str, n: int) -> str:
        """The form of ``singular``/``plural`` for the count ``n`` by the language's plural
        rule (German 2 forms, Russian 3, Japanese and Chinese 1); the caller formats ``n``
        into the result (``.format(n=n)``)."""
        return self.catalog.ngettext(singular, plural, n)

    def pgettext(self, context: str, message: str) -> str:
        """``message`` in ``context`` (the same English word with two meanings: a ``Record``
        button, a ``Record`` noun)."""
        return self.catalog.pgettext(context, message)


def languages(*, include_pseudo: bool = False) -> tuple[str, ...]:
    """The language codes offered (:data:`LANGUAGE_NAMES`), the pseudo-locale last if asked."""
    codes = tuple(LANGUAGE_NAMES)
    return codes + (PSEUDO_LANGUAGE,) if include_pseudo else codes


def _known(include_pseudo: bool) -> frozenset[str]:
    return frozenset(languages(include_pseudo=include_pseudo))


@functools.lru_cache(maxsize=16)
def translator(language: str) -> Translator:
    """The translator of ``language`` (a code of :func:`languages`, or the pseudo-locale).

    Raises:
        ValueError: an unknown code (naming the known ones).
    """
    if language not in _known(include_pseudo=True):
        raise ValueError(f"Unknown language {language!r}; use one of {', '.join(languages(include_pseudo=True))}.")
    if language == SOURCE_LANGUAGE:
        return Translator(language, gettext.NullTranslations())
    catalog = gettext.translation(DOMAIN, LOCALE_DIR, languages=[language], fallback=True)
    return Translator(language, catalog)


def _tag_language(tag: str, known: frozenset[str]) -> str | None:
    """Our catalog for one BCP 47 tag (``de-AT`` → ``de``, ``zh-CN`` → ``zh_Hans``), or None."""
    tag = tag.strip().lower().replace("_", "-")
    if not tag or tag == "*":
        return None
    if tag in _TAG_ALIASES:
        return _TAG_ALIASES[tag]
    if tag.startswith(_NOT_SIMPLIFIED):
        return None                              # Traditional Chinese: no catalog yet
    primary = tag.split("-", 1)[0]
    if primary == "zh":
        return "zh_Hans"
    return primary if primary in known else None


def negotiate(accept_language: str | None, default: str = SOURCE_LANGUAGE) -> str:
    """The language to start with for an ``Accept-Language`` header (RFC 9110 12.5.4): the
    offered language of the highest quality, the header's order breaking ties; ``default``
    when none is offered (or the header is missing or unreadable). ``q=0`` refuses a tag.

    ``"de-DE,de;q=0.9,en;q=0.8"`` → ``"de"``; ``"fr-FR, ja;q=0.5"`` → ``"ja"``.
    """
    if not accept_language:
        return default
    known = _known(include_pseudo=False)
    best: tuple[float, int, str] | None = None
    for order, item in enumerate(accept_language[:_MAX_HEADER].split(",")):
        tag, _, params = item.partition(";")
        quality = 1.0
        for param in params.split(";"):
            name, _, value = param.strip().partition("=")
            if name.strip().lower() == "q":
                try:
                    quality = float(value)
                except ValueError:
                    quality = 0.0
        if not 0.0 < quality <= 1.0:
            continue
        language = _tag_language(tag, known)
        if language is not None and (best is None or (-quality, order) < (-best[0], best[1])):
            best = (quality, order, language)
    return default if best is None else best[2]


ENGLISH = translator(SOURCE_LANGUAGE)
"""The source language's translator: the default ``tr`` of every function that composes text
(``def words(..., tr: Translator = ENGLISH)``), so tests and the CLI get English."""
