"""The Calibrate tab of one session (viser GUI): the wizards' menu and their views.

Built by ``tcp_pendant.views.calibrate.build_calibrate_tab`` for the session's workflow
(``Session.workflow``). Top to bottom:

* **Training mode** switch (on by default, for the classroom): reveals the true TOOL frame
  after a result with the error against it, and offers Auto-touch;
* **Calibrate** menu: the method (every registered wizard class, ``tcp_pendant.wizards.registry``,
  in its ``rank`` order: XYZ 4-point, XYZ reference, TCP & Z, X, three-point orientation, ABC
  world; in an exercise only the methods it allows, ``ExerciseRules.allowed_methods``), the
  options the chosen method declares (``Wizard.options``: one widget per option
  name, shared by the methods that declare it: touches and estimator; the calibrated tool from
  the library; the physical reference and new tools), Start (``CalibrationWorkflow.start(kind,
  **options)``), "Start from the N recorded points" (XYZ 4-point, when the Jog tab's Record point
  stored touches: they become its first steps, ``CalibrationWorkflow.start_from_touches``), and
  Resume for a calibration left half-way. It is hidden while a wizard is
  open, as on a pendant; Cancel (or Close, on a result) brings it back;
* the open wizard's step panel (``wizard_steps``), its result panel (``wizard_result``), its
  worked equations ("The math", ``math_panel``) and its scene nodes (``wizard_scene``);
* **Session record**: export the session (touches, wizards, results, errors) as JSON and load
  one back to replay it (how a trainer grades). A loaded file is bytes: refused above
  ``session_record.MAX_RECORD_BYTES`` as its transfer starts (``upload_guard``), then parsed and
  replayed in a worker thread (never on viser's event loop, where it would stall every
  browser), one load per session at a time; the result is added under the session lock.

All logic is in :class:`tcp_pendant.calibrate.CalibrationWorkflow` (no viser), owned by the
session, whose commands (``WizardCommands.start``, ``record_step``, ``save_result``, ...) are
the only way a click changes it; every click goes through :meth:`CalibrateView.action`
(``SessionLoop.on_loop``: the event loop, the session's lock and error notifications) inside
``Session.batch``, so a click ends in one change signal; the tab re-renders from the workflow's
state on that signal (:meth:`CalibrateView.on_change`), as the scene and the Tool tab do.

Language: every word of the tab is the session's (``session.translator``): the fixed labels and
hints through ``views.gui_words``, the wizard classes' titles, blurbs, options and variants (``N_``
msgids of ``tcp_pendant.wizards``) translated where shown, the composed texts by
``calibrate.text`` with ``tr``. A ``language`` change relabels everything and re-renders the
tab (:meth:`CalibrateView.relabel`), the chosen method and options kept; a dropdown's value is
read in the session's language, in the one it was shown in, or in English.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Coroutine
from typing import TypeVar, cast

import viser

from tcp_pendant.controller.tools import shown_tool_label
from tcp_pendant.controller.words import error_text
from tcp_pendant.calibrate import CalibrationWorkflow
from tcp_pendant.calibrate.library_choice import default_library_slot
from tcp_pendant.calibrate.text import (
    menu_markdown,
    replay_markdown,
)
from tcp_pendant.job_pool import JobRefused
from tcp_pendant.session import Session, SessionChange
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.gui_util import (
    ButtonEvent,
    CheckboxEvent,
    DropdownEvent,
    UploadEvent,
    client_of,
    number_of_option,
    set_content,
    set_options,
    set_value,
    slot_option,
    target_of,
)
from tcp_pendant.translation import ENGLISH, N_
from tcp_pendant.views.beam_replay import ScanPlayer
from tcp_pendant.views.gui_words import GuiWords
from tcp_pendant.views.math_panel import MathView
from tcp_pendant.views.upload_guard import limit_upload_size
from tcp_pendant.views.wizard_result import WizardResultView
from tcp_pendant.views.wizard_scene import WizardSceneView
from tcp_pendant.views.wizard_steps import WizardStepsView
from tcp_pendant.wizards import Wizard, wizard_classes
from tcp_pendant.wizards.describe import WizardOption
from tcp_pendant.wizards.session_record import (
    MAX_RECORD_BYTES,
    LoadedRecord,
    SessionRecordError,
    check_record_size,
    dumps,
    load_and_replay,
)
from tcpcal.tool import Tool

__all__ = ["NO_LIBRARY_TOOL", "SESSION_FILENAME", "CalibrateView"]

NO_LIBRARY_TOOL = N_("(library empty)")
"""The library dropdown's only option while the library is empty (shown translated)."""
SESSION_FILENAME = "tcp-pendant-session.json"
RECORD_REFUSED = N_("Session record not loaded")
"""Title of the one notification a refused session record gets."""

