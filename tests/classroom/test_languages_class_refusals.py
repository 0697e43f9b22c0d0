"""The class's refusals that reach a browser (the trainer's message box, a push of an unknown
tool, the welcome window's token lockout) are :class:`~tcp_pendant.controller.words.Words`:
English as before for logs and the CLI, said in the reader's language by ``error_text`` (what
the session's guard and the views show)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from support.pseudo_text import english_words

from tcp_pendant.classroom.class_messages import MAX_MESSAGE_CHARS, clean_message_text
from tcp_pendant.classroom.exercise_setup import ExerciseSetup
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.trainer_token import TrainerTokenLocked, locked
from tcp_pendant.controller.words import error_text
from tcp_pendant.translation import PSEUDO_LANGUAGE, translator

QPS = translator(PSEUDO_LANGUAGE)


def _refusal(fn: Any, *args: Any) -> ValueError:
    with pytest.raises(ValueError) as caught:
        fn(*args)
    return caught.value


def _check(exc: BaseException, english: str, names: set[str]) -> None:
    assert str(exc) == english
    said = error_text(exc, QPS)
    assert said.startswith("⟦") and english_words(said, names) == [], said


def test_the_message_boxs_refusals_in_english_and_the_pseudo_locale() -> None:
    _check(_refusal(clean_message_text, " \n "),
           "The message is empty: type what the trainees should read, then Send.", set())
    _check(_refusal(clean_message_text, "x" * (MAX_MESSAGE_CHARS + 5)),
           f"The message is {MAX_MESSAGE_CHARS + 5} characters long; shorten it to at most {MAX_MESSAGE_CHARS}.",
           set())
    _check(_refusal(clean_message_text, 3), "A message must be text, got int.", {"int"})


def test_the_token_lockout_in_english_and_the_pseudo_locale() -> None:
    exc = locked(3.4)
    assert isinstance(exc, TrainerTokenLocked)
    _check(exc, "Too many wrong trainer tokens from this browser: try again in 3 s.", set())
    assert "3" in error_text(exc, QPS)


def test_a_push_of_an_unknown_tool_in_english_and_the_pseudo_locale(tmp_path: Path) -> None:
    with Gradebook(tmp_path / "class.sqlite3") as book:
        setup = ExerciseSetup(book.settings, ("pointer", "torch"), None)
        exc = _refusal(setup.push, None, "laser", None, None)
    _check(exc, "Unknown tool 'laser'; use one of pointer, torch.", {"laser", "pointer", "torch"})
