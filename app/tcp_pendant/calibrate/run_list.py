"""The wizard runs of one pendant session and the one on show (no viser).

A :class:`RunList` is the workflow's list of runs (``runs``: each a
:class:`~tcp_pendant.wizards.session_record.WizardRun`, started, loaded from a record or given
back by the classroom after a restart), the index of the run on show (``current``; None: none),
and which result of each run was saved to the tool library. It answers what the Resume list
offers (:meth:`RunList.resumable`). Nothing in it is ever deleted: a run left is cancelled and
kept. Every wizard in it composes its texts in the list's language (:meth:`RunList.set_translator`).
"""

from __future__ import annotations

from collections.abc import Sequence
from datetime import datetime

import numpy as np

from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.wizards import Wizard, WizardResult, WizardStateError
from tcp_pendant.wizards.session_record import LoadedRecord, WizardRun, step_distances

__all__ = ["RunList"]


def _clock(iso_utc: str) -> str:
    """An ISO 8601 UTC time as the server's local HH:MM ("?" when unreadable)."""
    try:
        return datetime.fromisoformat(iso_utc.replace("Z", "+00:00")).astimezone().strftime("%H:%M")
    except ValueError:
        return "?"


class RunList:
    """The runs of one session, the one on show and the results saved (module docstring)."""

    def __init__(self) -> None:
        self.runs: list[WizardRun] = []
        self.current: int | None = None
        """The index in :attr:`runs` of the run on show (None: none)."""
        self._saved_results: dict[int, WizardResult] = {}    # run index -> the result saved from it
        self.translator: Translator = ENGLISH
        """The language of the runs' texts (the session's; :meth:`set_translator`)."""

    def set_translator(self, tr: Translator) -> None:
        """Every run's wizard, and every run added later, composes its texts in ``tr``'s language
        (``Wizard.set_translator``); a result saved keeps counting as saved."""
        self.translator = tr
        for i, run in enumerate(self.runs):
            was_saved = self.is_saved(i)
            run.wizard.set_translator(tr)
            if was_saved and i in self._saved_results and run.wizard.finished_result is not None:
                self._saved_results[i] = run.wizard.finished_result

    @property
    def run(self) -> WizardRun | None:
        """The run on show (open, finished or cancelled), or None."""
        return None if self.current is None else self.runs[self.current]

    @property
    def wizard(self) -> Wizard | None:
        """The wizard of the run on show, or None."""
        return None if self.current is None else self.runs[self.current].wizard

    def index_of(self, wizard: Wizard) -> int | None:
        """The run index of ``wizard`` (None: not one of these runs)."""
        return next((i for i, r in enumerate(self.runs) if r.wizard is wizard), None)

    def add(self, run: WizardRun) -> int:
        """Append ``run`` and put it on show; returns its index."""
        run.wizard.set_translator(self.translator)
        self.runs.append(run)
        self.current = len(self.runs) - 1
        return self.current

    def mark_saved(self, result: WizardResult) -> None:
        """``result`` of the run on show was just saved to the tool library."""
        if self.current is not None:
            self._saved_results[self.current] = result

    def is_saved(self, index: int) -> bool:
        """Run ``index`` is finished and its result, as it is now, was saved to the library (a
        finished check, which saves nothing, is done as it is)."""
        w = self.runs[index].wizard
        if not w.saves_to_library and w.finished_result is not None:
            return True
        saved = self._saved_results.get(index)
        return saved is not None and saved is w.finished_result

    def resumable(self) -> list[tuple[int, str]]:
        """``CalibrationWorkflow.resumable``: cancelled runs still to be done, newest first,
        with their labels."""
        _ = self.translator.gettext
        out = []
        for i in range(len(self.runs) - 1, -1, -1):
            w = self.runs[i].wizard
            if w.status != "cancelled" or self.is_saved(i):
                continue
            started = _clock(w.started_at)
            if w.finished_result is not None:
                out.append((i, _("{n}: {method}, result not saved, started {time}").format(
                    n=i + 1, method=_(w.title), time=started)))
            else:
                done = sum(1 for s in w.steps if s.recorded)
                out.append((i, _("{n}: {method}, at step {k} of {count} ({done} recorded), started {time}").format(
                    n=i + 1, method=_(w.title), k=w.step_index + 1, count=w.n_steps, done=done, time=started)))
        return out

    def to_resume(self, index: int | None) -> int:
        """The run ``CalibrationWorkflow.resume`` takes: ``index`` (any cancelled run, also a
        saved one) or, None, the newest of :meth:`resumable`.

        Raises:
            WizardStateError: there is none, or run ``index`` is not cancelled.
        """
        if index is None:
            options = self.resumable()
            if not options:
                raise WizardStateError(self.translator.gettext("There is no calibration left half-way to resume."))
            return options[0][0]
        i = int(index)
        if not (0 <= i < len(self.runs) and self.runs[i].wizard.status == "cancelled"):
            raise WizardStateError(self.translator.gettext("Calibration {n} is not waiting to be resumed.").format(
                n=i + 1))
        return i

    def put_back(self, runs: Sequence[WizardRun]) -> list[int]:
        """Append ``runs`` cancelled (waiting in the Resume list) and resume the newest on show
        (``CalibrationWorkflow.restore``); returns their indices."""
        indices = []
        for run in runs:
            if run.wizard.status != "cancelled":
                run.wizard.cancel()
            indices.append(self.add(run))
        self.runs[indices[-1]].wizard.resume()
        return indices

    def add_loaded(self, loaded: LoadedRecord) -> None:
        """Append every wizard of a record read and replayed, with its truth and distances,
        cancelled (waiting in the Resume list); the newest finished one is put on show."""
        finished: list[int] = []
        for check, entry in zip(loaded.checks, loaded.record.get("wizards", [])):
            true_tool = entry.get("true_tool") or {}
            T_true = true_tool.get("T_flange_tcp_true_m")
            check.wizard.set_translator(self.translator)
            self.runs.append(WizardRun(check.wizard, true_tool.get("key"),
                                       None if T_true is None else np.array(T_true, dtype=float),
                                       distance_mm=step_distances(entry)))
            if check.wizard.finished_result is not None:
                finished.append(len(self.runs) - 1)
            if check.wizard.status != "cancelled":
                check.wizard.cancel()         # every loaded wizard waits in the Resume list
        if finished:                          # ... but the newest finished one is put on show
            self.current = finished[-1]
            self.runs[self.current].wizard.resume()
