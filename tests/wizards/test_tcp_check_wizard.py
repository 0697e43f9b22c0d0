"""The TCP check (spin test) wizard's state machine without a controller: what
it declares to the registry, that Finish needs the check of the touch as recorded, that nothing
can be saved, that the record round trip keeps the check, that a stored check is checked, and
that the tool's name reaches the markdown only escaped."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from tcp_pendant.wizards import TcpCheckResult, TcpCheckWizard, Wizard, WizardError, WizardStateError
from tcp_pendant.wizards.registry import wizard_class, wizard_classes
from tcp_pendant.wizards.tcp_check import GOOD_CHECK_MM, CheckFigures, tcp_check_markdown
from tcpcal.tool import Tool

POSE = np.eye(4)
POSE[:3, 3] = (0.6, 0.1, 0.4)


def spin(devs=(0.1, 0.2, 0.3, 0.4, 0.5, 0.6), err=0.8, off=(0.8, 0.0, 0.0), reached=True):
    """A stand-in of ``controller.spin.SpinCheckResult`` (only what the wizard reads)."""
    labels = ["+A 30°", "-A 30°", "+B 30°", "-B 30°", "+C 30°", "-C 30°"]
    rows = [SimpleNamespace(label=lab, reached=reached or i > 1, message="" if reached or i > 1 else "joint limit",
                            stopped_by=None, deviation_mm=d) for i, (lab, d) in enumerate(zip(labels, devs))]
    return SimpleNamespace(angle_deg=30.0, rotations=rows, implied_tcp_error_mm=err,
                           implied_offset_flange_mm=None if off is None else np.array(off), fit_rms_mm=0.01)


def wizard(name: str = "Torch") -> TcpCheckWizard:
    return TcpCheckWizard(Tool(name=name, tcp_mm=(1.0, 2.0, 300.0)), slot=3, angle_deg=30)


def test_it_declares_a_library_check_with_a_touch_step() -> None:
    cls = wizard_class("tcp-check")
    assert cls is TcpCheckWizard and cls.title == "TCP check (spin test)" and cls in wizard_classes()
    assert cls.needs_tool == "library" and cls.saves_to_library is False
    assert [r.name for r in cls.step_roles] == ["touch"]
    assert cls.parse_options({"slot": 2}) == {"slot": 2, "angle_deg": 30}
    for bad in (0, 91, 12.5):
        with pytest.raises(WizardError, match="Check angle"):
            cls.parse_options({"slot": 2, "angle_deg": bad})
    with pytest.raises(WizardError, match="Tool data"):
        cls.parse_options({})


def test_finish_needs_the_check_of_the_touch_as_recorded() -> None:
    wiz = wizard()
    with pytest.raises(WizardStateError, match="Record"):
        wiz.give_check(spin())
    wiz.record(POSE)
    assert wiz.check_pending and wiz.check is None
    with pytest.raises(WizardStateError, match="Run the check first"):
        wiz.next()
    old = wiz.recorded_pose
    wiz.record(POSE)                                      # recorded again: the old check is stale
    with pytest.raises(WizardStateError, match="recorded again"):
        wiz.give_check(spin(), old)
    wiz.give_check(spin(), wiz.recorded_pose)
    assert not wiz.check_pending
    res = wiz.next()
    assert isinstance(res, TcpCheckResult) and wiz.is_complete
    assert res.tcp_mm == (1.0, 2.0, 300.0) and res.abc_deg is None          # the data is unchanged
    assert res.check.implied_tcp_error_mm == 0.8 and res.check.max_deviation_mm == 0.6
    assert res.per_touch_error_mm == (0.1, 0.2, 0.3, 0.4, 0.5, 0.6)
    wiz.back()
    wiz.record(POSE)                                      # a new touch needs a new check
    assert wiz.check_pending and wiz.check is None


def test_a_check_saves_nothing() -> None:
    wiz = wizard()
    wiz.record(POSE)
    wiz.give_check(spin())
    wiz.next()
    with pytest.raises(WizardStateError, match="saves nothing"):
        wiz.to_tool("x")


def test_verdicts() -> None:
    assert "TCP good" in CheckFigures.of(spin(err=GOOD_CHECK_MM)).verdict
    assert "off by 0.501" in CheckFigures.of(spin(err=0.501)).verdict
    undetermined = CheckFigures.of(spin(err=None, off=None, reached=False))
    assert "Not determined" in undetermined.verdict and undetermined.max_deviation_mm == 0.6


def test_the_record_round_trip_keeps_the_check_and_a_bad_one_is_refused() -> None:
    wiz = wizard()
    wiz.record(POSE)
    wiz.give_check(spin(reached=False))
    wiz.next()
    d = wiz.to_dict()
    again = Wizard.from_dict(d)
    assert isinstance(again, TcpCheckWizard) and again.is_complete
    assert again.result.check == wiz.result.check and again.slot == 3
    assert "+A 30° not reached: joint limit" in again.result.warnings
    unfinished = wizard()
    unfinished.record(POSE)
    back = Wizard.from_dict(unfinished.to_dict())
    assert back.check_pending and back.status == "in_progress"
    for field, value, words in (("deviation_mm", math.inf, "finite"), ("deviation_mm", "x", "number"),
                                ("deviation_mm", True, "number")):
        bad = wiz.to_dict()
        bad["params"]["check"]["rows"][0][field] = value
        with pytest.raises(WizardError, match=words):
            Wizard.from_dict(bad)
    bad = wiz.to_dict()
    bad["params"]["check"]["rows"] *= 2
    with pytest.raises(WizardError, match="at most 6"):
        Wizard.from_dict(bad)
    bad = wiz.to_dict()
    bad["params"]["check"]["rows"][0]["message"] = "m" * 5000
    assert len(Wizard.from_dict(bad).result.check.rows[0].message) == 200


def test_the_markdown_shows_six_rows_the_error_the_correction_and_escapes_the_name() -> None:
    wiz = wizard(name="<b>Torch</b> | *x*")
    wiz.record(POSE)
    wiz.give_check(spin())
    text = tcp_check_markdown(wiz.next())
    assert "<b>" not in text and "\\*x\\*" in text
    assert sum(1 for line in text.splitlines() if line.startswith("| ") and "30°" in line) == 6
    assert "Implied TCP error: 0.800 mm" in text and "X +0.800 · Y +0.000 · Z +0.000 mm" in text
    assert "off by 0.800" in text
    good = wizard()
    good.record(POSE)
    good.give_check(spin(err=0.2))
    assert "TCP good" in tcp_check_markdown(good.next()) and good.result.notes == ()
    assert wiz.result.notes and "changes no tool data" in wiz.result.notes[0]


def test_in_an_exercise_the_check_is_a_technicians_reading_without_the_answer() -> None:
    """What a technician sees: per rotation how far the tip moved, read to 0.5 mm; no implied
    error, no correction, no fit RMS - in the text and in the record alike."""
    from tcp_pendant.wizards.check_reading import CHECK_READING_MM

    figures = CheckFigures.of(spin(devs=(0.12, 0.26, 0.74, 0.76, 1.3, 0.0), err=0.8, off=(0.3, -0.6, 0.4)))
    reading = figures.as_reading()
    assert [r.deviation_mm for r in reading.rows] == [0.0, 0.5, 0.5, 1.0, 1.5, 0.0]
    assert reading.implied_tcp_error_mm is None and reading.correction_flange_mm is None
    assert reading.fit_rms_mm is None and reading.read_to_mm == CHECK_READING_MM
    assert "swung up to 1.5 mm" in reading.verdict and "calibrate" in reading.verdict
    assert "looks good" in CheckFigures.of(spin(devs=(0.1, 0.2, 0.0, 0.24, 0.1, 0.0))).as_reading().verdict
    wiz = wizard()
    wiz.record(POSE)
    wiz.give_check(reading)
    res = wiz.next()
    text = tcp_check_markdown(res)
    assert "Implied TCP error" not in text and "suggested correction" not in text and "+0.300" not in text
    assert "| \\+C 30° | 1.5 |" in text and "by eye" in text and "no TCP error, no correction" in text
    assert res.notes == () and res.per_touch_error_mm == (0.0, 0.5, 0.5, 1.0, 1.5, 0.0)
    stored = wiz.to_dict()["params"]["check"]
    assert stored["correction_flange_mm"] is None and stored["read_to_mm"] == CHECK_READING_MM
    again = Wizard.from_dict(wiz.to_dict())
    assert again.result.check == reading
    forged = wiz.to_dict()                                   # a reading that claims a correction
    forged["params"]["check"]["correction_flange_mm"] = [1.0, 2.0, 3.0]
    forged["params"]["check"]["implied_tcp_error_mm"] = 3.7
    assert Wizard.from_dict(forged).result.check.correction_flange_mm is None
