"""The jog's stop messages, the tilt hints and the server's refusals in the reader's language
(issue 47): the controller returns :class:`~tcp_pendant.controller.words.Words` (English text
that a view says again in its session's language); with the pseudo-locale every word of them is
from the catalogs, in English they are what they were."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from support.calib_helpers import make_controller, make_session
from support.pseudo_text import untranslated_words

from tcp_pendant.controller.jog import singularity_message
from tcp_pendant.controller.words import Words, error_text, in_language
from tcp_pendant.job_pool import JobRefused, OverShare, PoolFull, SessionBusy
from tcp_pendant.pendant.guidance import offset_markdown
from tcp_pendant.pendant.jogging import Jogger
from tcp_pendant.pendant.tilts import TiltOptions, reachable_line, stopped_advice
from tcp_pendant.pendant.touch_feedback import touch_feedback
from tcp_pendant.refusal_notices import RefusalNotices
from tcp_pendant.translation import ENGLISH, PSEUDO_LANGUAGE, translator

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

QPS = translator(PSEUDO_LANGUAGE)
NAMES = {"A1", "A2", "A3", "A4", "A5", "A6", "X", "Y", "Z", "A", "B", "C", "WORLD", "TOOL", "TCP", "mm", "deg",
         "Shift"}
"""Joint, axis, frame and key names and units: the same in every language."""


def test_a_joint_limit_stop_is_english_as_before_and_pseudo_translated_with_its_way_back() -> None:
    c = make_controller("kr6")
    j = Jogger(c)
    j.settings = j.settings.with_(mode="Joint", increment="100")
    res = None
    for _ in range(5):
        res = j.key(4, 1)                                 # A5 + until its limit
        if res is not None and res.stopped_by == "joint_limit":
            break
    assert res is not None and res.stopped_by == "joint_limit"
    assert isinstance(res.message, Words)
    assert res.message == "A5 at its limit +120.0 deg. The other key of that row (Shift+5) turns it back."
    assert in_language(res.message) == res.message
    said = in_language(res.message, QPS)
    assert said != res.message and "+120.0" in said and "Shift+5" in said
    assert untranslated_words(said, NAMES) == [], said
    back = j.key(4, -1)
    assert back is not None and back.ok
    j.settings = j.settings.with_(mode="Joint", increment="100")
    res = None
    for _ in range(5):
        res = j.key(4, -1)
        if res is not None and res.stopped_by == "joint_limit":
            break
    assert res is not None and "(key 5)" in res.message
    assert untranslated_words(in_language(res.message, QPS), NAMES) == []


def test_a_rotation_stopped_at_a_limit_and_its_advice_in_the_pseudo_locale() -> None:
    c = make_controller("kr6")
    j = Jogger(c)
    j.settings = j.settings.with_(increment="100")
    res = j.key("B", 1)                                   # 100 deg about WORLD Y: A5 runs into its limit
    assert res is not None and not res.ok and isinstance(res.message, Words)
    assert res.message.startswith("A5 at its limit +120.0 deg. ")
    said = in_language(res.message, QPS)
    assert untranslated_words(said, NAMES) == [], said
    advice = stopped_advice(TiltOptions(c).options("WORLD"), "B", 1)
    assert untranslated_words(advice.text(QPS), NAMES) == []


def test_the_singularity_names_and_the_tilt_line_in_the_pseudo_locale() -> None:
    c = make_controller("kr6")
    q = c.q_rad.copy()
    q[4] = 0.0                                            # A5 = 0: the wrist singularity
    msg = singularity_message(c.kinematics, q)
    assert isinstance(msg, Words) and msg.startswith("A5 near 0.0 deg: wrist singularity (A4 and A6 aligned)")
    assert untranslated_words(msg.text(QPS), NAMES) == [], msg.text(QPS)
    opts = TiltOptions(c).options("WORLD")
    english = reachable_line(opts, frame="WORLD", joint_mode=True)
    assert english == reachable_line(opts, frame="WORLD", joint_mode=True, tr=ENGLISH)
    assert "B + (A5 limit)" in english and english.endswith(" (Set Mode to Cartesian: the keys are joints now.)")
    said = reachable_line(opts, frame="WORLD", joint_mode=True, tr=QPS)
    assert untranslated_words(said, NAMES) == [], said
    assert "**C ±** (6, Shift+6)" in said


def test_the_offset_line_and_the_touch_feedback_in_the_pseudo_locale() -> None:
    assert offset_markdown((1.2, -0.4, -3.0), "TOOL") == "`ΔX +1.20  ΔY -0.40  ΔZ -3.00 mm` to the tip (TOOL)"
    said = offset_markdown((1.2, -0.4, -3.0), "TOOL", tr=QPS)
    assert "`ΔX +1.20  ΔY -0.40  ΔZ -3.00 mm`" in said and untranslated_words(said, NAMES) == []
    for offset in (np.array([-0.3, 0.2, 0.72]), np.zeros(3), np.array([np.nan, 0.0, 0.0])):
        said = touch_feedback(offset, "WORLD", tr=QPS)
        assert untranslated_words(said, NAMES) == [], said
    assert touch_feedback(np.array([2.0, 0.0, 0.1]), "TOOL", tr=ENGLISH).startswith("2.0 mm off, mostly −X (TOOL)")


def test_the_servers_refusals_and_the_count_of_refusals_left_out_in_the_pseudo_locale() -> None:
    refusals = (SessionBusy("The TCP check is still running here; wait for its result, then try again.",
                            "the TCP check"),
                PoolFull("The server is busy: 7 jobs are waiting. Try again in a moment.", 7),
                OverShare("The server is busy with this browser's jobs: try again in 3 s.", 2.4),
                JobRefused("The server is shutting down; the job was not started."))
    for exc in refusals:
        assert error_text(exc) == str(exc)                # English: the pool's own words
        said = error_text(exc, QPS)
        assert untranslated_words(said, NAMES | {"TCP"}) in ([], ["TCP"]) and said != str(exc), said
    assert error_text(ValueError("Some plain error.")) == "Some plain error."
    assert error_text(ValueError(Words("{joint} at its limit {value}", joint="A5", value="+1.0 deg")), QPS) \
        == QPS.gettext("{joint} at its limit {value}").format(joint="A5", value="+1.0 deg")
    clock = [0.0]
    notices = RefusalNotices(quiet_s=2.0, clock=lambda: clock[0])
    assert notices.body("No.") == "No."
    assert notices.body("No.") is None and notices.body("No.") is None
    clock[0] = 5.0
    more = lambda n: QPS.ngettext("({n} more click was refused meanwhile.)",  # noqa: E731
                                  "({n} more clicks were refused meanwhile.)", n).format(n=n)
    said = notices.body("No.", more)
    assert said is not None and said.startswith("No. ⟦") and "2" in said and untranslated_words(said, {"No"}) == []
    assert notices.body("No.") is None
    clock[0] = 10.0
    assert notices.body("No.") == "No. (1 more click was refused meanwhile.)"   # English by default
    clock[0] = 15.0
    assert notices.body("No.", more) == "No."              # nothing left out: no count


def test_a_sessions_refusal_notices_count_the_left_out_ones_in_its_language(tmp_path: Path) -> None:
    s = make_session(tmp_path / "tools.json")
    clock = [0.0]
    s.refusals = RefusalNotices(quiet_s=2.0, clock=lambda: clock[0], more_words=s.refusals.more_words)
    assert s.refusals.body("No.") == "No." and s.refusals.body("No.") is None
    s.set_language(PSEUDO_LANGUAGE)
    clock[0] = 5.0
    assert s.refusals.body("No.") == "No. " + QPS.ngettext("({n} more click was refused meanwhile.)",
                                                          "({n} more clicks were refused meanwhile.)", 1).format(n=1)
