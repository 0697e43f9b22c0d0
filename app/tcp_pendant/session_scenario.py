"""The systematic error a session plays for training (``Session.scenario_player``).

The physical world changes, the controller's beliefs do not (``controller.scenarios``):
``robot_accuracy`` sets the controller's ``true_kinematics`` (readouts, recorded poses and jogs
stay on the model); ``bent_tool`` bolts on the bent version of the mounted tool (and of any tool
mounted later: :meth:`ScenarioPlayer.physical`; the library data stay as they were);
``moved_reference`` knocks the reference tip after the scenario's touch ``k`` counted from when
it was set (free touches and wizard touches: :meth:`ScenarioPlayer.move_reference`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from tcp_pendant.controller import ToolModel, VirtualController
from tcp_pendant.controller.scenarios import Scenario, ScenarioWorld, bent_tool, realize

__all__ = ["ScenarioPlayer"]


class ScenarioPlayer:
    """Plays one scenario on a session's controller; the session's ``set_scenario`` command
    drives it and signals.

    Attributes:
        scenario: the systematic error played (off by default).
        world: the drawn errors of :attr:`scenario` (None while it is off).
    """

    def __init__(self, controller: VirtualController, records_total: Callable[[], int]) -> None:
        """``records_total()``: the touches the session recorded so far (free ones and the
        wizards' poses)."""
        self._controller = controller
        self._records_total = records_total
        self.scenario = Scenario()
        self.world: ScenarioWorld | None = None
        self._tip0: np.ndarray | None = None    # the reference tip before a scenario moved it
        self._beam_pinned = False               # the moved reference pinned the default beam sensor
        self._bent: dict[str, ToolModel] = {}   # tool key -> its bent version (bent_tool)
        self._unbent: dict[int, ToolModel] = {}  # id(bent version) -> the tool as it was
        self._base = 0                          # touches recorded before the scenario was set
        self._touches = 0                       # touches recorded since (never decreases)

    def play(self, kind: str, seed: int = 0) -> ScenarioWorld:
        """Play ``kind`` ("off", "bent_tool", "robot_accuracy" or "moved_reference"), its errors
        drawn from ``seed``; the previous scenario is undone first (the tip back where it was,
        the unbent tool).

        Raises:
            ControllerError: unknown kind or a bad seed (names what to choose).
        """
        scenario = Scenario(kind, seed=seed)  # type: ignore[arg-type]
        c = self._controller
        if self._tip0 is not None:              # undo the previous one
            c.set_reference_tip(self._tip0)
        if self._beam_pinned:                   # the default beam follows the tip again
            c.set_beam_sensor(None)
            self._beam_pinned = False
        unbent = self._unbent.get(id(c.mounted_tool), c.mounted_tool)
        self._bent.clear()
        self._unbent.clear()
        self._tip0 = c.reference_tip_world_m
        world = realize(scenario, c.kinematics, unbent)
        self.scenario = scenario
        self.world = None if scenario.kind == "off" else world
        c.set_true_kinematics(None if world.true_kinematics is c.kinematics else world.true_kinematics)
        if scenario.kind == "bent_tool":
            self._bent[unbent.key] = world.tool_true
            self._unbent[id(world.tool_true)] = unbent
        c.mount_tool(self.physical(unbent))
        self._base = self._records_total()
        self._touches = 0
        self.move_reference()
        return world

    def physical(self, tool: ToolModel) -> ToolModel:
        """The tool as it physically is under the scenario (bent_tool: its bent version)."""
        tool = self._unbent.get(id(tool), tool)
        world = self.world
        if world is None or world.tool_bend is None:
            return tool
        bent = self._bent.get(tool.key)
        if bent is None:
            bent = self._bent[tool.key] = bent_tool(tool, world.tool_bend)
            self._unbent[id(bent)] = tool
        return bent

    def move_reference(self) -> bool:
        """Moved reference tip: place the tip for the touches recorded since the scenario was
        set (the count never decreases: a knocked tip stays knocked). True if it moved."""
        world = self.world
        if world is None or world.reference_move is None or self._tip0 is None:
            return False
        self._touches = max(self._touches, self._records_total() - self._base)
        tip = world.reference_move.tip_world_m(self._tip0, self._touches)
        c = self._controller
        if np.array_equal(tip, c.reference_tip_world_m):
            return False
        if c.beam_sensor_is_default and not self._beam_pinned:
            # the knock moves the spike, not the beam device that stands beside it
            c.set_beam_sensor(c.beam_sensor)
            self._beam_pinned = True
        c.set_reference_tip(tip)
        return True
