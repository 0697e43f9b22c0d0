"""The jog panel of one session, laid out like a teach pendant (viser GUI).

Top to bottom (below the wizard dock, ``views.wizard_dock``): the touch indicator with the
offset "ΔX ΔY ΔZ mm" of the reference tip along the jog frame's axes (hidden by "Hide
distance"), the increment, the jog keys - one row per axis with − and + side by side (X Y Z A B
C, or A1..A6; in continuous mode the hold-to-jog keys, two per axis, since only single buttons
report a hold), the keys line, the TCP readout (frame + tool; below the keys, so that a
wizard's step, its Record and the keys fit above the fold at 1024x768), the status line (why a
jog stopped), within 20 mm a magnified text close-up of the two tips (hidden by "Hide
distance"), the front and side views of the tips (``views.tip_insets``, within 40 mm: geometry,
no numbers; the page's script floats them over the 3D view's corner) - everything that comes
and goes near the tip is below the keys, so the keys never move - then the jog settings (mode,
frame, override, readout frame), the joints, Home and the view (the camera buttons,
"Shadows"); the touches ("Record point" and the list) follow.
Every button group marks its selected option with "✓ " (viser's button groups show no
selection); a click's value is read without the mark. Keyboard shortcuts come from the page's
own script (``serve/static/pendant.js``, served by ``serve.client_script``): it clicks these buttons, so a
key is a click; every jog, increment and Record hint names its key and :data:`KEYS_LINE` sums
them up below the jog keys.

The deadman: a jog click, the start of a hold and a joint slider's move are carried out only
while fresh (``pendant.jogging.PressGate``, ``PRESS_BOUND_S`` after their arrival as
``views.arrival`` stamps it); the ones dropped are counted and reported once per burst, on the
status line and as a notification ("N jog presses dropped: the server was busy").

Widgets only call :class:`tcp_pendant.pendant.Jogger` and the session; all text comes from
``tcp_pendant.pendant.formatting``. Every callback runs on viser's event loop
(:meth:`SessionLoop.on_loop`), in the order the browser's messages arrived.

"Shadows" switches the shadows of viser's default lights for this browser (every browser in
``--shared`` mode, where its label says so). The page's script unchecks it when the browser
draws WebGL in software (no GPU: a thin client, a virtual machine), where the shadow maps cost
most of each frame (:data:`SHADOWS_LABEL`).

Language: every word of the panel is the session's (``session.translator``; the selector,
``views.language_selector``, is in the View folder). A ``language`` change relabels every
handle (:meth:`PendantPanel.relabel`) and re-renders the readouts; the key labels (``X −``,
``A1 +``), frame names (WORLD, BASE, TOOL) and numbers stay as they are. A button group's
click is read in the language it was shown in or in English (a click that crossed a switch).

Joint sliders: setting a slider's value from Python fires its ``on_update`` (later, on the
loop) with ``event.client is None``; those events are ignored. A slider the browser is
dragging is not echoed back: while the joint is where the browser's last value of that slider
put it, :meth:`PendantPanel.render` leaves the slider alone (the browser shows its own,
newer-or-equal value; writing the rounded angle back would pull its slider to an older one).
"""

from __future__ import annotations

import asyncio
import html
import math
import time
from collections.abc import Callable, Coroutine
from typing import TYPE_CHECKING, TypeVar

import numpy as np
import viser

from tcp_pendant.controller.tools import shown_tool_label
from tcp_pendant.controller import JogResult
from tcp_pendant.controller.words import in_language
from tcp_pendant.pendant import (
    CARTESIAN_AXES,
    dropped_presses_text,
    INCREMENTS,
    JOG_FRAMES,
    JogMode,
    joint_label,
    joint_readout_markdown,
    tcp_readout_markdown,
    touch_indicator_markdown,
)
from tcp_pendant.pendant.hold import HoldDriver, Timer
from tcp_pendant.pendant.jogging import CONTINUOUS
from tcp_pendant.pendant.guidance import CLOSEUP_WITHIN_MM, offset_markdown, side_view_markdown, tip_offset_xyz_mm
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.translation import ENGLISH, N_, SOURCE_LANGUAGE, Translator, translator
from tcp_pendant.views import arrival
from tcp_pendant.views.scene import closeup_camera, overview_camera
from tcp_pendant.views.gui_util import ButtonEvent, ButtonGroupEvent, CheckboxEvent, set_value, target_of
from tcp_pendant.views.language_selector import LanguageSelector
from tcp_pendant.views.tip_insets import TipInsets, tip_views_title
from tcp_pendant.views.touch_list import RECORD_POINT
from tcp_pendant.views.viser_adapter import queue_markdown
from tcp_pendant.views.wizard_dock import BACK, FINISH, NEXT, RECORD

