"""One owner of each piece of session state and one change signal.

In-process server and headless websocket clients (the browsers); clicks arrive as a browser's
would (``guiclick``). What is checked:

* a trainee's saved and activated tool is hers: a trainee connecting later starts with no
  active tool (TCP = flange) and the straight pointer; "No tool" on one page changes no other
  page; the library's ``active_slot`` is not written by a per-browser session;
* ``--shared`` starts with the library's active tool and writes it on Activate;
* a command ends in ONE change signal, and the views follow it without calling each other
  (the scene and the Tool tab follow a tool mounted by a command that knows no view);
* ``CalibrationWorkflow.wizard`` is a plain getter.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.controller import builtin_tools
from tcp_pendant.session import SessionChange

from support.calib_page import Page


pytestmark = pytest.mark.app_page(cls=Page, seed=5)


def _save_torch_as(p: Page, name: str) -> int:
    """Trainee ``p`` mounts the torch (Tool tab), calibrates it (4 auto-touches) and saves it."""
    v, tools = p.view, p.session.views["tools"]
    p.choose(tools.mounted, builtin_tools()["torch"].label)
    p.click(v.start)
    for _ in range(4):
        p.click(v.steps.auto_touch)
    assert v.workflow.result is not None
    p.choose(v.result.save_name, name)
    p.click(v.result.save)
    slot = p.session.tools.active_slot
    assert slot is not None and p.session.controller.active_tool.name == name
    return slot


def test_a_trainees_tool_does_not_become_the_next_trainees(page) -> None:
    a = page()
    app = a.app
    slot = _save_torch_as(a, "Torch A")
    a.choose(a.session.views["tools"].slots, f"{slot}: Torch A")
    a.click(a.session.views["tools"].activate)
    assert ToolLibrary(app.library.path).active_slot() is None      # the file's is not a trainee's

    b = page(on=app)                                 # B connects later
    sb = b.session
    assert sb.tools.active_slot is None and sb.controller.active_tool is None
    assert sb.controller.mounted_tool.key == "pointer"
    np.testing.assert_allclose(sb.controller.T_flange_tool, np.eye(4))
    assert "Active tool data: none (FLANGE) · mounted: " in sb.views["pendant"].tcp_md.content
    assert not sb.views["scene"]._active_axes.visible
    assert f"{slot}: Torch A" in sb.views["tools"].slots.options   # ... but sees the stored tool

    b.click(sb.views["tools"].deactivate)            # B's "No tool" is B's
    assert a.session.tools.active_slot == slot and a.session.controller.active_tool.name == "Torch A"
    assert "TOOL Torch A" in a.session.views["pendant"].tcp_md.content
    b.choose(sb.views["tools"].slots, f"{slot}: Torch A")
    b.click(sb.views["tools"].activate)              # B activates it: B's only
    assert sb.tools.active_slot == slot
    a.click(a.session.views["tools"].deactivate)     # A's "No tool" is A's
    assert a.session.controller.active_tool is None and sb.controller.active_tool.name == "Torch A"
    assert ToolLibrary(app.library.path).active_slot() is None


def test_shared_mode_starts_with_the_librarys_active_tool_and_sets_it(app_factory, tmp_path: Path) -> None:
    lib = ToolLibrary(tmp_path / "tools.json")
    lib.save(1, Tool(name="Pen", tcp_mm=(0.0, 0.0, 150.0)))
    lib.save(2, Tool(name="Torch", tcp_mm=(0.0, 0.0, 200.0)), activate=True)
    app = app_factory(shared=True, seed=5)
    s = app.shared_session
    assert s is not None and s.tools.active_slot == 2 and s.controller.active_tool.name == "Torch"
    with s.lock:
        s.tools.activate(1)
    assert ToolLibrary(lib.path).active_slot() == 1                # the shared start tool
    assert "TOOL Pen" in s.views["pendant"].tcp_md.content


def test_a_command_ends_in_one_change_signal_and_every_view_follows(page) -> None:
    p = page()
    s = p.session
    changes: list[SessionChange] = []
    s.subscribe(changes.append)
    torch = builtin_tools()["torch"]
    with s.lock:
        s.tools.mount_tool(torch)                          # a command that knows no view
    (change,) = changes
    assert change.tool and change.pose and change.state is not None
    assert change.state.key[3] == id(torch)          # the pose state is the new tool's
    assert s.views["scene"]._shown_mounted is torch                  # the scene reconciled
    assert s.views["tools"].mounted.value == torch.label              # the Tool tab followed

    changes.clear()
    p.click(p.view.start)                            # a Calibrate click: one signal at its end
    assert len(changes) == 1 and changes[0].wizard and changes[0].pose
    changes.clear()
    p.click(p.view.steps.auto_touch)                 # moves the robot and records: still one
    assert len(changes) == 1 and changes[0].pose and changes[0].wizard
    assert p.view.workflow.wizard.steps[0].recorded

    changes.clear()
    with s.lock:
        s.tools.set_active_data(Tool(name="Typed", tcp_mm=(0.0, 0.0, 123.0)))
    (change,) = changes
    assert change.tool and s.tools.active_slot is None
    np.testing.assert_allclose(s.views["scene"]._active_axes.position, (0.0, 0.0, 0.123), atol=1e-12)
    assert s.views["scene"]._active_label.text == "TOOL Typed"
    assert "TOOL Typed" in s.views["pendant"].tcp_md.content


def test_the_gizmos_stop_reaches_the_status_line_through_the_signal(page) -> None:
    p = page()
    s = p.session
    changes: list[SessionChange] = []
    s.subscribe(changes.append)
    scene = s.views["scene"]
    scene._gizmo_pending = (np.array([1.0, 0.0, 0.0, 0.0]), np.array([5.0, 0.0, 0.5]))   # out of reach
    with s.lock:
        scene._apply_gizmo()
    (change,) = changes
    assert change.jog is not None and not change.jog.ok
    assert change.jog.message in s.views["pendant"].status_md.content


def test_workflow_wizard_is_a_plain_getter(page) -> None:
    p = page()
    wf = p.view.workflow
    p.click(p.view.start)
    w = wf.wizard
    calls: list[Any] = []
    real = w.note_mounted_tool
    w.note_mounted_tool = lambda *a, **k: (calls.append(a), real(*a, **k))  # type: ignore[method-assign]
    for _ in range(5):
        assert wf.wizard is w and wf.is_open
    p.view.render()                                  # a whole re-render reads it many times
    assert calls == []
    with p.session.lock:
        p.session.tools.mount_tool(builtin_tools()["gripper"])    # the wizard learns it from the signal
    assert calls and calls[-1][0] == "gripper"
    calls.clear()
    with p.session.lock:
        assert wf.auto_touch(AutoTouchRequest()).ok   # the command tells it explicitly
    assert calls
