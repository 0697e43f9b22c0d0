"""The pendant's two magnified tip views (front and side) as one GUI image (viser).

The image comes from ``pendant.tip_insets`` (numpy, rendered on the server from the geometry:
the reference tip and the mounted tool's true tip); this view only places it below the jog
keys, labelled (:data:`CAPTION`; the page's script floats it over the 3D view's corner), and
replaces it after a move that changed it (``insets_key``: nothing is sent while the tool tip stays far from the window or has not moved). Shown with
and without "Hide distance": it draws what the eye would see, no number. It is hidden while
the tool tip is farther than ``tip_insets.NEAR_MM`` (40 mm, plain to see in the 3D view) from
the reference tip: there is nothing of the tool to see in it then, and a page that loads with
the robot in its ready pose does not carry the image.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from tcp_pendant.pendant.tip_insets import FAR, NEAR_MM, ZOOM_OUT, inset_zoom, insets_key, tip_insets_image
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.views.gui_util import target_of

if TYPE_CHECKING:
    from tcp_pendant.controller.pose_state import PoseState

__all__ = ["CAPTION", "CAPTION_ZOOMED", "TipInsets", "caption_for", "caption_text", "tip_views_title"]

def tip_views_title(tr: Translator = ENGLISH) -> str:
    """The caption's title ("Tip close-up"): the page's script finds the views by it (handed
    over in the pendant panel's hidden labels, ``data-tip-views``)."""
    return tr.gettext("Tip close-up")


def caption_text(zoomed: bool, tr: Translator = ENGLISH) -> str:
    """The image's label in ``tr``'s language: zoomed out (``ZOOM_OUT``×) or not; it holds
    :func:`tip_views_title`."""
    _ = tr.gettext
    if not zoomed:
        # TRANSLATORS: {title} is "Tip close-up" translated (the page finds the views by it)
        return _("{title} · left: front (X→, Z↑) · right: side (Y→, Z↑) · grid and bar 1 mm · "
                 "magenta: the tool tip").format(title=tip_views_title(tr))
    # TRANSLATORS: {title} is "Tip close-up" translated (the page finds the views by it)
    return _("{title}, zoomed out {zoom}× (orange frame) · left: front (X→, Z↑) · right: side (Y→, Z↑) · "
             "grid and bar {zoom} mm · magenta: the tool tip, or an arrow the way to it").format(
                 title=tip_views_title(tr), zoom=ZOOM_OUT)


CAPTION = caption_text(False)
CAPTION_ZOOMED = caption_text(True)
"""The image's label in English (:data:`CAPTION_ZOOMED` while zoomed out); the page's script
(``serve/static/pendant.js``) finds the views by its title (:func:`tip_views_title`) and
floats them over the 3D view's corner, out of the panel's way."""

FAR_MARGIN_MM = 1e-6
"""The pose state's touch distance (``|R^T (tip - p)|``) and :func:`insets_key`'s (``|p - tip|``)
are one length computed two ways (they differ by float rounding, ~1e-13 mm): beyond
``NEAR_MM`` plus this margin the key is FAR for sure, and a view showing FAR skips the key."""


def caption_for(reference_tip_world_m: np.ndarray, T_world_tooltrue: np.ndarray, *,
                tr: Translator = ENGLISH) -> str:
    """The image's label: zoomed out while the views are (``tip_insets.inset_zoom``), in
    ``tr``'s language (:func:`caption_text`)."""
    apex_mm = (T_world_tooltrue[:3, 3] - reference_tip_world_m) * 1000.0
    return caption_text(inset_zoom(apex_mm) != 1, tr)


class TipInsets:
    """Builds the caption and the image in the current GUI container of ``session.target.gui``."""

    def __init__(self, session: Session) -> None:
        self.session = session
        gui = target_of(session).gui
        c = session.controller
        self._key: tuple[object, ...] = insets_key(c.reference_tip_world_m, c.T_world_tool_true())
        near = self._key != FAR
        self.image = gui.add_image(tip_insets_image(c.reference_tip_world_m, c.T_world_tool_true()), format="png",
                                   label=caption_for(c.reference_tip_world_m, c.T_world_tool_true(),
                                                     tr=session.translator),
                                   visible=near)
        session.subscribe(self.on_change)

    def on_change(self, change: SessionChange) -> None:
        """A new pose redraws the views when they changed; a ``language`` change relabels them."""
        if change.language:
            c = self.session.controller
            self._set_label(caption_for(c.reference_tip_world_m, c.T_world_tool_true(), tr=self.session.translator))
        if change.pose and change.state is not None:
            if self._key == FAR and change.state.touch.distance_mm > NEAR_MM + FAR_MARGIN_MM:
                return                  # far, and shown far: nothing to draw (the key is FAR too)
            self.render(change.state)

    def render(self, state: PoseState) -> None:
        """Send a new image when the tips' geometry in the window changed."""
        tip = self.session.controller.reference_tip_world_m
        key = insets_key(tip, state.T_world_tool_true)
        if key == self._key:
            return
        self._key = key
        near = key != FAR
        if near:
            self.image.image = tip_insets_image(tip, state.T_world_tool_true)
            self._set_label(caption_for(tip, state.T_world_tool_true, tr=self.session.translator))
        if self.image.visible != near:
            self.image.visible = near

    def _set_label(self, label: str) -> None:
        if self.image.label != label:
            self.image.label = label
