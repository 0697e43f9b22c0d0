"""The "Your name" check: visible text of 1..40 characters, normalised so a reconnect matches;
look-alike names (a TR39 confusable skeleton) are told apart from different ones."""

from __future__ import annotations

import pytest
from tcp_pendant.classroom.names import (
    MAX_TRAINEE_NAME_LENGTH,
    TraineeNameError,
    looks_alike,
    name_keys,
    skeleton,
    validate_trainee_name,
)


@pytest.mark.parametrize("text, expected", [
    ("Anna", "Anna"),
    ("  Anna Meier \n", "Anna Meier"),
    ("Anna    Meier", "Anna Meier"),
    ("Jos\u0065\u0301", "Jos\u00e9"),                      # decomposed e + acute -> NFC é
    ('O\'Brien "Bob"', 'O\'Brien "Bob"'),                  # quotes are fine in a person's name
    ("李小龙", "李小龙"),
    ("x" * MAX_TRAINEE_NAME_LENGTH, "x" * MAX_TRAINEE_NAME_LENGTH),
    ("<b>bold</b>", "<b>bold</b>"),                        # kept as typed: the views escape it
    ("\u0639\u0644\u06cc\u200c\u0627\u06a9\u0628\u0631",        # Persian Ali-Akbar: ZWNJ breaks the
     "\u0639\u0644\u06cc\u200c\u0627\u06a9\u0628\u0631"),       # join of yeh and alef (UAX #31 A1)
    ("\u0930\u0941\u0915\u094d\u200c\u092e\u093f\u0923\u0940",  # Devanagari: ZWNJ after a virama
     "\u0930\u0941\u0915\u094d\u200c\u092e\u093f\u0923\u0940"),  # (half form, UAX #31 A2)
    ("\u0915\u094d\u200d\u0937", "\u0915\u094d\u200d\u0937"),   # ZWJ after a virama (UAX #31 B)
])
def test_accepted_names_are_normalised(text: str, expected: str) -> None:
    assert validate_trainee_name(text) == expected


@pytest.mark.parametrize("text, match", [
    ("", "empty"),
    ("   \t ", "empty"),
    ("x" * (MAX_TRAINEE_NAME_LENGTH + 1), "41 characters; shorten it to at most 40"),
    ("An\x00na", r"U\+0000"),
    ("An\tna", r"U\+0009"),
    ("\u200b", r"U\+200B \(ZERO WIDTH SPACE\)"),
    ("Anna\u202egnp.exe", r"U\+202E"),                     # right-to-left override
    ("\u3164", r"U\+3164 \(HANGUL FILLER\)"),              # a letter that draws nothing
    ("Ann\u2800a", r"U\+2800"),
    ("Anna\u00a0Meier", r"U\+00A0"),                       # no-break space inside the name
    # default-ignorable code points draw nothing: "Alice" on the screen, another name in the book
    ("Alice\ufe0f", r"U\+FE0F \(VARIATION SELECTOR-16\)"),
    ("Al\ufe00ice", r"U\+FE00 \(VARIATION SELECTOR-1\)"),
    ("Al\U000e0100ice", r"U\+E0100 \(VARIATION SELECTOR-17\)"),
    ("Alice\u180b", r"U\+180B \(MONGOLIAN FREE VARIATION SELECTOR ONE\)"),
    ("Alice\u17b4", r"U\+17B4 \(KHMER VOWEL INHERENT AQ\)"),
    ("Al\u17b5ice", r"U\+17B5 \(KHMER VOWEL INHERENT AA\)"),
    ("Al\u034fice", r"U\+034F \(COMBINING GRAPHEME JOINER\)"),
    ("Al\u200cice", r"U\+200C \(ZERO WIDTH NON-JOINER\)"),    # between Latin letters: no join to break
    ("Alice\u200d", r"U\+200D \(ZERO WIDTH JOINER\)"),
    ("\u0645\u062d\u0645\u062f\u200c\u0631\u0636\u0627", r"U\+200C"),  # dal joins no letter after it
    ("\U0001f469\u200d\U0001f4bb", r"U\+200D"),         # an emoji sequence, not a letter's conjunct
    (None, "must be text"),
    (b"Anna", "must be text"),
])
def test_refused_names_say_why(text: object, match: str) -> None:
    with pytest.raises(TraineeNameError, match=match):
        validate_trainee_name(text)


def test_error_is_a_value_error() -> None:
    assert issubclass(TraineeNameError, ValueError)


# --------------------------------------------------------------------------- look-alikes

@pytest.mark.parametrize("other", [
    "\u0410lice",            # Cyrillic capital A
    "ＡＬＩＣＥ",              # fullwidth capitals (NFKC)
    "A\u013aice",            # l with acute: a diacritic of the Combining Diacritical Marks, dropped
    "Al\u0301ice",           # the same, decomposed
    "alice", "ALICE",        # case
    "A1ice",                 # digit one for small l (TR39)
    "\U0001d400lice",        # mathematical bold A (NFKC)
])
def test_look_alikes_of_a_name(other: str) -> None:
    assert looks_alike("Alice", other) and looks_alike(other, "Alice")


