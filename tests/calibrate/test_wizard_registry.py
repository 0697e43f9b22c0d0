"""Wizards that describe themselves: a toy calibration method, declared and
registered here in the test and nowhere else, is offered by the Calibrate menu with its own
option, starts, is performed by auto-touch, recorded and replayed from a session record: no
other change to the app. Plus the registry's own checks of what a wizard declares."""

from __future__ import annotations

import json
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np
import pytest
from tcp_pendant.calibrate import JOBS, AutoTouchRequest, CalibrationWorkflow
from tcp_pendant.wizards import (
    StepSpec,
    Wizard,
    WizardError,
    WizardResult,
    register,
    unregister,
    wizard_class,
    wizard_classes,
)
from tcp_pendant.wizards.describe import TOUCH, StartContext, StepRole, WizardOption, WizardStart
from tcp_pendant.wizards.session_record import dumps

from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

from support.calib_helpers import make_controller
from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until


class ToyTapWizard(Wizard):
    """A toy method: tap the reference tip 1-3 times; the "TCP" is (0, 0, mean flange z in mm)."""

    kind = "toy-tap"
    title = "Toy tap"
    blurb = "Calibrates a **toy** TCP: tap the reference tip a few times."
    calibrates = "a toy TCP"
    rank = 90
    step_roles = (StepRole("tap", "the tool tip on the reference tip", TOUCH),)
    options = (WizardOption("n_taps", "Taps", "int", default=2, minimum=1, maximum=3),
               WizardOption("flavour", "Flavour", "choice", default="plain",
                            choices=(("plain", "plain taps"), ("double", "double taps"))))

    def __init__(self, n_taps: int = 2, flavour: str = "plain") -> None:
        super().__init__()
        self.n_taps, self.flavour = int(n_taps), flavour

    @classmethod
    def start(cls, ctx: StartContext, options: Mapping[str, Any]) -> WizardStart:
        return WizardStart(cls(options["n_taps"], options["flavour"]), true_tool=ctx.mounted_tool)

    def _step_specs(self) -> list[StepSpec]:
        return [StepSpec("tap", f"Tap {i + 1}", "Touch the reference tip; then press Record.")
                for i in range(self.n_taps)]

    def _compute(self, poses: list[np.ndarray]) -> WizardResult:
        z_mm = float(np.mean([T[2, 3] for T in poses])) * 1000.0
        return WizardResult(wizard=self.kind, method=f"toy-{self.flavour}", tcp_mm=(0.0, 0.0, z_mm))

    def to_tool(self, name: str) -> Tool:
        res = self._require_result()
        return Tool(name=name, tcp_mm=res.tcp_mm, calibration=self._calibration(res, res.figures))

    def _params(self) -> dict[str, Any]:
        return {"n_taps": self.n_taps, "flavour": self.flavour}

    @classmethod
    def _from_params(cls, params: Mapping[str, Any]) -> "ToyTapWizard":
        return cls(int(params["n_taps"]), str(params["flavour"]))


@pytest.fixture
def toy() -> Iterator[type[ToyTapWizard]]:
    register(ToyTapWizard)
    try:
        yield ToyTapWizard
    finally:
        unregister(ToyTapWizard.kind)


