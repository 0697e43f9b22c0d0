"""A session's tools (``Session.tools``): the physical tool on the flange, the exercise's tool
lock, the active tool data and its library slot, and the session's copy of the library's list.

The library (``tcpcal.ToolLibrary``, one file shared by every session and process) owns only the
stored tools; its ``active_slot`` is the CLI's ``tools activate`` and the ``--shared`` mode's
start tool: a per-browser session starts with no active tool (TCP = flange), never reads it and
never writes it; the ``--shared`` session starts with it and writes it when a tool is activated
or saved there. :class:`SessionTools` is also the workflow's ``ToolState``: a wizard mounts
tools and sets tool data through it, and reads there what limits it (the exercise's tool, its
rules, "Hide distance"). Every command ends in the session's one change signal.
"""

from __future__ import annotations

import threading
from typing import ContextManager, Protocol

from tcpcal.errors import TcpcalError
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool
from tcp_pendant.calibrate.pendant_rules import UNRESTRICTED, ExerciseRules, LibraryRights, check_tool_change
from tcp_pendant.calibrate.workflow import CalibrationWorkflow
from tcp_pendant.controller import ControllerError, ToolModel, VirtualController
from tcp_pendant.session_scenario import ScenarioPlayer
from tcp_pendant.translation import Translator

__all__ = ["SessionTools", "ToolsHost"]


class ToolsHost(Protocol):
    """What :class:`SessionTools` needs of its session."""

    lock: threading.RLock
    controller: VirtualController
    library: ToolLibrary
    workflow: CalibrationWorkflow
    shared: bool
    scenario_player: ScenarioPlayer
    rules: ExerciseRules
    hide_distance: bool
    translator: Translator

    def changed(self, *, tool: bool = False, library: bool = False) -> None: ...

    def batch(self) -> ContextManager[None]: ...