@pytest.mark.parametrize("a, b", [
    ("Ivan", "lvan"),                      # capital I and small l: the case-kept skeleton
    ("Emma", "Ernrna"),                    # m and r n (a prototype of two letters)
    ("Jos\u00e9", "Jose"),                 # accents dropped: a class with both asks for an initial
    ("\u0391nna", "Anna"),                 # Greek capital alpha
])
def test_more_look_alikes(a: str, b: str) -> None:
    assert looks_alike(a, b)


INVISIBLE_ALICES = ["Alice\ufe0f", "Al\ufe00ice", "Al\U000e0100ice", "Alice\u180b", "Alice\u17b4", "Al\u17b5ice"]
"""Issue 42: variation selectors 16 and 1, an ideographic variation selector, a Mongolian free
variation selector and the two Khmer inherent vowels, each drawn as nothing beside "Alice"."""


@pytest.mark.parametrize("other", INVISIBLE_ALICES)
def test_invisible_marks_are_dropped_when_names_are_compared(other: str) -> None:
    assert looks_alike("Alice", other) and looks_alike(other, "Alice")
    assert name_keys(other) == name_keys("Alice") == ("Alice", "alice")


#: Default-ignorable code points of most of the blocks that have them (DerivedCoreProperties.txt),
#: unassigned ones of the tag block included (E0FFF): each inside "Alice" is dropped.
DI_SAMPLE = [0x00AD, 0x034F, 0x061C, 0x115F, 0x1160, 0x17B4, 0x17B5, 0x180B, 0x180C, 0x180D, 0x180E,
             0x180F, 0x200B, 0x200C, 0x200D, 0x200E, 0x202E, 0x2060, 0x2064, 0x206F, 0x3164, 0xFE00,
             0xFE0F, 0xFEFF, 0xFFA0, 0xFFF0, 0x1BCA0, 0x1D173, 0xE0001, 0xE0041, 0xE0100, 0xE01EF, 0xE0FFF]


@pytest.mark.parametrize("cp", DI_SAMPLE, ids=lambda cp: f"U+{cp:04X}")
def test_the_skeleton_drops_every_default_ignorable_code_point(cp: str) -> None:
    assert skeleton(f"Al{chr(cp)}ice") == skeleton("Alice") == "Alice"
    assert name_keys(f"{chr(cp)}Alice{chr(cp)}") == ("Alice", "alice")


def test_the_default_ignorables_are_unicodes_table() -> None:
    """Default_Ignorable_Code_Point of DerivedCoreProperties.txt (Unicode 14 to 17): 4174 code
    points in 17 ranges, 4096 of them the tag and variation selector supplement block."""
    every = "".join(map(chr, range(0x110000)))
    dropped = [ch for ch in every if skeleton(f"a{ch}") == "a" and ch != "a"]
    assert len(dropped) == 4174
    assert dropped[0] == "\u00ad" and dropped[-1] == "\U000e0fff"
    assert sum(1 for ch in dropped if ord(ch) >= 0xE0000) == 4096


@pytest.mark.parametrize("a, b", [
    ("\u0639\u0644\u06cc\u200c\u0627\u06a9\u0628\u0631", "\u0639\u0644\u06cc\u0627\u06a9\u0628\u0631"),  # ZWNJ kept in the name,
    ("\u0915\u094d\u200d\u0937", "\u0915\u094d\u0937"),                                   # dropped in comparison
])
def test_joiners_kept_in_a_name_are_dropped_when_names_are_compared(a: str, b: str) -> None:
    assert validate_trainee_name(a) == a and looks_alike(a, b)


@pytest.mark.parametrize("a, b", [
    ("Alice", "Alicia"), ("Alice", "Alice B."), ("Alice", "Alise"), ("Alice", "Alice\u00b7"), ("Anna", "Anne"), ("Ben", "Bob"),
    ("Al1ce", "Alice"),                    # 1 is like l, not like i
    ("\u0915\u0941\u092e\u093e\u0930", "\u0915\u092e\u093e\u0930"),   # Devanagari vowel sign u: a letter, kept
    ("李小龙", "李小"),
])
def test_different_names_do_not_look_alike(a: str, b: str) -> None:
    assert not looks_alike(a, b)


def test_the_skeleton_maps_a_source_to_its_prototype_and_keeps_prototypes() -> None:
    assert skeleton("\u0410") == skeleton("A") == "A"          # Cyrillic A -> Latin A (a prototype)
    assert skeleton("m") == "rn" and skeleton("rn") == "rn"
    assert skeleton("1") == skeleton("l") == skeleton("I") == "l"
    assert name_keys("Ａｌｉｃｅ") == name_keys("Alice") == ("Alice", "alice")
