"""Small helpers shared by the views: where a session draws (:func:`target_of`), setting a
widget only when its value changed, and the types of viser's GUI events."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol, TypeVar

import viser

if TYPE_CHECKING:
    from tcp_pendant.session import GuiTarget, Session

__all__ = ["ButtonEvent", "ButtonGroupEvent", "CheckboxEvent", "DropdownEvent", "UploadEvent",
           "number_of_option", "set_content", "set_options", "set_value", "slot_option", "target_of"]

# The events viser hands to a widget's callback (``event.target`` is the widget, ``event.client``
# the browser that sent it, None for a change made by the server).
ButtonEvent = viser.GuiEvent[viser.GuiButtonHandle]
ButtonGroupEvent = viser.GuiEvent[viser.GuiButtonGroupHandle]
CheckboxEvent = viser.GuiEvent[viser.GuiCheckboxHandle]
DropdownEvent = viser.GuiEvent[viser.GuiDropdownHandle[str]]
UploadEvent = viser.GuiEvent[viser.GuiUploadButtonHandle]

_T = TypeVar("_T")
_T_co = TypeVar("_T_co", covariant=True)


class _Input(Protocol[_T_co]):
    """A viser input handle (slider, dropdown, text, checkbox, progress bar...)."""

    @property
    def value(self) -> _T_co: ...


def set_value(handle: _Input[_T], value: _T) -> None:
    """``handle.value = value``: viser's input handles define the ``value`` setter apart from
    its getter, which mypy reads as a read-only property; the assignment is viser's documented
    way to set an input (and sends it to the browser)."""
    handle.value = value  # type: ignore[misc]  # viser's setter is not next to its getter


def target_of(session: Session) -> GuiTarget:
    """Where ``session``'s views draw (``session.target``): None only for a session made
    without a browser (it has no views) or after it closed."""
    target = session.target
    if target is None:
        raise RuntimeError("this session has no browser to draw in (none given, or it was closed)")
    return target


class _Content(Protocol):
    """A widget with markdown or HTML ``content`` (viser's markdown and HTML handles)."""

    content: str


class _Options(Protocol):
    """A widget with ``options`` and a ``value`` among them (viser's dropdown)."""

    options: tuple[str, ...]

    @property
    def value(self) -> str: ...


def set_content(handle: _Content, text: str) -> None:
    """Set a markdown handle's content only when it changed (viser re-sends every assignment
    of ``content``; the Calibrate tab re-renders after every click and move)."""
    if handle.content != text:
        handle.content = text


def set_options(handle: _Options, options: tuple[str, ...], keep: str | None = None) -> None:
    """Give a dropdown new options, keeping ``keep`` (default: the current value) if still there."""
    keep = handle.value if keep is None else keep
    if tuple(handle.options) != options:
        handle.options = options
    value = keep if keep in options else options[0]
    if handle.value != value:
        set_value(handle, value)


def slot_option(slot: int, name: str) -> str:
    """A library slot as a dropdown option: ``"3: Torch"`` (read back by :func:`number_of_option`)."""
    return f"{slot}: {name}"


def number_of_option(option: str) -> int | None:
    """The leading number of a dropdown option such as ``"3: Torch"`` (a library slot, a run),
    or None for an option without one (``"(library empty)"``, ``"first free"``)."""
    head = str(option).split(":", 1)[0]
    return int(head) if head.isdigit() else None
