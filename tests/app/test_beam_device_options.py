"""The beam sensor's start options (a configurable repeatability, a finite
beam width, optionally two crossed beams): ``--beam-width``, ``--beam-repeatability``,
``--beam-crossed`` reach every session's controller, bad values are refused in words, and a
check on crossed beams measures the TCP on both."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tcp_pendant.calibrate.beam_service import beam_check_job
from tcp_pendant.serve.cli import build_parser, main
from tcp_pendant.controller import BeamDevice, ControllerError
from tcp_pendant.serve.server import AppConfig, PendantApp
from tcpcal.tool import Tool

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def test_options_default_to_one_half_millimetre_beam_of_20_microns() -> None:
    args = build_parser().parse_args([])
    assert (args.beam_width, args.beam_repeatability, args.beam_crossed) == (0.5, 0.02, False)
    args = build_parser().parse_args(["--beam-width", "0.8", "--beam-repeatability", "0.05", "--beam-crossed"])
    assert (args.beam_width, args.beam_repeatability, args.beam_crossed) == (0.8, 0.05, True)


def test_every_session_controller_gets_the_device(tmp_path: Path) -> None:
    app = PendantApp(AppConfig(port=0, tool_library=tmp_path / "t.json", beam_width_mm=0.8,
                               beam_repeatability_mm=0.05, beam_crossed=True))
    sensor = app.new_controller().beam_sensor
    assert sensor.width == pytest.approx(0.8e-3) and sensor.sigma == pytest.approx(0.05e-3)
    np.testing.assert_allclose(sensor.second_direction, [0.0, 1.0, 0.0])
    plain = PendantApp(AppConfig(port=0, tool_library=tmp_path / "t.json")).new_controller().beam_sensor
    assert plain.width == pytest.approx(0.5e-3) and plain.sigma == pytest.approx(2e-5)
    assert plain.second_direction is None
    np.testing.assert_array_equal(plain.point, sensor.point)       # the same place beside the tip


@pytest.mark.parametrize("kw,words", [({"beam_width_mm": 10.0}, "beam width must be 0.05 to 5 mm"),
                                      ({"beam_width_mm": float("nan")}, "beam width"),
                                      ({"beam_repeatability_mm": -0.1}, "repeatability must be 0 to 1 mm")])
def test_bad_values_are_refused_in_words(tmp_path: Path, kw, words) -> None:
    with pytest.raises(ControllerError, match=words):
        PendantApp(AppConfig(port=0, tool_library=tmp_path / "t.json", **kw))


def test_the_command_says_what_is_wrong(tmp_path: Path, capsys) -> None:
    rc = main(["--port", "0", "--tool-library", str(tmp_path / "t.json"), "--beam-width", "9"])
    assert rc == 2 and "beam width must be 0.05 to 5 mm, got 9 mm" in capsys.readouterr().err


def test_a_check_on_crossed_beams_of_the_set_repeatability(tmp_path: Path) -> None:
    app = PendantApp(AppConfig(port=0, tool_library=tmp_path / "t.json"))
    c = app.new_controller()
    T = c.mounted_tool.T_flange_tool_true
    tool = Tool.from_rotation("Pointer", tuple(T[:3, 3] * 1000.0), T[:3, :3])
    c.set_beam_device(BeamDevice(sigma_m=0.0, crossed=True))        # exact events, two beams
    check = beam_check_job(c, 1, tool, rng_seed=1).run()
    assert {ev.beam for ev in check.scan.events if ev.kind == "tip"} == {0, 1}
    np.testing.assert_allclose(check.measured_tcp_mm, T[:3, 3] * 1000.0, atol=1e-6)
    c.set_beam_device(BeamDevice(sigma_m=0.2e-3))                    # a poor device: 0.2 mm
    poor = beam_check_job(c, 1, tool, rng_seed=1).run()
    assert c.beam_sensor.second_direction is None
    assert 0.02 < poor.deviation_norm_mm < 1.0 and poor.ci95_mm > 5 * check.ci95_mm
    with pytest.raises(ControllerError, match="BeamDevice"):
        c.set_beam_device("crossed")                                 # type: ignore[arg-type]
