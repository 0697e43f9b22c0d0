"""The spin-test Check as a technician reads it on a real robot (no viser, no controller).

On a real robot the technician puts the tool tip on a spike, turns the tool by ±A, ±B, ±C about
the TCP and watches the tip: they see how far it swings off the spike, by eye, and nothing
else. The simulation computes far more - the deviation to a micrometre, the implied TCP error
vector and the correction (``controller.spin``) - and in an exercise that would be the answer
for one click. So in an exercise the Check shows only the reading: per rotation how far the
tip moved, rounded to :data:`CHECK_READING_MM`, and a verdict drawn from those readings.

Why 0.5 mm: by eye against a spike a technician judges a swing to about half a millimetre
(the pointed tip itself is about that wide; finer needs a dial gauge the exercise does not
give). It is also the exercise's "good" threshold and the touch tolerance, so "0.0 on every
rotation" means what the technician means by "the tip stays put". At the default 30° a
reading of 0.0 allows up to 0.25 mm of swing, i.e. up to 0.48 mm of TCP error off each
rotation axis (``|d| = 2 sin(θ/2) |e_perp|``, methods.md "TCP check"), so one Check cannot be
inverted into a TCP closer than "good".

A technician reads the swing against the spike, so in an exercise the Check needs the tool
tip near the reference tip (:data:`READ_WITHIN_MM`, about what the eye sees in the scene
anyway): a Check from anywhere with a made-up TCP (say X = Y = Z = 0) would otherwise measure
the tool without a touch. Repeating the Check from there with typed-in TCPs and watching the
readings is a hand calibration by spin test, as on a real robot: it needs the tip brought to
the spike first and costs a click per guess.

Units: mm and degrees.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

from tcp_pendant.translation import ENGLISH, N_, Translator

__all__ = ["CHECK_READING_MM", "NOT_AT_TIP", "READING_NOTE", "READ_WITHIN_MM", "check_readable", "read_mm",
           "reading_note", "reading_verdict"]

CHECK_READING_MM = 0.5
"""Resolution a technician reads the tip's swing to, by eye against a spike (mm)."""


def reading_note(*, tr: Translator = ENGLISH) -> str:
    """The note under an exercise's check (markdown): it shows only what a technician sees."""
    return tr.gettext("*In the exercise the check shows what a technician sees on a real robot: how far the "
                      "tip swung off the reference tip, read to {mm} mm by eye; no TCP error, no "
                      "correction.*").format(mm=f"{CHECK_READING_MM:g}")


READING_NOTE = reading_note()
"""The note in English (:func:`reading_note` in a session's language)."""


READ_WITHIN_MM = 5.0
"""In an exercise the Check is read against the reference tip: the tool tip must be this close (mm)."""
NOT_AT_TIP = N_("In the exercise the Check is read against the reference tip, as on a real robot: bring the "
              "tool tip to the reference tip first (within a few millimetres), then check.")


def check_readable(distance_mm: float, *, tr: Translator = ENGLISH) -> None:
    """Refuse an exercise's Check that has no reference tip to read the swing against.

    Args:
        distance_mm: true tool tip to reference tip where the check starts (mm).

    Raises:
        ValueError: farther than :data:`READ_WITHIN_MM` (or not finite).
    """
    if not math.isfinite(float(distance_mm)) or float(distance_mm) > READ_WITHIN_MM:
        raise ValueError(tr.gettext(NOT_AT_TIP))


def read_mm(value_mm: float) -> float:
    """``value_mm`` as read by eye: rounded to the nearest :data:`CHECK_READING_MM` (a
    non-finite value stays as it is)."""
    v = float(value_mm)
    if not math.isfinite(v):
        return v
    return round(v / CHECK_READING_MM) * CHECK_READING_MM + 0.0        # + 0.0: no "-0.0"


def reading_verdict(readings: Iterable[tuple[bool, float]], angle_deg: float, *,
                    tr: Translator = ENGLISH) -> str:
    """One line from the readings ``(reached, read_mm)`` of the rotations (plain text)."""
    _ = tr.gettext
    reached: Sequence[float] = [d for ok, d in readings if ok]
    if not reached:
        return _("Not determined: no rotation was reached; move away from the joint limits and singularities "
                 "and check again.")
    worst = max(reached)
    if worst < CHECK_READING_MM:
        return _("The tip stayed on the reference tip to the eye in every rotation of ±{angle}° "
                 "(under {mm} mm): the TCP looks good.").format(angle=f"{angle_deg:g}",
                                                               mm=f"{CHECK_READING_MM / 2:g}")
    return _("The tip swung up to {mm} mm off the reference tip at ±{angle}°: the TCP is off; "
             "calibrate the tool again.").format(mm=f"{worst:.1f}", angle=f"{angle_deg:g}")
