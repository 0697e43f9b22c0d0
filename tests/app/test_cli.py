"""CLI options without serving: bad options exit 2 with a message; host classification."""

from __future__ import annotations

import pytest

from tcp_pendant.serve.cli import build_parser, main
from tcp_pendant.serve.server import is_loopback, parse_xyz_mm, ready_configuration

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def test_defaults() -> None:
    a = build_parser().parse_args([])
    assert (a.robot, a.tool, a.host, a.port, a.shared, a.reference_tip) == ("kr6", "pointer", "127.0.0.1", 8080,
                                                                             False, None)
    assert a.seed is None and build_parser().parse_args(["--seed", "42"]).seed == 42


@pytest.mark.parametrize("argv,needle", [(["--robot", "nope"], "Unknown robot"),
                                         (["--robot", "/no/such.urdf"], "not found"),
                                         (["--reference-tip", "1,2"], "X,Y,Z"),
                                         (["--flange-link", "hand"], "no link 'hand'"),
                                         (["--port", "70000"], "--port"),
                                         (["--seed", "-3"], "seed must be a whole number >= 0")])
def test_bad_options_exit_2_with_message(argv: list[str], needle: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(argv) == 2
    assert needle in capsys.readouterr().err


def test_loopback_and_tip_parsing() -> None:
    assert is_loopback("127.0.0.1") and is_loopback("localhost") and is_loopback("::1")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.168.1.20")
    assert parse_xyz_mm("525, 0,445") == (525.0, 0.0, 445.0)


def test_ready_pose_points_flange_down(kr6) -> None:
    q = ready_configuration(kr6)
    assert kr6.T_world_flange(q)[2, 2] == pytest.approx(-1.0, abs=1e-9)


def test_network_warning_only_off_loopback() -> None:
    from tcp_pendant.serve.cli import network_warning

    assert network_warning("127.0.0.1") is None and network_warning("localhost") is None
    text = network_warning("0.0.0.0")
    assert text is not None and "anyone on the network" in text and "0.0.0.0" in text


def _serve(tmp_path, *args: str):
    """Start ``python -m tcp_pendant`` on a free port; returns (process, the ready line)."""
    import subprocess
    import sys

    import signal

    # Ctrl-C reaches the server even where this test runs with SIGINT ignored (nohup, some CI
    # shells): a child inherits the ignore, and Python then installs no KeyboardInterrupt handler.
    proc = subprocess.Popen([sys.executable, "-m", "tcp_pendant", "--port", "0", "--tool-library",
                             str(tmp_path / "tools.json"), *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert proc.stdout is not None
    for line in proc.stdout:
        if "ready" in line:
            return proc, line
    proc.kill()
    proc.wait(30)
    raise AssertionError(f"no ready line; exit {proc.returncode}: {proc.stderr.read() if proc.stderr else ''}")


def stop_with_ctrl_c(proc, timeout_s: float = 60.0) -> tuple[str, str]:
    """Ctrl-C to a server this test started and its output; killed if it is still running
    after ``timeout_s`` (the test then fails, and leaves no server behind)."""
    import signal
    import subprocess

    proc.send_signal(signal.SIGINT)
    try:
        return proc.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate(timeout=30)
        raise


@pytest.mark.parametrize("host,warned", [("127.0.0.1", False), ("0.0.0.0", True)])
def test_command_serves_prints_the_url_and_stops_on_ctrl_c(tmp_path, host: str, warned: bool) -> None:
    """The real command: prints the URL (which answers), warns off loopback, Ctrl-C stops it (0)."""
    import re
    import signal
    import urllib.request

    proc, line = _serve(tmp_path, "--host", host)
    try:
        url = re.search(r"http://\S+", line).group(0)
        urls = [url]
        if host == "0.0.0.0":                 # the URLs trainees can open, not 127.0.0.1
            from tcp_pendant.serve.addresses import interface_addresses

            assert proc.stdout is not None
            more = proc.stdout.readline()
            ips = [a for a in interface_addresses() if ":" not in a]
            if ips:
                listed = re.findall(r"http://\S+", more.split("(on this machine:")[0])
                assert "trainees open:" in more and listed[0] == url
                assert [u.rsplit(":", 1)[0][7:] for u in listed[1:]] == ips
                assert "127.0.0.1" not in url and "0.0.0.0" not in more
                urls = listed[1:] + re.findall(r"on this machine: (http://[^)\s]+)", more)
            else:
                assert "trainees cannot connect" in more
        for u in urls:                        # each one answers (this machine's own addresses)
            with urllib.request.urlopen(u, timeout=10) as r:
                assert r.status == 200
    finally:
        out, err = stop_with_ctrl_c(proc)
    assert proc.returncode == 0, err
    assert ("anyone on the network" in err) is warned


def test_busy_port_is_refused_with_a_hint(tmp_path) -> None:
    """A busy port is refused: viser must not move on to the next port silently while the class
    was told this one."""
    import socket
    import subprocess
    import sys

    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        proc = subprocess.Popen([sys.executable, "-m", "tcp_pendant", "--port", str(port), "--tool-library",
                                 str(tmp_path / "tools.json")],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        assert proc.stdout is not None and proc.stderr is not None
        for line in proc.stdout:
            if "ready" in line:
                proc.kill()
                proc.wait(30)
                raise AssertionError(f"served elsewhere instead of refusing port {port}: {line}")
        err = proc.stderr.read()
        proc.wait(30)
    assert proc.returncode == 2, err
    assert f"port {port} on 127.0.0.1 is already in use" in err
    assert "--port 0 for any free port" in err and f"--port {port + 1}" in err
