"""The stop at contact's pre-test (``Jogger._translate``, WORLD frame) on Python floats and the
true tool tip to rounding (``VirtualController.tool_tip_true_m``): every press stops where, and
says what, the jogger with the exact tip and the array step said (``tests/bench/panel_yardstick.py``),
also with the reference tip placed right at the pre-test's margin."""

from __future__ import annotations

from types import MethodType

import numpy as np
import pytest

from bench.panel_yardstick import legacy_translate

from tcp_pendant.controller import VirtualController, builtin_robots, builtin_tools
from tcp_pendant.controller.kinematics import RobotKinematics
from tcp_pendant.pendant.guidance import CONTACT_RADIUS_MM
from tcp_pendant.pendant.jogging import Jogger

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

_KIN: list[RobotKinematics] = []


def _pair(tool: str) -> tuple[Jogger, Jogger]:
    if not _KIN:
        _KIN.append(RobotKinematics.from_urdf(builtin_robots()["kr6"]))
    joggers = []
    for legacy in (False, True):
        c = VirtualController(_KIN[0], tool=builtin_tools()[tool])
        c.set_q(np.radians((10.0, -80.0, 100.0, 20.0, 40.0, 30.0)))
        j = Jogger(c)
        j.settings = j.settings.with_(increment="0.1", frame="WORLD")
        if legacy:
            j._translate = MethodType(legacy_translate, j)
        joggers.append(j)
    return joggers[0], joggers[1]


@pytest.mark.parametrize("tool", ["pointer", "torch"])
def test_presses_at_the_margin_stop_as_with_the_exact_tip(tool) -> None:
    new, old = _pair(tool)
    rng = np.random.default_rng(11)
    stops = 0
    for k in range(120):
        ax, sign = "XYZ"[k % 3], (1 if k % 2 else -1)
        q0 = new.controller.q_rad
        for j in (new, old):                       # both at the same joint angles
            j.controller.set_q(q0)
            j.controller.jog_cartesian("WORLD", "Y", 0.1)   # a kept jog state, as after a press
        tip = old.controller.T_world_tool_true()[:3, 3]
        step = np.zeros(3)
        step["XYZ".index(ax)] = sign * 0.1e-3
        # the reference tip ahead of or beside the path, its distance at |step| + radius +
        # a few 1e-12 m either side of the pre-test's margin (or well inside)
        beside = rng.normal(size=3)
        beside -= (beside @ step) / (step @ step) * step
        beside /= np.linalg.norm(beside)
        miss = CONTACT_RADIUS_MM / 1000.0 * float(rng.choice([0.0, 0.5, 0.999, 1.0]))
        ahead = float(rng.choice([1.0, 1.0 + 1e-9, 1.5]))
        ref = tip + step * ahead + beside * miss
        d = np.linalg.norm(ref - tip)
        margin = np.linalg.norm(step) + CONTACT_RADIUS_MM / 1000.0 * (1.0 + 1e-9) + 1e-12
        ref = tip + (ref - tip) * (margin + float(rng.choice([-3e-12, -1e-12, 0.0, 1e-12, 3e-12, 1e-6]))) / d \
            if k % 4 == 0 else ref
        for j in (new, old):
            j.controller.set_reference_tip(ref)
        a, b = new.key(ax, sign), old.key(ax, sign)
        assert a == b, (k, a, b)
        assert np.array_equal(new.controller.q_rad, old.controller.q_rad), k
        stops += a.stopped_by == "contact"
    assert stops >= 10                             # the stop itself was exercised, not only the pass
