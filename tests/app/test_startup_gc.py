"""The server process sets its start-up objects apart from the cyclic collector
(``tcp_pendant.serve.cli.set_apart_startup_objects``)."""

from __future__ import annotations

import gc
import weakref

import pytest

from tcp_pendant.serve.cli import set_apart_startup_objects

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def test_start_up_objects_are_frozen_and_garbage_is_collected_first() -> None:
    class Cycle:
        pass

    a, b = Cycle(), Cycle()
    a.other, b.other = b, a  # type: ignore[attr-defined]
    gone = weakref.ref(a)
    del a, b                                         # start-up garbage: a reference cycle
    try:
        frozen = set_apart_startup_objects()
        assert frozen == gc.get_freeze_count() > 1000
        assert gone() is None                            # collected, not frozen
    finally:
        gc.unfreeze()
    assert gc.get_freeze_count() == 0
