"""The language the trainer pushed to the class, and a pushed language on one trainee's pendant (no viser).

The trainer's dashboard pushes a language like its other settings (``ClassRoom.push_language``
to every trainee, ``ClassRoom.push_language_to`` to one). The class's language is kept in the
gradebook (``Gradebook.settings``, key :data:`LANGUAGE_SETTING`), so it outlasts a restart and
every server process of the class reads the same: a browser that connects later starts in it,
over ``--language`` and the browser's ``Accept-Language`` (the trainer chose it for this class
now; docs/languages.md "Choosing a language"). A push to one trainee is not kept: it holds until
that trainee's browser reconnects. Either way the trainee may switch back with the Language
selector.

:func:`apply_language` sets one trainee session's language through its own command
(``Session.set_language``: the pose, the touches and the wizard stay) and tells the trainee in
the new language.
"""

from __future__ import annotations

from tcp_pendant.classroom.class_settings import ClassSettings
from tcp_pendant.session import Session
from tcp_pendant.translation import LANGUAGE_NAMES, PSEUDO_LANGUAGE, N_, languages

__all__ = ["LANGUAGE_PUSHED_BODY", "LANGUAGE_PUSHED_TITLE", "LANGUAGE_SETTING", "apply_language",
           "check_language", "keep_language", "kept_language", "language_name"]

LANGUAGE_SETTING = "class_language"
"""The class setting holding the pushed language's code (absent or None: none pushed)."""
LANGUAGE_PUSHED_TITLE = N_("Your trainer changed the language")
"""The trainee's notification's title."""
LANGUAGE_PUSHED_BODY = N_("The pendant now speaks {language}. You may switch back with the Language "
                          "selector in the Jog tab's View folder.")
"""Its body (``{language}``: the language named in itself)."""


def check_language(language: object) -> str:
    """``language`` if it is a code the pendant offers (or the tests' pseudo-locale).

    Raises:
        ValueError: an unknown code (naming the known ones).
    """
    if not isinstance(language, str) or language not in languages(include_pseudo=True):
        raise ValueError(f"Unknown language {language!r:.40}; use one of {', '.join(languages())}.")
    return language


def language_name(language: str) -> str:
    """The language named in itself (``Deutsch``); the pseudo-locale by its code."""
    return LANGUAGE_NAMES.get(language, language if language != PSEUDO_LANGUAGE else "⟦Ƥšéûðö⟧")


def kept_language(settings: ClassSettings) -> str | None:
    """The class's pushed language (None: none pushed, or a kept value that is no code we offer)."""
    kept = settings.get(LANGUAGE_SETTING)
    return kept if isinstance(kept, str) and kept in languages(include_pseudo=True) else None


def keep_language(settings: ClassSettings, language: str | None) -> None:
    """Keep ``language`` as the class's (None: forget it; browsers start as ``--language`` says).

    Raises:
        ValueError: an unknown code.
    """
    settings.set(LANGUAGE_SETTING, None if language is None else check_language(language))


def apply_language(session: Session, language: str) -> None:
    """``language`` on one trainee's pendant (its views re-render; pose, touches and wizard
    stay) and a notice in that language. Nothing is shown when the pendant speaks it already."""
    if session.language == language:
        return
    session.set_language(language)
    _ = session.translator.gettext
    session.notify(_(LANGUAGE_PUSHED_TITLE), _(LANGUAGE_PUSHED_BODY).format(language=language_name(language)),
                   kind="info")
