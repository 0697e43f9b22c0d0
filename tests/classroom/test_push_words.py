"""What a "Push to this trainee" tells the trainee (``classroom.push_words``): each setting the
push set, in words; nothing else."""

from __future__ import annotations

from tcp_pendant.classroom.push_words import push_words


def test_each_setting_pushed_is_named() -> None:
    assert push_words(False, None, "locked", False) == (
        "The distance to the reference tip is hidden, and locked by the trainer; Auto-touch is off: "
        "touch by jogging.")
    assert push_words(None, "Bent-neck welding torch", "shown", True) == (
        "Free practice (no exercise: you may swap tools); the mounted tool is now Bent-neck welding torch; "
        "the distance to the reference tip is shown; Auto-touch is allowed.")


def test_the_mystery_exercise_names_no_tool_and_an_empty_push_says_so() -> None:
    text = push_words("mystery", "Straight pointer", None, None)
    assert text == "The exercise: calibrate your mystery tool (its true TCP is hidden)."
    assert "pointer" not in text                  # the mystery tool is mounted, not the one chosen
    assert push_words(False, None, None, None) == "Your trainer pushed your settings again; nothing changed."
