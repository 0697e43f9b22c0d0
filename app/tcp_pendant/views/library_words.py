"""tcpcal's tool-library reports in the reader's language (tcpcal stays English and knows
nothing of the app): the view words them itself from their data.

:func:`recovery_summary` is :meth:`tcpcal.library.LibraryRecovery.summary` (same English text)
said with a translator; the problems it lists are tcpcal's own lines (a slot and its field, as
the file has them) and stay as they are.
"""

from __future__ import annotations

from tcpcal.library import LibraryRecovery

from tcp_pendant.translation import ENGLISH, Translator

__all__ = ["recovery_summary"]


def recovery_summary(recovery: LibraryRecovery, tr: Translator = ENGLISH, *, max_problems: int = 5) -> str:
    """One plain-text paragraph in ``tr``'s language: what a load of a damaged library set
    aside, what it kept, where the backup is (plain text: a notification's body)."""
    _ = tr.gettext
    problems = recovery.problems
    shown = list(problems[:max_problems])
    if len(problems) > max_problems:
        shown.append(_("and {n} more").format(n=len(problems) - max_problems))
    what = "; ".join(shown)
    if recovery.whole_file:
        return _("The tool library {path} is corrupt ({what}); the whole file was moved aside to {backup} and "
                 "the library starts empty. Repair that file by hand to recover its tools.").format(
                     path=recovery.path, what=what, backup=recovery.backup)
    kept = ", ".join(str(s) for s in recovery.kept_slots) or _("none")
    n = len(problems)
    return tr.ngettext("The tool library {path} had {n} bad entry ({what}); it was set aside (the file as it was "
                       "is kept in {backup}); the valid tools were kept (slots {kept}).",
                       "The tool library {path} had {n} bad entries ({what}); they were set aside (the file as it "
                       "was is kept in {backup}); the valid tools were kept (slots {kept}).",
                       n).format(path=recovery.path, n=n, what=what, backup=recovery.backup, kept=kept)
