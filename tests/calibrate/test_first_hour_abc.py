"""With Auto-touch σ > 0, the ABC world result is no longer exact: the
operator error is applied to the alignment step as an angle, atan(σ / 100 mm) per tool axis."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.calibrate.autotouch import ANGLE_LEVER_MM, operator_angle_sigma_deg

from support.calib_helpers import library_tool_with_true_tcp


def abc_errors(workflow, library, sigma_mm: float, n: int, tool: str = "torch") -> tuple[np.ndarray, list[str]]:
    library.save(1, library_tool_with_true_tcp(tool, "T"))
    wf = workflow(tool=tool, seed=11)
    errs, messages = [], []
    for _ in range(n):
        wf.start("abc-world", slot=1)
        out = wf.auto_touch(AutoTouchRequest(sigma_mm=sigma_mm))
        assert out.ok, out.message
        messages.append(out.message)
        errs.append(wf.truth().orientation_error_deg)
    return np.array(errs), messages


def test_operator_angle_rule() -> None:
    assert ANGLE_LEVER_MM == 100.0
    assert operator_angle_sigma_deg(0.0) == 0.0
    assert operator_angle_sigma_deg(1.0) == pytest.approx(math.degrees(math.atan(0.01)))
    assert operator_angle_sigma_deg(2.0) == pytest.approx(1.1458, abs=1e-4)


def test_sigma_zero_stays_exact_and_says_so(workflow, library) -> None:
    errs, messages = abc_errors(workflow, library, 0.0, 2)
    assert np.all(errs < 1e-6)
    assert messages[0] == "Tool aligned with WORLD exactly and recorded."


def test_sigma_gives_an_orientation_error_of_the_matching_size(workflow, library) -> None:
    sigma_a = operator_angle_sigma_deg(2.0)          # deg per tool axis
    errs, messages = abc_errors(workflow, library, 2.0, 40)
    # the misalignment is a rotation vector with sigma_a per axis: |v| is Maxwell distributed,
    # mean 2 sqrt(2/pi) sigma_a = 1.60 sigma_a (sd of the mean of 40: 0.11 sigma_a)
    assert np.all(errs > 1e-3)
    assert 1.25 * sigma_a < errs.mean() < 1.95 * sigma_a
    assert np.sqrt(np.mean(errs**2)) == pytest.approx(math.sqrt(3.0) * sigma_a, rel=0.25)
    assert "by eye" in messages[0] and "σ 1.15° per axis = operator error 2 mm over 100 mm" in messages[0]
    # the message's angle is the error the result shows (ABC world takes the pose as aligned)
    shown = float(messages[0].split("by eye, ")[1].split("°")[0])
    assert shown == pytest.approx(errs[0], abs=0.006)
