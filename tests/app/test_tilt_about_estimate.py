"""The wizard's TCP estimate to tilt about (``calibrate.tcp_estimate``,
``WizardCommands.pivot_on_estimate``): its numbers against the touches it comes from, and what
it does on the KR 6 with the pointer: after two touches a 50° tilt about it keeps the tool tip
within a millimetre of the reference tip, where the same tilt about the flange swings it
~108 mm away; the readout names it as the estimate."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from support.calib_helpers import make_session, true_frame

from tcp_pendant.calibrate.tcp_estimate import TcpEstimate, tcp_estimate
from tcp_pendant.controller import builtin_tools
from tcp_pendant.wizards import WizardStateError

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

R_DOWN = np.diag([1.0, -1.0, -1.0])                    # flange Z pointing down (WORLD)


def _wizard(R_list: list[np.ndarray], t_mm: np.ndarray, r_mm: np.ndarray, noise_mm: list[np.ndarray] | None = None):
    """The three things ``tcp_estimate`` reads of an XYZ 4-point wizard, for touches that put
    the TCP ``t_mm`` (FLANGE) on ``r_mm`` (WORLD) in the orientations ``R_list`` (flange
    positions off by ``noise_mm``)."""
    poses = {}
    for i, R in enumerate(R_list):
        T = np.eye(4)
        T[:3, :3] = R
        f = r_mm - R @ t_mm + (0.0 if noise_mm is None else noise_mm[i])
        T[:3, 3] = f / 1000.0
        poses[i] = SimpleNamespace(T_world_flange_m=T)
    return SimpleNamespace(kind="xyz4", recorded_poses=poses, solver_touch_steps=lambda: tuple(range(4)))


def _tilted(axis: str, deg: float) -> np.ndarray:
    return Rotation.from_euler(axis, deg, degrees=True).as_matrix() @ R_DOWN


T_BENT = np.array([12.0, -7.0, 180.0])                 # a TCP off the flange axis (mm)
R_TIP = np.array([520.0, 3.0, 440.0])


def test_two_touches_miss_only_the_component_along_their_tilt_axis() -> None:
    R1, R2 = R_DOWN, _tilted("y", 45.0)                # a tilt about WORLD Y
    est = tcp_estimate(_wizard([R1, R2], T_BENT, R_TIP))
    assert est is not None and est.touches == 2
    axis_flange = R1.T @ np.array([0.0, 1.0, 0.0])      # WORLD Y in FLANGE: (0, -1, 0)
    missed = float(T_BENT @ axis_flange) * axis_flange
    np.testing.assert_allclose(est.tcp_mm, T_BENT - missed, atol=1e-9)    # minimum norm along it
    assert abs(est.tcp_mm[1]) < 1e-9 and abs(T_BENT[1]) == 7.0


def test_three_touches_give_the_tcp_and_noise_stays_of_its_size() -> None:
    rots = [R_DOWN, _tilted("y", 45.0), _tilted("x", 45.0)]
    est = tcp_estimate(_wizard(rots, T_BENT, R_TIP))
    assert est is not None and est.touches == 3
    np.testing.assert_allclose(est.tcp_mm, T_BENT, atol=1e-9)
    rng = np.random.default_rng(3)
    noisy = tcp_estimate(_wizard(rots, T_BENT, R_TIP, [rng.normal(0.0, 0.1, 3) for _ in rots]))
    assert noisy is not None
    err = float(np.linalg.norm(np.asarray(noisy.tcp_mm) - T_BENT))
    assert 0.0 < err < 0.6                              # 0.1 mm touches: a fraction of a mm


def test_no_estimate_from_one_touch_one_orientation_or_another_wizard() -> None:
    assert tcp_estimate(_wizard([R_DOWN], T_BENT, R_TIP)) is None
    assert tcp_estimate(_wizard([R_DOWN, R_DOWN], T_BENT, R_TIP)) is None
    other = _wizard([R_DOWN, _tilted("y", 45.0)], T_BENT, R_TIP)
    other.kind = "tcp_check"
    assert tcp_estimate(other) is None
    assert tcp_estimate(None) is None
    tool = TcpEstimate((1.0, 2.0, 3.0), 2).tool()
    assert tool.name == "Estimate, 2 touches" and tool.tcp_mm == (1.0, 2.0, 3.0) and tool.abc_deg == (0.0, 0.0, 0.0)


def _touch(s, R_world_flange: np.ndarray) -> None:
    """Put the pointer's true tip on the reference tip with the flange at ``R_world_flange``,
    Record, Next."""
    t_mm, _, _ = true_frame("pointer")
    c = s.controller
    T = np.eye(4)
    T[:3, :3] = R_world_flange
    T[:3, 3] = c.reference_tip_world_m - R_world_flange @ (t_mm / 1000.0)
    assert s.motion.move_tcp_to(T).ok                  # no tool data: the TCP is the flange
    s.wizard_commands.record_step()
    s.wizard_commands.next_step()


def _tip_after_tilt_mm(s) -> float:
    """The true tool tip's distance from the reference tip (mm) after C + by 5 x 10° in WORLD."""
    s.motion.set_jog_setting("increment", "10")
    for _ in range(5):
        assert s.motion.jog("C", 1).ok
    c = s.controller
    return float(np.linalg.norm(c.T_world_tool_true()[:3, 3] - c.reference_tip_world_m)) * 1000.0


@pytest.mark.parametrize("pivot", [True, False])
def test_a_tilt_about_the_estimate_keeps_the_tip_near(tmp_path, pivot: bool) -> None:
    s = make_session(tmp_path / "tools.json")
    s.wizard_commands.start("xyz4")
    R0 = s.controller.T_world_flange()[:3, :3]
    with pytest.raises(WizardStateError, match="two touches"):
        s.wizard_commands.pivot_on_estimate()
    _touch(s, R0)
    assert s.wizard_commands.estimate_offer() is None            # one touch: nothing to offer
    _touch(s, Rotation.from_euler("y", 45.0, degrees=True).as_matrix() @ R0)
    offer = s.wizard_commands.estimate_offer()
    assert offer is not None and offer.touches == 2
    truth = builtin_tools()["pointer"].T_flange_tool_true[:3, 3] * 1000.0
    assert float(np.linalg.norm(np.asarray(offer.tcp_mm) - truth)) < 0.01   # exact touches: on the TCP
    if pivot:
        est = s.wizard_commands.pivot_on_estimate()
        active = s.controller.active_tool
        assert active is not None and active.name == "Estimate, 2 touches"
        np.testing.assert_allclose(active.tcp_mm, est.tcp_mm)
        assert s.wizard_commands.estimate_offer() is None       # active already: the button hides
    swing = _tip_after_tilt_mm(s)
    if pivot:
        assert swing < 0.05
    else:
        lever = 180.0 * math.cos(math.radians(45.0))             # the pointer's 180 mm, across WORLD X
        expected = 2.0 * math.sin(math.radians(25.0)) * lever    # ~108 mm about the flange
        assert swing == pytest.approx(expected, rel=0.01)
