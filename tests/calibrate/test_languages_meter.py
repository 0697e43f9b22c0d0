"""The diversity meter's words, the tilt hint and the exercise's refusals in the reader's language
(issue 47): with the pseudo-locale every word is from the catalogs (names of axes, frames, keys
and units aside), in English they are what they were."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from support.calib_helpers import make_controller
from support.pseudo_text import untranslated_words

from tcp_pendant.calibrate.diversity import diversity_advice, failure_in_words
from tcp_pendant.calibrate.pendant_rules import (
    DISTANCE_LOCKED,
    ExerciseRules,
    LibraryRights,
    RuleRefusal,
    check_calibrated_tool,
    check_tool_change,
)
from tcp_pendant.calibrate.tilt_advice import MeterGain, TiltAdvisor
from tcp_pendant.controller.words import Words, error_text
from tcp_pendant.pendant.jogging import Jogger
from tcp_pendant.translation import PSEUDO_LANGUAGE, translator
from tcpcal.library import OwnerQuotaError, SlotOwnedError, ToolLibraryError
from tcpcal.pose_quality import candidate_gain

QPS = translator(PSEUDO_LANGUAGE)
NAMES = {"X", "Y", "Z", "A", "B", "C", "WORLD", "TOOL", "BASE", "FLANGE", "TCP", "mm", "deg", "Shift", "A5",
         "XYZ"}
R_DOWN = Rotation.from_euler("x", 180, degrees=True).as_matrix()


def tilt(axis: str, deg: float) -> np.ndarray:
    return R_DOWN @ Rotation.from_euler(axis, deg, degrees=True).as_matrix()


@pytest.mark.parametrize("recorded, candidate", [
    ([], R_DOWN),                                            # before the first touch
    ([R_DOWN], tilt("y", 50)),                               # one touch, far enough
    ([R_DOWN], tilt("y", 10)),                               # one touch, too near
    ([R_DOWN, tilt("y", 40)], tilt("y", -20)),               # one horizontal axis: the missing one
    ([R_DOWN, tilt("y", 40)], tilt("x", 35)),                # ... and this one adds it
    ([R_DOWN, tilt("z", 90)], tilt("z", 45)),                # only about the tool's own length
    ([R_DOWN, tilt("x", 45)], tilt("x", -45)),
    ([R_DOWN, tilt("y", 40), tilt("x", 40)], tilt("x", 40)),  # two axes: one more
])
def test_every_state_of_the_diversity_meter_in_the_pseudo_locale(recorded: list[np.ndarray],
                                                                  candidate: np.ndarray) -> None:
    rots = np.array(recorded).reshape(-1, 3, 3)
    angle = candidate_gain(rots, candidate, sigma=0.5).angle_to_nearest_deg if len(recorded) else math.inf
    english = diversity_advice(rots, candidate, angle)
    said = diversity_advice(rots, candidate, angle, tr=QPS)
    assert said != english and untranslated_words(said, NAMES) == [], said


def test_the_failure_in_words_wraps_tcpcals_sentence_in_the_readers_language() -> None:
    msg = "all touches rotate about nearly the same axis (flange [0.00, 1.00, 0.00]), so the TCP cannot"
    said = failure_in_words(msg, (0, 1, 0), R_DOWN, tr=QPS)
    tcpcal = "All touches rotate about nearly the same axis, so the TCP cannot."     # the solver's: English
    assert said.startswith(f"⟦{tcpcal} ")
    assert untranslated_words(said, NAMES | set(tcpcal.rstrip(".").replace(",", "").split())) == [], said


def test_the_tilt_hint_and_the_meters_basis_in_the_pseudo_locale() -> None:
    c = make_controller("kr6")
    R_wf = c.T_world_flange()[:3, :3]
    for mode in ("Cartesian", "Joint"):
        j = Jogger(c)
        j.settings = j.settings.with_(mode=mode)
        english = TiltAdvisor().advise(R_wf[None], R_wf, j, 0.5)
        said = TiltAdvisor().advise(R_wf[None], R_wf, j, 0.5, tr=QPS)
        assert english is not None and said is not None and english.option is not None
        assert english.text.startswith("Tilt next: ") and said.text != english.text
        assert untranslated_words(said.text, NAMES | {"TOOL"}) == [], said.text
    gain = candidate_gain(R_wf[None], R_wf, sigma=0.5)
    for measured, source in ((False, ""), (True, "your touches"), (True, "your last calibration")):
        m = MeterGain(gain, 0.21, measured, source)
        assert m.basis == m.basis_words() and untranslated_words(m.basis_words(QPS), NAMES) == []
    assert MeterGain(gain, 0.21, True, "your touches").basis == "your touches scatter 0.21 mm"


def test_the_exercises_refusals_are_english_as_before_and_said_in_the_readers_language() -> None:
    refusals: list[BaseException] = []
    for check in (lambda: check_tool_change("pointer", "Straight pointer", "torch", "Welding torch"),
                  lambda: check_calibrated_tool("pointer", "Straight pointer", "torch", "XYZ 4-point"),
                  lambda: ExerciseRules(distance_locked=True).check_hide_distance(False),
                  lambda: ExerciseRules(auto_touch_allowed=False).check_auto_touch()):
        with pytest.raises(RuleRefusal) as caught:
            check()
        refusals.append(caught.value)
    assert str(refusals[0]).startswith("This exercise keeps your own tool mounted (the straight pointer): ")
    assert str(refusals[2]) == DISTANCE_LOCKED
    for exc in refusals:
        said = error_text(exc, QPS)
        assert said != str(exc) and untranslated_words(
            said, NAMES | {"straight", "pointer", "welding", "torch", "Welding", "Straight"}) == [], said
    rules = ExerciseRules(min_touches=6)
    english = rules.touches_refusal(4, can_add_point=True)
    assert english == "This exercise asks for at least 6 touches: record 2 more (press Add point for another touch step)."
    assert isinstance(english, Words) and untranslated_words(english.text(QPS), NAMES) == []
    rights = LibraryRights(restricted=True, owner="ana", quota=2)
    for exc in (SlotOwnedError("owned", slot=3, owner="ben"), SlotOwnedError("owned", slot=3, owner=None),
                OwnerQuotaError("quota", owned=(1,), quota=1), OwnerQuotaError("quota", owned=(1, 4), quota=2)):
        with pytest.raises(ToolLibraryError) as caught, rights.in_words():
            raise exc
        said = error_text(caught.value, QPS)
        assert untranslated_words(said, NAMES) == [], said
    with pytest.raises(ToolLibraryError) as caught:
        LibraryRights(restricted=True).owner_kwargs()
    assert untranslated_words(error_text(caught.value, QPS), NAMES) == []
