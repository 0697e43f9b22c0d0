"""The "Your name" check: visible text of 1..40 characters, normalised so a reconnect matches."""

from __future__ import annotations

import pytest
from tcp_pendant.classroom.names import MAX_TRAINEE_NAME_LENGTH, TraineeNameError, validate_trainee_name


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