if TYPE_CHECKING:
    from tcp_pendant.controller.pose_state import PoseState

SliderEvent = viser.GuiEvent[viser.GuiSliderHandle[float]]
"""A joint slider's change."""
SettingHandle = TypeVar("SettingHandle", viser.GuiButtonGroupHandle, viser.GuiDropdownHandle[str],
                        viser.GuiSliderHandle[float])
"""The selectors of a jog setting: a button group, a dropdown, a slider."""
"""A jog setting's change: mode and increment (button groups), frame (dropdown), override (slider)."""

__all__ = ["HOLD_HZ", "KEYS_LINE", "MARK", "PendantPanel", "jog_key_hint", "marked", "set_markdown", "unmarked"]

HOLD_HZ = 20.0
"""Rate the browser is asked to send hold messages at; the jog itself ticks on the server's
20 Hz clock (``pendant.hold.HoldDriver``) while they keep coming."""

_AXIS_HINT = {"X": N_("translate along X (mm)"), "Y": N_("translate along Y (mm)"),
              "Z": N_("translate along Z (mm)"), "A": N_("rotate about Z through the TCP (deg)"),
              "B": N_("rotate about Y through the TCP (deg)"), "C": N_("rotate about X through the TCP (deg)")}
_MODE_WORDS = {JogMode.CARTESIAN: N_("Cartesian"), JogMode.JOINT: N_("Joint")}
"""The Mode buttons' words (the values are ``JogMode``'s English names)."""


MARK = "✓ "
"""Prefix of the selected option of a button group."""

CONNECTION_LOST = N_("This page cannot reach the pendant server (it is still trying). Your name and your "
                     "recorded touches are kept on the server: reload the page to join again.")
"""The page script's notice when the server stays unreachable (serve/static/pendant.js, 8.)."""
KEYS_LINE = N_("Keys: `1`…`6` jog **+** on the rows above, `Shift`+`1`…`6` jog **−**, "
             "`[` `]` smaller / larger increment, `R` Record, `N` Next / Finish, `B` Back")
"""The keyboard shortcuts (``serve/static/pendant.js``), shown below the jog keys (hidden by the
page's script on a touch screen, whose pointer is coarse: no keyboard there)."""

LAPSE_TEXT = N_("Jog stopped: the browser did not renew the held key for 0.25 s (a busy browser or "
              "a slow network); let go and press again.")
"""The status line when a hold's lease ran out (``pendant.hold``)."""

SHADOWS_LABEL = N_("Shadows")
"""The shadows checkbox of one browser's pendant; ``serve/static/pendant.js`` unchecks the checkbox
of this exact label in a browser that renders WebGL in software (its renderer's name says
SwiftShader, llvmpipe, softpipe, software or Basic Render), once per checkbox shown."""
SHARED_SHADOWS_LABEL = N_("Shadows (every screen)")
"""The same in ``--shared`` mode: it switches every browser's shadows, and the script leaves it alone."""
SHADOWS_HINT = N_("Shadows of the robot and the tools. Off by itself in a browser that draws 3D without a "
                "graphics card, where they cost most of each frame.")
INCREMENT_KEYS = N_("keys [ smaller, ] larger")
HIDE_DISTANCE_HINT = N_("Training: judge the touch by eye, as on a real robot (hides the distance, the Δ offsets "
                        "and the close-up).")
INCREMENT_HINT = N_("mm for X/Y/Z, deg for A/B/C and joints; Cont. = hold to jog; {keys}")


DROP_REPORT_EVERY_S = 1.0
"""Dropped jog presses are reported (status line, notification) at most this often (s)."""


def jog_key_hint(row: int, tr: Translator = ENGLISH) -> str:
    """The keys of jog-key row ``row`` (0-based) as its hint says them ("" past the 9th row)."""
    return tr.gettext("keys {n} (+) and Shift+{n} (−)").format(n=row + 1) if 0 <= row < 9 else ""


def _with_keys(hint: str, row: int, tr: Translator = ENGLISH) -> str:
    keys = jog_key_hint(row, tr)
    return f"{hint}; {keys}" if hint and keys else hint or keys


