"""The URLs trainees can open when the pendant listens on every interface (``--host 0.0.0.0``).

``http://127.0.0.1:PORT`` only works on the server itself; the class needs the machine's host
name and its network addresses. They are found without any network traffic: ``psutil`` when it
is installed, else the interfaces' IPv4 addresses (``SIOCGIFADDR`` on each of
``socket.if_nameindex()``, Linux) and ``/proc/net/if_inet6``, plus what the host name resolves
to locally. Loopback, link-local, multicast and unspecified addresses are left out (link-local
IPv6 would need a zone index that no browser URL bar accepts).
"""

from __future__ import annotations

import ipaddress
import socket
import struct
import sys
from collections.abc import Iterable
from pathlib import Path

__all__ = ["WILDCARD_HOSTS", "interface_addresses", "network_urls", "usable_address"]

WILDCARD_HOSTS: dict[str, tuple[int, ...]] = {
    "0.0.0.0": (4,),       # IPv4 only
    "::": (6,),            # IPv6 only (asyncio binds "::" with IPV6_V6ONLY)
    "": (4, 6),            # every interface of both families
}
"""Hosts that bind every interface, and the IP versions they serve."""

_SIOCGIFADDR = 0x8915


def usable_address(address: str) -> bool:
    """True for an address another machine can use to reach this one (not loopback, link-local,
    multicast or unspecified)."""
    try:
        ip = ipaddress.ip_address(address.split("%", 1)[0])
    except ValueError:
        return False
    return not (ip.is_loopback or ip.is_link_local or ip.is_multicast or ip.is_unspecified)


def _psutil_addresses() -> list[str] | None:
    try:
        import psutil
    except ImportError:
        return None
    out = []
    for addrs in psutil.net_if_addrs().values():
        out += [a.address for a in addrs if a.family in (socket.AF_INET, socket.AF_INET6)]
    return out


def _ioctl_ipv4_addresses() -> list[str]:
    if not sys.platform.startswith("linux"):
        return []
    import fcntl

    out = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:   # never connected: no packet
        for _, name in socket.if_nameindex():
            try:
                raw = fcntl.ioctl(s.fileno(), _SIOCGIFADDR, struct.pack("256s", name.encode()[:15]))
            except OSError:                                       # interface without IPv4
                continue
            out.append(socket.inet_ntoa(raw[20:24]))
    return out


def _proc_ipv6_addresses(path: Path = Path("/proc/net/if_inet6")) -> list[str]:
    try:
        lines = path.read_text().splitlines()
    except OSError:
        return []
    out = []
    for line in lines:
        field = line.split()[0] if line.split() else ""
        if len(field) == 32:
            out.append(str(ipaddress.IPv6Address(bytes.fromhex(field))))
    return out


def _hostname_addresses(hostname: str) -> list[str]:
    try:
        return [str(info[4][0]) for info in socket.getaddrinfo(hostname, None)]
    except OSError:
        return []


def interface_addresses() -> list[str]:
    """Every IP address of this machine that others can use, IPv4 first, without duplicates."""
    found = _psutil_addresses()
    if found is None:
        found = _ioctl_ipv4_addresses() + _proc_ipv6_addresses()
    found += _hostname_addresses(socket.gethostname())
    unique = {str(ipaddress.ip_address(a.split("%", 1)[0])) for a in found if usable_address(a)}
    return sorted(unique, key=lambda a: (ipaddress.ip_address(a).version, ipaddress.ip_address(a)))


def network_urls(host: str, port: int, *, hostname: str | None = None,
                 addresses: Iterable[str] | None = None) -> list[str]:
    """The URLs trainees can open: ``http://<host name>:PORT`` then one per usable address.

    Args:
        host: the address the server binds; only a wildcard (see ``WILDCARD_HOSTS``) gives more
            than one URL, any other host gives ``http://host:PORT`` (brackets for IPv6).
        port: the port actually served.
        hostname: this machine's name (default ``socket.gethostname()``).
        addresses: this machine's addresses (default :func:`interface_addresses`).

    Returns:
        The URLs, the host name first; for a wildcard host an empty list when the machine has no
        usable address (then only this machine can connect).
    """
    if host not in WILDCARD_HOSTS:
        shown = f"[{host}]" if ":" in host and not host.startswith("[") else host
        return [f"http://{shown}:{port}"]
    versions = WILDCARD_HOSTS[host]
    addrs = [a for a in (interface_addresses() if addresses is None else addresses)
             if usable_address(a) and ipaddress.ip_address(a.split("%", 1)[0]).version in versions]
    if not addrs:
        return []
    name = socket.gethostname() if hostname is None else hostname
    named = name and name not in ("localhost", "localhost.localdomain") and not usable_address(name)
    urls = [f"http://{name}:{port}"] if named else []
    for a in addrs:
        urls.append(f"http://[{a}]:{port}" if ":" in a else f"http://{a}:{port}")
    return urls
