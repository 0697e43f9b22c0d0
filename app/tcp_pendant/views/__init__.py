"""viser views of a pendant session: scene, jog panel, touch list, tool panel and the
"Calibrate" tab where the wizard views plug in (see ``tcp_pendant.views.calibrate``).

:func:`build_session_views` pins the exercise's instructions and the trainer's messages at the
top (``class_notices``), then lays a session out as three tabs, like a pendant's menu:
**Jog** (the running wizard's step dock, readouts, touch indicator, jog keys, touches), **Tool** (mounted tool, active tool
data, library, export, controller files, TCP check, numeric entry, then the TCP service with the beam
sensor) and **Calibrate** (wizards,
then the trainer's "Systematic error" panel).
"""

from __future__ import annotations

from collections.abc import Iterator

from tcp_pendant.session import Session
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.beam_check import BeamCheckView
from tcp_pendant.views.beam_replay import ScanPlayer
from tcp_pendant.views.calibrate import build_calibrate_tab
from tcp_pendant.views.class_notices import ClassNoticeView
from tcp_pendant.views.pendant_panel import PendantPanel
from tcp_pendant.views.scenario_panel import ScenarioPanel
from tcp_pendant.views.scene import SceneView
from tcp_pendant.views.tab_titles import TabTitles, tab_title
from tcp_pendant.views.tool_panel import ToolPanel
from tcp_pendant.views.touch_list import TouchListView
from tcp_pendant.views.wizard_dock import WizardDock
from tcp_pendant.views.gui_util import target_of

__all__ = [
    "BeamCheckView",
    "ClassNoticeView",
    "PendantPanel",
    "ScenarioPanel",
    "SceneView",
    "ToolPanel",
    "TouchListView",
    "WizardDock",
    "build_calibrate_tab",
    "build_session_views",
    "session_view_steps",
]


def build_session_views(session: Session, *, title: str = "TCP Pendant") -> None:
    """Build the scene and the GUI of ``session`` into ``session.target`` (under its lock).

    Fills ``session.views`` with ``"scene"``, ``"pendant"``, ``"touches"``, ``"tools"``,
    ``"calibrate"``, ... (for tests: the views never reach each other), each subscribed to the
    session's change signal, then pushes the first state. The views that play a beam scan's
    film are handed the session's one :class:`~tcp_pendant.views.beam_replay.ScanPlayer`.
    """
    for _ in session_view_steps(session, title=title):
        pass


def session_view_steps(session: Session, *, title: str = "TCP Pendant") -> Iterator[str]:
    """:func:`build_session_views` one view at a time: yields the name of each view built.

    The server builds a browser's session on viser's event loop and awaits between the steps
    (each a few to a few tens of ms), so other browsers are not stalled for a whole build. The
    lock and the GUI's ``atomic()`` are held from the first step to the last: nothing built is
    sent to the browser before the whole GUI is there, so no browser event can reach a
    half-built session. Closing the generator early (the browser left) leaves the context
    managers properly; the caller closes the session.
    """
    with session.lock, target_of(session).atomic():
        gui = target_of(session).gui
        scene = session.views["scene"] = SceneView(session)
        player = session.views["beam_player"] = ScanPlayer(session, stand=scene.beam_stand)
        scene.player = player
        yield "scene"
        session.views["notices"] = ClassNoticeView(session)   # the exercise's banner, the trainer's messages
        gui.add_markdown(f"#### {escape_markdown(title)}")   # one line in the panel: room for the keys
        tabs = gui.add_tab_group()
        tr = session.translator
        jog_tab = tabs.add_tab(tab_title("jog", tr))
        with jog_tab:
            session.views["dock"] = WizardDock(session)      # the running wizard's step, on top
            session.views["pendant"] = PendantPanel(session)
            session.views["touches"] = TouchListView(session)
        yield "jog"
        tool_tab = tabs.add_tab(tab_title("tool", tr))
        with tool_tab:
            session.views["tools"] = ToolPanel(session)
            session.views["beam_check"] = BeamCheckView(session, player)   # TCP service with the beam sensor
        yield "tool"
        calibrate_tab = tabs.add_tab(tab_title("calibrate", tr))
        session.views["calibrate"] = build_calibrate_tab(session, calibrate_tab, player)
        with calibrate_tab:
            session.views["scenario"] = ScenarioPanel(session)
        session.views["tabs"] = tabs
        session.views["tab_titles"] = TabTitles(session, {"jog": jog_tab, "tool": tool_tab,
                                                          "calibrate": calibrate_tab})
        yield "calibrate"
    session.changed(pose=True, tool=True)
