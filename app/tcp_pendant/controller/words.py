"""A message the controller composes, to be said later in the reader's language.

The controller (a jog's stop: a joint limit, a singularity, a target out of reach) cannot know
who reads its words: one server serves browsers in several languages, and the same stop reaches
logs and the CLI in English. So it returns :class:`Words`: a ``str`` holding the English text
(what logs, the CLI and the existing callers read, unchanged) that also keeps its message id
and placeholder values, so that a view says it again in its session's language with
:func:`in_language`. A placeholder value may itself be :class:`Words` (translated with it);
numbers go in already formatted (``f"{deg:.1f}"``: the readouts' decimal point).

A string built from :class:`Words` by concatenation or an f-string is a plain ``str`` again
(English): compose with another :class:`Words` instead (``Words(N_("{stop}. {advice}"), ...)``).

The message ids are marked ``N_()`` where they are written, so Babel extracts them. A message
with a count (plural forms) is made by :meth:`Words.by` from a function of the translator
(``Words.by(lambda tr: tr.ngettext(singular, plural, n).format(n=n))``).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from tcp_pendant.job_pool import JobRefused, OverShare, PoolFull, SessionBusy
from tcp_pendant.translation import ENGLISH, Translator

__all__ = ["Words", "error_text", "in_language"]


class Words(str):
    """English text (the ``str`` value) that can be said in another language (:meth:`text`).

    ``Words(msgid, **values)``: ``msgid`` is the English message with named ``{placeholders}``
    (marked ``N_()``), ``values`` the placeholders' values: text (names, formatted numbers) or
    :class:`Words`.
    """

    msgid: str
    values: dict[str, object]
    _say: Callable[[Translator], str] | None = None

    def __new__(cls, msgid: str, /, **values: object) -> Words:
        self = super().__new__(cls, _render(msgid, values, ENGLISH))
        self.msgid = msgid
        self.values = values
        return self

    @classmethod
    def by(cls, say: Callable[[Translator], str]) -> Words:
        """The words ``say(tr)`` composes (a count's plural forms: ``tr.ngettext``)."""
        english = say(ENGLISH)
        self = super().__new__(cls, english)
        self.msgid, self.values, self._say = english, {}, say
        return self

    def text(self, tr: Translator = ENGLISH) -> str:
        """The message in ``tr``'s language (each :class:`Words` value translated too)."""
        return self._say(tr) if self._say is not None else _render(self.msgid, self.values, tr)

    def __reduce__(self) -> tuple[type[str], tuple[str]]:
        """Pickled (an exception sent to another process) as its English text."""
        return str, (str(self),)


def _render(msgid: str, values: dict[str, object], tr: Translator) -> str:
    said = {k: in_language(v, tr) if isinstance(v, str) else v for k, v in values.items()}
    return tr.gettext(msgid).format(**said) if values else tr.gettext(msgid)


def in_language(text: str, tr: Translator = ENGLISH) -> str:
    """``text`` in ``tr``'s language when it is :class:`Words`; any other text as it is."""
    return text.text(tr) if isinstance(text, Words) else text


def error_text(exc: BaseException, tr: Translator = ENGLISH) -> str:
    """The words of an error shown to the browser, in ``tr``'s language: an exception raised
    with :class:`Words` (a ``ControllerError(Words(...))``, a rule's refusal) said again in
    that language, a job the server refused (``job_pool``: busy, rate limited, full) worded
    from its data; any other exception's text as it is (English)."""
    said = exc.args[0] if len(exc.args) == 1 else None
    if isinstance(said, Words):
        return said.text(tr)
    if isinstance(exc, JobRefused):
        return _refusal_text(exc, tr)
    return str(exc)


def _refusal_text(exc: JobRefused, tr: Translator) -> str:
    """``job_pool``'s refusals (the pool imports no translation: its data, worded here)."""
    _ = tr.gettext
    if isinstance(exc, SessionBusy) and exc.what:
        # TRANSLATORS: {what} is the job, as the view that started it named it ("The TCP check")
        return _("{what} is still running here; wait for its result, then try again.").format(
            what=exc.what[:1].upper() + exc.what[1:])
    if isinstance(exc, PoolFull):
        return tr.ngettext("The server is busy: {n} job is waiting. Try again in a moment.",
                           "The server is busy: {n} jobs are waiting. Try again in a moment.",
                           exc.waiting).format(n=exc.waiting)
    if isinstance(exc, OverShare):
        wait = max(1, math.ceil(exc.retry_in_s))
        return _("The server is busy with this browser's jobs: try again in {seconds} s.").format(seconds=wait)
    if str(exc) == "The server is shutting down; the job was not started.":
        return _("The server is shutting down; the job was not started.")
    return str(exc)
