"""The trainer dashboards open on this server process, and when they re-render (no viser).

:class:`Dashboards` keeps each trainer's dashboard (``classroom.class_views.TrainerView``, one
per session) and re-renders every one of them from one read of the class: at once when the last
render is :data:`RENDER_INTERVAL_S` old, else once when it is (later changes join that one), and
every :data:`TICK_S` while one is open (its clocks). Renders run on viser's event loop
(``call_later``), each under its own session's guard.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Collection

from tcp_pendant.classroom.class_board import ClassBoard
from tcp_pendant.classroom.class_views import TrainerView
from tcp_pendant.classroom.gradebook_store import GradebookError
from tcp_pendant.session import Session

__all__ = ["RENDER_INTERVAL_S", "TICK_S", "Dashboards"]

log = logging.getLogger(__name__)

RENDER_INTERVAL_S = 0.5
"""Dashboards re-render at most this often (seconds): a class of 100 trainees touching at once
costs one gradebook read and one table per trainer browser per interval."""
TICK_S = 5.0
"""Dashboards re-render at least this often while one is open (its clocks: time on the step,
since the last touch, stuck)."""


class Dashboards:
    """The open trainer dashboards (module docstring).

    Args:
        read_class: the class as the dashboards show it, read now: the gradebook's board and
            the names connected on every process (raises ``GradebookError``: no render).
        call_later: ``call_later(delay_s, fn)`` runs ``fn`` on viser's event loop after a delay;
            None: dashboards render at once, every time (tests).
    """

    def __init__(self, read_class: Callable[[], tuple[ClassBoard, Collection[str]]],
                 call_later: Callable[[float, Callable[[], None]], None] | None) -> None:
        self._read_class = read_class
        self._call_later = call_later
        self._lock = threading.Lock()
        self.views: dict[int, TrainerView] = {}     # id(session) -> its dashboard
        self._render_due = False                    # a throttled render is scheduled
        self._tick_due = False                      # the clock tick is scheduled
        self._last_render = -float("inf")           # time.monotonic() of the last render

    def shows(self, session: Session) -> bool:
        """``session``'s browser shows a dashboard (the trainer's browser)."""
        with self._lock:
            return id(session) in self.views

    def add(self, session: Session, view: TrainerView) -> None:
        """``view`` is the dashboard of ``session`` now; its clock starts."""
        with self._lock:
            self.views[id(session)] = view
        self._schedule_tick()

    def drop(self, session: Session) -> None:
        """``session`` closed: its dashboard goes."""
        with self._lock:
            self.views.pop(id(session), None)

    def refresh(self) -> None:
        """Re-render every open dashboard (on viser's event loop), throttled (module docstring)."""
        with self._lock:
            if self._render_due or not self.views:
                return
            wait = self._last_render + RENDER_INTERVAL_S - time.monotonic()
            if wait > 0 and self._call_later is not None:
                self._render_due = True
                later = self._call_later
            else:
                later = None
        if later is not None:
            try:
                later(wait, self._render_trainers)
            except RuntimeError:                 # the loop is closed: the server is stopping
                with self._lock:
                    self._render_due = False
            return
        self._render_trainers()

    def _render_trainers(self) -> None:
        with self._lock:
            self._render_due = False
            self._last_render = time.monotonic()
            views = list(self.views.values())
        if not views:
            return
        try:
            board, connected = self._read_class()
        except GradebookError:
            log.exception("the gradebook could not be read for the dashboards")
            return
        for view in views:
            try:
                view.session.loop.guard(view.render)(board, connected)
            except Exception:
                log.exception("trainer dashboard refresh failed")
        self._schedule_tick()

    def _schedule_tick(self) -> None:
        with self._lock:
            if self._tick_due or not self.views or self._call_later is None:
                return
            self._tick_due = True
            later = self._call_later
        try:
            later(TICK_S, self._tick)
        except RuntimeError:
            with self._lock:
                self._tick_due = False

    def _tick(self) -> None:
        with self._lock:
            self._tick_due = False
        self.refresh()
