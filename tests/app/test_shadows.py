"""The "Shadows" checkbox of the jog panel's View folder, over real websockets: it switches the
shadows of viser's default lights for the browser that clicked it only (every browser in
``--shared`` mode, where its label says so)."""

from __future__ import annotations

import pytest

from support.wsclient import InputsClient, wait_until

from tcp_pendant.views.pendant_panel import SHADOWS_LABEL, SHARED_SHADOWS_LABEL

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _lights(c: InputsClient) -> list[tuple[bool, bool]]:
    """(enabled, cast_shadow) of every EnableLightsMessage ``c`` received, in order."""
    return [(m["enabled"], m["cast_shadow"]) for m in list(c.messages) if m.get("type") == "EnableLightsMessage"]


def _set(c: InputsClient, label: str, value: bool) -> None:
    c.send({"type": "GuiUpdateMessage", "uuid": c.uuid_of(label), "updates": {"value": value}})


def _count(c: InputsClient, kind: str) -> int:
    return sum(m.get("type") == kind for m in list(c.messages))


def test_shadows_switch_for_the_browser_that_clicked_only(app_factory) -> None:
    app = app_factory()
    anna, ben = InputsClient(app.port), InputsClient(app.port)
    try:
        for c in (anna, ben):
            wait_until(lambda c=c: SHADOWS_LABEL in c.labels(), timeout=30, what="the Shadows checkbox")
            assert _lights(c) == []                              # viser's default: lights with shadows
        _set(anna, SHADOWS_LABEL, False)
        wait_until(lambda: _lights(anna) == [(True, False)], what="Anna's lights without shadows")
        # Ben's own click, handled after Anna's: his camera's answer comes after anything her
        # click had sent him (one stream per browser, in order)
        cameras = _count(ben, "SetCameraLookAtMessage")
        _set(ben, "Close-up on reference tip", True)   # a camera pose he does not have yet
        wait_until(lambda: _count(ben, "SetCameraLookAtMessage") > cameras, what="Ben's camera")
        assert _lights(ben) == []
        assert [s.views["pendant"].shadows.value for s in app.sessions.values()] == [False, True]   # Anna's, Ben's
        _set(anna, SHADOWS_LABEL, True)
        wait_until(lambda: _lights(anna)[-1:] == [(True, True)], what="Anna's shadows back")
    finally:
        anna.ws.close()
        ben.ws.close()


def test_the_shared_pendant_switches_every_screen_and_says_so(app_factory) -> None:
    app = app_factory(shared=True)
    anna, ben = InputsClient(app.port), InputsClient(app.port)
    try:
        for c in (anna, ben):
            wait_until(lambda c=c: SHARED_SHADOWS_LABEL in c.labels(), timeout=30, what="the shared Shadows checkbox")
            assert SHADOWS_LABEL not in c.labels()               # the page's script leaves this one alone
        _set(anna, SHARED_SHADOWS_LABEL, False)
        for c in (anna, ben):
            wait_until(lambda c=c: _lights(c) == [(True, False)], what="every screen's lights without shadows")
        assert app.shared_session.views["pendant"].shadows.value is False
    finally:
        anna.ws.close()
        ben.ws.close()