def mode_word(mode: JogMode, tr: Translator = ENGLISH) -> str:
    """The Mode button of ``mode`` in ``tr``'s language."""
    return tr.gettext(_MODE_WORDS[mode])


def increment_word(increment: str, tr: Translator = ENGLISH) -> str:
    """An Increment button: the numbers as they are, ``Cont.`` in ``tr``'s language."""
    return tr.pgettext("increment", "Cont.") if increment == CONTINUOUS else increment


def _read_choice(label: str, words: dict[str, str], tr: Translator) -> str:
    """The value of the button ``label`` of a group whose values have ``words`` (value → English
    word): ``label`` in ``tr``'s language or in English, else ``label`` itself."""
    for value, word in words.items():
        if label in (word, tr.gettext(word)):
            return value
    return label


def marked(options: tuple[str, ...], selected: str) -> tuple[str, ...]:
    """``options`` with the selected one marked (``"✓ 10"``)."""
    return tuple(MARK + o if o == selected else o for o in options)


def unmarked(label: str) -> str:
    """A button group's value without the selection mark."""
    return label[len(MARK):] if label.startswith(MARK) else label


def set_markdown(handle: viser.GuiMarkdownHandle, text: str) -> None:
    """``handle.content = text`` for the readouts, which change on every jog step.

    viser's public setter runs its generic prop machinery (type-hint casting that builds
    ``typing`` aliases on every call: ~4x the cost of the message itself here, measured by
    tests/bench/bench_server.py); for texts without images (nothing for viser's markdown
    parser to inline) this stores the same ``_markdown`` prop and queues the same
    ``GuiUpdateMessage`` (``views.viser_adapter.queue_markdown``). Falls back to the public
    setter for a removed handle or if viser's internals differ.
    """
    if "![" in text or not queue_markdown(handle, text):
        handle.content = text


