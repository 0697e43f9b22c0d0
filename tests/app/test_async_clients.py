"""The load clients' clock: a readout is stamped when it reached the socket, not when it was read.

bench_class_load runs its clients on the server's own CPUs, where they wait for one; their
latency figures hold only if the receive stamps are the kernel's (SO_TIMESTAMPNS) and the
press-to-readout matching is right.
"""

from __future__ import annotations

import select
import socket
import time

import pytest

from support.async_clients import _ANCILLARY, SO_TIMESTAMPNS, LoadClient, _arrival_monotonic, latencies


def test_a_read_late_is_stamped_with_its_arrival() -> None:
    listener = socket.create_server(("127.0.0.1", 0))
    receiver = socket.create_connection(listener.getsockname())
    sender, _ = listener.accept()
    try:
        receiver.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
        offset = time.time() - time.monotonic()
        sent = time.monotonic()
        sender.sendall(b"readout")
        assert select.select([receiver], [], [], 30.0)[0], "the bytes never arrived"
        arrived_by = time.monotonic()              # they are in the receive queue, stamped
        time.sleep(0.2)                            # the client is busy; the bytes wait in the kernel
        read = time.monotonic()
        data, ancillary, _, _ = receiver.recvmsg(4096, _ANCILLARY)
        stamp = _arrival_monotonic(ancillary, offset)
    finally:
        for s in (receiver, sender, listener):
            s.close()
    assert data == b"readout"
    assert sent - 0.005 <= stamp <= arrived_by + 0.005   # when the bytes arrived (the clocks' rounding)
    assert read - stamp >= 0.2 - 0.005                   # not when they were read


def test_no_stamp_from_the_kernel_falls_back_to_now() -> None:
    before = time.monotonic()
    assert before <= _arrival_monotonic([], 0.0) <= time.monotonic()


def test_each_press_is_matched_to_the_first_readout_that_shows_it() -> None:
    c = LoadClient(0)
    c.sends = [10.0, 10.05, 10.10]
    # X before: 5.00 mm; the first press shows at 10.02, the next two together at 10.16
    c.readouts = [(10.02, 5.10), (10.16, 5.30)]
    figures = latencies([c], [5.0], 0.1)
    assert figures.asked == 3 and figures.answered == 3 and figures.unanswered == 0
    assert [round(v, 6) for v in figures.latencies_ms] == [20.0, 110.0, 60.0]


def test_a_press_never_shown_is_unanswered() -> None:
    c = LoadClient(0)
    c.sends = [1.0, 1.05]
    c.readouts = [(1.01, 0.1)]
    figures = latencies([c], [0.0], 0.1)
    assert figures.asked == 2 and figures.answered == 1 and figures.unanswered == 1
    assert figures.percentile(50) == pytest.approx(10.0)
