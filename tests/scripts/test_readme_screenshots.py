"""The caption under the 4-point screenshot (docs/trainer.md) quotes the seeded run of
``scripts/readme_screenshots.py`` (regenerating gave 0.72 mm while the caption said
0.51 mm). The calibration is computed here without a browser, by the function the script
itself uses for the caption and checks the browser's page against."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[2]


def script() -> ModuleType:
    spec = importlib.util.spec_from_file_location("readme_screenshots", ROOT / "scripts" / "readme_screenshots.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module            # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def test_trainer_guide_caption_quotes_the_seeded_run() -> None:
    s = script()
    figures = s.seeded_figures()
    error, inside, ci95 = s.caption_figures((ROOT / "docs" / "trainer.md").read_text(encoding="utf-8"))
    assert error == pytest.approx(figures.position_error_mm, abs=0.005)
    assert ci95 == pytest.approx(figures.ci95_mm, abs=0.005)
    assert inside is figures.inside


def test_the_seeded_run_is_repeatable_and_the_seed_matters() -> None:
    s = script()
    a, b = s.seeded_figures(), s.seeded_figures()
    assert a == b
    s.SEED += 1
    assert s.seeded_figures() != a


def test_update_caption_rewrites_only_the_numbers() -> None:
    s = script()
    text = ("*Six touches with a simulated operator error of 0.3 mm: the TCP is 0.48 mm from the true one,\n"
            "inside its 95 % radius of 0.51 mm. (Regenerate: ...)*")
    new = s.update_caption(text, s.CaptionFigures(position_error_mm=0.9049, ci95_mm=0.8412))
    assert new == ("*Six touches with a simulated operator error of 0.3 mm: the TCP is 0.90 mm from the true one,\n"
                   "outside its 95 % radius of 0.84 mm. (Regenerate: ...)*")
    assert s.caption_figures(new) == (0.90, False, 0.84)
    with pytest.raises(ValueError, match="no caption"):
        s.update_caption("no caption here", s.CaptionFigures(0.1, 0.2))
