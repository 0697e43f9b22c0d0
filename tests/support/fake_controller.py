"""A test double of the controller for auto-touch (the contract of docs/architecture.md): it places
the true tool exactly as ``VirtualController.auto_approach`` promises (the reference tip at
``tip_offset_tool_mm`` in TOOL coordinates, tool X tilted from WORLD -Z) with the synthetic
geometry of ``tests/wizards/conftest.py`` (its ``synth`` fixture), and records every call."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from tcpcal.tool import Tool


@dataclass
class FakeController:
    synth: SimpleNamespace
    tools: dict
    mounted_tool: SimpleNamespace
    fail_first: int = 0
    calls: list = field(default_factory=list)
    T: np.ndarray = field(default_factory=lambda: np.eye(4))

    @property
    def reference_tip_world_m(self):
        return self.synth.reference_mm / 1000.0

    def _synth_tool(self):
        return self.synth.tools[self.mounted_tool.key]

    def mount_tool(self, tool):
        self.mounted_tool = tool

    def T_world_flange(self):
        return self.T.copy()

    def auto_approach(self, *, tilt_deg, azimuth_deg, spin_deg=0.0, sigma_mm=0.0,
                      tip_offset_tool_mm=(0.0, 0.0, 0.0), rng=None):
        self.calls.append(("approach", tilt_deg, azimuth_deg, spin_deg, tuple(tip_offset_tool_mm)))
        if self.fail_first > 0:
            self.fail_first -= 1
            return SimpleNamespace(ok=False, message="unreachable from this direction")
        noise = rng.normal(0.0, sigma_mm, 3) if sigma_mm > 0 else None
        self.T = self.synth.flange_pose_m(self._synth_tool(),
                                          self.synth.tool_orientation(tilt_deg, azimuth_deg, spin_deg),
                                          offset_tool_mm=tip_offset_tool_mm, noise_mm=noise)
        return SimpleNamespace(ok=True, message="")

    def move_true_tool_to(self, T_world_tool):
        self.calls.append(("move", T_world_tool.copy()))
        st = self._synth_tool()
        T = np.eye(4)
        T[:3, :3] = T_world_tool[:3, :3] @ st.R_flange_tool.T
        T[:3, 3] = T_world_tool[:3, 3] - T[:3, :3] @ (st.tcp_mm / 1000.0)
        self.T = T
        return SimpleNamespace(ok=True, message="")


def models(synth):
    return {k: SimpleNamespace(key=k, label=k, T_flange_tool_true=t.T_flange_tool_true_m)
            for k, t in synth.tools.items()}


def fake(synth, key="pointer", **kw):
    m = models(synth)
    return FakeController(synth, m, m[key], **kw)


def exact_tool(synth, key):
    t = synth.tools[key]
    return Tool.from_rotation(key, tuple(t.tcp_mm), t.R_flange_tool)
