"""The dashboard replay's "Robot at touch" choice (viser GUI): which recorded touch the replay's
robot is posed at (``views.dashboard_replay.ReplayScene.show_touch``).

Each option names a touch in recording order: ``"3: step 2, Auto-touch"``, an overwritten one
marked; the number before the colon is the touch's place (1-based) in ``replay.touches``.
"""

from __future__ import annotations

from typing import Any

from tcp_pendant.classroom.replay import CalibrationReplay
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.views.dashboard_replay import ReplayScene
from tcp_pendant.views.gui_util import set_options

__all__ = ["NO_TOUCH", "pose_replay_touch", "set_replay_touches", "touch_option"]

NO_TOUCH = N_("(no replay) ")
"""The choice while no replay is on show (English; ``tr.gettext(NO_TOUCH)`` where shown)."""


def touch_option(index: int, replay: CalibrationReplay, *, tr: Translator = ENGLISH) -> str:
    """The option of touch ``index`` (0-based) of ``replay``, in ``tr``'s language; it starts
    with ``"<n>:"`` in every language (:func:`pose_replay_touch` reads it)."""
    t = replay.touches[index]
    _ = tr.gettext
    n, step = index + 1, t.step_index + 1
    if t.auto:
        text = (_("step {step}, Auto-touch, overwritten") if t.overwritten else _("step {step}, Auto-touch"))
    else:
        text = (_("step {step}, by hand, overwritten") if t.overwritten else _("step {step}, by hand"))
    return f"{n}: {text.format(step=step)}"


def set_replay_touches(dropdown: Any, replay: CalibrationReplay, shown: int | None, *,
                       tr: Translator = ENGLISH) -> None:
    """List ``replay``'s touches in ``dropdown`` with the touch ``shown`` chosen; show it."""
    options = tuple(touch_option(i, replay, tr=tr) for i in range(len(replay.touches))) or (tr.gettext(NO_TOUCH),)
    keep = options[shown] if shown is not None and 0 <= shown < len(options) else options[-1]
    set_options(dropdown, options, keep)
    dropdown.visible = bool(replay.touches)


def pose_replay_touch(scene: ReplayScene, dropdown: Any) -> None:
    """The robot at the touch chosen in ``dropdown`` (an option of :func:`touch_option`)."""
    head = str(dropdown.value).split(":", 1)[0]
    if head.isdigit() and scene.shown is not None:
        scene.show_touch(int(head) - 1)
