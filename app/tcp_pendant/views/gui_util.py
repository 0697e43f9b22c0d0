"""Small helpers shared by the wizard views."""

from __future__ import annotations

from typing import Any

__all__ = ["number_of_option", "set_content", "set_options", "slot_option"]


def set_content(handle: Any, text: str) -> None:
    """Set a markdown handle's content only when it changed (viser re-sends every assignment
    of ``content``; the Calibrate tab re-renders after every click and move)."""
    if handle.content != text:
        handle.content = text


def set_options(handle: Any, options: tuple[str, ...], keep: str | None = None) -> None:
    """Give a dropdown new options, keeping ``keep`` (default: the current value) if still there."""
    keep = handle.value if keep is None else keep
    if tuple(handle.options) != options:
        handle.options = options
    value = keep if keep in options else options[0]
    if handle.value != value:
        handle.value = value


def slot_option(slot: int, name: str) -> str:
    """A library slot as a dropdown option: ``"3: Torch"`` (read back by :func:`number_of_option`)."""
    return f"{slot}: {name}"


def number_of_option(option: str) -> int | None:
    """The leading number of a dropdown option such as ``"3: Torch"`` (a library slot, a run),
    or None for an option without one (``"(library empty)"``, ``"first free"``)."""
    head = str(option).split(":", 1)[0]
    return int(head) if head.isdigit() else None
