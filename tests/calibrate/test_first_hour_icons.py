"""The status icons must render in Debian's chromium without an emoji
font. The app's strings may use only symbols that the DejaVu fonts (Debian's default) draw:
no code point of the emoji ranges except an explicit list that DejaVu Sans covers."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

APP = Path(__file__).resolve().parents[2] / "app" / "tcp_pendant"

# symbols of the emoji-ish blocks that DejaVu Sans has glyphs for (checked with fc-list below)
DEJAVU_SYMBOLS = frozenset("⚠✓✔✗✘✖")
EMOJI_RANGES = ((0x1F000, 0x1FAFF), (0x2600, 0x27BF), (0x2B00, 0x2BFF), (0xFE00, 0xFE0F))


def _is_emoji(ch: str) -> bool:
    cp = ord(ch)
    return any(lo <= cp <= hi for lo, hi in EMOJI_RANGES)


def _offending(text: str) -> list[str]:
    return sorted({ch for ch in text if _is_emoji(ch) and ch not in DEJAVU_SYMBOLS})


def test_the_check_catches_the_icons_that_showed_as_empty_boxes() -> None:
    # the two icons seen as empty boxes, and a variation selector that asks for emoji style
    assert _offending("✅ **TOUCHING** and 🛑 **CRASH** ⚠\ufe0f") == sorted("✅🛑\ufe0f")
    assert _offending("✔ **TOUCHING** and ✖ **CRASH** ⚠ ✘ ● ▶ ℹ") == []


def test_no_app_string_uses_an_emoji_that_debian_fonts_lack() -> None:
    bad = {}
    for path in sorted(APP.rglob("*.py")):
        chars = _offending(path.read_text(encoding="utf-8"))
        if chars:
            bad[str(path.relative_to(APP))] = chars
    assert bad == {}, f"emoji without a glyph in DejaVu: {bad}"


def test_touch_indicator_icons_are_dejavu_symbols() -> None:
    from tcp_pendant.pendant.formatting import touch_indicator_markdown

    class _Touch:
        crashed, touching, penetration_mm, distance_mm = False, True, 0.0, 0.2

    class _Crash(_Touch):
        crashed, penetration_mm = True, 1.5

    touching = touch_indicator_markdown(_Touch(), hide_distance=False)    # type: ignore[arg-type]
    crash = touch_indicator_markdown(_Crash(), hide_distance=False)       # type: ignore[arg-type]
    assert touching.startswith("✔ **TOUCHING**") and crash.startswith("✖ **CRASH**")


@pytest.mark.skipif(shutil.which("fc-list") is None, reason="fontconfig's fc-list is not installed")
def test_dejavu_sans_has_every_whitelisted_symbol() -> None:
    for ch in sorted(DEJAVU_SYMBOLS):
        out = subprocess.run(["fc-list", f":charset={ord(ch):x}", "family"], capture_output=True,
                             text=True, check=True).stdout
        assert "DejaVu Sans" in out, f"{ch} (U+{ord(ch):04X}) is not in DejaVu Sans"