class PendantPanel:
    """Builds the jog panel in the current GUI container of ``session.target.gui``."""

    def __init__(self, session: Session) -> None:
        self.session = session
        gui = target_of(session).gui
        self._from_client: dict[int, float] = {}   # slider -> angle (deg, 0.01) its browser value set
        self._last_text: dict[str, str] = {}
        self._joint_folder_shown = False           # joint_folder.visible as _show_settings set it
        self._hide_locked = False                  # hide_distance.disabled as render set it
        self._last_stop = ""
        self._stop_key: tuple[object, ...] | None = None
        self._hold: HoldDriver | None = None
        self._drop_report_due = False
        self._drop_reported_at = -math.inf          # monotonic s of the last drop report

        self._readout = "WORLD"
        self.touch_md = gui.add_markdown("")
        self._build_keys(gui)
        self.keys_md = gui.add_markdown(self._keys_markdown())
        # the TCP readout below the keys: the step, its Record and the keys fit above the fold
        # at 1024x768 with a wizard open (a fixed three lines: the keys above it never move)
        self.tcp_md = gui.add_markdown("")
        # what appears near the tip or at a stop goes below the keys, so no key moves when it
        # shows (the keys stay where the trainee's pointer is, above the fold at 1024x768)
        self.status_md = gui.add_markdown("")
        self.closeup_md = gui.add_markdown("", visible=False)
        self.insets = TipInsets(session)           # front and side views of the tips (no numbers)
        self._build_joint_folder(gui)
        self._build_settings(gui)
        self._wire_settings()
        if session.language != SOURCE_LANGUAGE:
            self.relabel()
        self._show_settings()
        session.subscribe(self.on_change)

    def _build_keys(self, gui: viser.GuiApi) -> None:
        """"Hide distance", the increment, the compact key rows (Cartesian, joints) and the
        hold-to-jog keys of continuous mode."""
        session = self.session
        st = session.jogger.settings
        self.hide_distance = gui.add_checkbox("Hide distance", session.hide_distance, hint=HIDE_DISTANCE_HINT)
        self.increment = gui.add_button_group("Increment", marked(INCREMENTS, st.increment),
                                              hint=INCREMENT_HINT.format(keys=INCREMENT_KEYS))
        # compact keys: one row per axis (− and + side by side); clicks only
        self.cart_rows: dict[str, viser.GuiButtonGroupHandle] = {}
        for r, ax in enumerate(CARTESIAN_AXES):
            row = gui.add_button_group(ax, (f"{ax} −", f"{ax} +"), hint=_with_keys(_AXIS_HINT[ax], r))
            row.on_click(session.loop.on_loop(self._row_cb(ax)))
            self.cart_rows[ax] = row
        self.joint_rows: list[viser.GuiButtonGroupHandle] = []
        for i, name in enumerate(session.controller.kinematics.joint_names):
            row = gui.add_button_group(name, (f"{name} −", f"{name} +"), visible=False,
                                       hint=_with_keys(f"jog {name} (deg)", i))
            row.on_click(session.loop.on_loop(self._row_cb(i)))
            self.joint_rows.append(row)
        # hold-to-jog keys (continuous mode): viser reports holds of single buttons only
        self.cart_folder = gui.add_folder("Cartesian jog (hold)", visible=False)
        with self.cart_folder:
            self.cart_buttons: dict[tuple[str, int], viser.GuiButtonHandle] = {}
            for r, ax in enumerate(CARTESIAN_AXES):
                for sign, sym in ((-1, "−"), (1, "+")):
                    b = gui.add_button(f"{ax} {sym}", hint=_with_keys(_AXIS_HINT[ax], r),
                                       color="gray" if sign < 0 else "blue")
                    self._wire_key(b, ax, sign)
                    self.cart_buttons[(ax, sign)] = b

    def _build_joint_folder(self, gui: viser.GuiApi) -> None:
        """Joint mode's sliders and hold-to-jog keys (deg)."""
        c = self.session.controller
        k = c.kinematics
        self.joint_folder = gui.add_folder("Joint jog", visible=False)
        with self.joint_folder:
            self.joint_sliders: list[viser.GuiSliderHandle[float]] = []
            self.joint_buttons: dict[tuple[int, int], viser.GuiButtonHandle] = {}
            q_deg = np.degrees(c.q_rad)
            for i, name in enumerate(k.joint_names):
                lo, hi = math.degrees(k.lower_rad[i]), math.degrees(k.upper_rad[i])
                s = gui.add_slider(joint_label(name, lo, hi), min=lo, max=hi, step=0.01,
                                   initial_value=float(np.clip(q_deg[i], lo, hi)))
                s.on_update(self._slider_cb(i))
                self.joint_sliders.append(s)
                for sign, sym in ((-1, "−"), (1, "+")):
                    b = gui.add_button(f"{name} {sym}", color="gray" if sign < 0 else "blue",
                                       hint=_with_keys(f"hold to jog {name} (deg)", i))
                    self._wire_key(b, i, sign)
                    self.joint_buttons[(i, sign)] = b

    def _build_settings(self, gui: viser.GuiApi) -> None:
        """The jog settings, the joints readout, the two poses and the view."""
        st = self.session.jogger.settings
        self.settings_folder = gui.add_folder("Jog settings")
        with self.settings_folder:
            self.mode = gui.add_button_group("Mode", marked((JogMode.CARTESIAN.value, JogMode.JOINT.value),
                                                            st.mode.value))
            self.frame = gui.add_dropdown("Jog frame", JOG_FRAMES, initial_value=st.frame)
            self.override = gui.add_slider("Override %", min=1, max=100, step=1, initial_value=st.override_pct)
            self.readout_frame = gui.add_button_group("Readout", marked(("WORLD", "BASE"), self._readout))
            self.settings_md = gui.add_markdown("")
        self.joints_md = gui.add_markdown("")
        self.home = gui.add_button("Ready pose", hint="Back to the start pose (teleport): HOME with the "
                                   "flange pointing down.")
        self.kuka_home = gui.add_button("HOME", hint="The robot's HOME position (teleport); on a KR 6 the "
                                        "wrist is singular there (A5 = 0).")
        self.view_folder = gui.add_folder("View")
        with self.view_folder:
            self.closeup = gui.add_button("Close-up on reference tip")
            self.overview_btn = gui.add_button("Overview")
            self.shadows = gui.add_checkbox(SHARED_SHADOWS_LABEL if self.session.shared else SHADOWS_LABEL, True,
                                            hint=SHADOWS_HINT)
            self.language = LanguageSelector(self.session)

    def _wire_settings(self) -> None:
        g = self.session.loop.on_loop
        self.mode.on_click(g(self._setting("mode", self._mode_of)))
        self.frame.on_update(g(self._setting("frame", str)))
        self.increment.on_click(g(self._setting("increment", self._increment_of)))
        self.override.on_update(g(self._setting("override_pct", float)))
        self.readout_frame.on_click(g(self._on_readout_frame))
        self.hide_distance.on_update(g(self._on_hide_distance))
        self.home.on_click(g(self._on_home))
        self.kuka_home.on_click(g(self._on_kuka_home))
        self.closeup.on_click(g(self._on_camera(True)))
        self.overview_btn.on_click(g(self._on_camera(False)))
        self.shadows.on_update(g(self._on_shadows))

    def on_change(self, change: SessionChange) -> None:
        """The change signal: the status line from the move's outcome (a move that is not a
        jog - auto-touch, Home, a wizard's tool change - clears a stop message it made stale),
        the readouts from the change's pose state; a ``language`` change relabels the panel."""
        if change.language:
            self.relabel()
            self._show_settings()
            self.render(change.state)
        if change.jog is not None:
            self.show_jog_result(change.jog)
            self._stop_key = None if change.state is None else change.state.key
        elif change.pose and self._last_stop and change.state is not None and change.state.key != self._stop_key:
            self.show_jog_result(JogResult(True, 1.0, None, ""))
        if change.pose:
            self.render(change.state)

    def relabel(self) -> None:
        """Every word of the panel in the session's language (labels, hints, the keys line):
        at a ``language`` change, and once at the start in a language other than English. The
        key labels (``X −``), frame names and numbers are the same in every language."""
        tr = self.session.translator
        _ = tr.gettext
        self.hide_distance.label, self.hide_distance.hint = _("Hide distance"), _(HIDE_DISTANCE_HINT)
        self.increment.label = _("Increment")
        self.increment.hint = _(INCREMENT_HINT).format(keys=_(INCREMENT_KEYS))
        for r, (ax, row) in enumerate(self.cart_rows.items()):
            row.hint = _with_keys(_(_AXIS_HINT[ax]), r, tr)
        names = self.session.controller.kinematics.joint_names
        for i, (name, row) in enumerate(zip(names, self.joint_rows)):
            row.hint = _with_keys(_("jog {joint} (deg)").format(joint=name), i, tr)
        self.cart_folder.label = _("Cartesian jog (hold)")
        for (ax, _sign), b in self.cart_buttons.items():
            b.hint = _with_keys(_(_AXIS_HINT[ax]), CARTESIAN_AXES.index(ax), tr)
        self.joint_folder.label = _("Joint jog")
        for (i, _sign), b in self.joint_buttons.items():
            b.hint = _with_keys(_("hold to jog {joint} (deg)").format(joint=names[i]), i, tr)
        self._set_md(self.keys_md, "keys", self._keys_markdown())
        self.settings_folder.label = _("Jog settings")
        self.mode.label, self.frame.label = _("Mode"), _("Jog frame")
        self.override.label, self.readout_frame.label = _("Override %"), _("Readout")
        self.home.label = _("Ready pose")
        self.home.hint = _("Back to the start pose (teleport): HOME with the flange pointing down.")
        self.kuka_home.hint = _("The robot's HOME position (teleport); on a KR 6 the wrist is singular there (A5 = 0).")
        self.view_folder.label = _("View")
        self.closeup.label, self.overview_btn.label = _("Close-up on reference tip"), _("Overview")
        self.shadows.label = _(SHARED_SHADOWS_LABEL if self.session.shared else SHADOWS_LABEL)
        self.shadows.hint = _(SHADOWS_HINT)
        if self._last_text.get("status"):
            self._set_md(self.status_md, "status", "")     # a stop message in the other language: cleared
            self._last_stop = ""

    def _keys_markdown(self) -> str:
        """The keys line and, hidden below it, the labels the page's script looks for in this
        language (``<div hidden data-tcp-pendant-labels data-increment=... data-cont=...
        data-shadows=... data-keys-line=... data-tip-views=... data-record-point=... data-record=...
        data-next=... data-finish=... data-back=... data-lost=... data-reload=... data-key-r=...>``,
        attributes escaped): it finds the Increment row, continuous mode, the Shadows checkbox, the
        keys line, the tip views, "Record point" and the wizard's Record, Next, Finish and Back
        buttons (keys R, N, B) by them, and writes the lost-connection notice, its button and the
        keys' tooltips ("Key R") with them."""
        tr = self.session.translator
        _ = tr.gettext
        labels = {"increment": _("Increment"), "cont": increment_word(CONTINUOUS, tr),
                  "shadows": _(SHADOWS_LABEL), "keys-line": _(KEYS_LINE).split(" ", 1)[0],
                  "tip-views": tip_views_title(tr), "record-point": _(RECORD_POINT),
                  "record": _(RECORD), "next": _(NEXT), "finish": _(FINISH), "back": _(BACK),
                  "lost": _(CONNECTION_LOST), "reload": _("Reload the page"),
                  **{f"key-{k.lower()}": _("Key {key}").format(key=k) for k in "RNB"}}
        attrs = " ".join(f'data-{k}="{html.escape(v, quote=True)}"' for k, v in labels.items())
        return f"{_(KEYS_LINE)}\n\n<div hidden data-tcp-pendant-labels {attrs}></div>"

    def _mode_of(self, label: str | float) -> JogMode:
        """The Mode button ``label`` (this or English's words) as a ``JogMode``."""
        words = {m.value: w for m, w in _MODE_WORDS.items()}
        return JogMode(_read_choice(str(label), words, self.session.translator))

    def _increment_of(self, label: str | float) -> str:
        """The Increment button ``label`` as the jog setting (``Cont.`` in any language → ``CONTINUOUS``)."""
        text = str(label)
        return CONTINUOUS if text in (CONTINUOUS, increment_word(CONTINUOUS, self.session.translator)) else text

    # ------------------------------------------------------------ wiring
    def _wire_key(self, button: viser.GuiButtonHandle, axis: str | int, sign: int) -> None:
        """Click and hold of a jog key, on viser's event loop like every callback
        (:meth:`SessionLoop.on_loop`): besides thread safety, that spares every jog tick a hand-over
        to viser's thread pool (a thread wake-up and GIL hand-over per tick: 10-30 % of a jog
        step's server CPU, measured by bench_server.py). The step is synchronous, under the
        session lock, and never waits on the event loop."""
        on_loop = self.session.loop.on_loop
        button.on_click(on_loop(lambda _event: self._jog(axis, sign, hold_tick=False)))
        button.on_hold(on_loop(lambda _event: self._on_hold(axis, sign)), callback_hz=HOLD_HZ)

    def _jog(self, axis: str | int, sign: int, *, hold_tick: bool) -> None:
        if hold_tick is False and self.session.jogger.settings.continuous:
            self._stop_hold()                        # the click that ends a hold: no move
            return
        arrived = arrival.arrived_s()
        if not hold_tick and not self.session.jogger.gate.admit(arrived):
            self._report_drops_soon()                # a stale press: dropped, never carried out late
            return
        waited = None if arrived is None else time.monotonic() - arrived
        self.session.motion.jog(axis, sign, hold_tick=hold_tick, waited_s=waited)

    # hold-to-jog on the server's 20 Hz clock (pendant/hold.py)
    def _on_hold(self, axis: str | int, sign: int) -> None:
        """A browser's hold message: the first starts the server's ticks, later ones keep them
        alive (the browser may send them far slower than 20 Hz)."""
        if not self.session.jogger.settings.continuous:
            return
        if self._hold is None:
            loop = asyncio.get_running_loop()
            guard = self.session.loop.guard

            def schedule(delay_s: float, fn: Callable[[], object]) -> Timer:
                return loop.call_later(delay_s, guard(fn))

            self._hold = HoldDriver(self._hold_step, schedule, on_lapse=self._on_lapse)
            self.session.on_close(self._hold.stop)
        self._hold.held(axis, sign, arrival.arrived_s())
        if self._hold.dropped:
            self._report_drops_soon()

    def _on_lapse(self, _key: object) -> None:
        """The held key's lease ran out (no renewal for ``LEASE_S``): stopped, and said so."""
        text = f"⚠ {self.session.translator.gettext(LAPSE_TEXT)}"
        self._set_md(self.status_md, "status", text)
        self._last_stop = text
        self.session.motion.release_jog()

    def _hold_step(self, axis: str | int, sign: int) -> JogResult | None:
        """One server tick of the held key (under the session lock, on the loop)."""
        s = self.session
        if s.closed or not s.jogger.settings.continuous:
            self._stop_hold()
            return None
        return s.motion.jog(axis, sign, hold_tick=True)

    def _report_drops_soon(self) -> None:
        """Report the dropped presses once the loop has worked through what is queued now (one
        report per burst: a busy server is not sent a notification per press), and at most
        once per :data:`DROP_REPORT_EVERY_S` (an overloaded server does not spend the time it
        lacks on a report per loop round; the next report counts every press dropped since)."""
        if self._drop_report_due:
            return
        self._drop_report_due = True
        loop = asyncio.get_running_loop()
        wait = self._drop_reported_at + DROP_REPORT_EVERY_S - time.monotonic()
        if wait > 0:
            loop.call_later(wait, self.session.loop.guard(self._report_drops))
        else:
            loop.call_soon(self.session.loop.guard(self._report_drops))

    def _report_drops(self) -> None:
        self._drop_report_due = False
        self._drop_reported_at = time.monotonic()
        n = self.session.jogger.gate.take_dropped()
        if self._hold is not None:
            n, self._hold.dropped = n + self._hold.dropped, 0
        if n:
            _ = self.session.translator.gettext
            text = dropped_presses_text(n, self.session.translator)
            self._set_md(self.status_md, "status", "⚠ " + _("{sentence}.").format(sentence=text))
            self.session.notify(_("Jog presses dropped"), _("{what}; press again.").format(what=text), kind="warning")
            self.render()                            # a dropped slider move: the slider shows the joint

    def _stop_hold(self) -> None:
        if self._hold is not None:
            self._hold.stop()
        self.session.motion.release_jog()

    def _row_cb(self, axis: str | int) -> Callable[[ButtonGroupEvent], None]:
        """Click on a compact key row: the value is the key's label ("X +", "A3 −")."""
        def cb(event: ButtonGroupEvent) -> None:
            sign = 1 if str(event.target.value).endswith("+") else -1
            self._jog(axis, sign, hold_tick=False)
        return cb

    def _on_readout_frame(self, event: ButtonGroupEvent) -> None:
        value = unmarked(str(event.target.value))
        if value not in ("WORLD", "BASE"):
            raise ValueError(f"Unknown readout frame {value!r}; use WORLD or BASE.")
        self._readout = value
        self.readout_frame.options = marked(("WORLD", "BASE"), value)
        self.render()

    def _on_hide_distance(self, event: CheckboxEvent | None) -> None:
        if event is not None and getattr(event, "client", 1) is None:
            return                                   # our own assignment
        try:
            self.session.set_hide_distance(bool(self.hide_distance.value))
        except ValueError:                           # refused (an exercise's lock): undo the tick
            set_value(self.hide_distance, self.session.hide_distance)
            raise

    def _slider_cb(self, index: int) -> Callable[[SliderEvent], Coroutine[object, object, None]]:
        """The callback of joint slider ``index`` (0-based): set the joint to the browser's
        value (deg, clipped to the limits) and remember it, so that :meth:`render` does not
        echo it back."""
        s = self.session

        def cb(event: SliderEvent) -> None:
            if event.client is None:
                return                                # our own update of the slider: no loop
            if not s.jogger.gate.admit(arrival.arrived_s()):
                self._from_client.pop(index, None)    # render writes the joint's angle back
                self._report_drops_soon()
                return
            value = float(event.target.value)
            if not math.isfinite(value):
                return
            with s.batch():                           # the echo rule is set before the one signal
                applied = round(s.motion.set_joint(index, value), 2)
                if abs(applied - value) <= 0.005:     # the browser shows the angle: no echo
                    self._from_client[index] = applied
                else:                                 # clipped: render sends the limit
                    self._from_client.pop(index, None)

        return s.loop.on_loop(cb)

    def _setting(self, name: str, kind: Callable[[str | float], object]
                 ) -> Callable[[viser.GuiEvent[SettingHandle]], None]:
        """Callback of one selector: only the selector that fired changes its setting (a button
        group's value is the option just clicked)."""
        def cb(event: viser.GuiEvent[SettingHandle]) -> None:
            value = event.target.value
            self._stop_hold()
            self.session.motion.set_jog_setting(name, kind(unmarked(value) if isinstance(value, str) else value))
            self._show_settings()
            self.render()
        return cb

    def _show_settings(self) -> None:
        st = self.session.jogger.settings
        joint = st.mode is JogMode.JOINT
        hold = st.continuous
        for row in self.cart_rows.values():
            row.visible = not joint and not hold
        for row in self.joint_rows:
            row.visible = joint and not hold
        self.cart_folder.visible = not joint and hold
        self.joint_folder.visible = joint
        self._joint_folder_shown = joint            # what render reads (only written here)
        for b in self.joint_buttons.values():
            b.visible = hold
        self.frame.disabled = joint
        tr = self.session.translator
        _ = tr.gettext
        modes = (JogMode.CARTESIAN, JogMode.JOINT)
        for group, options, value in ((self.increment, tuple(increment_word(i, tr) for i in INCREMENTS),
                                       increment_word(st.increment, tr)),
                                      (self.mode, tuple(mode_word(m, tr) for m in modes), mode_word(st.mode, tr))):
            want = marked(options, value)
            if tuple(group.options) != want:
                group.options = want
        unit = "deg" if joint else "mm / deg"
        step = (_("continuous while held") if st.continuous
                else _("{increment} {unit} per press").format(increment=st.increment, unit=unit))
        where = _("joints") if joint else _("{frame} frame").format(frame=st.frame)
        self._set_md(self.settings_md, "settings", _("{mode} jog in {where}, {step}, override {override} %").format(
            mode=mode_word(st.mode, tr), where=where, step=step, override=f"{st.override_pct:.0f}"))

    def _on_home(self, _event: ButtonEvent) -> None:
        self.session.motion.ready()

    def _on_kuka_home(self, _event: ButtonEvent) -> None:
        self.session.motion.home()

    def _on_camera(self, close: bool) -> Callable[[ButtonEvent], None]:
        def cb(event: ButtonEvent) -> None:
            client = event.client
            if client is None:
                return
            (closeup_camera if close else overview_camera)(client, self.session.controller.reference_tip_world_m)
        return cb

    def _on_shadows(self, _event: CheckboxEvent | None = None) -> None:
        """The default lights cast shadows or not, where this panel draws (module docstring)."""
        target_of(self.session).scene.configure_default_lights(True, cast_shadow=bool(self.shadows.value))

    # ------------------------------------------------------------ display
    def show_jog_result(self, res: JogResult) -> None:
        """Status line: the stop message of a jog (limit, singularity, unreachable), else clear."""
        if res.ok and not self._last_stop and self._last_text.get("status") == "":
            return                                   # a clear line stays clear: nothing to send or note
        tr = self.session.translator
        said = "" if res.ok else in_language(res.message, tr)   # the controller's Words in this language
        text = "" if res.ok else f"⚠ {said}"
        self._set_md(self.status_md, "status", text)
        if text and text != self._last_stop:
            self.session.notify(tr.gettext("Jog stopped"), said, kind="warning")
        self._last_stop = text

    def _set_md(self, handle: viser.GuiMarkdownHandle, key: str, text: str) -> None:
        """Send ``text`` unless it is what ``handle`` shows already."""
        if self._last_text.get(key) != text:
            set_markdown(handle, text)
            self._last_text[key] = text

    def render(self, state: PoseState | None = None) -> None:
        """Readouts, touch indicator and joint sliders from the session's pose state (``state``:
        the change signal's; None: the session's now; no feedback); only texts and slider
        values that changed are sent, and a slider whose joint is still where the browser's own
        value of it put it is not written (module docstring)."""
        s = self.session
        state = s.pose_state() if state is None else state
        tool = s.controller.active_tool
        tr = s.translator
        self._set_md(self.tcp_md, "tcp", tcp_readout_markdown(state.readout(self._readout), None if tool is None
                                                              else tool.name, shown_tool_label(s.controller.mounted_tool.label, tr), tr))
        hide = s.hide_distance
        if bool(self.hide_distance.value) != hide:
            set_value(self.hide_distance, hide)
        locked = s.rules.distance_locked
        if self._hide_locked != locked:            # locked by the trainer
            self.hide_distance.disabled = self._hide_locked = locked
        touch = touch_indicator_markdown(state.touch, hide_distance=hide, tr=tr)
        closeup = ""
        if not hide:
            jf = s.jogger.settings.frame
            delta = tip_offset_xyz_mm(state, s.controller.reference_tip_world_m, jf)
            touch += "\n\n" + offset_markdown(delta, jf, tr=tr)
            if state.touch.distance_mm <= CLOSEUP_WITHIN_MM:
                closeup = side_view_markdown(delta, jf)
        self._set_md(self.touch_md, "touch", touch)
        if closeup or self._last_text.get("closeup"):   # else it is hidden and empty already
            self._set_md(self.closeup_md, "closeup", closeup)
            if self.closeup_md.visible != bool(closeup):
                self.closeup_md.visible = bool(closeup)
        angles = state.joint_angles_deg
        self._set_md(self.joints_md, "joints", joint_readout_markdown(angles, tr))
        if not self._joint_folder_shown:
            return                      # hidden sliders are synced when joint mode is shown
        for i, (slider, v) in enumerate(zip(self.joint_sliders, angles.values())):
            value = round(float(v), 2)
            mine = self._from_client.get(i)
            if mine is not None:
                if mine == value:
                    continue                        # the browser's own value: no echo
                del self._from_client[i]            # moved since by a jog, Home, the gizmo ...
            if slider.value != value:               # a joint jog moves one slider: one update
                set_value(slider, value)
