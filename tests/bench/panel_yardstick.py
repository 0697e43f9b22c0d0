"""The jog panel's readouts and the jogger's work around the IK as they were before the
per-step speed work on them: the yardstick of ``bench_panel.py`` (old and new code measured in
one process, alternating) and of ``tests/app/test_panel_fast_paths.py`` (the new texts must be
the old ones to the last character). Copies of ``PendantPanel.on_change`` / ``show_jog_result`` /
``_set_md`` / ``render`` / ``set_markdown`` (and ``viser_adapter.queue_markdown``), the readout
formatting (``pendant.formatting``, ``pendant.guidance``), ``Jogger._translate`` (with
``_clear_of``) and ``VirtualController.T_world_tool_true`` (a fresh FK per press) of that
version. Not used by the app.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MethodType
from typing import Any

import numpy as np

from tcp_pendant.controller import JogResult, PoseReadout, TouchGeometry
from tcp_pendant.controller.touch import TOUCH_TOLERANCE_MM
from tcp_pendant.pendant.guidance import CLOSEUP_WITHIN_MM, contact_stop, jog_frame_rotation, side_view_markdown
from tcp_pendant.pendant.jogging import _CLEAR_M, _WORLD_AXES
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views import viser_adapter
from tcp_pendant.views.gui_util import set_value
from tcp_pendant.views.pendant_panel import PendantPanel

__all__ = ["install_legacy", "install_new", "legacy_joint_readout_markdown", "legacy_offset_markdown",
           "legacy_tcp_readout_markdown", "legacy_tip_offset_mm", "legacy_touch_indicator_markdown"]


# ------------------------------------------------------------------ formatting (pendant/formatting.py)
def legacy_fmt_num(value: float, decimals: int = 2) -> str:
    v = float(value)
    if not math.isfinite(v):
        return str(v)
    text = f"{v:.{decimals}f}"
    return text[1:] if text[0] == "-" and not text.strip("-0.") else text


_SEP = "\x1f"


def _two_decimals(values: tuple[float, ...]) -> list[str]:
    texts = (_SEP.join(("%.2f",) * len(values)) % values).split(_SEP)
    return ["0.00" if t == "-0.00" else t for t in texts]


def legacy_tcp_readout_markdown(readout: PoseReadout, tool_name: str | None) -> str:
    r = readout
    x, y, z, a, b, c = _two_decimals((r.x_mm, r.y_mm, r.z_mm, r.a_deg, r.b_deg, r.c_deg))
    w = max(len(x), len(y), len(z), len(a), len(b), len(c))
    tool = "Active tool data: none (FLANGE)" if tool_name is None else f"Active tool data: TOOL {escape_markdown(tool_name)}"
    return (f"**TCP in {r.frame}** · {tool}\n\n```\nX {x:>{w}} mm   A {a:>{w}} deg\n"
            f"Y {y:>{w}} mm   B {b:>{w}} deg\nZ {z:>{w}} mm   C {c:>{w}} deg\n```")


def legacy_joint_readout_markdown(angles_deg: Mapping[str, float]) -> str:
    values = _two_decimals(tuple(angles_deg.values()))
    items = [f"{n} {v:>8}" for n, v in zip(angles_deg, values)]
    lines = ["  ".join(items[i:i + 3]) for i in range(0, len(items), 3)]
    return "**Joints (deg)**\n\n```\n" + "\n".join(lines) + "\n```"


def legacy_touch_indicator_markdown(touch: TouchGeometry, *, hide_distance: bool) -> str:
    if touch.crashed:
        return (f"✖ **CRASH**: the tool tip went {legacy_fmt_num(touch.penetration_mm, 1)} mm through the "
                "reference tip. Jog back out.")
    if hide_distance:
        return "Distance to reference tip: *hidden (judge by eye)*"
    if touch.touching:
        return (f"✔ **TOUCHING** the reference tip ({legacy_fmt_num(touch.distance_mm)} mm ≤ "
                f"{TOUCH_TOLERANCE_MM} mm)")
    return f"Distance to reference tip: **{legacy_fmt_num(touch.distance_mm)} mm**"


# ------------------------------------------------------------------ guidance (pendant/guidance.py)
def legacy_tip_offset_mm(state: Any, reference_tip_world_m: np.ndarray, frame: str) -> np.ndarray:
    d_world_m = np.asarray(reference_tip_world_m, dtype=float) - np.asarray(state.T_world_tool_true)[:3, 3]
    return jog_frame_rotation(state, frame).T @ d_world_m * 1000.0


def _n(v: float) -> str:
    text = f"{v:+.2f}" if abs(v) < 100 else f"{v:+.1f}"
    return "0.00" if float(text) == 0.0 else text


def legacy_offset_markdown(delta_mm: np.ndarray, frame: str) -> str:
    d = np.asarray(delta_mm, dtype=float)
    return f"`ΔX {_n(d[0])}  ΔY {_n(d[1])}  ΔZ {_n(d[2])} mm` to the tip ({frame})"


# ------------------------------------------------------------------ the panel (views/pendant_panel.py)
def legacy_queue_markdown(handle: Any, text: str) -> bool:
    """``views.viser_adapter.queue_markdown`` of that version (viser's message class imported per call)."""
    try:
        from viser._messages import GuiUpdateMessage

        impl = handle._impl
        if impl.removed:
            return False
        object.__setattr__(handle, "_content", text)
        if impl.props._markdown != text:
            impl.props._markdown = text
            impl.gui_api._websock_interface.queue_message(GuiUpdateMessage(impl.uuid, {"_markdown": text}))
    except (AttributeError, ImportError) as exc:
        return viser_adapter._fallback("markdown", exc)
    return viser_adapter._fast("markdown")


def set_markdown(handle: Any, text: str) -> None:
    if "![" in text or not legacy_queue_markdown(handle, text):
        handle.content = text


def legacy_on_change(self: PendantPanel, change: Any) -> None:
    if change.jog is not None:
        legacy_show_jog_result(self, change.jog)
        self._stop_key = None if change.state is None else change.state.key
    elif change.pose and self._last_stop and change.state is not None and change.state.key != self._stop_key:
        legacy_show_jog_result(self, JogResult(True, 1.0, None, ""))
    if change.pose:
        legacy_render(self, change.state)


def legacy_show_jog_result(self: PendantPanel, res: JogResult) -> None:
    text = "" if res.ok else f"⚠ {res.message}"
    legacy_set_md(self, self.status_md, "status", text)
    if text and text != self._last_stop:
        self.session.notify("Jog stopped", res.message, kind="warning")
    self._last_stop = text


def legacy_set_md(self: PendantPanel, handle: Any, key: str, text: str) -> None:
    if self._last_text.get(key) != text:
        set_markdown(handle, text)
        self._last_text[key] = text


def legacy_render(self: PendantPanel, state: Any = None) -> None:
    s = self.session
    state = s.pose_state() if state is None else state
    frame = self._readout
    tool = s.controller.active_tool
    legacy_set_md(self, self.tcp_md, "tcp",
                  legacy_tcp_readout_markdown(state.readout(frame), None if tool is None else tool.name))
    hide = s.hide_distance
    if bool(self.hide_distance.value) != hide:
        set_value(self.hide_distance, hide)
    if self.hide_distance.disabled != s.rules.distance_locked:
        self.hide_distance.disabled = s.rules.distance_locked
    touch = legacy_touch_indicator_markdown(state.touch, hide_distance=hide)
    closeup = ""
    if not hide:
        jf = s.jogger.settings.frame
        delta = legacy_tip_offset_mm(state, s.controller.reference_tip_world_m, jf)
        touch += "\n\n" + legacy_offset_markdown(delta, jf)
        if state.touch.distance_mm <= CLOSEUP_WITHIN_MM:
            closeup = side_view_markdown(delta, jf)
    legacy_set_md(self, self.touch_md, "touch", touch)
    legacy_set_md(self, self.closeup_md, "closeup", closeup)
    if self.closeup_md.visible != bool(closeup):
        self.closeup_md.visible = bool(closeup)
    angles = state.joint_angles_deg
    legacy_set_md(self, self.joints_md, "joints", legacy_joint_readout_markdown(angles))
    if not self.joint_folder.visible:
        return
    for i, (slider, v) in enumerate(zip(self.joint_sliders, angles.values())):
        value = round(float(v), 2)
        mine = self._from_client.get(i)
        if mine is not None:
            if mine == value:
                continue
            del self._from_client[i]
        if slider.value != value:
            set_value(slider, value)


# ------------------------------------------------------------------ the jogger (pendant/jogging.py)
def _clear_of(tip_m: np.ndarray, step_m: np.ndarray, reference_m: np.ndarray) -> bool:
    px, py, pz = tip_m.tolist()
    rx, ry, rz = reference_m.tolist()
    return math.hypot(rx - px, ry - py, rz - pz) > math.hypot(*step_m.tolist()) + _CLEAR_M


def legacy_T_world_tool_true(controller: Any) -> np.ndarray:
    """``true_kinematics.T_world_flange(q) @ T_flange_tool_true``: a fresh FK."""
    return controller.T_world_flange_true() @ controller.mounted_tool.T_flange_tool_true


def legacy_translate(self: Any, ax: str, amount_mm: float) -> JogResult:
    c = self.controller
    if not self.stop_at_contact:
        return c.jog_cartesian(self.settings.frame, ax, amount_mm)
    i = "XYZ".index(ax)
    axis_m = _WORLD_AXES[:, i] if self.settings.frame == "WORLD" else self.frame_rotation()[:, i]
    step_m = axis_m * (amount_mm / 1000.0)
    tip_m = legacy_T_world_tool_true(c)[:3, 3]
    stop = None if _clear_of(tip_m, step_m, c.reference_tip_world_m) else (
        contact_stop(tip_m, step_m, c.reference_tip_world_m))
    if stop is None:
        return c.jog_cartesian(self.settings.frame, ax, amount_mm)
    res = c.jog_cartesian(self.settings.frame, ax, amount_mm * stop.fraction)
    if not res.ok:
        return res
    return JogResult(False, stop.fraction, "contact",
                     f"Stopped at the reference tip after {abs(amount_mm) * stop.fraction:.2f} of "
                     f"{abs(amount_mm):g} mm (touch-up: the tool tip touches it). Press again to go on.")


# ------------------------------------------------------------------ switching a session
def _swap_panel_subscriber(session: Any, fn: Any) -> None:
    panel = session.views["pendant"]
    for i, f in enumerate(session._subscribers):
        if getattr(f, "__self__", None) is panel or getattr(f, "panel_of", None) is panel:
            session._subscribers[i] = fn
            return
    raise RuntimeError("the session has no jog panel subscribed")


def install_legacy(session: Any, wrap: Any = None) -> None:
    """The session's jog panel renders and its jogger translates as before (``wrap(fn)``: a
    timing wrapper around the panel's subscriber, or None)."""
    panel = session.views["pendant"]
    fn = MethodType(legacy_on_change, panel)
    fn = fn if wrap is None else wrap(fn)
    fn.panel_of = panel
    _swap_panel_subscriber(session, fn)
    session.jogger._translate = MethodType(legacy_translate, session.jogger)


def install_new(session: Any, wrap: Any = None) -> None:
    """The app's own code again (``wrap`` as for :func:`install_legacy`)."""
    panel = session.views["pendant"]
    fn = panel.on_change if wrap is None else wrap(panel.on_change)
    try:
        fn.panel_of = panel
    except AttributeError:                      # a bound method takes no attributes: keep it as is
        pass
    _swap_panel_subscriber(session, fn)
    session.jogger.__dict__.pop("_translate", None)
