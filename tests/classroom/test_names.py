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


@pytest.mark.parametrize("a, b", [
    ("Alice", "Alicia"), ("Alice", "Alice B."), ("Anna", "Anne"), ("Ben", "Bob"),
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
