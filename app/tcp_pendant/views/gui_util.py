"""Small helpers shared by the views: where a session draws (:func:`target_of`) and the
browsers that show it (:func:`client_of`, :func:`clients_of`) as viser's types, setting a
widget only when its value changed, the types of viser's GUI events and the error charts'
legend option."""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, TypeVar, cast

import viser
from viser.uplot import Legend

from tcp_pendant.controller.words import error_text
from tcp_pendant.job_pool import JobRefused

if TYPE_CHECKING:
    from tcp_pendant.session import Session

__all__ = ["CHART_LEGEND", "ButtonEvent", "ButtonGroupEvent", "CheckboxEvent", "DropdownEvent", "UploadEvent",
           "ViserTarget", "client_of", "clients_of", "number_of_option", "refused_before_job", "set_content",
           "set_options", "set_value", "slot_option", "target_of"]

ViserTarget = viser.ClientHandle | viser.ViserServer
"""Where a session's views draw: its browser, or (``--shared``) the server, every browser."""

CHART_LEGEND: Legend = {"live": False}
"""uPlot ``legend`` option of the error charts: the series names with their colours, no values
at the cursor (a live legend reads "touch: -- error (mm): --" until the pointer is on the chart)."""

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


def refused_before_job(session: Session, *, running: bool, what: str, not_started: str) -> bool:
    """Whether a click that would start a job of ``session`` (a check in the job pool) is refused
    at once, before the loop takes the job, each refusal told in one notification: the session
    closed (nothing to tell), the view's own ``what`` still running, or the session may not start
    a job now (``Session.admit_job``: its job runs, or its share of the server's time is used up;
    titled ``not_started``). ``what`` and ``not_started`` come in the session's language."""
    if session.closed:
        return True
    if running:
        _ = session.translator.gettext
        session.notify_refusal(_("Check running"), _("A {what} is still running here; wait for its result.").format(
            what=what))
        return True
    try:
        session.loop.admit_job()
    except JobRefused as exc:
        session.notify_refusal(not_started, error_text(exc, session.translator))
        return True
    return False


def target_of(session: Session) -> ViserTarget:
    """Where ``session``'s views draw (``session.target``): None only for a session made
    without a browser (it has no views) or after it closed. The session keeps it as a
    ``session.GuiTarget`` (its layer imports no viser); the server gives it viser's only."""
    target = session.target
    if target is None:
        raise RuntimeError("this session has no browser to draw in (none given, or it was closed)")
    return cast(ViserTarget, target)


def client_of(session: Session) -> viser.ClientHandle | None:
    """The browser of a per-browser ``session`` (``session.client``; None: ``--shared``, no
    browser, or closed), as the viser client the server gave it."""
    return cast("viser.ClientHandle | None", session.client)


def clients_of(session: Session) -> list[viser.ClientHandle]:
    """The browsers that show ``session`` (``Session.clients``), as viser clients."""
    return cast("list[viser.ClientHandle]", session.clients())


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
