"""tcpcal's library recovery report, worded by the app (``views.library_words``): in English
the very text tcpcal's ``LibraryRecovery.summary`` gives, in the pseudo-locale from the
catalogs but for the file's paths and tcpcal's own problem lines."""

from __future__ import annotations

from pathlib import Path

import pytest

from support.pseudo_text import english_words

from tcp_pendant.translation import PSEUDO_LANGUAGE, translator
from tcp_pendant.views.library_words import recovery_summary
from tcpcal.library import LibraryRecovery

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

PROBLEMS = tuple(f"slot {i}: tcp_mm[0] must be a finite number, got nan." for i in range(1, 8))


@pytest.mark.parametrize("recovery", [
    LibraryRecovery(Path("/srv/tools.json"), Path("/srv/tools.json.bad"), PROBLEMS[:1], kept_slots=(2, 5)),
    LibraryRecovery(Path("/srv/tools.json"), Path("/srv/tools.json.bad"), PROBLEMS[:3], kept_slots=()),
    LibraryRecovery(Path("/srv/tools.json"), Path("/srv/tools.json.bad"), PROBLEMS, kept_slots=(9,)),
    LibraryRecovery(Path("/srv/tools.json"), Path("/srv/tools.json.bad"), ("not JSON: line 1",), whole_file=True),
], ids=["one-bad", "none-kept", "more", "whole-file"])
def test_the_recovery_summary_in_english_is_tcpcals_and_in_the_pseudo_locale_from_the_catalogs(
        recovery: LibraryRecovery) -> None:
    assert recovery_summary(recovery) == recovery.summary()
    said = recovery_summary(recovery, translator(PSEUDO_LANGUAGE))
    rest = said
    for piece in (str(recovery.backup), str(recovery.path), *recovery.problems):
        rest = rest.replace(piece, " ")
    assert said.startswith("⟦") and english_words(rest, set()) == [], said
    assert all(p in said for p in recovery.problems[:5]) and str(recovery.backup) in said
