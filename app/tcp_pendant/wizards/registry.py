"""The calibration methods the app offers: wizard classes that describe themselves.

A wizard class declares its kind, label (``title``), blurb, step roles with their auto-touch
roles, start options with their choices, variants, the tool it needs and how it is built
(``Wizard.start``); :func:`register` adds it. The Calibrate menu (methods, options shown per
method), the steps view (variants, Add point, meter), auto-touch, the session record
(``Wizard.from_dict`` by kind) and ``CalibrationWorkflow.start`` read only this registry, so a
new method is the solver, one wizard module (registered here) and its tests, plus its words.
"""

from __future__ import annotations

import re

from tcp_pendant.wizards.base import Wizard, WizardError

__all__ = ["WIZARD_TYPES", "register", "unregister", "wizard_class", "wizard_classes"]

WIZARD_TYPES: dict[str, type[Wizard]] = {}
"""Wizard kind (as in ``Wizard.to_dict()["kind"]``) -> class: every registered method."""

_ROLE_NAME = re.compile(r"[a-z][a-z0-9_]*")


def register(cls: type[Wizard], *, replace: bool = False) -> type[Wizard]:
    """Add a wizard class to the registry (usable as a class decorator).

    Raises:
        WizardError: not a ``Wizard`` subclass; its kind is not a lower-case word or is taken
            (unless ``replace``); no title or blurb; no ``start``; step roles or options named
            twice; option names that are not identifiers.
    """
    if not (isinstance(cls, type) and issubclass(cls, Wizard)):
        raise WizardError(f"{cls!r} is not a Wizard class.")
    kind = getattr(cls, "kind", None)
    if not isinstance(kind, str) or not re.fullmatch(r"[a-z][a-z0-9-]*", kind):
        raise WizardError(f"{cls.__name__}.kind must be a lower-case word (letters, digits, '-'), got {kind!r}.")
    if kind in WIZARD_TYPES and WIZARD_TYPES[kind] is not cls and not replace:
        raise WizardError(f"The wizard kind {kind!r} is registered already ({WIZARD_TYPES[kind].__name__}).")
    if not getattr(cls, "title", "") or not cls.blurb:
        raise WizardError(f"{cls.__name__} must declare a title and a blurb (what the menu shows).")
    if cls.start.__func__ is Wizard.start.__func__:  # type: ignore[attr-defined]
        raise WizardError(f"{cls.__name__} must say how it is started (classmethod start).")
    roles = [r.name for r in cls.step_roles]
    if not roles or len(set(roles)) != len(roles) or not all(_ROLE_NAME.fullmatch(r) for r in roles):
        raise WizardError(f"{cls.__name__}.step_roles must name each role once, in lower case: {roles}.")
    names = [o.name for o in cls.options]
    if len(set(names)) != len(names) or not all(n.isidentifier() for n in names) or "variant" in names:
        raise WizardError(f"{cls.__name__}.options must name each option once, as identifiers "
                          f"('variant' is given by variants): {names}.")
    WIZARD_TYPES[kind] = cls
    return cls


def unregister(kind: str) -> None:
    """Remove the wizard kind ``kind`` (tests of a toy method)."""
    WIZARD_TYPES.pop(kind, None)


def wizard_classes() -> list[type[Wizard]]:
    """The registered wizard classes in menu order (``rank``, then title)."""
    return sorted(WIZARD_TYPES.values(), key=lambda c: (c.rank, c.title))


def wizard_class(kind: str) -> type[Wizard]:
    """The class of ``kind``.

    Raises:
        WizardError: unknown kind (the message lists the registered ones).
    """
    cls = WIZARD_TYPES.get(kind)
    if cls is None:
        raise WizardError(f"Unknown calibration method {kind!r}; choose one of "
                          f"{', '.join(c.kind for c in wizard_classes())}.")
    return cls
