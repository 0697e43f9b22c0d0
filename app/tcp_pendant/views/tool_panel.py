"""The tool panel of one session (viser GUI): mounted tool, active tool data, the shared tool
library (activate, rename, delete, export to controller text) and numeric tool entry.

The library is the server's ``tcpcal.ToolLibrary`` (one file, shared by every session and
process); the session keeps the list it last read (``SessionTools.reload_library``, also called by
the server's watcher when the file changes, so a trainee sees the tools others save) and this
panel re-renders it on the session's ``library`` change. Mount, Activate and "No tool" are the
session's commands (``SessionTools.mount_tool`` / ``activate`` / ``deactivate``): this session only
(in ``--shared`` mode Activate also sets the library's active slot, the shared start tool);
the panel re-renders the mounted tool and the active data on the session's ``tool`` change.

Check (TCP check, spin test): "Check" turns the selected library tool (or "Check
active tool": the active data) about its TCP by +-A, +-B, +-C at the chosen angle and shows how
far the TRUE tip moves per rotation and the implied TCP error (``views.tool_check``; the six
rotations run in a worker thread on a copy of the robot model, the robot does not move).

Controller files: "Download file" renders the selected tool as a whole
controller file of the chosen format (``tcpcal.controllers.export_tool_file``, tool number =
the slot, as ``tcpcal tools export SLOT --format F --output FILE``) and sends it to the browser
that clicked; a refusal (e.g. ABB's reserved ``tool0``) is one notification.

Numeric entry: every field is validated (``tcp_pendant.pendant.tool_entry``) and its error is
shown right under it; the tool is saved only if all fields are valid (nothing half-way).

Language: every word is the session's (``session.translator``); a ``language`` change relabels
every handle (:meth:`ToolPanel.relabel`) and re-renders the texts shown (the entry's outcome and
the last check included). Tool names, slot numbers, formats, axis names and units stay as they
are; files sent to the browser are the controller's, the same in every language.
"""

from __future__ import annotations

import logging
import dataclasses
from collections.abc import Callable, Coroutine
from typing import Protocol, cast

import viser

from tcp_pendant.controller.tools import shown_tool_label
from tcp_pendant.controller.words import error_text
from tcp_pendant.controller import builtin_tools
from tcp_pendant.pendant import FIELDS, ToolEntry, parse_tool_entry, tool_data_markdown
from tcp_pendant.pendant.tool_entry import entry_preview_markdown
from tcp_pendant.job_pool import JobRefused
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.translation import N_, SOURCE_LANGUAGE, Translator, languages, translator
from tcp_pendant.controller.spin import DEFAULT_SPIN_ANGLE_DEG, MAX_SPIN_ANGLE_DEG, SpinCheckResult
from tcp_pendant.views.library_words import recovery_summary
from tcp_pendant.views.gui_util import (
    ButtonEvent,
    DropdownEvent,
    client_of,
    number_of_option,
    refused_before_job,
    set_content,
    set_options,
    set_value,
    slot_option,
    target_of,
)
from tcp_pendant.views.tool_check import CheckJob, check_job, check_markdown
from tcp_pendant.wizards.check_reading import check_readable
from tcpcal.controllers import CONTROLLER_FORMATS, export_tool_file
from tcpcal.errors import TcpcalError
from tcpcal.formats import FORMATS, export_tool, text_format
from tcpcal.tool import Tool

__all__ = ["CONTROLLER_FILE_REFUSED", "NO_TOOL", "TOOL_LOCKED_LINE", "ToolPanel", "controller_file"]

log = logging.getLogger(__name__)

NO_TOOL = N_("(library empty)")
"""The Slot dropdown's only option while the library is empty (shown translated)."""
FIRST_FREE = N_("first free")
"""The "Save in slot" option: the library's first free slot (shown translated)."""
CONTROLLER_FILE_REFUSED = N_("Controller file not written")
"""Title of the one notification when a controller refuses the tool (name, number)."""
TOOL_LOCKED_LINE = N_("Locked by the exercise")
"""The start of the line under "Mounted tool" while the exercise holds its tool."""
_LOCKED_TEXT = N_("Locked by the exercise: you calibrate your own tool, the {tool}. "
                  "The XYZ reference method mounts its reference tool for its first touch by itself.")
