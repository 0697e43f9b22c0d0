"""tcpcal's warnings and refusals in the session's language (no viser).

tcpcal is a solver with no user interface and no language: its results carry plain English
remarks (``TcpResult.warnings``, ``OrientationResult.warnings``, ...). A wizard shows them to a
trainee, so they are read here by their wording (the numbers in them kept as tcpcal wrote them)
and said again from the catalogs. A remark this table does not know stays as tcpcal wrote it.
The session record keeps tcpcal's English (``Wizard.result_in``).
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from tcp_pendant.translation import ENGLISH, N_, Translator

__all__ = ["solver_warning", "solver_warnings"]

_NUM = r"[-+0-9.einfa]+"
_VEC = r"\[[-0-9., ]+\]"

_WHAT = {"the tool's -X axis": N_("the tool's -X axis"),
         "the tool's +Y axis": N_("the tool's +Y axis"),
         "the tool's +Y half-plane": N_("the tool's +Y half-plane"),
         "the tool's +Y axis (distance from the X axis, Delta4)":
             N_("the tool's +Y axis (distance from the X axis, Delta4)"),
         "the tool's +Y half-plane (distance from the X axis, Delta4)":
             N_("the tool's +Y half-plane (distance from the X axis, Delta4)"),
         "the tool's +Y half-plane (distance from the X axis)":
             N_("the tool's +Y half-plane (distance from the X axis)"),
         "the current tool Y": N_("the current tool Y"),
         "the flange Y axis": N_("the flange Y axis"),
         "the flange Z axis": N_("the flange Z axis")}
"""Phrases tcpcal puts into its remarks ({what}, {label})."""

_TABLE: tuple[tuple[re.Pattern[str], str], ...] = tuple((re.compile(pattern), msgid) for pattern, msgid in (
    (rf"the touch orientations differ by at most (?P<deg>{_NUM}) deg: tilt the tool 30-60 deg between touches, "
     r"about two different axes, for a precise TCP\.",
     N_("the touch orientations differ by at most {deg} deg: tilt the tool 30-60 deg between touches, "
        "about two different axes, for a precise TCP.")),
    (rf"the TCP along flange (?P<axis>{_VEC}) is (?P<ratio>{_NUM}) times less certain than across it: the "
     r"touches tilt little about a second axis; add a touch tilted about another axis\.",
     N_("the TCP along flange {axis} is {ratio} times less certain than across it: the touches tilt little "
        "about a second axis; add a touch tilted about another axis.")),
    (rf"touches (?P<i>\d+) and (?P<j>\d+) \(0-based\) are only (?P<deg>{_NUM}) deg apart in orientation, so "
     r"one of them adds little: re-record it from a clearly different orientation\.",
     N_("touches {i} and {j} (0-based) are only {deg} deg apart in orientation, so one of them adds little: "
        "re-record it from a clearly different orientation.")),
    (rf"the residuals \(noise estimate (?P<noise>{_NUM})\) are larger than the given sigma (?P<sigma>{_NUM}) "
     r"explains: the touches are less precise than assumed, or something is not rigid or not calibrated "
     r"\(tool, reference point, robot\)\.",
     N_("the residuals (noise estimate {noise}) are larger than the given sigma {sigma} explains: the touches "
        "are less precise than assumed, or something is not rigid or not calibrated (tool, reference point, "
        "robot).")),
    (r"with only 4 touches a careless touch cannot be detected; record 5 to 8 touches for a checkable result\.",
     N_("with only 4 touches a careless touch cannot be detected; record 5 to 8 touches for a checkable result.")),
    (rf"the flange positions are nearly coplanar \(thickness / extent = (?P<ratio>{_NUM})\): the sphere fit is "
     r"very sensitive to touch noise here; prefer method 'lstsq'\.",
     N_("the flange positions are nearly coplanar (thickness / extent = {ratio}): the sphere fit is very "
        "sensitive to touch noise here; prefer method 'lstsq'.")),
    (r"without the outliers the touches are degenerate: (?P<reason>.*)",
     N_("without the outliers the touches are degenerate: {reason}")),
    (rf"touch (?P<touches>\d+) \(0-based\) stands out \(residual (?P<residuals>[^)]*) vs noise estimate "
     rf"(?P<noise>{_NUM})\): probably a careless touch; see the result without it \(without_outliers\), or "
     r"re-record it\.",
     N_("touch {touches} (0-based) stands out (residual {residuals} vs noise estimate {noise}): probably a "
        "careless touch; see the result without it (without_outliers), or re-record it.")),
    (r"touch (?P<touches>\d+) \(0-based\) stands out \(residual (?P<residuals>[^)]*) vs the others\): probably "
     r"a careless touch; see the result without it \(without_outliers\), or re-record it\.",
     N_("touch {touches} (0-based) stands out (residual {residuals} vs the others): probably a careless touch; "
        "see the result without it (without_outliers), or re-record it.")),
    (rf"touches (?P<touches>[\d, ]+) \(0-based\) stand out \(residual (?P<residuals>[^)]*) vs noise estimate "
     rf"(?P<noise>{_NUM})\): probably a careless touch; see the result without them \(without_outliers\), or "
     r"re-record them\.",
     N_("touches {touches} (0-based) stand out (residual {residuals} vs noise estimate {noise}): probably a "
        "careless touch; see the result without them (without_outliers), or re-record them.")),
    (r"touches (?P<touches>[\d, ]+) \(0-based\) stand out \(residual (?P<residuals>[^)]*) vs the others\): "
     r"probably a careless touch; see the result without them \(without_outliers\), or re-record them\.",
     N_("touches {touches} (0-based) stand out (residual {residuals} vs the others): probably a careless touch; "
        "see the result without them (without_outliers), or re-record them.")),
    (r"reference method: one touch per tool and no redundancy, so the residuals are zero by construction; the "
     r"TCP error is the sum of both touches' errors and of the known TCP's own error\. Check the result, e\.g\. "
     r"with a 4-point calibration\.",
     N_("reference method: one touch per tool and no redundancy, so the residuals are zero by construction; the "
        "TCP error is the sum of both touches' errors and of the known TCP's own error. Check the result, e.g. "
        "with a 4-point calibration.")),
    (r"no sigma given: the uncertainty of the TCP cannot be estimated from one touch per tool\.",
     N_("no sigma given: the uncertainty of the TCP cannot be estimated from one touch per tool.")),
    (rf"the measured X is (?P<deg>{_NUM}) deg from perpendicular to Z; X was corrected \(Z kept\)\. Check that "
     r"the x rows put the reference exactly on the tool's X axis\.",
     N_("the measured X is {deg} deg from perpendicular to Z; X was corrected (Z kept). Check that the x rows "
        "put the reference exactly on the tool's X axis.")),
    (rf"(?P<row>[zx]) row (?P<n>\d+): the reference is only (?P<d>{_NUM}) from the TCP; the angular error grows "
     rf"as the distance shrinks \(back off at least (?P<min>{_NUM})\)\.",
     N_("{row} row {n}: the reference is only {d} from the TCP; the angular error grows as the distance "
        "shrinks (back off at least {min}).")),
    (rf"tool Z points (?P<deg>{_NUM}) deg away from the TCP direction \(back towards the flange\); for a "
     r"straight tool the z rows probably put the reference behind the TCP \(the tool moved forwards instead of "
     r"backing off\)\.",
     N_("tool Z points {deg} deg away from the TCP direction (back towards the flange); for a straight tool the "
        "z rows probably put the reference behind the TCP (the tool moved forwards instead of backing off).")),
    (rf"touch (?P<n>\d+) \((?P<what>.*)\): displacement (?P<length>{_NUM}) is shorter than (?P<min>{_NUM}); the "
     r"angular error grows as \(touch error\)/\(displacement\), move farther from the TCP for a more accurate "
     r"orientation\.",
     N_("touch {n} ({what}): displacement {length} is shorter than {min}; the angular error grows as (touch "
        "error)/(displacement), move farther from the TCP for a more accurate orientation.")),
    (rf"orthogonality defect (?P<deg>{_NUM}) deg is large \(> (?P<max>{_NUM}) deg\): the -X and \+Y touches "
     r"disagree; repeat them more carefully and farther from the TCP\.",
     N_("orthogonality defect {deg} deg is large (> {max} deg): the -X and +Y touches disagree; repeat them "
        "more carefully and farther from the TCP.")),
    (r"tool X points back towards the flange \(more than 120 deg from the TCP direction\): if the tool's "
     r"working direction points away from the flange, the tip was probably placed on the \+X axis in the "
     r"second step \(Delta1 > 0 instead of negative\); check and repeat it\.",
     N_("tool X points back towards the flange (more than 120 deg from the TCP direction): if the tool's "
        "working direction points away from the flange, the tip was probably placed on the +X axis in the "
        "second step (Delta1 > 0 instead of negative); check and repeat it.")),
    (r"5D: the current tool Y is \(nearly\) parallel to the new tool X; tool Y was taken from (?P<label>.*) "
     r"instead\.",
     N_("5D: the current tool Y is (nearly) parallel to the new tool X; tool Y was taken from {label} instead.")),
    (r"5D: only tool X is calibrated; tool Y is (?P<label>.*) projected normal to X\.",
     N_("5D: only tool X is calibrated; tool Y is {label} projected normal to X.")),
    (rf"the TCP along flange (?P<axis>{_VEC}) is (?P<ratio>{_NUM}) times less certain than across it: the "
     r"events see the beam along similar flange directions; add events with the tool turned about its own "
     r"axis or tilted across the beam \(tilting about the beam itself adds nothing\)\.",
     N_("the TCP along flange {axis} is {ratio} times less certain than across it: the events see the beam "
        "along similar flange directions; add events with the tool turned about its own axis or tilted across "
        "the beam (tilting about the beam itself adds nothing).")),
    (r"with only (?P<n>\d+) tip events a bad event cannot be told from the others and the noise estimate is "
     r"poor; record 4 to 8 events\.",
     N_("with only {n} tip events a bad event cannot be told from the others and the noise estimate is poor; "
        "record 4 to 8 events.")),
    (rf"the residuals \(noise estimate (?P<noise>{_NUM})\) are larger than the given sigma (?P<sigma>{_NUM}) "
     r"explains: the events are less precise than assumed, or the beam position or direction, the tool or the "
     r"robot is not what the model says\.",
     N_("the residuals (noise estimate {noise}) are larger than the given sigma {sigma} explains: the events "
        "are less precise than assumed, or the beam position or direction, the tool or the robot is not what "
        "the model says.")),
    (r"(?P<k>\d+) axis events determine the direction exactly, without redundancy: its uncertainty cannot be "
     r"estimated; cross the beam at a third orientation or give sigma\.",
     N_("{k} axis events determine the direction exactly, without redundancy: its uncertainty cannot be "
        "estimated; cross the beam at a third orientation or give sigma.")),
    # tcpcal's refusals of touches that cannot give a result (DegenerateTouchesError)
    (rf"all (?P<n>\d+) touches have the same orientation \(at most (?P<deg>{_NUM}) deg apart\), so the TCP "
     r"cannot be determined; the 4-point method needs clearly different orientations: tilt the tool 30-60 deg "
     r"between touches, about two different axes\.",
     N_("all {n} touches have the same orientation (at most {deg} deg apart), so the TCP cannot be determined; "
        "the 4-point method needs clearly different orientations: tilt the tool 30-60 deg between touches, "
        "about two different axes.")),
    (rf"the flange positions are coplanar, so the sphere fit cannot locate the reference \(thickness / extent = "
     rf"(?P<ratio>{_NUM})\); use method 'lstsq', or touch from orientations that move the flange out of that "
     r"plane\.",
     N_("the flange positions are coplanar, so the sphere fit cannot locate the reference (thickness / extent = "
        "{ratio}); use method 'lstsq', or touch from orientations that move the flange out of that plane.")),
    (rf"touch (?P<n>\d+) \((?P<what>.*)\): the reference tip is still at the TCP \(\|Delta\| = "
     rf"(?P<length>{_NUM})\); move the tool so that the tip lies on (?P<what2>.*), clearly away from the TCP "
     r"\(e\.g\. 50 mm or more\), then record again\.",
     N_("touch {n} ({what}): the reference tip is still at the TCP (|Delta| = {length}); move the tool so that "
        "the tip lies on {what2}, clearly away from the TCP (e.g. 50 mm or more), then record again.")),
    (r"touch (?P<n>\d+) \((?P<what>.*)\): the reference tip lies on the tool X axis, so tool Y is undefined; "
     r"move the tool sideways so that the tip lies on the tool's \+Y side\.",
     N_("touch {n} ({what}): the reference tip lies on the tool X axis, so tool Y is undefined; move the tool "
        "sideways so that the tip lies on the tool's +Y side.")),
    (r"every \+Y point lies on the tool X axis, so tool Y is undefined; move the tool sideways so that the tip "
     r"lies on the tool's \+Y side\.",
     N_("every +Y point lies on the tool X axis, so tool Y is undefined; move the tool sideways so that the tip "
        "lies on the tool's +Y side.")),
    (rf"axis event (?P<i>\d+): the beam met the tool axis (?P<d>{_NUM}) ahead of the TCP, beyond the tip; the "
     r"crossings should be on the shaft behind the tip\.",
     N_("axis event {i}: the beam met the tool axis {d} ahead of the TCP, beyond the tip; the crossings should "
        "be on the shaft behind the tip.")),
))


def solver_warning(text: str, *, tr: Translator = ENGLISH) -> str:
    """One tcpcal remark in ``tr``'s language (``text`` itself when the table does not know it,
    or in English)."""
    if tr is ENGLISH:
        return text
    for pattern, msgid in _TABLE:
        m = pattern.fullmatch(text)
        if m is not None:
            values = {k: (tr.gettext(_WHAT[v]) if k in ("what", "what2", "label") and v in _WHAT else v)
                      for k, v in m.groupdict().items()}
            return tr.gettext(msgid).format(**values)
    return text


def solver_warnings(texts: Iterable[str], *, tr: Translator = ENGLISH) -> list[str]:
    """:func:`solver_warning` of each remark, in order."""
    return [solver_warning(t, tr=tr) for t in texts]
