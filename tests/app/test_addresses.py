"""``--host 0.0.0.0``: the URLs trainees can open (host name and non-loopback addresses), with the
address discovery replaced by fixed answers."""

from __future__ import annotations

import pytest

from tcp_pendant.serve import addresses
from tcp_pendant.serve.addresses import interface_addresses, network_urls, usable_address
from tcp_pendant.serve.cli import ready_urls

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

MACHINE = ["127.0.0.1", "192.168.1.20", "fe80::1%eth0", "::1", "2001:db8::5", "10.0.0.7", "169.254.3.3",
           "0.0.0.0"]


def test_usable_addresses_exclude_loopback_link_local_and_unspecified() -> None:
    assert [a for a in MACHINE if usable_address(a)] == ["192.168.1.20", "2001:db8::5", "10.0.0.7"]
    assert not usable_address("vm") and not usable_address("")


@pytest.mark.parametrize("host,expected", [
    ("0.0.0.0", ["http://classroom-pc:8094", "http://192.168.1.20:8094", "http://10.0.0.7:8094"]),
    ("::", ["http://classroom-pc:8094", "http://[2001:db8::5]:8094"]),
    ("", ["http://classroom-pc:8094", "http://192.168.1.20:8094", "http://[2001:db8::5]:8094",
          "http://10.0.0.7:8094"]),
    ("192.168.1.20", ["http://192.168.1.20:8094"]),
    ("2001:db8::5", ["http://[2001:db8::5]:8094"]),
])
def test_network_urls_per_bound_host(host: str, expected: list[str]) -> None:
    assert network_urls(host, 8094, hostname="classroom-pc", addresses=MACHINE) == expected


def test_no_usable_address_gives_no_url_and_localhost_is_no_name() -> None:
    assert network_urls("0.0.0.0", 8080, hostname="classroom-pc", addresses=["127.0.0.1", "::1"]) == []
    assert network_urls("0.0.0.0", 8080, hostname="localhost", addresses=["10.1.2.3"]) == ["http://10.1.2.3:8080"]


def test_interface_addresses_merges_the_sources_without_psutil(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(addresses, "_psutil_addresses", lambda: None)
    monkeypatch.setattr(addresses, "_ioctl_ipv4_addresses", lambda: ["127.0.0.1", "192.0.2.2"])
    monkeypatch.setattr(addresses, "_proc_ipv6_addresses", lambda: ["::1", "fe80::fc00:ff:fe00:1", "fd00::2"])
    monkeypatch.setattr(addresses, "_hostname_addresses", lambda name: ["127.0.1.1", "192.0.2.2", "10.9.8.7"])
    assert interface_addresses() == ["10.9.8.7", "192.0.2.2", "fd00::2"]


def test_proc_if_inet6_is_parsed(tmp_path) -> None:
    f = tmp_path / "if_inet6"
    f.write_text("fe8000000000000000fc00fffe000001 04 40 20 80     eth0\n"
                 "00000000000000000000000000000001 01 80 10 80       lo\n"
                 "fd000000000000000000000000000002 04 40 00 82     eth0\n")
    assert addresses._proc_ipv6_addresses(f) == ["fe80::fc:ff:fe00:1", "::1", "fd00::2"]
    assert addresses._proc_ipv6_addresses(tmp_path / "absent") == []


def test_ready_line_urls() -> None:
    local = "http://127.0.0.1:8080"
    assert ready_urls(local, [], "127.0.0.1") == local
    assert ready_urls("http://10.0.0.7:8080", ["http://10.0.0.7:8080"], "10.0.0.7") == "http://10.0.0.7:8080"
    text = ready_urls(local, ["http://pc:8080", "http://10.0.0.7:8080"], "0.0.0.0")
    assert text.splitlines() == ["http://pc:8080",
                                 "  trainees open: http://pc:8080  http://10.0.0.7:8080   (on this machine: "
                                 "http://127.0.0.1:8080)"]
    assert "trainees cannot connect" in ready_urls(local, [], "0.0.0.0")
