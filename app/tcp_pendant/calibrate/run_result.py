"""The result of the run on show: what it is against the truth, and its Save (no viser).

A :class:`RunResult` belongs to one ``CalibrationWorkflow``. It reads the run on show (its
``RunList``): the result, its comparison with the hidden true TOOL frame in training mode
(``wizards.truth``), the tool Save would store and the name it offers, the distances at record
the result panel may show; and it saves the result to the shared tool library
(``library_save.save_result``, one atomic write), noting it in the run list and the run log.

Units: frames 4x4 in metres (FLANGE -> TOOL); distances mm.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from tcp_pendant.calibrate.library_save import save_result
from tcp_pendant.calibrate.pendant_rules import LibraryRights
from tcp_pendant.calibrate.run_list import RunList
from tcp_pendant.calibrate.run_log import RunLog
from tcp_pendant.controller import T_flange_tool_m, ToolModel
from tcp_pendant.controller.tools import shown_tool_label
from tcp_pendant.events import ToolSaved
from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.wizards import WizardResult, WizardStateError
from tcp_pendant.wizards.truth import TruthComparison, compare_with_truth
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

__all__ = ["RunResult"]


class RunResult:
    """The result of the run on show of ``run_list`` (module docstring).

    Args:
        run_list: the workflow's runs.
        tools: the physical tools by key (their labels name a saved tool).
        library: the server's tool library (shared by every session).
        log: the workflow's run log (a save is a :class:`~tcp_pendant.events.ToolSaved`).
    """

    def __init__(self, run_list: RunList, tools: Mapping[str, ToolModel], library: ToolLibrary,
                 log: RunLog) -> None:
        self._run_list, self._tools, self._library, self._log = run_list, tools, library, log

    @property
    def result(self) -> WizardResult | None:
        """The result of the wizard on show (None: none yet)."""
        w = self._run_list.wizard
        return None if w is None else w.result

    def truth(self, training: bool) -> TruthComparison | None:
        """In ``training`` mode: the result against the hidden true TOOL frame (None otherwise)."""
        run, res = self._run_list.run, self.result
        if not training or run is None or res is None or run.T_flange_tool_true_m is None:
            return None
        return compare_with_truth(res, run.T_flange_tool_true_m)

    def T_flange_tool_true_m(self, training: bool) -> np.ndarray | None:
        """In ``training`` mode, after a result: the hidden true TOOL frame (4x4, metres)."""
        run = self._run_list.run
        if not training or run is None or self.result is None:
            return None
        return run.T_flange_tool_true_m

    def preview_tool(self) -> Tool | None:
        """The tool Save would store (named "preview"), or None before a result."""
        w = self._run_list.wizard
        if w is None or w.result is None or not w.saves_to_library:
            return None
        return w.to_tool("preview")

    def T_flange_tool_computed_m(self) -> np.ndarray | None:
        """The computed TOOL frame of the result (4x4, metres, FLANGE -> TOOL), or None."""
        tool = self.preview_tool()
        return None if tool is None else T_flange_tool_m(tool)

    def default_save_name(self, *, tr: Translator = ENGLISH) -> str:
        """The calibrated tool's own name, else its physical tool's label in ``tr``'s language,
        else "Tool" in it (the name offered: the trainee may type another)."""
        w = self._run_list.wizard
        if w is not None and w.library_tool_name is not None:
            return w.library_tool_name
        run = self._run_list.run
        tool = None if run is None or run.true_tool_key is None else self._tools.get(run.true_tool_key)
        return tr.gettext("Tool") if tool is None else shown_tool_label(tool.label, tr)

    def distances_shown(self, hide_truth: bool) -> tuple[dict[int, float], set[int]]:
        """The run on show's distance-at-record of its touch steps (mm, by 0-based step) and the
        steps recorded with "Hide distance" on; empty with the truth hidden."""
        run = self._run_list.run
        if run is None or hide_truth:
            return {}, set()
        return dict(run.distance_mm), set(run.distance_hidden)

    def save(self, name: str, slot: int | None, rights: LibraryRights) -> tuple[int, Tool]:
        """Store the result on show in the library as ``name`` (slot None: the slot holding that
        name, else the first free one) within ``rights``; returns (slot, tool). Nothing is
        written if anything is wrong.

        Raises:
            WizardStateError: no wizard, not finished, a check saves nothing, empty name,
                library full.
            tcpcal.TcpcalError: the library refused (the name is used by another slot, ...).
        """
        _ = self._run_list.translator.gettext
        w = self._run_list.wizard
        if w is None:
            raise WizardStateError(_("No calibration is open: choose a method and press Start."))
        if not w.saves_to_library:
            raise WizardStateError(_("The {method} saves nothing to the library: it only checks the tool data.").format(
                method=_(w.title)))
        name = str(name).strip()
        if not name:
            raise WizardStateError(_("Type a name for the tool before saving."))
        slot_tool = save_result(w, self._library, name, slot, rights)
        if w.result is not None:
            self._run_list.mark_saved(w.result)
        self._log.add(ToolSaved(self._run_list.current, slot_tool[0], slot_tool[1].name))
        return slot_tool