class _Labelled(Protocol):
    """A handle with a label (viser's inputs, buttons and folders)."""

    label: str


MATRIX_FORMAT = N_("Matrix")
"""The export format that is no vendor's (a 4x4 matrix): the one option said in the trainee's
language."""

class _Hinted(Protocol):
    """A handle with a hint (viser's inputs and buttons)."""

    hint: str | None


EntryOutcome = tuple[dict[str, str], str]
"""What a Save of the numeric entry said: the errors by field ("name", "X".."C") and the line under it."""


def controller_file(tool: Tool, slot: int, label: str) -> tuple[str, str]:
    """(file name, text) of ``tool`` as the whole controller file of the format labelled
    ``label`` in the menu, tool number ``slot`` (``tcpcal tools export SLOT --format F``).

    Raises:
        ValueError: unknown format; the controller refuses the tool (tcpcal's message).
    """
    fmt = next((f for f in CONTROLLER_FORMATS.values() if f.label == label), None)
    if fmt is None:
        raise ValueError(f"Unknown controller format {label!r}; choose one of "
                         f"{', '.join(f.label for f in CONTROLLER_FORMATS.values())}.")
    text = export_tool_file(tool, fmt.name, number=int(slot))
    return fmt.filename.format(n=int(slot)) or f"tool{int(slot)}.txt", text


