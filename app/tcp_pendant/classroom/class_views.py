"""What the class room shows in a browser, as the server hands it over (no viser).

The class room decides when a browser sees the "Your name" welcome window or the trainer's
dashboard, and reads the address a browser connects from (the trainer token's lockout counts
per address); the windows themselves are viser views (``views.identity``,
``views.dashboard``) and the address is read through viser's internals
(``views.viser_adapter``). The views sit above the classroom, so the classroom never imports
them: the server builds a :class:`ClassViews` of those three callables and gives it to the
``ClassRoom`` it makes. The protocols say what the class room calls on what they return.
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

from tcp_pendant.classroom.class_board import ClassBoard
from tcp_pendant.session import Browser, Session

if TYPE_CHECKING:
    from tcp_pendant.classroom.class_room import ClassRoom

__all__ = ["ClassViews", "TrainerView", "WelcomeWindow"]


class WelcomeWindow(Protocol):
    """The "Your name" window of one session (``views.identity.IdentityPrompt``)."""

    def reopen(self, message: str, *, forget: bool) -> None:
        """Show the window again with ``message``; ``forget``: the page drops the name and key."""


class TrainerView(Protocol):
    """The trainer's dashboard in one browser (``views.dashboard.TrainerDashboard``)."""

    @property
    def session(self) -> Session:
        """The trainer's session (its browser shows the dashboard)."""

    def render(self, board: ClassBoard | None = None, connected: Collection[str] | None = None) -> None:
        """Show the class (``board`` and ``connected``: read now when not given)."""


@dataclass(frozen=True)
class ClassViews:
    """The browser side of the class room.

    Attributes:
        welcome: builds the welcome window of a new session, given the session, what to call
            with a typed name and browser key (returns the name as stored and the key issued
            now) and what to call with a typed trainer token (True: it was right).
        dashboard: turns a session's browser into the trainer's dashboard of the class room.
        client_address: the IP address a browser (``Session.client``) connects from, None when
            there is none to read.
    """

    welcome: Callable[[Session, Callable[[object, str], tuple[str, str | None]], Callable[[str], bool]], WelcomeWindow]
    dashboard: Callable[[Session, ClassRoom], TrainerView]
    client_address: Callable[[Browser | None], str | None]
