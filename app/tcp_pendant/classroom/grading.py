"""Grade a trainee's honest session record against the gradebook (no viser).

A trainee's export in a class carries no truth (``session_record`` version 2, ``honest``), but
each wizard carries its ``record_id``: the gradebook's calibration id. :func:`grade_record`
looks every replayed wizard up there, compares it with the true TOOL frame the gradebook keeps
(``wizards.truth.compare_with_truth``) and with the result the gradebook stored when the
trainee finished (a record whose poses were edited afterwards no longer matches it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.gradebook_store import GradebookError
from tcp_pendant.wizards.session_record import LoadedRecord
from tcp_pendant.wizards.truth import compare_with_truth

__all__ = ["GRADEBOOK_TOLERANCE_MM", "RecordGrade", "grade_record"]

GRADEBOOK_TOLERANCE_MM = 1e-6
"""The replayed TCP must equal the gradebook's stored one within this (mm)."""


@dataclass(frozen=True)
class RecordGrade:
    """One wizard of a trainee's record, graded against the gradebook.

    Attributes:
        index: position in the record's ``"wizards"`` (0-based).
        record_id: the gradebook calibration id the record names (None: none).
        trainee: the trainee the gradebook files it under ("" if unknown).
        method: the wizard kind.
        matches_gradebook: the replayed result equals the one the gradebook stored (None: no
            stored result to compare with).
        position_error_mm / orientation_error_deg: error against the gradebook's truth, or None.
        grade: "good" | "fair" | "poor" | None.
        message: plain words.
    """

    index: int
    record_id: int | None
    trainee: str
    method: str
    matches_gradebook: bool | None
    position_error_mm: float | None
    orientation_error_deg: float | None
    grade: str | None
    message: str


def grade_record(loaded: LoadedRecord, gradebook: Gradebook) -> tuple[RecordGrade, ...]:
    """Grade every wizard of a loaded (parsed and replayed) record against ``gradebook``.

    Safe to call off viser's event loop (the gradebook takes its own lock).
    """
    rows = {r.calibration_id: r for r in gradebook.grades.rows()}
    out: list[RecordGrade] = []
    for check, entry in zip(loaded.checks, loaded.record.get("wizards", [])):
        rid = entry.get("record_id")
        res = check.wizard.finished_result
        if rid is None:
            out.append(RecordGrade(check.index, None, "", check.kind, None, None, None, None,
                                   "no record id: not recorded in this class's gradebook"))
            continue
        try:
            truth = gradebook.records.truth(rid)
        except GradebookError:
            out.append(RecordGrade(check.index, rid, "", check.kind, None, None, None, None,
                                   f"calibration {rid} is not in this gradebook"))
            continue
        row = rows.get(rid)
        trainee = row.trainee if row is not None else ""
        T_true = truth.get("T_flange_tool_true_m")
        if res is None:
            out.append(RecordGrade(check.index, rid, trainee, check.kind, None, None, None, None,
                                   "unfinished: no result to grade"))
            continue
        matches = None
        if row is not None and row.tcp_mm is not None:
            diff = float(np.linalg.norm(np.asarray(res.tcp_mm) - np.asarray(row.tcp_mm)))
            matches = diff <= GRADEBOOK_TOLERANCE_MM
        if T_true is None:
            out.append(RecordGrade(check.index, rid, trainee, check.kind, matches, None, None, None,
                                   "the gradebook keeps no truth for it"))
            continue
        cmp = compare_with_truth(res, np.asarray(T_true, dtype=float))
        words = {True: "matches the gradebook", False: "DIFFERS from the result the gradebook stored",
                 None: "not finished in the gradebook"}[matches]
        out.append(RecordGrade(check.index, rid, trainee, check.kind, matches, cmp.position_error_mm,
                               cmp.orientation_error_deg, cmp.grade, f"{cmp.verdict}; {words}"))
    return tuple(out)