class ToolPanel:
    """Builds the tool panel in the current GUI container of ``session.target.gui``."""

    def __init__(self, session: Session) -> None:
        self.session = session
        gui = target_of(session).gui
        c = session.controller
        self._tools = builtin_tools()
        self._tool_key_by_label = {t.label: key for key, t in self._tools.items()}
        labels = [t.label for t in self._tools.values()]
        mounted = c.mounted_tool.label if c.mounted_tool.label in labels else labels[0]
        self.mounted = gui.add_dropdown("Mounted tool", labels, initial_value=mounted,
                                        hint="The physical tool bolted on the flange.")
        self.mounted_lock_md = gui.add_markdown("", visible=False)
        self.active_md = gui.add_markdown("")
        self.library_folder = gui.add_folder("Tool library")
        with self.library_folder:
            self.slots = gui.add_dropdown("Slot", (NO_TOOL,), initial_value=NO_TOOL)
            self.slot_md = gui.add_markdown("")
            self.activate = gui.add_button("Activate", color="blue")
            self.deactivate = gui.add_button("No tool (TCP = flange)", color="gray")
            self.new_name = gui.add_text("New name", "")
            self.rename = gui.add_button("Rename")
            self.delete = gui.add_button("Delete", color="red")
        self.export_folder = gui.add_folder("Export", expand_by_default=False)
        with self.export_folder:
            self.export_fmt = gui.add_dropdown("Format", self._format_options(), initial_value="KUKA")
            self.export = gui.add_button("Export")
            self.export_text = gui.add_text("Controller text", "", multiline=True,
                                            hint="Select and copy into the controller.")
            file_labels = [f.label for f in CONTROLLER_FORMATS.values()]
            self.file_fmt = gui.add_dropdown("Controller file", file_labels, initial_value=file_labels[0],
                                             hint="A whole file the controller loads (tool number = slot).")
            self.download = gui.add_button("Download file", hint="Sent to this browser.")
        self.check_folder = gui.add_folder("TCP check")
        with self.check_folder:
            self.check_angle = gui.add_number("Angle (deg)", DEFAULT_SPIN_ANGLE_DEG, min=1.0,
                                              max=MAX_SPIN_ANGLE_DEG, step=1.0,
                                              hint="The tool turns about its TCP by +-A, +-B, +-C.")
            self.check = gui.add_button("Check", color="blue",
                                        hint="Check the selected library tool on the mounted tool.")
            self.check_active = gui.add_button("Check active tool",
                                               hint="Check the active tool data on the mounted tool.")
            self.check_md = gui.add_markdown("")
        self.entry_folder = gui.add_folder("Enter tool numerically", expand_by_default=False)
        with self.entry_folder:
            self.entry_name = gui.add_text("Name", "")
            self.entry_name_err = gui.add_markdown("", visible=False)
            self.entry_fields: dict[str, viser.GuiTextHandle] = {}
            self.entry_errors: dict[str, viser.GuiMarkdownHandle] = {}
            for f in FIELDS:
                unit = "mm" if f in "XYZ" else "deg"
                self.entry_fields[f] = gui.add_text(f"{f} ({unit})", "0")
                self.entry_errors[f] = gui.add_markdown("", visible=False)
            self.entry_slot = gui.add_dropdown("Save in slot", (FIRST_FREE,), initial_value=FIRST_FREE)
            self.entry_preview = gui.add_markdown("")
            self.entry_save = gui.add_button("Save to library", color="green")
            self.entry_md = gui.add_markdown("")

        self._checking = False
        self.last_check: tuple[CheckJob, SpinCheckResult] | None = None
        self._check_subject: tuple[int | None, str, bool] | None = None  # the last check's (slot, tool name, reading)
        self._entry_said: Callable[[Translator], EntryOutcome] | None = None
        self._wire()
        self._show_entry_preview()
        self._library: dict[int, Tool] = {}
        # a new browser hears of the library's latest recovery; later ones as they happen
        self._recoveries_told = max(0, len(session.library.recoveries) - 1)
        self._library_error: str | None = None
        self.show_library()
        self._show_mounted()
        self._show_active()
        if session.language != SOURCE_LANGUAGE:
            self.relabel()
        session.subscribe(self.on_change)

    def _wire(self) -> None:
        """Every handle's callback, on viser's event loop."""
        g = self.session.loop.on_loop
        self.mounted.on_update(g(self._on_mount))
        self.slots.on_update(g(lambda _e: self._show_slot()))
        self.activate.on_click(g(self._on_activate))
        self.deactivate.on_click(g(self._on_deactivate))
        self.rename.on_click(g(self._on_rename))
        self.delete.on_click(g(self._on_delete))
        self.export.on_click(g(self._on_export))
        self.download.on_click(g(self._on_download))
        self.check.on_click(self._check_callback(self._selected_for_check))
        self.check_active.on_click(self._check_callback(self._active_for_check))
        self.entry_save.on_click(g(self._on_entry_save))
        for handle in (self.entry_name, *self.entry_fields.values()):
            handle.on_update(g(lambda _e: self._show_entry_preview()))

    @property
    def tr(self) -> Translator:
        """The session's language."""
        return self.session.translator

    def on_change(self, change: SessionChange) -> None:
        """The change signal: the list on ``library``, the mounted tool and the active data on
        ``tool``, every text on ``language``."""
        if change.language:
            self.relabel()
            return
        if change.library:
            self.show_library()
        if change.tool:
            self._show_mounted()
            self._show_active()

    def _labels(self) -> list[tuple[object, str, str | None]]:
        """Every handle with a fixed label: (handle, English label, English hint or None)."""
        return [
            (self.mounted, N_("Mounted tool"), N_("The physical tool bolted on the flange.")),
            (self.library_folder, N_("Tool library"), None),
            (self.slots, N_("Slot"), None),
            (self.activate, N_("Activate"), None),
            (self.deactivate, N_("No tool (TCP = flange)"), None),
            (self.new_name, N_("New name"), None),
            (self.rename, N_("Rename"), None),
            (self.delete, N_("Delete"), None),
            (self.export_folder, N_("Export"), None),
            (self.export_fmt, N_("Format"), None),
            (self.export, N_("Export"), None),
            (self.export_text, N_("Controller text"), N_("Select and copy into the controller.")),
            (self.file_fmt, N_("Controller file"), N_("A whole file the controller loads (tool number = slot).")),
            (self.download, N_("Download file"), N_("Sent to this browser.")),
            (self.check_folder, N_("TCP check"), None),
            (self.check_angle, N_("Angle (deg)"), N_("The tool turns about its TCP by +-A, +-B, +-C.")),
            (self.check, N_("Check"), N_("Check the selected library tool on the mounted tool.")),
            (self.check_active, N_("Check active tool"), N_("Check the active tool data on the mounted tool.")),
            (self.entry_folder, N_("Enter tool numerically"), None),
            (self.entry_name, N_("Name"), None),
            (self.entry_slot, N_("Save in slot"), None),
            (self.entry_save, N_("Save to library"), None),
        ]

    def _format_option(self, fmt: str) -> str:
        """An export format as the dropdown offers it: a vendor's name as it is, the generic
        matrix in the session's language."""
        label = text_format(fmt).label
        return self.tr.gettext(MATRIX_FORMAT) if label == MATRIX_FORMAT else label

    @staticmethod
    def _format_of(option: str) -> str | None:
        """The export format an option names, in any language (a click sent just before a
        language switch names it in the old one); None for no format."""
        said = {translator(code).gettext(MATRIX_FORMAT) for code in languages(include_pseudo=True)}
        return next((f for f in FORMATS if option == text_format(f).label
                     or (text_format(f).label == MATRIX_FORMAT and option in said)), None)

    def _format_options(self) -> list[str]:
        return [self._format_option(f) for f in FORMATS]

    def relabel(self) -> None:
        """Every label, hint, option and text in the session's language (a ``language`` change)."""
        _ = self.tr.gettext
        chosen = self._format_of(str(self.export_fmt.value)) or FORMATS[0]
        if tuple(self.export_fmt.options) != tuple(self._format_options()):
            self.export_fmt.options = self._format_options()
        set_value(self.export_fmt, self._format_option(chosen))
        for handle, label, hint in self._labels():
            cast(_Labelled, handle).label = _(label)
            if hint is not None:
                cast(_Hinted, handle).hint = _(hint)   # folders have no hint: none is given for them
        self.show_library()
        self._show_mounted()
        self._show_active()
        self._show_entry_preview()
        self._show_entry_outcome()
        if self.last_check is not None and self._check_subject is not None:
            job, result = self.last_check
            slot, name, reading = self._check_subject
            job = dataclasses.replace(job, title=self._check_title(slot, name))
            self.check_md.content = check_markdown(job, result, reading=reading, tr=self.tr)

    # ------------------------------------------------------------ library
    def reload(self) -> None:
        """Re-read the shared library (``SessionTools.reload_library``; the panel re-renders on its
        change signal)."""
        self.session.tools.reload_library()

    def show_library(self) -> None:
        """Render the session's list of the library's tools (keeps the selection).

        A damaged file's valid tools are listed; what the library set aside (and where its
        backup is) is told to this browser once per recovery. An unreadable file lists no
        tools and says why (once per reason), so the rest of the pendant still works.
        """
        s = self.session
        error = s.tools.library_error
        if error is not None and error != self._library_error:
            s.notify(self.tr.gettext("Tool library unavailable"), error, kind="error")
        self._library_error = error
        self._tell_recoveries()
        lib = s.tools.library_tools
        self._library = lib
        options = tuple(slot_option(slot, t.name) for slot, t in sorted(lib.items())) or (self.tr.gettext(NO_TOOL),)
        current = number_of_option(self.slots.value)
        self.slots.options = options
        pick = next((o for o in options if number_of_option(o) == current), options[0])
        if self.slots.value != pick:
            set_value(self.slots, pick)
        free = [str(n) for n in range(1, s.library.N_SLOTS + 1) if n not in lib]
        first_free = self.tr.gettext(FIRST_FREE)
        keep = first_free if number_of_option(self.entry_slot.value) is None else None
        set_options(self.entry_slot, (first_free, *free), keep=keep)
        self._show_slot()

    def _tell_recoveries(self) -> None:
        """Notify this browser of each library recovery it has not been told of (viser shows a
        notification's body as plain text, so tool names and paths need no escaping)."""
        recoveries = self.session.library.recoveries
        for rec in recoveries[self._recoveries_told:]:
            title = (self.tr.gettext("Tool library moved aside") if rec.whole_file
                     else self.tr.gettext("Tool library: bad entries set aside"))
            self.session.notify(title, recovery_summary(rec, self.tr), kind="warning")
        self._recoveries_told = len(recoveries)

    def _selected(self) -> tuple[int, Tool]:
        slot = number_of_option(self.slots.value)
        tool = None if slot is None else self._library.get(slot)
        if slot is None or tool is None:
            raise ValueError(self.tr.gettext("Select a tool of the library first (the library is empty?)."))
        return slot, tool

    def _show_slot(self) -> None:
        slot = number_of_option(self.slots.value)
        tool = None if slot is None else self._library.get(slot)
        self.slot_md.content = "" if tool is None or slot is None else tool_data_markdown(
            tool, slot, selected=True, tr=self.tr) + self._owner_line(slot)

    def _owner_line(self, slot: int) -> str:
        """Whose the selected slot is (a class): a trainee reads "yours" or "not yours" (no
        classmate's name), the trainer the owner's name (escaped)."""
        s, _ = self.session, self.tr.gettext
        rights, owner = s.tools.library_rights, s.tools.library_owners.get(slot)
        if rights.restricted:
            if rights.mine(s.tools.library_owners, slot):
                return "\n\n" + _("Yours: you can rename and delete it.")
            if owner is not None:
                return "\n\n" + _("This slot is another trainee's: activate and check it; you cannot change it.")
            return "\n\n" + _("This slot is the trainer's: activate and check it; you cannot change it.")
        if owner is not None:
            return "\n\n" + _("Saved by trainee {name}.").format(name=escape_markdown(owner))
        return ""

    def _choices(self) -> dict[str, str]:
        """Mounted tool's choices, label in the session's language -> key: the built-in tools and
        the exercise's tool."""
        held = self.session.tools.exercise_tool
        english = self._tool_key_by_label if held is None else {**self._tool_key_by_label, held.label: held.key}
        return {shown_tool_label(label, self.tr): key for label, key in english.items()}

    def _key_of(self, label: str) -> str | None:
        """The tool a Mounted tool ``label`` names: in the session's language, or in English (a
        click that crossed a language switch)."""
        held = self.session.tools.exercise_tool
        english = self._tool_key_by_label if held is None else {**self._tool_key_by_label, held.label: held.key}
        return self._choices().get(label, english.get(label))

    def _show_mounted(self) -> None:
        """The mounted tool; in an exercise that holds its tool, the dropdown locked with why."""
        held = self.session.tools.exercise_tool
        label = shown_tool_label(self.session.controller.mounted_tool.label, self.tr)
        options = tuple(self._choices())
        if label in options:
            set_options(self.mounted, options, keep=label)   # its own handler then sees no change
        self.mounted.disabled = held is not None
        set_content(self.mounted_lock_md, "" if held is None else self.tr.gettext(_LOCKED_TEXT).format(
            tool=escape_markdown(shown_tool_label(held.label, self.tr, in_sentence=True))))
        self.mounted_lock_md.visible = held is not None

    def _show_active(self) -> None:
        self.active_md.content = tool_data_markdown(self.session.controller.active_tool, self.session.tools.active_slot,
                                                    tr=self.tr)

    # ------------------------------------------------------------ callbacks
    def _on_mount(self, event: DropdownEvent) -> None:
        """Mount the tool chosen (``SessionTools.mount_tool``); a refused change (the exercise holds
        its tool) puts the dropdown back on the tool mounted."""
        key = self._key_of(str(event.target.value))
        if key is None:
            self._show_mounted()
            raise ValueError(self.tr.gettext("Unknown tool {name}; choose one of the list.").format(
                name=repr(event.target.value)))
        if key == self.session.controller.mounted_tool.key:
            return
        held = self.session.tools.exercise_tool
        try:
            self.session.tools.mount_tool(held if held is not None and key == held.key else self._tools[key])
        except ValueError:
            self._show_mounted()
            raise

    def _on_activate(self, _event: ButtonEvent) -> None:
        slot, _ = self._selected()
        tool = self.session.tools.activate(slot)
        self.session.notify(self.tr.gettext("Tool activated"), f"{slot}: {tool.name}", kind="success")

    def _on_deactivate(self, _event: ButtonEvent) -> None:
        self.session.tools.deactivate()

    def _on_rename(self, _event: ButtonEvent) -> None:
        slot, tool = self._selected()
        name = str(self.new_name.value).strip()
        if not name:
            raise ValueError(self.tr.gettext("Type the new name in 'New name' first."))
        s = self.session
        with s.batch():
            s.tools.rename_tool(slot, name)
            if s.client is not None:
                # a courtesy, per browser only: in --shared mode the box is every browser's, and
                # another trainee may be typing in it
                set_value(self.new_name, "")

    def _on_delete(self, _event: ButtonEvent) -> None:
        slot, tool = self._selected()
        self.session.tools.delete_tool(slot)
        self.session.notify(self.tr.gettext("Tool deleted"), f"{slot}: {tool.name}")

    def _on_export(self, _event: ButtonEvent) -> None:
        slot, tool = self._selected()
        label = str(self.export_fmt.value)
        fmt = self._format_of(label)
        if fmt is None:
            raise ValueError(self.tr.gettext("Unknown export format {name}.").format(name=repr(label)))
        number = text_format(fmt).slot_for(slot)  # the controller's tool numbers, else its default
        kw = {} if number is None else {"slot": number}
        set_value(self.export_text, export_tool(tool, fmt, **kw))

    def _on_download(self, event: ButtonEvent) -> None:
        slot, tool = self._selected()
        try:
            filename, text = controller_file(tool, slot, str(self.file_fmt.value))
        except (TcpcalError, ValueError) as exc:
            self.session.notify(self.tr.gettext(CONTROLLER_FILE_REFUSED), error_text(exc, self.tr), kind="warning")
            return
        # to the browser that clicked (in --shared mode the session is every browser's)
        target = event.client or client_of(self.session) or target_of(self.session)
        target.send_file_download(filename, text.encode("utf-8"), save_immediately=True)

    # ------------------------------------------------------------ TCP check
    def _check_title(self, slot: int | None, name: str) -> str:
        """What a check is of, plain text: "slot 2: Torch", or the name of unsaved tool data."""
        return name if slot is None else self.tr.gettext("slot {slot}: {name}").format(slot=slot, name=name)

    def _selected_for_check(self) -> tuple[int | None, Tool]:
        return self._selected()

    def _active_for_check(self) -> tuple[int | None, Tool]:
        tool = self.session.controller.active_tool
        if tool is None:
            raise ValueError(self.tr.gettext("No tool data is active (TCP = flange): activate a tool or pick one "
                                             "in the library and press Check."))
        return self.session.tools.active_slot, tool

    def _check_callback(self, which: Callable[[], tuple[int | None, Tool]]
                        ) -> Callable[[ButtonEvent], Coroutine[object, object, None]]:
        async def callback(_event: ButtonEvent) -> None:
            await self.run_check(which)
        return callback

    async def run_check(self, which: Callable[[], tuple[int | None, Tool]]) -> None:
        """Run the TCP check of ``which()`` (library slot or None, tool): the job is taken under the session
        lock on the loop, the six rotations run in the server's job pool (``SessionLoop.run_job``),
        the result is shown on the loop. One check at a time per session (one job of any kind:
        the pool refuses another meanwhile, in words, and a session whose jobs used their share of
        the server's time: ``SessionLoop.admit_job``, before the job is taken); the loop's work on
        it counts against that share (``SessionLoop.charged``); errors become one notification."""
        s = self.session
        _ = self.tr.gettext
        if refused_before_job(s, running=self._checking, what=_("TCP check"), not_started=_("Check not started")):
            return
        try:
            with s.loop.charged(), s.lock:
                slot, tool = which()
                title = self._check_title(slot, tool.name)
                if s.rules.in_exercise:                 # read against the spike, as on a robot
                    check_readable(s.pose_state().touch.distance_mm, tr=self.tr)
                job = check_job(s.controller, tool, title, self.check_angle.value, tr=self.tr)
                shown = self.check_md.content
                self.check_md.content = _("Checking {title} ...").format(title=escape_markdown(title))
        except ValueError as exc:
            s.notify(_("Not done"), error_text(exc, self.tr), kind="warning")
            return
        self._checking = True
        try:
            result = await s.loop.run_job(job.run, what="a TCP check")
        except JobRefused as exc:      # this session's other job, or a full queue: nothing ran
            with s.lock:
                self.check_md.content = shown
            s.notify_refusal(self.tr.gettext("Check not started"), error_text(exc, self.tr))
            return
        except Exception as exc:  # a browser's click must never kill the server
            log.exception("TCP check failed")
            s.notify(self.tr.gettext("TCP check failed"), f"{type(exc).__name__}: {exc}", kind="error")
            return
        finally:
            self._checking = False
        with s.loop.charged(), s.lock:
            if s.closed:
                return
            self.last_check = (job, result)
            reading = s.rules.in_exercise
            self._check_subject = (slot, tool.name, reading)
            self.check_md.content = check_markdown(job, result, reading=reading, tr=self.tr)

    def _entry(self) -> ToolEntry:
        return ToolEntry(str(self.entry_name.value), {f: str(h.value) for f, h in self.entry_fields.items()})

    def _show_entry_preview(self) -> None:
        """Live line under the form: what Save would store, as this server has received it."""
        self.entry_preview.content = entry_preview_markdown(self._entry(), tr=self.tr)

    def _show_entry_outcome(self) -> None:
        """The last Save's errors and line, in the session's language (none before a Save)."""
        if self._entry_said is None:
            return
        errors, line = self._entry_said(self.tr)
        self._show_entry_errors(errors)
        self.entry_md.content = line

    def _on_entry_save(self, _event: ButtonEvent) -> None:
        """Save the typed tool if every field is valid; what it says is kept as a function of the
        language (``_entry_said``), so that a language switch re-says it."""
        entry = self._entry()
        res = parse_tool_entry(entry)
        lib = self.session.library
        slot: int | None = None
        name_problem: Callable[[Translator], str] | None = None
        if res.tool is not None:
            name = res.tool.name
            found = lib.find(name)
            choice = number_of_option(self.entry_slot.value)
            slot = lib.first_free_slot() if choice is None else choice
            if found is not None:
                taken = found[0]
                name_problem = lambda tr: tr.gettext(  # noqa: E731
                    "Name: '{name}' is already in slot {slot}; choose another name").format(name=name, slot=taken)
            elif slot is None:
                name_problem = lambda tr: tr.gettext("Name: the library is full; delete a tool first")  # noqa: E731

        def errors_in(tr: Translator) -> dict[str, str]:
            errors = dict(parse_tool_entry(entry, tr=tr).errors)
            if name_problem is not None:
                errors["name"] = name_problem(tr)
            return errors

        if res.errors or name_problem is not None or res.tool is None or slot is None:
            self._entry_said = lambda tr: (errors_in(tr), tr.gettext("⚠ Not saved: correct the fields marked above."))
            self._show_entry_outcome()
            return
        tool, saved_in = res.tool, slot
        try:
            self.session.tools.store_tool(slot, tool)
        except ValueError as exc:       # e.g. another trainee's slot, a full quota: said here too
            refused = exc
            self._entry_said = lambda tr: ({}, tr.gettext("⚠ Not saved: {why}").format(
                why=escape_markdown(error_text(refused, tr))))
            self._show_entry_outcome()
            raise
        self._entry_said = lambda tr: ({}, tr.gettext("✔ Saved **{name}** in slot {slot}.").format(
            name=escape_markdown(tool.name), slot=saved_in))
        self._show_entry_outcome()
        set_value(self.slots, slot_option(slot, tool.name))
        self._show_slot()

    def _show_entry_errors(self, errors: dict[str, str]) -> None:
        pairs = [("name", self.entry_name_err), *((f, self.entry_errors[f]) for f in FIELDS)]
        for key, handle in pairs:
            msg = errors.get(key)
            handle.content = "" if msg is None else f"**⚠ {escape_markdown(msg)}**"
            handle.visible = msg is not None