def test_a_registered_kind_is_offered_started_performed_recorded_and_replayed(toy, app_factory, tmp_path) -> None:
    app = app_factory(tool="pointer")
    ws = DrainingClient(app.port)
    try:
        wait_until(lambda: len(app.sessions) == 1, what="session built")
        session = next(iter(app.sessions.values()))
        v = session.views["calibrate"]
        client = session.client
        assert "Toy tap" in v.method.options                       # offered by the menu
        taps, flavour = v.option_widgets["n_taps"], v.option_widgets["flavour"]
        assert not taps.visible and not flavour.visible            # XYZ 4-point is chosen
        choose(v.method, "Toy tap", client)
        assert taps.visible and flavour.visible and not v.n_points.visible and not v.library_tool.visible
        assert v.method_md.content == toy.blurb
        assert "Calibrates a toy TCP of the **straight pointer**" in v.menu_md.content
        choose(taps, 3, client)
        choose(flavour, "double taps", client)
        click(v.start, client)                                      # startable
        wiz = v.workflow.wizard
        assert isinstance(wiz, ToyTapWizard) and (wiz.n_taps, wiz.flavour) == (3, "double")
        assert v.steps.folder.visible and "Tap 1" in v.steps.steps_md.content
        assert not v.steps.variant.visible and not v.steps.add_point.visible
        assert not v.steps.meter_bar.visible
        for _ in range(3):
            click(v.steps.auto_touch, client)                       # its role's auto-touch: a touch
            tip = np.asarray(session.controller.reference_tip_world_m)
            assert np.linalg.norm(session.controller.T_world_tool_true()[:3, 3] - tip) < 1e-9
        res = v.workflow.result
        assert res is not None and res.method == "toy-double" and v.result.folder.visible
        record = json.loads(dumps(v.workflow.export_record()))   # recordable ...
        assert record["wizards"][0]["state"]["kind"] == "toy-tap"
    finally:
        ws.close()
    other = CalibrationWorkflow(make_controller(), ToolLibrary(tmp_path / "other.json"), robot="kr6")
    checks = other.load_record(json.dumps(record))                  # ... and replayable
    assert [c.matches for c in checks] == [True] and isinstance(other.wizard, ToyTapWizard)
    assert other.result.tcp_mm == pytest.approx(res.tcp_mm, abs=1e-12)


def test_the_menu_lists_the_registry_in_rank_order(toy) -> None:
    kinds = [c.kind for c in wizard_classes()]
    assert kinds[-1] == "toy-tap" and wizard_class("toy-tap").title == "Toy tap"
    assert wizard_class("toy-tap").blurb == toy.blurb
    unregister("toy-tap")
    assert [c.kind for c in wizard_classes()] == ["xyz4", "reference", "tcp-zx", "three-point", "abc-world",
                                                  "beam", "tcp-check"]


def test_each_class_declares_its_controller_job_and_result_view() -> None:
    """Only the methods the controller runs name a job, and each name has its job; how a result
    is shown and what its panel offers are declared, not found by class."""
    declared = {c.kind: (c.controller_job, c.result_view, c.result_extras) for c in wizard_classes()}
    assert declared["tcp-check"][:2] == ("spin_check", "spin_check")
    assert declared["beam"][:2] == ("beam_scan", "beam_scan")
    assert declared["xyz4"] == (None, "touches", frozenset({"estimators", "sphere"}))
    for kind in ("reference", "tcp-zx", "three-point", "abc-world"):
        assert declared[kind] == (None, "touches", frozenset()), kind
    assert {job for job, _, _ in declared.values() if job is not None} == set(JOBS)


def test_start_options_are_checked_against_the_declaration(toy, library) -> None:
    wf = CalibrationWorkflow(make_controller(), library, robot="kr6")
    with pytest.raises(WizardError, match=r"Taps: 4 is out of range 1\.\.3"):
        wf.start("toy-tap", n_taps=4)
    with pytest.raises(WizardError, match=r"Flavour: 'sour' is not one of \['plain', 'double'\]"):
        wf.start("toy-tap", flavour="sour")
    with pytest.raises(WizardError, match=r"takes no option colour; it takes flavour, n_taps"):
        wf.start("toy-tap", colour="red")
    wiz = wf.start("toy-tap")                                      # the declared defaults
    assert (wiz.n_taps, wiz.flavour) == (2, "plain")
    out = wf.auto_touch(AutoTouchRequest())
    assert out.ok and out.role == "tap"


def test_the_registry_refuses_what_a_wizard_does_not_declare_properly(toy) -> None:
    with pytest.raises(WizardError, match="registered already"):
        register(type("Other", (ToyTapWizard,), {}))               # the same kind again
    with pytest.raises(WizardError, match="title and a blurb"):
        register(type("NoBlurb", (ToyTapWizard,), {"kind": "no-blurb", "blurb": ""}))
    with pytest.raises(WizardError, match="each option once"):
        register(type("Twice", (ToyTapWizard,), {"kind": "twice", "options": toy.options * 2}))
    with pytest.raises(WizardError, match="lower-case word"):
        register(type("Bad", (ToyTapWizard,), {"kind": "Bad Kind"}))
    with pytest.raises(WizardError, match="declares no step role 'touch'"):
        toy.step_role("touch")
    assert wizard_class("toy-tap") is toy
    with pytest.raises(WizardError, match="Unknown calibration method 'no-such'"):
        wizard_class("no-such")
