"""What a trainee is told when a restart brings their calibrations back
(``classroom.restore.restored_words``): plural forms by the language's rule, the method's title
in the trainee's language, and nothing outside the catalogs in the pseudo-locale."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from support.pseudo_text import untranslated_words

from tcp_pendant.classroom.restore import restored_words
from tcp_pendant.translation import PSEUDO_LANGUAGE, translator
from tcp_pendant.wizards.xyz4 import Xyz4Wizard


def _restored(n_open: int, n_finished: int) -> list[Any]:
    run = SimpleNamespace(wizard=SimpleNamespace(title=Xyz4Wizard.title))
    return ([SimpleNamespace(run=run, finished=False)] * n_open + [SimpleNamespace(run=run, finished=True)] * n_finished)


def test_english_counts_and_names_the_method() -> None:
    assert restored_words(_restored(1, 0)) == \
        "1 calibration you had in progress came back, at its step with its touches."
    assert restored_words(_restored(2, 1)) == (
        "2 calibrations you had in progress came back, each at its step with its touches. "
        "Your XYZ 4-point result not saved yet came back: save it to the tool library or close it.")


def test_russian_takes_its_three_plural_forms_and_the_method_in_russian() -> None:
    ru = translator("ru")
    assert restored_words(_restored(1, 0), tr=ru).startswith("Восстановлена 1 незавершённая калибровка")
    assert restored_words(_restored(3, 0), tr=ru).startswith("Восстановлены 3 незавершённые калибровки")
    assert restored_words(_restored(5, 0), tr=ru).startswith("Восстановлено 5 незавершённых калибровок")
    assert ru.gettext(Xyz4Wizard.title) in restored_words(_restored(0, 1), tr=ru)


def test_the_pseudo_locale_leaves_no_english_word() -> None:
    qps = translator(PSEUDO_LANGUAGE)
    assert untranslated_words(restored_words(_restored(2, 1), tr=qps), set()) == []
