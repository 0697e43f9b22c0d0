"""In an exercise no touch's true distance leaves the server: not in the session record a
trainee exports, not in the result's table of touches recorded with the distance hidden.

Why it matters: with the recorded flange poses (R_i, p_i) and the reference tip r, which the
trainee has anyway, the true distances d_i give the true TCP t by trilateration,
|R_i t + p_i - r| = d_i, from touches recorded anywhere in the air (issue "Earned grades,
round two", items 1 and 2). The attack is replayed here: an XYZ 4-point recorded about 300 mm
from the tip, the tool turned between records. In free practice the same attack recovers the
TCP from the export to 1e-6 mm, which shows the check can fail; in an exercise there is nothing
to solve with."""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import numpy as np
import pytest
from scipy.optimize import least_squares
from tcp_pendant.wizards.session_record import dumps

from tcpcal.origin import solve_xyz4
from support.calib_page import Page

pytestmark = pytest.mark.app_page(cls=Page, seed=5)

TURNS = (("A", 10.0), ("B", 10.0), ("C", 10.0), ("A", -20.0), ("B", -20.0))


def trilaterate(record: Mapping[str, Any]) -> np.ndarray | None:
    """The TCP (mm, FLANGE) solved from an exported record's first wizard: its touches' flange
    poses, the reference tip and the ``"distance_mm"`` of each touch; None when the record
    carries no distances."""
    entry = record["wizards"][0]
    distances = entry.get("distance_mm")
    if not distances:
        return None
    tip_mm = np.asarray(record["reference_tip_world_m"], dtype=float) * 1e3
    poses = entry["state"]["poses"]
    T = [np.asarray(poses[k]["T_world_flange_m"], dtype=float) for k in distances]
    d = np.array([float(v) for v in distances.values()])
    R, p = np.array([t[:3, :3] for t in T]), np.array([t[:3, 3] * 1e3 for t in T])
    start = solve_xyz4(R, p).tcp                   # the wrong sphere centre: only a start point

    def residual(t: np.ndarray) -> np.ndarray:
        return np.linalg.norm(R @ t + p - tip_mm, axis=1) - d

    return np.asarray(least_squares(residual, start, xtol=1e-15, ftol=1e-15, gtol=1e-15).x)


def record_in_the_air(wf: Any, *, hide_distance: bool) -> list[float]:
    """An XYZ 4-point recorded 300 mm above the tip, the tool turned between records (five
    touches, a 5-point run); returns the true distances at record (mm)."""
    c = wf.controller
    wf.state.hide_distance = hide_distance
    wf.start("xyz4", n_points=5)
    c.jog_cartesian("world", "Z", 300.0)
    distances = []
    for i, (axis, deg) in enumerate(TURNS):
        if i:
            c.jog_cartesian("tool", axis, deg)
        distances.append(float(c.touch_geometry().distance_mm))
        wf.record()
        if i < len(TURNS) - 1:
            wf.next()
    assert min(distances) > 200.0
    assert wf.next() is not None                  # Finish: a (wrong) result from the air
    return distances


@pytest.mark.parametrize("exercise", [False, True], ids=["free practice", "exercise"])
def test_the_export_gives_no_distance_to_trilaterate_the_tcp_from_in_an_exercise(workflow, exercise: bool) -> None:
    wf = workflow()
    wf.honest_records = exercise                  # a classroom's trainee
    wf.hide_truth = exercise                      # the exercise (WizardCommands.set_hide_truth)
    true_tcp = wf.controller.mounted_tool.T_flange_tool_true[:3, 3] * 1e3
    record_in_the_air(wf, hide_distance=True)
    text = dumps(wf.export_record())
    record = json.loads(text)
    solved = trilaterate(record)
    if not exercise:                              # the lesson's data: the attack works on it
        assert solved is not None
        np.testing.assert_allclose(solved, true_tcp, atol=1e-6)
        return
    assert solved is None and "distance_mm" not in text
    assert not any(k.startswith("T_flange_tcp_true") for k in text.split('"'))
    assert record["honest"] is True
    assert wf.run.distance_mm == {} and wf.run.distance_hidden == set()   # kept by the gradebook only
    wf.hide_truth = False                         # the trainer ends the exercise: still none
    assert "distance_mm" not in dumps(wf.export_record()) and wf.distances_shown() == ({}, set())


def record_in_the_air_on_the_page(p: Any, *, exercise: bool) -> list[float]:
    """The same attack through the Calibrate tab (an XYZ 4-point, "Hide distance" on, the truth
    hidden in an exercise); returns each touch's true distance at record (mm)."""
    v, s = p.view, p.session
    s.set_hide_distance(True)
    if exercise:
        s.wizard_commands.set_hide_truth(True)                    # what the classroom sets in an exercise
    with s.lock:
        s.controller.jog_cartesian("world", "Z", 300.0)
    p.click(v.start)
    distances = []
    for i in range(4):
        with s.lock:
            if i:
                s.controller.jog_cartesian("tool", TURNS[i][0], TURNS[i][1])
            distances.append(float(s.controller.touch_geometry().distance_mm))
        p.click(v.steps.record)
        p.click(v.steps.next)
    assert v.workflow.result is not None and min(distances) > 200.0
    return distances


def test_the_result_shows_no_distance_table_in_an_exercise(page) -> None:
    p = page()
    v = p.view
    distances = record_in_the_air_on_the_page(p, exercise=True)
    assert v.workflow.run.distance_mm == {} and not v.result.hidden_md.visible
    shown = "\n".join(str(h.content) for h in (v.result.result_md, v.result.hidden_md, v.result.warnings_md))
    assert "distance hidden" not in shown and "distance at record" not in shown
    for d in distances:                           # no true distance, to the 0.1 or 0.01 mm shown
        assert f"{d:.2f}" not in shown and f"{d:.1f} mm" not in shown


def test_free_practice_keeps_the_distance_table(page) -> None:
    p = page()
    v = p.view
    distances = record_in_the_air_on_the_page(p, exercise=False)
    assert v.result.hidden_md.visible
    for i, d in enumerate(distances):
        assert f"| P{i + 1} | {d:.2f} mm |" in v.result.hidden_md.content
