"""The Calibrate tab's words, tables and chart data (no viser)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from tcp_pendant.calibrate import error_bars
from tcp_pendant.calibrate.chart import BAR_HALF_WIDTH, error_axis_top_mm
from tcp_pendant.calibrate.text import (
    comparison_markdown,
    menu_markdown,
    meter_level,
    meter_markdown,
    replay_markdown,
    result_markdown,
    save_preview_markdown,
    truth_markdown,
    warnings_markdown,
)
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.wizards import WizardResult, Xyz4Wizard
from tcp_pendant.wizards.truth import compare_with_truth

from tcpcal.pose_quality import CandidateGain, assess_touches


# ------------------------------------------------------------------ chart
def test_error_bars_enclose_each_error_once() -> None:
    errors = [0.1, 0.5, 0.2]
    bars = error_bars([1, 2, 5], errors, outliers=[2])
    x, normal, outlier, mean = bars.columns
    assert len(x) == len(normal) == len(outlier) == len(mean) == 12
    assert np.all(np.diff(x) >= 0)                              # uPlot wants ascending x
    # area under each series = bar width x height of the bars it holds (trapezoids of the outline)
    width = 2 * BAR_HALF_WIDTH
    assert np.trapezoid(normal, x) == pytest.approx(width * (0.1 + 0.2))
    assert np.trapezoid(outlier, x) == pytest.approx(width * 0.5)
    assert normal.max() == pytest.approx(0.2) and outlier.max() == pytest.approx(0.5)
    np.testing.assert_allclose(mean, np.mean(errors))
    # each bar stands on its touch number
    assert x[4:8].tolist() == pytest.approx([2 - BAR_HALF_WIDTH, 2 - BAR_HALF_WIDTH, 2 + BAR_HALF_WIDTH,
                                             2 + BAR_HALF_WIDTH])


def test_error_bars_refuse_mismatched_or_unordered_touches() -> None:
    with pytest.raises(ValueError, match="equal-length"):
        error_bars([1, 2], [0.1])
    with pytest.raises(ValueError, match="ascending"):
        error_bars([2, 1], [0.1, 0.2])


# ------------------------------------------------------------------ meter
def _gain(before: float, after: float, angle: float, too_close: bool = False) -> CandidateGain:
    reduction = (1.0 if math.isfinite(after) else 0.0) if math.isinf(before) else 1.0 - after / before
    return CandidateGain(before, after, reduction, angle, too_close, "")


@pytest.mark.parametrize("gain,value,color", [
    (_gain(math.inf, math.inf, math.inf), 100.0, "yellow"),      # first touch: not determinable yet
    (_gain(math.inf, 0.8, 60.0), 100.0, "green"),                # makes the TCP determinable
    (_gain(0.8, 0.4, 22.5), 50.0, "green"),                      # -50 %
    (_gain(0.8, 0.78, 30.0), 100.0 * 30 / 45, "yellow"),         # adds little
    (_gain(0.8, 0.7, 9.0, too_close=True), 20.0, "red"),
])
def test_meter_level(gain: CandidateGain, value: float, color: str) -> None:
    v, c = meter_level(gain)
    assert v == pytest.approx(value) and c == color


def test_meter_words_give_units_and_the_figures() -> None:
    q = assess_touches(np.eye(3)[None], sigma=0.5)
    assert "Too close" in meter_markdown(_gain(0.8, 0.7, 9.0, too_close=True), q, 0.5)
    text = meter_markdown(_gain(0.8, 0.4, 30.0), q, 0.5)
    assert "0.80 mm → **0.40 mm** (-50 %)" in text and "operator error 0.5 mm" in text
    assert "Nearest recorded orientation: 30° away" in text
    assert "determinable: predicted RMS error **0.80 mm**" in meter_markdown(_gain(math.inf, 0.8, 50.0), q, 0.5)
    stuck = _gain(math.inf, math.inf, math.inf)                 # not determinable even with this pose
    assert "Not determinable yet. " + q.message in meter_markdown(stuck, q, 0.5)
    assert "Not determinable yet.\n" in meter_markdown(stuck, None, 0.5) + "\n"


# ------------------------------------------------------------------ results
def _xyz4_result(synth_rotations: np.ndarray, noise: np.ndarray) -> WizardResult:
    """A 4-point result from poses built here: tool tip t, reference r, R_i given."""
    t_mm, r_mm = np.array([5.0, -3.0, 150.0]), np.array([600.0, 50.0, 300.0])
    wiz = Xyz4Wizard(n_points=len(synth_rotations))
    for R, e in zip(synth_rotations, noise):
        T = np.eye(4)
        T[:3, :3] = R
        T[:3, 3] = (r_mm + e - R @ t_mm) / 1000.0              # R t + f = r (+ error), metres
        wiz.record(T)
        out = wiz.next()
    return out


def _rotations(n: int, seed: int = 0) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(seed)
    return Rotation.from_rotvec(rng.normal(0.0, 0.6, (n, 3))).as_matrix()


def table_rows(md: str) -> list[list[str]]:
    return [[c.strip() for c in line.strip().strip("|").split("|")]
            for line in md.splitlines() if line.startswith("|")]


def test_result_table_states_every_figure_with_its_unit() -> None:
    rng = np.random.default_rng(1)
    res = _xyz4_result(_rotations(6), rng.normal(0.0, 0.3, (6, 3)))
    md = result_markdown(res)
    rows = table_rows(md)
    assert all(len(r) == 2 for r in rows), rows                  # no stray pipe splits a row
    cells = dict(rows[2:])
    assert cells["mean error"] == f"{res.mean_error_mm:.2f} mm"
    assert cells["max error"] == f"{res.max_error_mm:.2f} mm"
    assert cells["RMS error"] == f"{res.rms_error_mm:.2f} mm"
    assert cells["95 % radius of the TCP"] == f"{res.ci95_mm:.2f} mm"
    assert cells["error per touch (mm)"] == ", ".join(f"P{i + 1} {e:.2f}" for i, e in enumerate(res.per_touch_error_mm))
    x, y, z = res.tcp_mm
    assert f"**TCP** X {x:.2f} · Y {y:.2f} · Z {z:.2f} mm" in md
    assert "Orientation" not in md                               # 4-point calibrates no A, B, C
    assert "ℹ A small residual does not prove an accurate TCP" in warnings_markdown(res)


def test_orientation_rows_and_the_estimator_table() -> None:
    res = WizardResult(wizard="three-point", method="three-point-1", tcp_mm=(1.0, 2.0, 3.0),
                       abc_deg=(30.0, -68.0, 0.0), rotation=np.eye(3), orthogonality_defect_deg=0.0123,
                       displacements_mm=(60.0, 45.5))
    md = result_markdown(res)
    assert all(len(r) == 2 for r in table_rows(md))
    assert "**Orientation** A 30.00 · B -68.00 · C 0.00°" in md
    assert "| orthogonality defect | 0.012° |" in md
    assert "| displacement lengths Δ | 60.0 mm, 45.5 mm |" in md

    xyz = _xyz4_result(_rotations(6, seed=2), np.zeros((6, 3)))
    rows = table_rows(comparison_markdown(xyz))
    assert len(rows) == 2 + 3 and all(len(r) == 8 for r in rows)
    assert rows[2][0].endswith("◀ reported") and "least squares" in rows[2][0]
    for r in rows[2:]:                                           # exact data: every estimator agrees
        assert [float(v) for v in r[1:4]] == pytest.approx([5.0, -3.0, 150.0], abs=0.006)


def test_truth_words() -> None:
    res = WizardResult(wizard="xyz4", method="xyz4-lstsq", tcp_mm=(0.0, 0.0, 181.0), ci95_mm=0.5)
    T = np.eye(4)
    T[2, 3] = 0.180
    md = truth_markdown(compare_with_truth(res, T))                 # 1 mm off: fair (0.5 to 2 mm)
    assert md.startswith("● **Against the true TOOL frame: fair: position error 1.00 mm < 2 mm**")
    assert "**1.000 mm**" in md and "**outside** the 95 % radius" in md
    T[2, 3] = 0.1775                                                # 3.5 mm off: poor
    assert truth_markdown(compare_with_truth(res, T)).startswith("✘ **Against the true TOOL frame: poor")


def test_menu_and_save_echo_the_choices() -> None:
    assert "straight pointer" in menu_markdown("xyz4", library_tool=None, reference_tool="A",
                                               new_tool="B", mounted_tool="Straight pointer")
    assert "library is empty" in menu_markdown("three-point", library_tool=None, reference_tool="A",
                                               new_tool="B", mounted_tool="Torch")
    ref = menu_markdown("reference", library_tool="1: Pointer", reference_tool="Straight pointer",
                        new_tool="Welding torch", mounted_tool="Straight pointer")
    assert "**1: Pointer** on the *straight pointer*" in ref and "*welding torch*" in ref
    assert "two different" in menu_markdown("reference", library_tool="1: P", reference_tool="X",
                                            new_tool="X", mounted_tool="X")
    assert save_preview_markdown("Pen", "3: (empty)", (1, 2, 3), (0, 90, -0.0)) == \
        "Will save **Pen** · X 1.00 Y 2.00 Z 3.00 mm · A 0.00 B 90.00 C 0.00° · slot: 3: \\(empty\\)"
    assert "*(type a name)*" in save_preview_markdown(" ", "auto", (0, 0, 0), (0, 0, 0))


def test_replay_table_has_one_row_per_wizard() -> None:
    assert replay_markdown(()) == "The record holds no calibration."
    from tcp_pendant.wizards.session_record import ReplayCheck

    check = ReplayCheck(index=0, kind="xyz4", wizard=Xyz4Wizard(), matches=True, tcp_diff_mm=0.0,
                        rotation_diff_deg=None, truth=None, message="replayed result matches the record")
    rows = table_rows(replay_markdown([check]))
    assert rows[-1] == ["1", escape_markdown("XYZ 4-point"), "✔ replayed result matches the record", "–"]
    assert re.fullmatch(r"[-| ]+", replay_markdown([check]).splitlines()[1])


@pytest.mark.parametrize(("errors", "top"), [([0.0, 0.0, 0.0, 0.0], 0.01), ([0.31, 0.12], 0.5),
                                             ([0.9], 2.0), ([0.004], 0.01), ([0.05, 0.01], 0.1), ([], 0.01)])
def test_error_axis_top_is_round_and_leaves_the_ticks_apart(errors: list[float], top: float) -> None:
    got = error_axis_top_mm(errors)
    assert got == pytest.approx(top)
    assert got >= 1.2 * max(errors, default=0.0)
    # uPlot writes ticks with at most 3 decimals; its finest step on this axis (a tenth of it)
    # must still read as distinct numbers
    ticks = [f"{k * got / 10:.3f}" for k in range(11)]
    assert len(set(ticks)) == 11, ticks
