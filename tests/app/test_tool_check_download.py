"""The Tool tab and the touch list: "Check" (the TCP check of a saved or the active
tool: deviation per rotation, implied TCP error; the robot does not move), controller files
downloaded to the clicking browser (each parsed back by tcpcal's own parser; a refusal is one
notification), and "Export CSV" of the touches with joint values, solved by ``tcpcal solve xyz4``.
In-process server, headless websocket clients as browsers (``guiclick``)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from support.app_page import AppPage, true_tip_at, truth_tool
from support.guiclick import click
from support.wsclient import DrainingClient, wait_until

from tcp_pendant.controller import builtin_tools
from tcp_pendant.serve.server import PendantApp
from tcp_pendant.text_escape import escape_markdown
from tcp_pendant.views.tool_panel import CONTROLLER_FILE_REFUSED
from tcp_pendant.views.touch_list import TOUCHES_FILENAME, touches_csv_text
from tcpcal.cli import main as tcpcal_main
from tcpcal.controllers import CONTROLLER_FORMATS, parse_tool_file
from tcpcal.origin import solve_xyz4
from tcpcal.tool import Tool


class Page(AppPage):
    """One connected browser: its session, views and what was sent to it."""

    def __init__(self, app: PendantApp) -> None:
        super().__init__(app)
        self.sent: list[tuple[str, bytes]] = []
        self.client.send_file_download = lambda name, data, *a, **k: self.sent.append((name, data))  # type: ignore
        self.tools = self.session.views["tools"]
        self.touches = self.session.views["touches"]

    def select_slot(self, slot: int) -> None:
        opt = next(o for o in self.tools.slots.options if o.startswith(f"{slot}:") or o.startswith(f"{slot} "))
        self.choose(self.tools.slots, opt)


pytestmark = pytest.mark.app_page(cls=Page)


# ----------------------------------------------------------------------------- Check
def test_check_of_the_true_data_stays_put_and_a_1mm_error_shows(page) -> None:
    p = page({1: truth_tool("pointer", "Exact"), 2: truth_tool("pointer", "Off", (0.0, 1.0, 0.0))})
    q = p.session.controller.q_rad
    p.select_slot(1)
    p.click(p.tools.check)
    job, res = p.tools.last_check
    assert res.implied_tcp_error_mm < 0.01 and res.max_deviation_mm < 0.01
    md = p.tools.check_md.content
    assert "TCP check of slot 1: Exact" in md and "TCP good" in md
    assert all(f"| {r.label} | {r.deviation_mm:.3f} |" in md for r in res.rotations)
    p.select_slot(2)
    p.choose(p.tools.check_angle, 20.0)
    p.click(p.tools.check)
    job, res = p.tools.last_check
    assert res.angle_deg == 20.0 and res.all_reached
    assert res.implied_tcp_error_mm == pytest.approx(1.0, abs=0.01)
    assert "TCP off by 1.000 mm" in p.tools.check_md.content
    assert "(+0.000, -1.000, +0.000) mm in FLANGE axes" in p.tools.check_md.content   # no "-0.000"
    np.testing.assert_array_equal(p.session.controller.q_rad, q)    # the robot did not move
    assert p.notes == []


def test_in_an_exercise_the_check_of_a_zero_tool_shows_a_reading_not_the_answer(page) -> None:
    """The one-click answer: X = Y = Z = 0 saved, then Check. In an exercise the Check shows
    what a technician would see - how far the tip swung per rotation, read to 0.5 mm - and no
    implied TCP error vector or correction (which would be the true TCP)."""
    from tcp_pendant.classroom.exercise_rules import class_rules

    p = page({1: Tool(name="Zero", tcp_mm=(0.0, 0.0, 0.0))})
    p.session.set_rules(class_rules("mystery"))
    p.select_slot(1)
    p.click(p.tools.check)                  # from the ready pose: no spike to read the swing against
    assert p.tools.last_check is None and p.notes and "bring the tool tip to the reference tip" in p.notes[-1][1]
    s = p.session
    true_tip_at(s, (0.0, 0.0, 2.0))          # the tip brought to the reference tip (as a touch would)
    c = s.controller
    p.click(p.tools.check)
    job, res = p.tools.last_check
    true_tcp = np.asarray(c.mounted_tool.T_flange_tool_true)[:3, 3] * 1000.0
    assert res.implied_tcp_error_mm == pytest.approx(np.linalg.norm(true_tcp), abs=0.05)  # computed ...
    md = p.tools.check_md.content                                     # ... but not shown
    assert "Implied" not in md and "FLANGE axes" not in md and "by eye" in md
    rows = re.findall(r"^\| [+-][ABC] 30° \| (\S+) \|", md, flags=re.M)
    assert len(rows) == 6 and all(float(v) % 0.5 == 0.0 for v in rows)
    assert [float(v) for v in rows] == [round(r.deviation_mm * 2) / 2 for r in res.rotations]
    assert "calibrate the tool again" in md


def test_check_active_tool_and_no_active_tool(page) -> None:
    p = page({3: truth_tool("pointer", "Pointer cal")})
    p.click(p.tools.check_active)
    assert p.notes and "No tool data is active" in p.notes[-1][1] and p.tools.last_check is None
    p.select_slot(3)
    p.click(p.tools.activate)
    p.click(p.tools.check_active)
    job, res = p.tools.last_check
    assert job.title == "slot 3: Pointer cal" and res.implied_tcp_error_mm < 0.01


def test_check_finds_the_bend_of_a_bent_tool_with_the_stale_data(page) -> None:
    p = page({1: truth_tool("pointer", "Stale")})
    world = p.session.set_scenario("bent_tool", 6)
    p.select_slot(1)
    p.click(p.tools.check)
    _, res = p.tools.last_check
    assert res.implied_tcp_error_mm == pytest.approx(world.tool_bend.shift_mm, rel=0.05, abs=0.1)
    assert "TCP off by" in p.tools.check_md.content


def test_check_escapes_the_tool_name_and_refuses_a_bad_angle(page) -> None:
    hostile = "<img src=x>**b**[a](j:x)"
    p = page({1: truth_tool("pointer", hostile)})
    p.select_slot(1)
    p.click(p.tools.check)
    md = p.tools.check_md.content
    assert escape_markdown(hostile) in md and "<img" not in md
    p.choose(p.tools.check_angle, 120.0)
    p.click(p.tools.check)
    assert "at most 90 degrees" in p.notes[-1][1]


# ----------------------------------------------------------------------------- controller files
@pytest.mark.parametrize("fmt", sorted(CONTROLLER_FORMATS))
def test_each_controller_file_downloads_and_parses_back(page, fmt: str) -> None:
    tool = Tool("Torch_A", (12.5, -3.25, 180.125), (10.0, -20.0, 30.0))
    p = page({2: tool})
    f = CONTROLLER_FORMATS[fmt]
    p.select_slot(2)
    p.choose(p.tools.file_fmt, f.label)
    p.click(p.tools.download)
    ((name, data),) = p.sent
    assert name == f.filename.format(n=2)
    entries = parse_tool_file(data.decode("utf-8"), fmt)
    entry = next(e for e in entries if e.number in (2, None)) if len(entries) > 1 else entries[0]
    np.testing.assert_allclose(entry.tcp_mm, tool.tcp_mm, atol=1e-3)
    np.testing.assert_allclose(entry.rotation, tool.rotation, atol=1e-5)
    assert p.notes == []


def test_a_refused_tool_is_one_notification_and_nothing_is_sent(page) -> None:
    p = page({1: Tool("tool0", (0.0, 0.0, 100.0))})
    p.select_slot(1)
    p.choose(p.tools.file_fmt, CONTROLLER_FORMATS["abb"].label)
    p.click(p.tools.download)
    assert p.sent == []
    assert len(p.notes) == 1 and p.notes[0][0] == CONTROLLER_FILE_REFUSED and "tool0" in p.notes[0][1]


def test_shared_mode_sends_the_file_to_the_browser_that_clicked(app_factory) -> None:
    app = app_factory({1: Tool("T1", (0.0, 0.0, 100.0))}, shared=True)
    ws = [DrainingClient(app.port), DrainingClient(app.port)]
    try:
        wait_until(lambda: len(app.server.get_clients()) == 2, what="two browsers")
        a, b = app.server.get_clients().values()
        got: dict[int, list[str]] = {a.client_id: [], b.client_id: []}
        for c in (a, b):
            c.send_file_download = lambda name, data, *_, _id=c.client_id, **__: got[_id].append(name)
        panel = app.shared_session.views["tools"]
        app.shared_session.tools.reload_library()
        click(panel.download, b)
        assert got == {a.client_id: [], b.client_id: ["tool1_config.dat"]}
    finally:
        for w in ws:
            w.close()


# ----------------------------------------------------------------------------- touches CSV
def test_touch_csv_with_joints_round_trips_through_tcpcal_solve_xyz4(page, tmp_path: Path, capsys) -> None:
    p = page()
    s, c = p.session, p.session.controller
    for tilt, az in ((0, 0), (30, 0), (30, 120), (35, 240), (25, 60)):
        assert c.auto_approach(tilt_deg=tilt, azimuth_deg=az).ok
        s.moved()
        p.click(p.touches.record)
    p.click(p.touches.export_csv)
    ((name, data),) = p.sent
    assert name == TOUCHES_FILENAME
    text = data.decode("utf-8")
    assert text.splitlines()[0] == "name,x,y,z,a,b,c,j1,j2,j3,j4,j5,j6"
    path = tmp_path / "touches.csv"
    path.write_text(text)
    capsys.readouterr()
    assert tcpcal_main(["solve", "xyz4", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    R = np.array([t.T_world_flange[:3, :3] for t in s.touches])
    P = np.array([t.T_world_flange[:3, 3] * 1000.0 for t in s.touches])
    direct = solve_xyz4(R, P)
    np.testing.assert_allclose(out["tcp_mm"], direct.tcp, atol=1e-9)
    np.testing.assert_allclose(out["tcp_mm"], builtin_tools()["pointer"].T_flange_tool_true[:3, 3] * 1000, atol=1e-6)
    np.testing.assert_allclose(out["joints_deg"], [t.joints_deg for t in s.touches], atol=1e-12)


def test_touch_csv_without_touches_is_refused(page) -> None:
    p = page()
    p.click(p.touches.export_csv)
    assert p.sent == [] and "No touch recorded" in p.notes[-1][1]
    with pytest.raises(ValueError, match="No touch"):
        touches_csv_text([])