log = logging.getLogger(__name__)

OptionWidget = viser.GuiSliderHandle[int] | viser.GuiDropdownHandle[str]
"""The menu widget of a start option: a slider for a number, a dropdown for the others."""

_E = TypeVar("_E")
"""The event an action's callback takes (viser's, of the widget it is attached to)."""


class CalibrateView:
    """The Calibrate tab of ``session`` (see the module docstring).

    Attributes:
        workflow: the session's wizards (``Session.workflow``; viser-free logic), rendered here.
        menu_*, steps, result, scene, record_*: the widgets and sub-views (for tests).
    """

    def __init__(self, session: Session, player: ScanPlayer) -> None:
        self.session = session
        self.workflow: CalibrationWorkflow = session.workflow
        self._menu_mounted_key: str | None = None
        self._library: dict[int, Tool] = {}
        self._library_pick: tuple[str, int | None] | None = None   # (option, active slot then)
        self._resume_runs: tuple[int, ...] = ()                    # the runs the Resume list offered
        gui = target_of(session).gui
        tools = self.workflow.tools
        self._physical = {t.label: key for key, t in tools.items()}
        self.words = GuiWords(session.translator)     # the fixed labels and hints, relabelled per language
        self._shown_in = session.translator           # the language the options on show are in
        keep = self.words.keep

        self.training = keep(gui.add_checkbox(
            N_("Training mode"), True,
            hint=N_("Reveals the true TOOL frame after a result, with the error against it, and offers Auto-touch.")))
        self._classes: dict[str, type[Wizard]] = {c.title: c for c in wizard_classes()}
        self.menu_folder = keep(gui.add_folder(N_("Calibrate")))
        with self.menu_folder:
            labels = self._method_labels(tuple(self._classes))
            self.method = keep(gui.add_dropdown(N_("Method"), labels, initial_value=labels[0]))
            self.method_md = gui.add_markdown("")
            self.option_widgets: dict[str, OptionWidget] = {}
            self._option_specs: dict[str, WizardOption] = {}
            for cls in self._classes.values():
                for opt in cls.options:
                    if opt.name not in self.option_widgets:
                        self._option_specs[opt.name] = opt
                        self.option_widgets[opt.name] = self._add_option_widget(gui, opt)
            self.menu_md = gui.add_markdown("")
            self.start = keep(gui.add_button(N_("Start"), color="green"))
            self.start_from_points = gui.add_button(
                "Start from the recorded points", color="blue", visible=False,
                hint=N_("XYZ 4-point from the touches of the Jog tab's Record point: they become its first steps."))
            self.resume_list = keep(gui.add_dropdown(N_("To resume"), ("-",), visible=False,
                                                     hint=N_("Calibrations you left: where, and when they started.")))
            self.resume = gui.add_button("Resume", color="blue", visible=False)
        widgets = self.option_widgets
        self._slot_widgets = [cast("viser.GuiDropdownHandle[str]", widgets[n])    # a library slot: a dropdown
                              for n, o in self._option_specs.items() if o.kind == "library_slot"]
        # the built-in methods' widgets by their old names (tests and views read them)
        self.n_points = widgets.get("n_points")
        self.estimator = widgets.get("estimator")
        self.library_tool = self._slot_widgets[0] if self._slot_widgets else None
        self.reference_physical = widgets.get("reference_tool_key")
        self.new_physical = widgets.get("new_tool_key")
        self.steps = WizardStepsView(self)
        self.result = WizardResultView(self)
        self.math = MathView(session)          # renders itself on the session's wizard signal
        self.record_folder = keep(gui.add_folder(N_("Session record"), expand_by_default=False))
        with self.record_folder:
            self.export = keep(gui.add_button(N_("Export session (JSON)"),
                                              hint=N_("Touches, calibrations, results and errors, for grading.")))
            self.load = keep(gui.add_upload_button(N_("Load session (JSON)"), mime_type="application/json"))
            self.record_md = gui.add_markdown("")
        self.scene = WizardSceneView(session, self.workflow, player)

        act = self.action
        self.training.on_update(act(self._on_training, user_only=True))
        for widget in self._slot_widgets:
            widget.on_update(act(self._on_library_pick, user_only=True))
        echoed = [self.method] + [self.option_widgets[n] for n, o in self._option_specs.items()
                                  if o.kind in ("choice", "physical_tool")]
        for choice in echoed:
            choice.on_update(act(lambda _e: None, user_only=True))       # re-render: echo the choice
        self.start.on_click(act(self._on_start, sync=True))
        self.start_from_points.on_click(act(self._on_start_from_points, sync=True))
        self.resume.on_click(act(self._on_resume))
        self.resume_list.on_update(act(lambda _e: None, user_only=True))   # the button names the pick
        self.export.on_click(act(self._on_export))
        self._loading_record = False
        self.load.on_upload(self._on_upload)
        limit_upload_size(self.load, MAX_RECORD_BYTES, self._upload_refused)
        session.subscribe(self.on_change)
        self.refresh_library()      # the session's list: no file read here (an unreadable file is told once)
        self.render()

    def _add_option_widget(self, gui: viser.GuiApi, opt: WizardOption) -> OptionWidget:
        """The menu widget of a declared start option (hidden until a method that takes it is
        chosen); its label and hint are the option's msgids (the wizard class's ``N_``)."""
        hint = opt.hint or None
        if opt.kind == "int":
            lo, hi = int(opt.minimum if opt.minimum is not None else 0), int(opt.maximum if opt.maximum is not None else 100)
            return self.words.keep(gui.add_slider(opt.label, min=lo, max=hi, step=1,
                                   initial_value=int(opt.default if opt.default is not None else lo), hint=hint))
        if opt.kind == "choice":
            labels = self._choice_labels(opt)
            initial = next((self.gettext(label) for v, label in opt.choices if v == opt.default), labels[0])
            return self.words.keep(gui.add_dropdown(opt.label, labels, initial_value=initial, hint=hint))
        if opt.kind == "library_slot":
            empty = self.gettext(NO_LIBRARY_TOOL)
            return self.words.keep(gui.add_dropdown(opt.label, (empty,), initial_value=empty, hint=hint))
        physical = self._physical_labels()
        mounted = shown_tool_label(self.session.controller.mounted_tool.label, self.session.translator)
        initial = mounted if mounted in physical else physical[0]
        if opt.default == "other":
            initial = next((p for p in physical if p != initial), physical[0])
        return self.words.keep(gui.add_dropdown(opt.label, physical, initial_value=initial, hint=hint))

    def gettext(self, message: str) -> str:
        """``message`` (an English msgid) in the session's language."""
        return self.session.translator.gettext(message)

    def _method_labels(self, titles: tuple[str, ...]) -> tuple[str, ...]:
        """The Method dropdown's options: the wizard classes' titles in the session's language."""
        return tuple(self.gettext(t) for t in titles)

    def _choice_labels(self, opt: WizardOption) -> tuple[str, ...]:
        return tuple(self.gettext(label) for _, label in opt.choices)

    def said_as(self, message: str) -> set[str]:
        """The ways an option ``message`` may come back from the browser: in the session's
        language, in the language the options were shown in (a click that crossed a switch) or
        in English."""
        return {message, self.gettext(message), self._shown_in.gettext(message)}

    def _option_value(self, opt: WizardOption) -> object:
        """The value of ``opt`` as chosen in its widget (checked by the wizard class at Start);
        a choice is read in any language it may come in (:meth:`said_as`)."""
        widget = self.option_widgets[opt.name]
        if opt.kind == "int":
            return int(widget.value)
        if opt.kind == "choice":
            choices = self._option_specs[opt.name].choices
            values = {said: v for v, label in choices for said in self.said_as(label)}
            if widget.value not in values:
                raise ValueError(self.gettext("{option}: unknown choice {value!r}.").format(
                    option=self.gettext(opt.label), value=widget.value))
            return values[widget.value]
        if opt.kind == "library_slot":
            return self._selected_slot(widget)
        key = self._physical_key(str(widget.value))
        if key is None:
            raise ValueError(self.gettext("{option}: unknown physical tool {value!r}.").format(
                option=self.gettext(opt.label), value=widget.value))
        return key

    def _physical_labels(self) -> tuple[str, ...]:
        """The physical tools' labels in the session's language (a physical-tool option's choices)."""
        return tuple(shown_tool_label(label, self.session.translator) for label in self._physical)

    def _physical_key(self, said: str) -> str | None:
        """The physical tool ``said`` names: in the session's language, the one the options on
        show are in, or English; None for none."""
        for tr in (self.session.translator, self._shown_in, ENGLISH):
            key = next((k for label, k in self._physical.items() if shown_tool_label(label, tr) == said), None)
            if key is not None:
                return key
        return None

    def _class_of(self, label: str) -> type[Wizard] | None:
        """The wizard class a Method option names (its title in the session's language or in
        English)."""
        return next((c for t, c in self._classes.items() if label in self.said_as(t)), None)

    def _chosen_class(self) -> type[Wizard]:
        return self._class_of(str(self.method.value)) or next(iter(self._classes.values()))

    def _is_empty_library(self, value: object) -> bool:
        return value in self.said_as(NO_LIBRARY_TOOL)

    def relabel(self) -> None:
        """A ``language`` change: the fixed labels and hints, the options of the Method and of
        the choices, then the whole tab in the new language."""
        self.words.relabel(self.session.translator)
        chosen = self._chosen_class()
        self.method.options = self._method_labels(tuple(self._classes))     # _render_menu narrows them
        set_value(self.method, self.gettext(chosen.title))
        for name, opt in self._option_specs.items():
            widget = self.option_widgets[name]
            if opt.kind == "choice":
                value = self._option_value(opt)
                labels = self._choice_labels(opt)
                set_options(cast("viser.GuiDropdownHandle[str]", widget), labels,
                            keep=next(self.gettext(lab) for v, lab in opt.choices if v == value))
            elif opt.kind == "physical_tool":
                key = self._physical_key(str(widget.value))
                label = next((lab for lab, k in self._physical.items() if k == key), None)
                set_options(cast("viser.GuiDropdownHandle[str]", widget), self._physical_labels(),
                            keep=None if label is None else shown_tool_label(label, self.session.translator))
        if not self._library:
            for widget in self._slot_widgets:
                set_options(widget, (self.gettext(NO_LIBRARY_TOOL),))
        hint = self.gettext("XYZ 4-point from the touches of the Jog tab's Record point: they become its first steps.")
        if self.start_from_points.hint != hint:
            self.start_from_points.hint = hint
        self._shown_in = self.session.translator
        self.result.relabel()
        self.steps.relabel()

    def on_change(self, change: SessionChange) -> None:
        """The change signal: the live parts after a move; the library list when it was
        re-read; the whole tab after a Calibrate click or a tool change (the open wizard is
        told which tool is mounted first); every text after a ``language`` change."""
        if change.language:
            self.relabel()
        if change.library:
            self.refresh_library(render=False)
        if change.pose:
            self.on_motion()
        if change.touches and not (change.wizard or change.tool or change.library):
            self._render_menu()                # "Start from the N recorded points"
        if change.wizard or change.tool or change.library or change.language:
            self.render()

    # ------------------------------------------------------------ plumbing
    def action(self, fn: Callable[[_E], object], *, user_only: bool = False,
               sync: bool = False) -> Callable[[_E], Coroutine[object, object, None]]:
        """Wrap a GUI callback: ``Session.on_loop`` (viser's event loop, session lock, error
        notifications), inside ``Session.batch``, ending in one change signal with ``wizard``
        (with ``sync`` also ``pose``: the click may have moved the robot, as auto-touch does).
        Tool and library changes the click made through the session's commands join that
        signal; every view re-renders on it.

        Args:
            fn: the callback, given the viser event.
            user_only: ignore events fired by our own assignments to a handle's value (viser
                fires on_update for those too, with ``event.client is None``), as for the
                dropdowns and checkboxes the views also set.
            sync: the callback may move the robot: Start, Mount, Auto-touch, Save.
        """
        s = self.session

        def run(event: _E) -> None:
            if user_only and getattr(event, "client", None) is None:
                return
            with s.batch():
                try:
                    fn(event)
                finally:
                    s.changed(wizard=True, pose=sync)

        run.__qualname__ = getattr(fn, "__qualname__", "action")
        return s.loop.on_loop(run)

    def saved(self, slot: int, tool: Tool) -> None:
        """After "Save to tool library" (the session made it the active tool)."""
        self.session.notify(self.gettext("Tool saved"), self.gettext("Slot {slot}: {name} is now the active tool.").format(
            slot=slot, name=tool.name), kind="success")

    # ------------------------------------------------------------ callbacks
    def _on_training(self, event: CheckboxEvent) -> None:
        self.session.wizard_commands.set_training(bool(event.target.value))

    def _on_library_pick(self, event: DropdownEvent) -> None:
        # the user's pick holds until the active tool data changes (then the default is offered)
        self._library_pick = (str(event.target.value), self.session.tools.active_slot)

    def _library_option(self, options: tuple[str, ...]) -> str | None:
        """The library option to show: the user's pick, else :func:`default_library_slot`."""
        pick = self._library_pick
        if pick is not None and pick[0] in options and pick[1] == self.session.tools.active_slot:
            return pick[0]
        c = self.session.controller
        slot = default_library_slot(self._library, active_slot=self.session.tools.active_slot,
                                    active_tool_name=None if c.active_tool is None else c.active_tool.name,
                                    mounted_label=c.mounted_tool.label, mounted_key=c.mounted_tool.key)
        return None if slot is None else slot_option(slot, self._library[slot].name)

    def _selected_slot(self, widget: OptionWidget | None = None) -> int:
        picked = widget or self.library_tool                     # None: the library is empty
        slot = None if picked is None else number_of_option(str(picked.value))
        if slot is None:
            raise ValueError(self.gettext("The tool library is empty: calibrate the TCP first (XYZ 4-point) and save it."))
        return slot

    def _on_start(self, _event: ButtonEvent) -> None:
        if self._class_of(str(self.method.value)) is None:
            raise ValueError(self.gettext("Unknown calibration method {value!r}.").format(value=self.method.value))
        cls = self._chosen_class()
        self.session.wizard_commands.start(cls.kind, **{opt.name: self._option_value(opt) for opt in cls.options})

    def _on_start_from_points(self, _event: ButtonEvent) -> None:
        """XYZ 4-point from the free touches (``CalibrationWorkflow.start_from_touches``)."""
        cls = self._chosen_class()
        if cls.kind != "xyz4":
            raise ValueError(self.gettext("Only the XYZ 4-point method starts from the recorded points; choose it first."))
        spec = self._option_specs.get("estimator")
        estimator = "lstsq" if spec is None else str(self._option_value(spec))
        self.session.wizard_commands.start_from_touches(estimator=estimator)

    def _on_resume(self, _event: ButtonEvent) -> None:
        number = number_of_option(self.resume_list.value)
        if number is None:
            raise ValueError(self.gettext("There is no calibration to resume."))
        if number - 1 not in {i for i, _ in self.workflow.resumable()}:
            raise ValueError(self.gettext("Calibration {number} is not waiting to be resumed any more; choose one in "
                                     "'To resume'.").format(number=number))
        self.session.wizard_commands.resume(number - 1)

    def _on_export(self, event: ButtonEvent) -> None:
        data = dumps(self.workflow.export_record(self.session.touches)).encode("utf-8")
        # to the browser that clicked (in --shared mode the session is every browser's)
        target = getattr(event, "client", None) or client_of(self.session) or target_of(self.session)
        target.send_file_download(SESSION_FILENAME, data, save_immediately=True)
        n = len(self.workflow.runs)
        set_content(self.record_md, self.session.translator.ngettext(
            "Exported {n} calibration as {file}.", "Exported {n} calibrations as {file}.", n).format(
                n=n, file=SESSION_FILENAME))

    async def _on_upload(self, event: UploadEvent) -> None:
        """"Load session (JSON)": the size is checked at once, parsing and replay run in
        the server's job pool (``SessionLoop.run_job``, off viser's event loop: the other browsers
        keep jogging; each record is bounded by the record limits), then the
        wizards are added under the session lock. A refused record gets one notification
        (:data:`RECORD_REFUSED`) saying what is wrong; nothing of the session changes."""
        session = self.session
        if session.closed or getattr(event, "client", None) is None:
            return
        upload = event.target.value
        name = str(upload.name or self.gettext("The file"))
        content = upload.content
        if self._loading_record:
            session.notify(self.gettext(RECORD_REFUSED), self.gettext(
                "{file}: another session record is still being loaded here; wait until it is shown, then "
                "load this one.").format(file=name), kind="warning")
            return
        try:
            check_record_size(len(content))
        except SessionRecordError as exc:
            self._refuse_record(name, exc)
            return
        self._loading_record = True
        try:
            with session.lock:
                set_content(self.record_md, self.gettext("Loading {file} ...").format(file=escape_markdown(name)))
            data = bytes(content)
            loaded = await session.loop.run_job(lambda: load_and_replay(data), what="a session record's load")
        except (SessionRecordError, JobRefused) as exc:
            self._refuse_record(name, exc)
            return
        except Exception as exc:  # never let an upload kill the server
            log.exception("loading the session record %r failed", name)
            session.notify(self.gettext("Internal error"), f"{type(exc).__name__}: {exc}", kind="error")
            return
        finally:
            self._loading_record = False
        await self.action(lambda _e: self._show_loaded(str(upload.name or "session"), loaded))(event)

    def _show_loaded(self, name: str, loaded: LoadedRecord) -> None:
        checks = self.session.wizard_commands.load_record(loaded)
        set_content(self.record_md, self.gettext("**Loaded {file}**").format(file=escape_markdown(name)) + "\n\n"
                    + replay_markdown(checks, tr=self.session.translator))

    def _refuse_record(self, name: str, exc: Exception) -> None:
        if not self.session.closed:
            with self.session.lock:
                set_content(self.record_md, "")
            self.session.notify(self.gettext(RECORD_REFUSED), f"{name}: {error_text(exc, self.session.translator)}",
                                kind="warning")

    def _upload_refused(self, filename: str, size_bytes: int) -> None:
        """``upload_guard``: a transfer above the size limit was dropped as it started."""
        try:
            check_record_size(size_bytes)
        except SessionRecordError as exc:
            self._refuse_record(filename or self.gettext("The file"), exc)

    # ------------------------------------------------------------ library and motion
    def refresh_library(self, *, render: bool = True) -> None:
        """Re-list the library's tools as the session last read them (``SessionTools.library_tools``;
        the file is not read here). Called on the session's ``library`` change."""
        tools = self.session.tools.library_tools
        self._library = dict(tools)
        options = tuple(slot_option(s, t.name) for s, t in sorted(tools.items())) or (self.gettext(NO_LIBRARY_TOOL),)
        for widget in self._slot_widgets:
            set_options(widget, options, keep=self._library_option(options))
        self.result.refresh_slots(tools)
        if render:
            self._render_menu()

    def on_motion(self) -> None:
        """After every move of the robot (and a tool change on the Tool tab): the live parts only
        (meter, triads, ABC target), and the menu when the mounted tool changed. Returns at once
        when no wizard is on show: this runs on every jog step of every session."""
        if self.session.closed:
            return
        if self.session.controller.mounted_tool.key != self._menu_mounted_key:
            self._render_menu()
        if self.workflow.wizard is None or not (self.workflow.is_open or self.scene.showing):
            return
        self.steps.update_meter()
        self.scene.on_motion()

    # ------------------------------------------------------------ render
    def render(self) -> None:
        """Re-render the whole tab from the workflow's state."""
        if self.session.closed:
            return
        self._render_menu()
        self.steps.render()
        self.result.render()
        self.scene.render()

    def _render_menu(self) -> None:
        self._menu_mounted_key = self.session.controller.mounted_tool.key
        rules = self.session.rules                # an exercise may offer some methods only
        offered = tuple(t for t, c in self._classes.items() if rules.allows_method(c.kind)) or tuple(self._classes)
        set_options(self.method, self._method_labels(offered))
        cls = self._chosen_class()
        set_content(self.method_md, self.gettext(cls.blurb))
        taken = {o.name for o in cls.options}
        for name, widget in self.option_widgets.items():
            widget.visible = name in taken
        library_widget = next((self.option_widgets[o.name] for o in cls.options if o.kind == "library_slot"), None)
        needs_tool = library_widget is not None
        for widget in self._slot_widgets:
            wanted = self._library_option(tuple(widget.options))
            if wanted is not None and widget.value != wanted and wanted in widget.options:
                set_value(widget, wanted)
        empty = library_widget is None or self._is_empty_library(library_widget.value)
        physical = [self.option_widgets[o.name].value for o in cls.options if o.kind == "physical_tool"]
        mounted = shown_tool_label(self.session.controller.mounted_tool.label, self.session.translator)
        set_content(self.menu_md, menu_markdown(
            cls.kind, library_tool=None if empty else str(library_widget.value),   # type: ignore[union-attr]
            reference_tool=str(physical[0]) if physical else mounted,
            new_tool=str(physical[1]) if len(physical) > 1 else mounted,
            mounted_tool=mounted, tr=self.session.translator))
        self.start.disabled = needs_tool and empty
        n_points = len(self.session.touches)
        self.start_from_points.visible = cls.kind == "xyz4" and n_points >= 1
        label = self.session.translator.ngettext("Start from the {n} recorded point", "Start from the {n} recorded points",
                                                 n_points).format(n=n_points)
        if n_points and self.start_from_points.label != label:
            self.start_from_points.label = label
        self.menu_folder.visible = not self.workflow.is_open     # a pendant shows the wizard alone
        waiting = self.workflow.resumable()
        self.resume_list.visible = self.resume.visible = bool(waiting)
        if waiting:
            runs = tuple(i for i, _ in waiting)
            picked = number_of_option(self.resume_list.value)
            # the user's pick (by run number) holds until another run is left: then the newest
            keep = next((label for i, label in waiting if i + 1 == picked), None) \
                if set(runs) <= set(self._resume_runs) else None
            self._resume_runs = runs
            set_options(self.resume_list, tuple(label for _, label in waiting), keep=keep or waiting[0][1])
            number = number_of_option(self.resume_list.value)
            chosen = next((label for i, label in waiting if number == i + 1), waiting[0][1])
            # names what the click brings back (the list's label without its last part, the start time)
            label = self.gettext("Resume {calibration}").format(calibration=chosen.rsplit(", ", 1)[0])
            if self.resume.label != label:
                self.resume.label = label
