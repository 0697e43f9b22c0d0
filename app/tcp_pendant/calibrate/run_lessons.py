"""What the session's earlier runs teach the one on show (no viser).

The beam wizard's lesson compares the automatic calibration with the trainee's last manual one
of the same physical tool (:func:`manual_comparison`): its method, wall time and, in training
mode without an exercise, its errors against its own true tool (``wizards.truth``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from tcp_pendant.wizards import ManualComparison
from tcp_pendant.wizards.beam import wall_time_s
from tcp_pendant.wizards.session_record import WizardRun
from tcp_pendant.wizards.truth import compare_with_truth

__all__ = ["manual_comparison"]


def manual_comparison(runs: Sequence[WizardRun], index: int | None, *, show_truth: bool,
                      auto_touches: Callable[[int, Sequence[int]], int]) -> ManualComparison | None:
    """The last finished manual calibration in ``runs`` of the same physical tool as run
    ``index``: its method, number, wall time from start to result, and with ``show_truth`` its
    errors against its own true tool; ``auto_touches(j, steps)`` counts the steps of run ``j``
    Auto-touch recorded. Manual: a method with steps done by hand (no step the controller runs)
    that calibrates a TCP. None when there is none."""
    i = index
    if i is None or not 0 <= i < len(runs):
        return None
    key = runs[i].true_tool_key
    if key is None:
        return None
    for j in range(len(runs) - 1, -1, -1):
        run = runs[j]
        w, res = run.wizard, run.wizard.finished_result
        if (j == i or res is None or run.true_tool_key != key or res.tcp_result is None
                or not w.saves_to_library or type(w).controller_job is not None):
            continue
        seconds = wall_time_s(w.started_at, res.computed_at)
        pos = ang = grade = None
        if show_truth and run.T_flange_tool_true_m is not None:
            cmp = compare_with_truth(res, run.T_flange_tool_true_m)
            pos, ang, grade = cmp.position_error_mm, cmp.x_axis_error_deg, cmp.grade
        auto = auto_touches(j, list(w.recorded_poses))
        return ManualComparison(w.title, w.kind, j + 1, 0.0 if seconds is None else seconds, pos, ang, grade,
                                touches=len(w.recorded_poses), auto_touches=auto)
    return None
