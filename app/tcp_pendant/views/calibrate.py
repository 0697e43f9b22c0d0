"""The "Calibrate" tab: the wizards' menu and views (``views.wizard_menu.CalibrateView``) of the
session's calibration workflow (``Session.workflow``, which the server builds with the session),
then the trainer's "Systematic error" panel below them (built by ``views.build_session_views``).
"""

from __future__ import annotations

import viser

from tcp_pendant.session import Session
from tcp_pendant.views.beam_replay import ScanPlayer
from tcp_pendant.views.wizard_menu import CalibrateView

__all__ = ["build_calibrate_tab"]


def build_calibrate_tab(session: Session, tab: viser.GuiTabHandle, player: ScanPlayer) -> CalibrateView:
    """Fill the Calibrate tab (``tab``: a viser tab handle) with the wizards' views of
    ``session.workflow``; ``player``: the session's scan film (the beam result replays its scan)."""
    with tab:
        return CalibrateView(session, player)
