"""CLI options without serving: bad options exit 2 with a message; host classification."""

from __future__ import annotations

import pytest

from tcp_pendant.cli import build_parser, main
from tcp_pendant.server import is_loopback, parse_xyz_mm, ready_configuration


def test_defaults() -> None:
    a = build_parser().parse_args([])
    assert (a.robot, a.tool, a.host, a.port, a.shared, a.reference_tip) == ("kr6", "pointer", "127.0.0.1", 8080,
                                                                             False, None)


@pytest.mark.parametrize("argv,needle", [(["--robot", "nope"], "Unknown robot"),
                                         (["--robot", "/no/such.urdf"], "not found"),
                                         (["--reference-tip", "1,2"], "X,Y,Z"),
                                         (["--flange-link", "hand"], "no link 'hand'"),
                                         (["--port", "70000"], "--port")])
def test_bad_options_exit_2_with_message(argv: list[str], needle: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(argv) == 2
    assert needle in capsys.readouterr().err


def test_loopback_and_tip_parsing() -> None:
    assert is_loopback("127.0.0.1") and is_loopback("localhost") and is_loopback("::1")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.168.1.20")
    assert parse_xyz_mm("525, 0,445") == (525.0, 0.0, 445.0)


def test_ready_pose_points_flange_down(kr6) -> None:
    q = ready_configuration(kr6)
    assert kr6.T_base_flange(q)[2, 2] == pytest.approx(-1.0, abs=1e-9)
