"""The "Calibrate" tab: where the calibration wizard views plug in.

How to plug in (for ``views/wizard_*.py``): provide a module ``tcp_pendant.views.wizard_menu``
with a function

    def build_calibrate_views(session: tcp_pendant.session.Session) -> object

It is called once per session, under ``session.lock``, *inside* the Calibrate tab's GUI
container (so plain ``session.target.gui.add_*`` calls land in the tab; the container is also
``session.calibrate_container``). Use ``session.controller`` (flange pose:
``controller.T_world_flange()``), ``session.library``, ``session.notify``,
``session.add_motion_listener`` (live pose-diversity meter), ``session.guard`` (wrap every
callback: lock + error notification), ``session.views["scene"].scene`` (draw triads) and
``session.touches``. Return value is stored as ``session.views["calibrate"]``.

Alternatively (tests, other plug-ins) call :func:`register_calibrate_view` with such a function
before sessions are built. Without any plug-in the tab says that the wizards are not installed.
"""

from __future__ import annotations

import importlib
import logging
from collections.abc import Callable
from typing import Any

from tcp_pendant.session import Session
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.gui_util import target_of

__all__ = ["WIZARD_MODULE", "build_calibrate_tab", "register_calibrate_view"]

log = logging.getLogger(__name__)

WIZARD_MODULE = "tcp_pendant.views.wizard_menu"
_REGISTERED: list[Callable[[Session], Any]] = []


def register_calibrate_view(factory: Callable[[Session], Any]) -> None:
    """Add a view factory called in every new session's Calibrate tab."""
    _REGISTERED.append(factory)


def _factories() -> list[Callable[[Session], Any]]:
    out = list(_REGISTERED)
    try:
        module = importlib.import_module(WIZARD_MODULE)
    except ModuleNotFoundError as exc:
        if exc.name != WIZARD_MODULE:
            log.exception("%s failed to import", WIZARD_MODULE)
        return out
    fn = getattr(module, "build_calibrate_views", None)
    if callable(fn) and fn not in out:
        out.append(fn)
    return out


def build_calibrate_tab(session: Session, tab: Any) -> None:
    """Fill the Calibrate tab (``tab``: a viser tab handle) with the plugged-in views."""
    session.calibrate_container = tab
    with tab:
        factories = _factories()
        if not factories:
            target_of(session).gui.add_markdown("*Calibration wizards are not installed in this build.*")
            return
        for fn in factories:
            try:
                session.views.setdefault("calibrate", fn(session))
            except Exception as exc:
                log.exception("calibrate view %s failed", fn)
                target_of(session).gui.add_markdown(
                    f"⚠ The calibration view could not be built: {escape_markdown(str(exc))}")
