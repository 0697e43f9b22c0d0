"""What a restart gives back to a trainee: the calibrations in progress, and a finished result
not saved yet, from the gradebook.

The recorder keeps each calibration's wizard in the gradebook as it is acknowledged
(``Gradebook.run_states.save``: a session record entry without truth). When a trainee joins
again under their name (after a reload, a reconnect to another server process, or a restart
of the server with the same gradebook), :func:`runs_to_restore` rebuilds those wizards with the
truth the gradebook keeps apart (``calibrations.truth_json``), so the trainee finds each one at
its step with its touches, and :class:`~tcp_pendant.classroom.recorder.TraineeRecorder` goes on
writing into the same calibrations (``TraineeRecorder.adopt``). A finished calibration whose
result was on show and not saved to the tool library comes back on show too (recomputed with
tcpcal from its touches), so the trainee can still save it; it outlasts every restart until it
is saved (``RunStates.mark_saved``) or dismissed (closed, or left for another calibration). A
finished check (a method that saves nothing) is done and does not come back. No viser here.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.wizards import Wizard, WizardError
from tcp_pendant.wizards.session_record import WizardRun, step_distances, step_joints

__all__ = ["RestoredRun", "restored_words", "runs_to_restore"]

log = logging.getLogger(__name__)


@dataclass(frozen=True, eq=False)
class RestoredRun:
    """A calibration in progress, rebuilt: the run for the workflow and where it is stored.

    Attributes:
        run: the wizard with its true tool, joints and distances.
        calibration_id: its gradebook calibration.
        touch_ids: step -> the gradebook id of the touch that counts (the next overwrite links it).
        finished: a finished result not saved yet (else a calibration in progress).
    """

    run: WizardRun
    calibration_id: int
    touch_ids: dict[int, int]
    finished: bool = False


def _truth_matrix(truth: object) -> np.ndarray | None:
    T = truth.get("T_flange_tool_true_m") if isinstance(truth, dict) else None
    if T is None:
        return None
    out = np.asarray(T, dtype=float)
    return out if out.shape == (4, 4) and np.all(np.isfinite(out)) else None


def runs_to_restore(gradebook: Gradebook, trainee: str) -> list[RestoredRun]:
    """The calibrations of ``trainee`` in progress with a stored wizard, rebuilt, oldest first.
    A stored wizard that cannot be rebuilt (a file from another version, damaged) is skipped
    with a log line; the calibration stays in the gradebook as it is."""
    out = []
    for row in gradebook.run_states.open_runs(trainee):
        entry = row["entry"]
        try:
            wizard = Wizard.from_dict(entry["state"])
        except (WizardError, KeyError, TypeError, ValueError) as exc:
            log.warning("calibration %s of %r not restored: %s", row["calibration_id"], trainee, exc)
            continue
        finished = row.get("status") == "finished"
        if finished and (wizard.finished_result is None or not wizard.saves_to_library):
            continue                      # a check is done when finished; a result that no longer computes: skipped
        key = (entry.get("true_tool") or {}).get("key") or row["tool_key"]
        run = WizardRun(wizard, key, _truth_matrix(row["truth"]),
                        joints_deg=step_joints(entry), distance_mm=step_distances(entry))
        out.append(RestoredRun(run, int(row["calibration_id"]), dict(row["touch_ids"]), finished))
    return out


def restored_words(restored: list[RestoredRun], *, tr: Translator = ENGLISH) -> str:
    """What the trainee is told about ``restored`` (plain text), e.g. "1 calibration you had in
    progress came back, at its step with its touches. Your XYZ 4-point result not saved yet came
    back: save it to the tool library or close it."), in ``tr``'s language."""
    open_ = [r for r in restored if not r.finished]
    results = [r for r in restored if r.finished]
    parts = []
    if open_:
        n = len(open_)
        parts.append(tr.ngettext("{n} calibration you had in progress came back, at its step with its touches.",
                                 "{n} calibrations you had in progress came back, each at its step with its "
                                 "touches.", n).format(n=n))
    for r in results:
        parts.append(tr.gettext("Your {method} result not saved yet came back: save it to the tool library "
                                "or close it.").format(method=tr.gettext(r.run.wizard.title)))
    return " ".join(parts)
