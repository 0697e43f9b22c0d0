"""How far a touch really was, said after the Record (no viser): free practice's teacher.

With "Hide distance" on the trainee judges the touch by eye; in free practice (no exercise)
each Record then says how far the tool tip really was from the reference tip and which way,
so the eye learns what 0.5 mm looks like: "0.8 mm off, mostly −Z (WORLD): the tool tip was
0.7 mm −Z of the reference tip". In an exercise it says nothing (the grade is the feedback).

Units: mm; the direction in the jog frame's axes (the keys that would have corrected it).
"""

from __future__ import annotations

import numpy as np

from tcp_pendant.translation import ENGLISH, Translator

__all__ = ["touch_feedback"]


def touch_feedback(tip_offset_mm: np.ndarray, frame: str, *, tr: Translator = ENGLISH) -> str:
    """The words for one recorded touch (plain text, our own words, in ``tr``'s language).

    Args:
        tip_offset_mm: (3,) the reference tip relative to the tool tip along the jog frame's
            axes, mm (``guidance.tip_offset_mm``: the jog that would have closed the gap).
        frame: the jog frame's name, e.g. "WORLD".
    """
    off = -np.asarray(tip_offset_mm, dtype=float)      # the tool tip relative to the reference tip
    dist = float(np.linalg.norm(off))
    if not np.isfinite(dist):
        return tr.gettext("how far the touch was is not known")
    if dist < 0.05:
        return tr.gettext("the touch was spot on (0.0 mm off)")
    i = int(np.argmax(np.abs(off)))
    way = f"{'+' if off[i] > 0 else '−'}{'XYZ'[i]}"
    return tr.gettext("{distance} mm off, mostly {way} ({frame}): the tool tip was {along} mm {way} "
                      "of the reference tip").format(distance=f"{dist:.1f}", way=way, frame=frame,
                                                     along=f"{abs(off[i]):.1f}")