class SessionTools:
    """The session's tool commands and the state they change (module docstring).

    Attributes:
        exercise_tool: the physical tool the exercise keeps mounted (a classroom's mystery
            tool; None: the trainee mounts any tool); change it with :meth:`set_exercise_tool`.
        active_slot: library slot of the active tool data (None: no tool or typed-in only).
        library_tools: the library's tools as this session last read them (slot -> tool).
        library_error: why the library could not be read at the last :meth:`reload_library`
            (None: it was).
        library_owners: who owns each owned slot, as this session last read it (a class's
            trainees).
        library_rights: how this pendant may change the library (``calibrate.pendant_rules``;
            the classroom sets it with :meth:`set_library_rights`).
    """

    def __init__(self, host: ToolsHost) -> None:
        self._host = host
        self.exercise_tool: ToolModel | None = None
        self.active_slot: int | None = None
        self.library_tools: dict[int, Tool] = {}
        self.library_error: str | None = None
        self.library_owners: dict[int, str] = {}
        self.library_rights: LibraryRights = UNRESTRICTED

    @property
    def rules(self) -> ExerciseRules:
        """The session's exercise rules (the workflow reads them: the methods, Auto-touch)."""
        return self._host.rules

    @property
    def hide_distance(self) -> bool:
        """The session's "Hide distance" (the workflow notes it with each touch)."""
        return self._host.hide_distance

    # ------------------------------------------------------------ the physical tool
    def mount_tool(self, tool: ToolModel) -> None:
        """Bolt another physical tool on (the active tool data does not change). While the
        "bent tool" scenario plays, the tool bolted on is the bent version of ``tool``.

        Raises:
            RuleRefusal: the exercise keeps its tool mounted (:attr:`exercise_tool`) and
                ``tool`` is another one; nothing changes.
        """
        with self._host.lock:
            held = self.exercise_tool
            if held is not None:
                check_tool_change(held.key, held.label, tool.key, tool.label)
            self._mount(tool)

    def _mount(self, tool: ToolModel) -> None:
        tool = self._host.scenario_player.physical(tool)
        if tool is self._host.controller.mounted_tool:
            return
        self._host.controller.mount_tool(tool)
        self._host.changed(tool=True)

    def set_exercise_tool(self, tool: ToolModel | None) -> None:
        """The exercise's tool (the classroom's mystery tool of this trainee): mounted now, and
        from now on "Mounted tool" is locked to it. :meth:`mount_tool` refuses another tool in
        words; a calibration may only measure it (``WizardCommands.start``); a wizard step's own
        tool change (the XYZ reference method's reference tool, :meth:`mount_step_tool`) may
        mount another for that run's steps, and the exercise's tool is mounted again when the
        run ends or is cancelled. None: released, any tool may be mounted (free practice;
        ``Session.set_rules`` of free practice releases it too). One ``tool`` signal."""
        with self._host.lock, self._host.batch():
            if tool is None and self.exercise_tool is None:
                return
            self.exercise_tool = tool
            if tool is not None:
                self._mount(tool)
            self._host.changed(tool=True)

    def mount_step_tool(self, tool: ToolModel) -> None:
        """The tool change a wizard step asks for (its "Mount the tool" button, Auto-touch):
        :meth:`mount_tool`, except that while the exercise holds its tool, the run on show may
        mount the tool of its current step when that run calibrates the exercise's tool (the
        XYZ reference method's reference tool for its first touch).

        Raises:
            RuleRefusal: the exercise holds its tool and this is no such step.
        """
        with self._host.lock:
            if not self._step_may_mount(tool.key):
                self.mount_tool(tool)
                return
            self._mount(tool)

    def _step_may_mount(self, key: str) -> bool:
        """The run on show is in progress, calibrates the exercise's tool and its current step
        needs the tool ``key`` (the exception to the exercise's lock)."""
        held, run, w = self.exercise_tool, self._host.workflow.run, self._host.workflow.wizard
        return (held is not None and run is not None and w is not None and w.status == "in_progress"
                and run.true_tool_key == held.key and w.step.mount_tool_key == key)

    def remount_exercise_tool(self) -> None:
        """The exercise's tool back on the flange, unless the run on show is in progress,
        calibrates it and one of its steps asks for the tool on the flange now (the XYZ
        reference method between its two touches)."""
        held = self.exercise_tool
        mounted = self._host.controller.mounted_tool
        if held is None or mounted.key == held.key:
            return
        run, w = self._host.workflow.run, self._host.workflow.wizard
        if (run is not None and w is not None and w.status == "in_progress" and run.true_tool_key == held.key
                and any(step.mount_tool_key == mounted.key for step in w.steps)):
            return
        self._mount(held)

    # ------------------------------------------------------------ the active tool data
    def set_active_data(self, tool: Tool | None, slot: int | None = None) -> None:
        """Make ``tool`` the active tool data (typed in, a wizard's, or the library's ``slot``);
        None: no tool (TCP = flange). The library file is not written."""
        with self._host.lock:
            self._host.controller.set_active_tool(tool)
            self.active_slot = slot if tool is not None else None
            self._host.changed(tool=True)

    def activate(self, slot: int) -> Tool:
        """"Activate": the library tool in ``slot`` (as last read) becomes the active tool data.
        In ``--shared`` mode the library's active slot is set too (the shared start tool).

        Raises:
            ControllerError: the slot is empty.
        """
        with self._host.lock:
            tool = self.library_tools.get(int(slot))
            if tool is None:
                raise ControllerError(self._host.translator.gettext(
                    "Slot {slot} of the tool library is empty; pick a stored tool.").format(slot=slot))
            if self._host.shared:
                self._host.library.activate(int(slot))
            self.set_active_data(tool, int(slot))
            return tool

    def deactivate(self) -> None:
        """"No tool": TCP = flange (this session only; the library file is not written)."""
        self.set_active_data(None)

    def apply_saved(self, slot: int, tool: Tool) -> None:
        """After ``tool`` was saved in ``slot`` of the library: it is the active tool data, and
        the session's list of tools is re-read (``--shared``: the library's active slot too)."""
        with self._host.lock, self._host.batch():
            if self._host.shared:
                self._host.library.activate(int(slot))
            self.reload_library()
            self.set_active_data(tool, int(slot))

    # ------------------------------------------------------------ the library
    def reload_library(self) -> dict[int, Tool]:
        """Re-read the library's tools into :attr:`library_tools` (an unreadable file gives no
        tools and :attr:`library_error` says why) and signal ``library``."""
        with self._host.lock:
            try:
                tools = self._host.library.tools()
                owners = self._host.library.owners()
            except TcpcalError as exc:  # e.g. permissions: ToolLibraryError names the file
                tools, owners, self.library_error = {}, {}, str(exc)
            else:
                self.library_error = None
            self.library_tools = dict(tools)
            self.library_owners = dict(owners)
            self._host.changed(library=True)
            return self.library_tools

    def set_library_rights(self, rights: LibraryRights) -> None:
        """How this pendant may change the library from now on (a class: the trainee's slots
        only; ``classroom.library_rights``)."""
        with self._host.lock:
            self.library_rights = rights
            self._host.changed(library=True)

    def store_tool(self, slot: int, tool: Tool) -> None:
        """Write ``tool`` into ``slot`` of the library (numeric entry) and re-read the list.

        Raises:
            tcpcal.TcpcalError: the library refused (the name is in another slot, the slot is
                another trainee's, the trainee's quota is full, ...).
        """
        with self._host.lock:
            rights = self.library_rights
            with rights.in_words():
                self._host.library.save(int(slot), tool, **rights.save_kwargs())
            self.reload_library()

    def rename_tool(self, slot: int, name: str) -> None:
        """Rename the library tool in ``slot`` (a trainee: one of theirs); the active data
        carries the new name when it is that slot's. One signal."""
        with self._host.lock, self._host.batch():
            rights = self.library_rights
            with rights.in_words():
                self._host.library.rename(int(slot), name, **rights.owner_kwargs())
            self.reload_library()
            renamed = self.library_tools.get(int(slot))
            if self.active_slot == int(slot) and renamed is not None:
                self.set_active_data(renamed, int(slot))

    def delete_tool(self, slot: int) -> None:
        """Delete the library tool in ``slot`` (a trainee: one of theirs) and re-read the list."""
        with self._host.lock:
            rights = self.library_rights
            with rights.in_words():
                self._host.library.remove(int(slot), **rights.owner_kwargs())
            self.reload_library()
