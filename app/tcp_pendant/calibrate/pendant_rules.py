"""What one pendant may do: its exercise's rules and its library rights, as data with their
checks (no viser).

These are the types the session holds (``Session.rules``, ``SessionTools.library_rights``) and
the calibration workflow obeys (Finish, Auto-touch, the tool a run measures, Save to the
library); they sit here, in the lowest layer that enforces them, so that neither the workflow
nor the session imports the classroom. Their values are the class's: the classroom decides
them and hands them to each session (``classroom.exercise_rules.class_rules``,
``classroom.library_rights.trainee_rights``; ``Session.set_rules``,
``SessionTools.set_library_rights``). Without a class a pendant has :data:`FREE_PRACTICE` and
:data:`UNRESTRICTED`.

:class:`ExerciseRules`: the session's commands refuse what the exercise forbids, in words,
whatever a browser sends (a disabled checkbox is only the polite half):

* ``distance_locked``: "Hide distance" is on and stays on - the distance, the Δ line, the text
  close-up, the stop at the tip and its message are off (the trainee judges the touch by eye);
* ``auto_touch_allowed``: Auto-touch (the robot touches for the trainee) may be used;
* ``in_exercise``: the spin-test Check shows a technician's reading only
  (``wizards.check_reading``);
* ``instructions``: the trainer's words for the exercise (plain text; a banner on the trainee's
  panel shows them, escaped);
* ``allowed_methods``: the calibration methods (wizard kinds) the trainee may start (None: all);
  the Calibrate menu offers only those and ``WizardCommands.start`` refuses the others in words;
* ``min_touches``: the fewest touches a Finish takes (0: the method's own minimum). It applies
  to the methods whose touch count the trainee chooses (an ``n_points`` start option or Add
  point: XYZ 4-point, TCP & Z, X); a method with a fixed number of poses (three-point, ABC
  world, XYZ reference, the checks) keeps its own count.

The exercise's tool (``SessionTools.set_exercise_tool``, the classroom's mystery tool of each trainee)
is not a class-wide rule: each trainee has their own. While one is held, "Mounted tool" is locked
to it (:func:`check_tool_change` refuses another in words), a calibration may only measure it
(:func:`check_calibrated_tool`), and the one exception is a wizard step's own tool change: the XYZ
reference method touches first with its known reference tool (``WizardCommands.mount_required_tool``),
and the exercise's tool is mounted again when that run ends or is cancelled.

:class:`LibraryRights`: who a pendant may change the shared tool library as. A class pendant
(``restricted``) writes with its trainee's name as the slot's ``owner`` (kept in the library
file, ``tcpcal.library``, so the check and the write are one step under the file's lock): it
saves into an empty slot or one of its own, renames and deletes only its own, within its
``quota``. A refusal names no other trainee (the class list is the trainer's to see) and says
what to do instead.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TypedDict

from tcpcal.library import OwnerQuotaError, SlotOwnedError, ToolLibraryError
from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.controller.tools import shown_tool_label
from tcp_pendant.controller.words import Words
from tcp_pendant.translation import N_

__all__ = [
    "AUTO_TOUCH_REFUSED",
    "DISTANCE_LOCKED",
    "ExerciseRules",
    "FREE_PRACTICE",
    "LibraryRights",
    "RuleRefusal",
    "TOOL_LOCKED_WORDS",
    "UNRESTRICTED",
    "check_calibrated_tool",
    "check_tool_change",
]

DISTANCE_LOCKED = N_("The trainer has locked the distance aids for this exercise: judge the touch by eye, "
                     "as on a real robot (the distance, the Δ line and the stop at the tip stay off).")
AUTO_TOUCH_REFUSED = N_("Auto-touch is off in this exercise: the robot would touch for you. Jog the tool tip "
                        "onto the reference tip and press Record (the trainer can allow Auto-touch).")
TOOL_LOCKED_WORDS = "This exercise keeps your own tool mounted"
"""The start of the refusal of a tool change in an exercise (:func:`check_tool_change`)."""


class RuleRefusal(ControllerError):
    """A command the exercise forbids (a ``ValueError``: the session shows it as a warning); its
    message is :class:`~tcp_pendant.controller.words.Words` (``words.error_text`` says it in the
    session's language)."""


def check_tool_change(held_key: str, held_label: str, wanted_key: str, wanted_label: str) -> None:
    """Refuse mounting the tool ``wanted_key`` while the exercise holds the tool ``held_key``
    mounted (the same tool is no change and passes).

    Raises:
        RuleRefusal: ``wanted_key`` is another tool; the words say what stays mounted and why.
    """
    if wanted_key == held_key:
        return
    raise RuleRefusal(Words(N_("This exercise keeps your own tool mounted (the {held}): the trainer gave it to you "
                               "to calibrate, so the {wanted} cannot be mounted. (The XYZ reference method mounts "
                               "its reference tool for its first touch by itself, with its Mount the tool button.)"),
                            held=_tool_words(held_label), wanted=_tool_words(wanted_label)))


def _tool_words(label: str) -> Words:
    """A tool model's label inside a sentence, said in the reader's language (English: in
    lower case, "the straight pointer")."""
    return Words.by(lambda tr: shown_tool_label(label, tr, in_sentence=True))


def check_calibrated_tool(held_key: str, held_label: str, calibrated_key: str | None, method_title: str) -> None:
    """Refuse a calibration that would measure another tool than the exercise's ``held_key``
    (``calibrated_key``: the physical tool whose truth grades it; None: none, e.g. a check).

    Raises:
        RuleRefusal: it measures another tool; the words name the one to choose.
    """
    if calibrated_key is None or calibrated_key == held_key:
        return
    raise RuleRefusal(Words(N_("This exercise calibrates your own tool (the {held}): the {method} method can only "
                               "measure it. Choose the {held} as the tool to calibrate (the XYZ reference method: "
                               "as its New tool)."), held=_tool_words(held_label), method=Words(method_title)))


@dataclass(frozen=True)
class ExerciseRules:
    """The rules one trainee's pendant follows (see the module docstring).

    Attributes:
        exercise: the exercise id (e.g. "mystery"), None in free practice.
        distance_locked: "Hide distance" is on and cannot be switched off.
        auto_touch_allowed: Auto-touch may be used.
        instructions: the trainer's words (plain text; "" none).
        allowed_methods: the wizard kinds the trainee may start (None: every method).
        min_touches: the fewest touches a Finish of a method with a chosen touch count takes
            (0: none).
    """

    exercise: str | None = None
    distance_locked: bool = False
    auto_touch_allowed: bool = True
    instructions: str = ""
    allowed_methods: tuple[str, ...] | None = None
    min_touches: int = 0

    def allows_method(self, kind: str) -> bool:
        """The method ``kind`` may be started."""
        return self.allowed_methods is None or kind in self.allowed_methods

    def check_method(self, kind: str, titles: dict[str, str]) -> None:
        """Refuse starting a method the exercise does not allow.

        Args:
            kind: the wizard kind asked for.
            titles: wizard kind -> its title (the words name the allowed methods).

        Raises:
            RuleRefusal: ``kind`` is not one of :attr:`allowed_methods`.
        """
        if self.allows_method(kind):
            return
        allowed: str = ""
        for k in self.allowed_methods or ():           # "A or B or C", each title in the reader's language
            title = Words(titles.get(k, k))
            allowed = Words(N_("{first} or {second}"), first=allowed, second=title) if allowed else title
        raise RuleRefusal(Words(N_("This exercise does not use the {method} method: choose {methods} (the trainer "
                                   "chose the methods)."), method=Words(titles.get(kind, kind)), methods=allowed))

    def touches_refusal(self, n_touches: int, *, can_add_point: bool) -> str | None:
        """Why a Finish with ``n_touches`` touches is refused (None: it is not), for a method
        whose touch count the trainee chooses (:class:`~tcp_pendant.controller.words.Words`)."""
        missing = self.min_touches - int(n_touches)
        if missing <= 0:
            return None
        how = (Words(N_("press Add point for another touch step")) if can_add_point else
               Words(N_("start it again with {n} touches or more"), n=self.min_touches))
        return Words(N_("This exercise asks for at least {n} touches: record {missing} more ({how})."),
                     n=self.min_touches, missing=missing, how=how)

    @property
    def in_exercise(self) -> bool:
        return self.exercise is not None

    def check_hide_distance(self, hide: bool) -> None:
        """Refuse showing the distance while it is locked.

        Raises:
            RuleRefusal: ``hide`` is False and the distance aids are locked.
        """
        if self.distance_locked and not hide:
            raise RuleRefusal(Words(DISTANCE_LOCKED))

    def check_auto_touch(self) -> None:
        """Refuse Auto-touch where the exercise forbids it.

        Raises:
            RuleRefusal: Auto-touch is not allowed.
        """
        if not self.auto_touch_allowed:
            raise RuleRefusal(Words(AUTO_TOUCH_REFUSED))


FREE_PRACTICE = ExerciseRules()
"""No exercise: nothing is locked, Auto-touch is allowed, the Check shows all it computes."""


class OwnerKwargs(TypedDict, total=False):
    """The keywords of ``ToolLibrary.rename``/``remove`` for a pendant's rights (none: no rule)."""

    owner: str


class SaveKwargs(OwnerKwargs, total=False):
    """The keywords of ``ToolLibrary.save``: the owner's and the quota of slots."""

    quota: int


@dataclass(frozen=True)
class LibraryRights:
    """How a pendant may change the library (see the module docstring).

    Attributes:
        restricted: a class pendant (changes need an ``owner``).
        owner: the trainee's name (None: not joined yet, or unrestricted).
        quota: slots one owner may hold (None: no limit).
    """

    restricted: bool = False
    owner: str | None = None
    quota: int | None = None

    def owner_kwargs(self) -> OwnerKwargs:
        """The keywords of ``ToolLibrary.rename``/``remove`` for these rights.

        Raises:
            ToolLibraryError: a class pendant that has not joined (the words say what to do).
        """
        if not self.restricted:
            return OwnerKwargs()
        if self.owner is None:
            raise ToolLibraryError(Words(N_("Join the class with your name first: in a class each library slot "
                                            "belongs to the trainee who saved it.")))
        return OwnerKwargs(owner=self.owner)

    def save_kwargs(self) -> SaveKwargs:
        """The keywords of ``ToolLibrary.save`` (owner and quota) for these rights."""
        kw = SaveKwargs(**self.owner_kwargs())
        if kw and self.quota is not None:
            kw["quota"] = self.quota
        return kw

    def mine(self, owners: dict[int, str], slot: int) -> bool:
        """Whether ``slot`` may be renamed or deleted with these rights."""
        return not self.restricted or (self.owner is not None and owners.get(slot) == self.owner)

    @contextmanager
    def in_words(self) -> Iterator[None]:
        """Turn tcpcal's ownership refusals into a trainee's words (a ``ToolLibraryError``)."""
        try:
            yield
        except SlotOwnedError as exc:
            whose = (Words(N_("Slot {slot} belongs to another trainee"), slot=exc.slot) if exc.owner is not None
                     else Words(N_("Slot {slot} is the trainer's (saved without an owner)"), slot=exc.slot))
            raise ToolLibraryError(Words(N_("{whose}: you can activate and check it, not change it. Save into a "
                                            "free slot or one of your own, or ask the trainer."), whose=whose)) from None
        except OwnerQuotaError as exc:
            slots = ", ".join(map(str, exc.owned))
            n = len(exc.owned)
            quota = exc.quota
            raise ToolLibraryError(Words.by(lambda tr: tr.ngettext(
                "You have {n} tool in the library (slot {slots}), the most a trainee may keep ({quota}): delete "
                "one of yours first, or save into one of your slots to replace it.",
                "You have {n} tools in the library (slots {slots}), the most a trainee may keep ({quota}): delete "
                "one of yours first, or save into one of your slots to replace it.", n).format(
                    n=n, slots=slots, quota=quota))) from None


UNRESTRICTED = LibraryRights()
"""The trainer, ``--shared`` and a pendant without a class."""
