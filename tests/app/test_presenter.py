"""Presenter mode: the GUI checkbox and ``--presenter`` change what is
rendered: a readout in >= 28 px monospace numbers, the running wizard's step list with the
current step marked, the per-touch error chart, a narrower panel, larger scene labels; user
text escaped."""

from __future__ import annotations

import re

import pytest

from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until

from tcp_pendant.serve.cli import build_parser
from tcp_pendant.controller.readout import PoseReadout
from tcp_pendant.views.presenter import (
    CHART_HEIGHT_PX,
    LABEL_SCALE,
    NORMAL_WIDTH_PX,
    READOUT_FONT_PX,
    PRESENTER_WIDTH_PX,
    presenter_readout_markdown,
    presenter_steps_markdown,
)

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _session(app):
    wait_until(lambda: len(app.sessions) == 1 and "presenter" in next(iter(app.sessions.values())).views,
               what="a session with its presenter view")
    return next(iter(app.sessions.values()))


def _font_px(md: str, cls: str) -> int:
    m = re.search(rf'class="{cls}" style="font-size:(\d+)px', md)
    assert m, md
    return int(m.group(1))


def test_the_checkbox_switches_presenter_mode_and_its_large_readout(app_factory) -> None:
    app = app_factory()
    c = DrainingClient(app.port)
    try:
        s = _session(app)
        view = s.views["presenter"]
        assert view.toggle.value is False and not view.folder.visible
        assert view.readout_md.content == ""                 # nothing rendered while off
        labels = s.views.labels.drawn()
        assert {"world", "flange", "tool", "tip", "computed", "true", "target"} <= set(labels)
        assert all(h.font_screen_scale == 1.0 for h in labels.values())
        choose(view.toggle, True, s.client)
        assert view.folder.visible and view.panel_width_px == PRESENTER_WIDTH_PX
        assert LABEL_SCALE >= 1.5 and all(h.font_screen_scale == LABEL_SCALE for h in labels.values())
        md = view.readout_md.content
        assert _font_px(md, "presenter-readout") >= 28 and "font-family:monospace" in md
        r = s.pose_state().readout("WORLD")
        for name, v in (("X", r.x_mm), ("Z", r.z_mm)):
            assert f"{name}&nbsp;" + f"{v:8.2f}".replace(" ", "&nbsp;") in md
        assert f"A&nbsp;{r.a_deg:.2f}&nbsp;&nbsp;B&nbsp;{r.b_deg:.2f}" in md      # A B C on one smaller line
        dist = f"{s.pose_state().touch.distance_mm:.2f}"
        assert dist in md
        # the readout follows a jog
        s.moved(s.controller.jog_joint(0, 5.0))
        r2 = s.pose_state().readout("WORLD")
        assert abs(r2.y_mm - r.y_mm) > 1.0
        assert f"{r2.y_mm:8.2f}".replace(" ", "&nbsp;") in view.readout_md.content
        # Hide distance hides it in the presenter readout too
        s.set_hide_distance(True)
        assert dist not in view.readout_md.content and "hidden" in view.readout_md.content
        choose(view.toggle, False, s.client)
        assert not view.folder.visible and view.panel_width_px == NORMAL_WIDTH_PX
        assert all(h.font_screen_scale == 1.0 for h in labels.values())
    finally:
        c.close()


def test_presenter_step_list_marks_the_current_step_and_the_chart_is_tall(app_factory) -> None:
    app = app_factory(presenter=True)
    c = DrainingClient(app.port)
    try:
        s = _session(app)
        view = s.views["presenter"]
        assert view.toggle.value is True and view.folder.visible
        assert "No wizard running" in view.steps_md.content
        cal = s.views["calibrate"]
        click(cal.start, s.client)
        wiz = cal.workflow.wizard
        md = view.steps_md.content
        assert _font_px(md, "presenter-steps") >= 18
        titles = [st.title for st in wiz.steps]
        at = [md.index(f"{k + 1}. {t}") for k, t in enumerate(titles)]
        assert at == sorted(at) and md.count('white-space:nowrap') == len(titles)   # in order, none split
        assert f'<b class="current-step">▶ 1. {titles[0]}</b>' in md
        assert not view.chart.visible
        for _ in range(8):
            if cal.workflow.result is not None:
                break
            click(cal.steps.auto_touch, s.client)
            if cal.workflow.result is None and wiz.step_index == 1:
                assert f'<b class="current-step">▶ 2. {titles[1]}</b>' in view.steps_md.content
                assert f"✔ 1. {titles[0]}" in view.steps_md.content
        res = cal.workflow.result
        assert res is not None and '<b class="current-step">▶ Result</b>' in view.steps_md.content
        assert view.chart.visible and view.chart.height == CHART_HEIGHT_PX
        assert list(view.chart.data[1][:len(res.per_touch_error_mm)]) == pytest.approx(res.per_touch_error_mm, abs=1e-9)  # exact touches: errors ~1e-11 mm
    finally:
        c.close()


def test_presenter_markdown_escapes_text_and_formats_numbers_only() -> None:
    md = presenter_readout_markdown(PoseReadout("WORLD<script>", 525.0, -0.004, 400.0, 180.0, 0.0, -90.0), None)
    assert "<script>" not in md and "&lt;script&gt;" in md and "hidden" in md
    assert _font_px(md, "presenter-readout") == READOUT_FONT_PX >= 28

    class Step:
        def __init__(self, i: int, title: str, recorded: bool) -> None:
            self.index, self.title, self.recorded = i, title, recorded

    class Wiz:
        title = "XYZ <b>4</b>"
        steps = (Step(0, "<img src=x>", True), Step(1, "Touch 2", False))
        step_index, is_complete, result = 1, False, None

    md = presenter_steps_markdown(Wiz())
    assert "<img" not in md and "&lt;img src=x&gt;" in md and "<b>4</b>" not in md
    assert '<b class="current-step">▶ 2. Touch 2</b>' in md


def test_presenter_option_of_the_cli() -> None:
    assert build_parser().parse_args(["--presenter"]).presenter is True
    assert build_parser().parse_args([]).presenter is False
